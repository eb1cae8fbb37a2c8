// ToolKinematics (see tool_kinematics.hpp).
#include "core/tool/tool_kinematics.hpp"

#include "core/state_error.hpp"

namespace tissue {

ToolKinematics::ToolKinematics(double probe_radius_m, double blade_length_m, double max_step_m)
    : m_probe_radius_m(probe_radius_m), m_blade_length_m(blade_length_m), m_max_step_m(max_step_m) {}

void ToolKinematics::set(const ToolPose& pose) {
  validate(pose);
  m_pose = pose;
  m_pose.orientation.normalize();
  if (!m_stepped) m_applied_position_m = m_pose.tip_position_m;  // nothing held it back yet
}

Eigen::Vector3d ToolKinematics::pole_offset_m(const ToolPose& pose) const {
  if (pose.mode != ToolMode::probe || !(m_probe_radius_m > 0.0)) return Eigen::Vector3d::Zero();
  return m_probe_radius_m * tool_axis(pose.orientation);
}

ToolPose ToolKinematics::touching() const {
  ToolPose touching = m_pose;
  touching.tip_position_m -= pole_offset_m(touching);
  return touching;
}

ToolKinematics::Move ToolKinematics::next_move() const {
  // A pose farther than a hand can move in one step is approached at the hand's top speed; the tool
  // catches up with it over the next steps (docs/DESIGN.md, "One Tissue step").
  Move move{m_applied, touching(), {}};
  move.current = reachable_pose(move.previous, move.target, m_blade_length_m, m_max_step_m);
  return move;
}

void ToolKinematics::apply(const Move& move) {
  m_applied = move.current;
  m_stepped = true;
  // Only a tool that keeps its mode and does something is ever held back (reachable_pose); then the
  // applied pose differs from the target, else the position is the one set, bitwise.
  const ToolPose& target = move.target;
  const ToolPose& current = move.current;
  const bool held_back = target.mode != ToolMode::none && current.mode == target.mode &&
                         (current.tip_position_m != target.tip_position_m ||
                          current.orientation.coeffs() != target.orientation.coeffs());
  m_applied_position_m = m_pose.tip_position_m;
  if (held_back) {
    m_applied_position_m = current.tip_position_m;
    if (current.mode == ToolMode::probe) m_applied_position_m += pole_offset_m(current);  // (-0 + 0 is +0)
  }
}

void ToolKinematics::check(const State& state) {
  if (!state.applied_position_m.allFinite()) throw StateError("the state's applied tool position is not finite");
}

void ToolKinematics::restore(const State& state) {
  check(state);
  m_pose = state.tool;
  m_applied = state.applied;
  m_applied_position_m = state.applied_position_m;
  m_stepped = true;  // the saved applied position stands until the next step
}

}  // namespace tissue
