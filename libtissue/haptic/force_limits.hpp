// What the device may be asked for: a force no larger than it can exert (the clamp), and one that
// changes no faster than the hand can take without a kick (the rate limiter). Two functions, one
// job each. Applied in this order, clamp then rate limit, the result keeps both: the rate limiter
// moves from the previous command (inside the ball |f| <= max) toward the clamped target (inside
// it too), and the ball is convex.
#pragma once

#include <Eigen/Core>

namespace tissue::haptic {

struct LimitedForce {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  bool acted = false;  ///< the limit changed the force
};

/// Scales `force_n` down to magnitude `max_force_n` (> 0) if it is larger; direction kept.
LimitedForce clamp_magnitude(const Eigen::Vector3d& force_n, double max_force_n);

/// Moves from `previous_n` toward `target_n` by at most `max_change_n` (> 0, may be +inf):
/// |result - previous| <= max_change_n, along the straight line (the direction of the change kept).
LimitedForce limit_rate(const Eigen::Vector3d& previous_n, const Eigen::Vector3d& target_n, double max_change_n);

}  // namespace tissue::haptic
