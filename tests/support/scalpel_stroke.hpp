// A scripted scalpel stroke on a Tissue, as the cutting tests draw it: a vertical blade (tool axis +z,
// its tip at z = -2 cm) moved in a straight line over (x, y) at 0.2 m/s, one Tissue step per position,
// then put away with a step of mode none (so the next stroke starts where it is set next, not here:
// a scalpel moved between two steps sweeps the whole way).
#pragma once

#include "core/tissue.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace tissue::test_support {

/// From (x, y) `from` to `to` with steps of `step_s`; `after_step()` after every step, the last one too.
template <class AfterStep>
void draw_scalpel(Tissue& tissue, const Eigen::Vector2d& from, const Eigen::Vector2d& to, double step_s,
                  AfterStep&& after_step) {
  constexpr double SPEED_M_PER_S = 0.2, TIP_Z_M = -0.02;
  const int steps = static_cast<int>(std::ceil((to - from).norm() / (SPEED_M_PER_S * step_s)));
  for (int n = 0; n <= steps; ++n) {
    const Eigen::Vector2d at = from + (to - from) * n / steps;
    tissue.set_tool(
        ToolPose{Eigen::Vector3d(at.x(), at.y(), TIP_Z_M), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
    tissue.step();
    after_step();
  }
  tissue.set_tool(ToolPose{Eigen::Vector3d(to.x(), to.y(), TIP_Z_M), Eigen::Quaterniond::Identity(), ToolMode::none});
  tissue.step();
  after_step();
}

}  // namespace tissue::test_support
