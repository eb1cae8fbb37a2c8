#include "haptic/force_limits.hpp"

namespace tissue::haptic {

LimitedForce clamp_magnitude(const Eigen::Vector3d& force_n, double max_force_n) {
  const double magnitude = force_n.norm();
  if (magnitude <= max_force_n) return {force_n, false};
  return {force_n * (max_force_n / magnitude), true};
}

LimitedForce limit_rate(const Eigen::Vector3d& previous_n, const Eigen::Vector3d& target_n, double max_change_n) {
  const Eigen::Vector3d change = target_n - previous_n;
  const double magnitude = change.norm();
  if (magnitude <= max_change_n) return {target_n, false};
  return {previous_n + change * (max_change_n / magnitude), true};
}

}  // namespace tissue::haptic
