// The tool's pose as the host drives it, its one check, and the hand's top speed as a pose rule.
#pragma once

#include "core/parameter_error.hpp"
#include "ports/tool.hpp"

#include <Eigen/Geometry>

#include <string_view>

namespace tissue {

/// Parses "none" / "probe" / "scalpel"; throws ParameterError otherwise.
ToolMode parse_tool_mode(std::string_view name);

/// The tool as the host drives it. The tool axis is the local +z axis, from the tip toward the
/// handle; the scalpel's cutting edge is the segment from the tip along that axis.
/// A ball-ended probe (InteractionSettings::probe_radius_m > 0) is posed by its ball's centre and
/// touches the tissue with the ball's pole along the axis, toward the tip (ToolKinematics::touching).
struct ToolPose {
  Eigen::Vector3d tip_position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  ToolMode mode = ToolMode::none;
};

/// Throws ParameterError for a non-finite position or a non-finite or zero quaternion.
void validate(const ToolPose& pose);

/// The tool axis (local +z, from the tip toward the handle) of a unit quaternion (ports/tool.hpp).
inline Eigen::Vector3d tool_axis(const Eigen::Quaterniond& orientation) {
  const auto axis = tissue::tool_axis(orientation.w(), orientation.x(), orientation.y(), orientation.z());
  return {axis[0], axis[1], axis[2]};
}

/// The pose a tool reaches from `previous` toward `target` when no point of its blade (blade_length_m
/// along the axis from the tip) may travel more than max_step_m: `target` itself when it is within
/// reach, when the mode changes or when the tool does nothing; otherwise the fraction of the way
/// (position linear, orientation along the shorter arc) whose path bound |tip move| + L angle is
/// max_step_m.
ToolPose reachable_pose(const ToolPose& previous, const ToolPose& target, double blade_length_m, double max_step_m);

}  // namespace tissue
