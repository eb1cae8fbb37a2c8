// hand_on_walls: the closed-loop table of issue 20, measured (a tool, not a test: the figures go to
// docs/BENCHMARKS.md). A 0.2 kg hand pushing down with 1 N (0.5 N on the soft wall) is dropped from
// 1 cm onto a wall at z = 0; HapticLoop.fmu renders it from 100 Hz samples one step late.
//   hand_on_walls [duration_s]
#include "hand_on_tissue.hpp"

#include <cstdio>
#include <cstdlib>
#include <memory>

using namespace tissue::host;
using namespace tissue::host::hand_test;

namespace {

void row(SyntheticTissue& tissue, LoopSettings settings, const char* note) {
  const LoopResult r = run_hand_on(tissue, settings);
  const double static_depth_mm = 1e3 * -settings.hand.push_n[2] /
                                 (tissue.name().rfind("300 ", 0) == 0 ? 300.0 : 2000.0);
  if (!r.completed) {
    std::printf("| %s | b %.1f | %s | failed: %s |\n", tissue.name().c_str(), settings.hand.damping_n_s_per_m, note,
                r.failure.c_str());
    return;
  }
  std::printf(
      "| %s | %.1f | %s | %.2f | %.3f (static %.3f) | %.1f Hz, %.3f mm | %s | %+.2e | %llu | %.2f |\n", tissue.name().c_str(),
      settings.hand.damping_n_s_per_m, note, 1e3 * r.hand.residual_speed_m_per_s, 1e3 * r.penetration_m(),
      static_depth_mm, r.hand.chatter_frequency_hz, 1e3 * r.hand.chatter_amplitude_m,
      std::isnan(r.hand.settle_time_s) ? "never" : (std::to_string(r.hand.settle_time_s) + " s").c_str(),
      r.lowest_one_port_energy_j, static_cast<unsigned long long>(r.samples_refused), r.hand.window_s);
}

}  // namespace

int main(int argc, char** argv) {
  const double duration_s = argc > 1 ? std::atof(argv[1]) : 5.0;
  std::printf(
      "| tissue | hand b [N s/m] | loop | residual speed [mm/s] | mean penetration [mm] | chatter | settled at | lowest "
      "one-port energy [J] | samples refused | window [s] |\n|---|---:|---|---:|---:|---|---|---:|---:|---:|\n");
  for (const double damping : {1.0, 3.0, 5.0}) {
    LoopSettings s;
    s.duration_s = duration_s;
    s.hand.damping_n_s_per_m = damping;
    s.hand.push_n = {0.0, 0.0, -1.0};
    Wall stiff_kc(2000.0, true), stiff_force(2000.0, false);
    for (const bool control : {true, false}) {
      s.passivity_control = control;
      row(stiff_kc, s, control ? "controller on" : "controller off");
    }
    for (const bool control : {true, false}) {
      s.passivity_control = control;
      row(stiff_force, s, control ? "controller on" : "controller off");
    }
    LoopSettings soft = s;
    soft.hand.push_n = {0.0, 0.0, -0.5};
    Wall soft_force(300.0, false);
    for (const bool control : {true, false}) {
      soft.passivity_control = control;
      row(soft_force, soft, control ? "controller on" : "controller off");
    }
    LoopSettings strong = s;
    strong.max_force_n = 100.0;
    strong.max_force_rate_n_per_s = 1e9;
    for (const bool control : {true, false}) {
      strong.passivity_control = control;
      Wall wall(2000.0, true);
      row(wall, strong, control ? "controller on, maxForce 100 N, no rate limit" : "controller off, maxForce 100 N, no rate limit");
    }
    ViscoelasticWall viscous(2000.0, 5.0);
    s.passivity_control = true;
    row(viscous, s, "controller on");
    // Issue 42: force-only walls with a viscous part (c/k one and two sample periods), and the same
    // walls reporting K_c, D_c and the surface near (what the loop does at best).
    for (const double c : {20.0, 40.0}) {
      ViscoelasticWall force_only(2000.0, c, Reports{false, false, false});
      row(force_only, s, "controller on");
      ViscoelasticWall reporting(2000.0, c);
      row(reporting, s, "controller on");
    }
    CorruptedSamples corrupted(std::make_unique<Wall>(2000.0, true), 7);
    row(corrupted, s, "controller on");
  }
  return 0;
}
