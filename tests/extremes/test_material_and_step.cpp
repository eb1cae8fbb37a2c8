// Extremes of the material and of the step size. A cantilever (10 x 2 x 2 cubes of 1 cm, clamped
// at x = 0) released from rest under gravity: Young's modulus from 100 Pa (it falls like a rope)
// to 1 GPa (its element modes are near 100 kHz), Poisson's ratio 0 to 0.499 (nearly
// incompressible: lambda = 166 mu); steps of 10 us and 0.1 s, on the beam and on the pad with the
// probe pressed into its top.
#include "extremes_support.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

namespace tissue::extremes {
namespace {

std::string modulus_text(double young_modulus_pa) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0e", young_modulus_pa);
  return text;
}

// The beam falls for 0.1 s under gravity (100 steps of 1 ms; the soft one 5 cm, as in free fall).
Case material_case(double young_modulus_pa, double poisson_ratio, std::string id) {
  Case c;
  c.id = std::move(id);
  char label[96];
  std::snprintf(label, sizeof label, "beam under gravity, E = %s Pa, nu = %g", modulus_text(young_modulus_pa).c_str(),
                poisson_ratio);
  c.label = label;
  c.scene = [young_modulus_pa, poisson_ratio] {
    Scene scene = cantilever_beam();
    scene.settings.body.material.young_modulus_pa = young_modulus_pa;
    scene.settings.body.material.poisson_ratio = poisson_ratio;
    return scene;
  };
  c.script = [](Run& run) { run.steps(phase_steps(100)); };
  if (young_modulus_pa >= 1e9 || poisson_ratio > 0.45) {
    c.may_refuse = {Method::ida_krylov};
    c.refusal_note =
        "GMRES with the diagonal Schur-complement preconditioner crawls on a stiff or nearly "
        "incompressible body: more than IDA_MAX_INTERNAL_STEPS internal steps in one step";
  }
  return c;
}

// The beam under gravity with steps of `step_s` for `steps` steps.
Case beam_step_case(double step_s, int steps, std::string id, std::string label) {
  Case c;
  c.id = std::move(id);
  c.label = std::move(label);
  c.scene = [step_s] {
    Scene scene = cantilever_beam();
    scene.settings.step_size_s = step_s;
    return scene;
  };
  c.script = [steps](Run& run) { run.steps(phase_steps(steps)); };
  return c;
}

// The pad with steps of `step_s`: the probe pressed 5 mm into its top at `speed_m_per_s` (2 mm
// under sanitizers, where IDA takes ~40 ms for each of the 10 us steps), held, lifted;
// `hold_steps` at each end.
Case pad_step_case(double step_s, double speed_m_per_s, int hold_steps, std::string id, std::string label) {
  Case c;
  c.id = std::move(id);
  c.label = std::move(label);
  c.scene = [step_s] {
    Scene scene = pad();
    scene.settings.step_size_s = step_s;
    return scene;
  };
  c.script = [hold_steps, speed_m_per_s](Run& run) {
    const Eigen::Vector3d top(PAD_X_M, PAD_Y_M, PAD_TOP_M);
    const Eigen::Vector3d above = top + Eigen::Vector3d(0.0, 0.0, 0.002);
    run.step_with(ToolPose{above, Eigen::Quaterniond::Identity(), ToolMode::probe});
    const double depth_m = UNDER_SANITIZER ? 0.002 : 0.005;
    move_tool(run, top - Eigen::Vector3d(0.0, 0.0, depth_m), speed_m_per_s, ToolMode::probe);
    run.steps(phase_steps(hold_steps));
    move_tool(run, above, speed_m_per_s, ToolMode::probe);
    run.steps(phase_steps(hold_steps));
  };
  return c;
}

const std::vector<Case>& cases() {
  static const std::vector<Case> all = [] {
    std::vector<Case> list;
    const std::vector<std::tuple<double, const char*>> moduli{{1e2, "Soft"}, {1e5, "Mid"}, {1e9, "Stiff"}};
    const std::vector<std::tuple<double, const char*>> ratios{{0.0, "Nu0"}, {0.3, "Nu03"}, {0.499, "Nu0499"}};
    for (const auto& [modulus, modulus_id] : moduli) {
      for (const auto& [ratio, ratio_id] : ratios) {
        list.push_back(material_case(modulus, ratio, std::string("Beam") + modulus_id + ratio_id));
      }
    }
    list.push_back(beam_step_case(1e-5, 300, "BeamStep1e5", "beam under gravity, h = 1e-5 s (300 steps)"));
    list.push_back(beam_step_case(0.1, 20, "BeamStep01", "beam under gravity, h = 0.1 s (20 steps)"));
    list.back().may_refuse = {Method::ida_krylov};
    list.back().refusal_note = "GMRES crawls through a 0.1 s step of the released beam";
    const std::string depth = UNDER_SANITIZER ? "2 mm" : "5 mm";
    list.push_back(pad_step_case(1e-5, 5.0, 50, "PadStep1e5", "pad: probe pressed " + depth + " at 5 m/s, h = 1e-5 s"));
    list.push_back(pad_step_case(0.1, 0.05, 4, "PadStep01", "pad: probe pressed " + depth + " at 5 cm/s, h = 0.1 s"));
    return list;
  }();
  return all;
}

TISSUE_EXTREMES_SUITE(MaterialAndStep, cases);

}  // namespace
}  // namespace tissue::extremes
