// ToolPose's check and the reachable pose (see tool_pose.hpp).
#include "core/tool/tool_pose.hpp"

#include <cmath>
#include <string>

namespace tissue {

ToolMode parse_tool_mode(std::string_view name) {
  if (const auto mode = tool_mode_named(name)) return *mode;
  throw ParameterError("unknown tool mode '" + std::string(name) + "' (expected none, probe or scalpel)");
}

void validate(const ToolPose& pose) {
  if (!pose.tip_position_m.allFinite()) throw ParameterError("tool position must be finite");
  const double norm = pose.orientation.coeffs().norm();
  if (!std::isfinite(norm) || !(norm > MIN_ORIENTATION_NORM)) {
    throw ParameterError("tool orientation must be a finite, non-zero quaternion");
  }
}

ToolPose reachable_pose(const ToolPose& previous, const ToolPose& target, double blade_length_m, double max_step_m) {
  // Only a tool that interacts in both poses is held to the hand's speed; a mode switch or a tool
  // that does nothing goes where it is put.
  if (target.mode != previous.mode || target.mode == ToolMode::none || !(max_step_m > 0.0)) return target;
  // With the position moved linearly and the orientation along the shorter arc, no point of the
  // blade travels farther than |tip move| + L * turn angle: the fraction f of the way keeps every
  // point's path, and so its chord, within f times that.
  const double path_m = (target.tip_position_m - previous.tip_position_m).norm() +
                        blade_length_m * previous.orientation.angularDistance(target.orientation);
  if (!(path_m > max_step_m)) return target;
  const double fraction = max_step_m / path_m;
  ToolPose reached = target;
  reached.tip_position_m = previous.tip_position_m + fraction * (target.tip_position_m - previous.tip_position_m);
  reached.orientation = previous.orientation.slerp(fraction, target.orientation).normalized();
  return reached;
}

}  // namespace tissue
