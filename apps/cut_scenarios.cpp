// Frog cut scenarios (see cut_scenarios.hpp).
#include "cut_scenarios.hpp"

#include <algorithm>
#include <cmath>

namespace tissue::apps {

std::vector<CutScenario> frog_cut_scenarios() {
  // Strokes across the body (y from -0.06 to 0.06 m clears the legs' width), along it, diagonally,
  // through the head, and through the shins.
  const CutStroke across_body{"across-body", {0.002, -0.06}, {0.002, 0.06}};
  const CutStroke along_body{"along-body", {-0.09, 0.0031}, {0.075, 0.0031}};
  const CutStroke diagonal{"diagonal", {-0.035, -0.06}, {0.035, 0.06}};
  const CutStroke across_head{"across-head", {0.041, -0.04}, {0.041, 0.04}};
  const CutStroke left_shin{"left-shin", {-0.055, 0.07}, {-0.055, 0.005}};
  const CutStroke right_shin{"right-shin", {-0.055, -0.07}, {-0.055, -0.005}};
  // Issue 21, several cuts per tet: the other diagonal (an X with `diagonal`), and a triangle of three
  // strokes on the back that overshoot each other's ends (the corners' tets cut twice).
  const CutStroke other_diagonal{"other-diagonal", {0.035, -0.06}, {-0.035, 0.06}};
  const CutStroke triangle_base{"triangle-base", {-0.045, -0.03}, {0.025, -0.03}};
  const CutStroke triangle_left{"triangle-left", {-0.045, -0.04}, {0.0, 0.035}};
  const CutStroke triangle_right{"triangle-right", {0.025, -0.04}, {-0.01, 0.035}};
  return {
      {"test2-across-body", {across_body}},
      {"test3-along-body", {along_body}},
      {"test4-diagonal", {diagonal}},
      {"test5-body-and-head", {across_body, across_head}},
      {"test6-two-legs", {left_shin, right_shin}},
      {"test7-body-head-leg", {across_body, across_head, left_shin}},
      {"test8-across-and-along", {across_body, along_body}},
      {"test9-x", {diagonal, other_diagonal}},
      {"test10-triangle", {triangle_base, triangle_left, triangle_right}},
  };
}

int run_stroke(Tissue& tissue, const CutStroke& stroke, const StrokeSettings& settings,
               const std::function<void(const TissueStepReport&)>& on_step) {
  const double length_m = (stroke.to_m - stroke.from_m).norm();
  const double step_m = settings.speed_m_per_s * tissue.settings().step_size_s;
  const int steps = std::max(1, static_cast<int>(std::ceil(length_m / step_m)));
  const auto pose = [&](double s, ToolMode mode) {
    const Eigen::Vector2d xy = stroke.from_m + s * (stroke.to_m - stroke.from_m);
    return ToolPose{Eigen::Vector3d(xy.x(), xy.y(), settings.tip_height_m), Eigen::Quaterniond::Identity(), mode};
  };
  for (int n = 0; n <= steps; ++n) {
    tissue.set_tool(pose(static_cast<double>(n) / steps, ToolMode::scalpel));
    on_step(tissue.step());
  }
  tissue.set_tool(pose(1.0, ToolMode::none));
  on_step(tissue.step());
  return steps + 2;
}

}  // namespace tissue::apps
