// ToolKinematics: the tool as the hand sets it and as the steps apply it. The hand's pose is checked
// once (set), a ball probe touches with its pole (touching), and a step moves the tool from the pose
// it applied last toward the hand's at no more than the hand's top speed (next_move); once the
// step is taken, the pose it reached is the applied one (apply).
#pragma once

#include "core/tool/tool_pose.hpp"

#include <Eigen/Core>

namespace tissue {

class ToolKinematics {
 public:
  /// Where the step takes the tool: from `previous` (the pose the last step applied) to `current`
  /// (`target`, or the pose on the way to it that the hand's top speed reaches).
  struct Move {
    ToolPose previous;
    ToolPose target;
    ToolPose current;
  };
  /// What a saved state holds of the tool.
  struct State {
    ToolPose tool;
    ToolPose applied;
    Eigen::Vector3d applied_position_m = Eigen::Vector3d::Zero();
  };

  /// `probe_radius_m` >= 0 (0: a point tip); no point of the blade (`blade_length_m` from the tip
  /// along the axis) moves more than `max_step_m` in one step (<= 0: no limit).
  ToolKinematics(double probe_radius_m, double blade_length_m, double max_step_m);

  /// The pose for the next step, as the hand gives it (a ball probe by its centre): the one check of
  /// a pose (validate) and its one normalization. Throws ParameterError (pose kept) for a non-finite
  /// position or a non-finite or zero quaternion.
  void set(const ToolPose& pose);
  /// The pose as set (normalized).
  [[nodiscard]] const ToolPose& pose() const { return m_pose; }
  /// The pose that touches the tissue: pose(), with a ball probe's pole for its centre.
  [[nodiscard]] ToolPose touching() const;
  /// The next step's move (nothing changes until apply()).
  [[nodiscard]] Move next_move() const;
  /// The step that took `move` succeeded: its current pose is the applied one.
  void apply(const Move& move);
  /// The touching pose the last step applied.
  [[nodiscard]] const ToolPose& applied() const { return m_applied; }
  /// The position the last step applied, in set()'s terms (a ball probe's centre): the position set,
  /// bitwise, unless the hand's top speed held the tool back.
  [[nodiscard]] const Eigen::Vector3d& applied_position_m() const { return m_applied_position_m; }
  /// The applied position minus the applied touching point (a ball probe's centre - pole; zero for a
  /// point tip); before the first step, of the pose set.
  [[nodiscard]] Eigen::Vector3d touching_offset_m() const {
    return m_stepped ? Eigen::Vector3d(m_applied_position_m - m_applied.tip_position_m) : pole_offset_m(m_pose);
  }
  /// A step was applied (or a state restored): the applied position is a step's, not the set one.
  [[nodiscard]] bool stepped() const { return m_stepped; }

  [[nodiscard]] State state() const { return {m_pose, m_applied, m_applied_position_m}; }
  /// Throws StateError for a state restore() refuses: a non-finite applied position.
  static void check(const State& state);
  /// The saved tool; its applied position stands until the next step. Throws StateError (nothing
  /// changed) where check() does.
  void restore(const State& state);

 private:
  [[nodiscard]] Eigen::Vector3d pole_offset_m(const ToolPose& pose) const;

  double m_probe_radius_m;
  double m_blade_length_m;
  double m_max_step_m;
  ToolPose m_pose;
  ToolPose m_applied;
  Eigen::Vector3d m_applied_position_m = Eigen::Vector3d::Zero();
  bool m_stepped = false;  // a step (or a restore) has set m_applied_position_m
};

}  // namespace tissue
