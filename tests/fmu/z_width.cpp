// z_width: the Z-width chart of issue 20 (docs/z_width.png, docs/BENCHMARKS.md "Haptic loop"). For
// hands of 0.05, 0.2 and 0.5 kg with damping 0.5, 2 and 5 N s/m, the stiffest wall on which the hand
// settles (dropped from 1 cm pushing 1 N: below 1 mm/s over the last second of 20 s, no chatter
// above 10 um; 20 s is ten decay times of the slowest hand, 2 m / b = 2 s), up to which every wall of
// a log grid over [30, 1e5] N/m settles, for
//   (a) an ideal wall rendered directly at 1 kHz (f = -K z held over each tick),
//   (b) HapticLoop.fmu with 100 Hz samples one step late, carrying K_c,
//   (c) the same with force-only samples;
// with Colgate and Schenkel's passivity bound b > K T / 2 (K = 2 b / T) drawn for reference.
//   z_width [out.png [device.maxForceRate N/s]]
#include "hand_on_tissue.hpp"

#include "compare/plot_png.hpp"
#include "output/png_renderer.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

using namespace tissue::host;
using namespace tissue::host::hand_test;

namespace {

constexpr double LOWEST_N_PER_M = 30.0, HIGHEST_N_PER_M = 1e5;
constexpr double SETTLED_SPEED_M_PER_S = 1e-3, CHATTER_M = 10e-6;
constexpr double RUN_S = 20.0;
double g_max_force_rate_n_per_s = 1000.0;  // device.maxForceRate (the FMU's start value unless given)

bool settled(const HandFigures& f) {
  return f.residual_speed_m_per_s < SETTLED_SPEED_M_PER_S && f.chatter_amplitude_m < CHATTER_M;
}

HandSettings hand_of(double mass_kg, double damping_n_s_per_m) {
  HandSettings hand;
  hand.mass_kg = mass_kg;
  hand.damping_n_s_per_m = damping_n_s_per_m;
  hand.push_n = {0.0, 0.0, -1.0};
  return hand;
}

// (a) The hand on an ideal wall rendered at 1 kHz, no haptic loop.
bool settles_on_ideal_wall(const HandSettings& hand, double stiffness_n_per_m) {
  DeviceWaypoint start;
  start.pose.position_m = {0.0, 0.0, 0.01};
  HandDevice device({start}, hand, TICK_S);
  for (int n = 0; n < static_cast<int>(RUN_S / TICK_S); ++n) {
    const double t = n * TICK_S;
    const double z = device.read(t).position_m[2];
    device.write_force(t, {0.0, 0.0, z < 0.0 ? -stiffness_n_per_m * z : 0.0});
  }
  return settled(device.figures());
}

// (b), (c) The hand on HapticLoop.fmu.
bool settles_through_the_loop(const HandSettings& hand, double stiffness_n_per_m, bool reports_stiffness) {
  LoopSettings settings;
  settings.hand = hand;
  settings.duration_s = RUN_S;
  settings.max_force_rate_n_per_s = g_max_force_rate_n_per_s;
  Wall wall(stiffness_n_per_m, reports_stiffness);
  const LoopResult r = run_hand_on(wall, settings);
  return r.completed && settled(r.hand);
}

// The stiffest K of a log grid over [LOWEST, HIGHEST] (24 values, 1.42x apart) below which every
// wall of the grid settles: stability need not be monotonic in K (the controller, the rate limit),
// so a bisection could jump over an unstable band; LOWEST / 1.42 if even LOWEST does not settle.
double z_width(const std::function<bool(double)>& settles) {
  constexpr int STEPS = 24;
  double stable = LOWEST_N_PER_M / std::pow(HIGHEST_N_PER_M / LOWEST_N_PER_M, 1.0 / (STEPS - 1));
  for (int i = 0; i < STEPS; ++i) {
    const double k = LOWEST_N_PER_M * std::pow(HIGHEST_N_PER_M / LOWEST_N_PER_M, static_cast<double>(i) / (STEPS - 1));
    if (!settles(k)) break;
    stable = k;
  }
  return stable;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "z_width.png";
  if (argc > 2) g_max_force_rate_n_per_s = std::atof(argv[2]);
  LogLogPlot plot;
  plot.width = 1100;
  plot.height = 700;
  plot.title = "Z-width: the stiffest wall a hand settles on (dropped from 1 cm, pushing 1 N)";
  plot.x_title = "hand damping b [N s/m]";
  plot.y_title = "wall stiffness K [N/m]";
  const std::vector<double> masses{0.05, 0.2, 0.5}, dampings{0.5, 2.0, 5.0};
  const char* cases[] = {"(a) ideal wall", "(b) loop, K_c", "(c) loop, force only"};
  std::printf("| hand m [kg] | b [N s/m] | (a) ideal 1 kHz wall [N/m] | (b) HapticLoop, K_c [N/m] | (c) force only [N/m] "
              "| 2 b / T [N/m] |\n|---:|---:|---:|---:|---:|---:|\n");
  for (std::size_t c = 0; c < 3; ++c) {
    for (const double m : masses) plot.series.push_back(std::string(cases[c]) + ", " + std::to_string(m).substr(0, 4) + " kg");
  }
  plot.series.push_back("K = 2 b / T");
  for (std::size_t i = 0; i < masses.size(); ++i) {
    for (const double b : dampings) {
      const HandSettings hand = hand_of(masses[i], b);
      const double ideal = z_width([&](double k) { return settles_on_ideal_wall(hand, k); });
      const double with_kc = z_width([&](double k) { return settles_through_the_loop(hand, k, true); });
      const double force_only = z_width([&](double k) { return settles_through_the_loop(hand, k, false); });
      std::printf("| %.2f | %.1f | %.0f | %.0f | %.0f | %.0f |\n", masses[i], b, ideal, with_kc, force_only,
                  2.0 * b / TICK_S);
      // Slightly apart in x so that coinciding points of the three cases stay visible.
      plot.points.push_back({b * 0.97, ideal, i});
      plot.points.push_back({b, with_kc, masses.size() + i});
      plot.points.push_back({b * 1.03, force_only, 2 * masses.size() + i});
    }
  }
  for (const double b : {0.5, 1.0, 2.0, 5.0}) {
    plot.front.push_back(plot.points.size());
    plot.points.push_back({b, 2.0 * b / TICK_S, 3 * masses.size()});
  }
  plot.front_name = "Colgate-Schenkel bound";
  plot.notes.push_back("(a) f = -K z held over each 1 ms tick, no damping; (b), (c) HapticLoop.fmu, samples at 100 Hz one");
  plot.notes.push_back("step late, its contact damped by 2 N s/m + T K_c; settled: under 1 mm/s over the last second of 20 s,");
  plot.notes.push_back("chatter under 10 um; the grid spans 30 N/m (none settles) to 1e5 N/m (all up to it settle).");
  write_png(out, render_log_log_plot(plot));
  std::printf("wrote %s\n", out.c_str());
  return 0;
}
