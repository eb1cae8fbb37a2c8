#include "haptic/contact_force.hpp"

namespace tissue::haptic {

Eigen::Vector3d intermediate_force(const TissueSample& sample, const Eigen::Vector3d& tool_position_m) {
  return sample.force_on_tool_n - sample.contact_stiffness_n_per_m * (tool_position_m - sample.tool_position_m);
}

Eigen::Vector3d unilateral_force(const Eigen::Vector3d& force_n, const TissueSample& sample,
                                 const Eigen::Vector3d& tool_position_m) {
  const Eigen::Vector3d& normal = sample.contact_normal;
  // A pressed surface follows the tool back by its rebound f_n / k_n (0 without a stiffness).
  const double pressed_n = sample.force_on_tool_n.dot(normal);
  const double normal_stiffness_n_per_m = normal.dot(sample.contact_stiffness_n_per_m * normal);
  const double follows_m =
      pressed_n > 0.0 && normal_stiffness_n_per_m > 0.0 ? pressed_n / normal_stiffness_n_per_m : 0.0;
  const bool outside = (tool_position_m - sample.contact_point_m).dot(normal) > follows_m;
  if (outside || force_n.dot(normal) < 0.0) return Eigen::Vector3d::Zero();
  return force_n;
}

Eigen::Vector3d near_surface_force(const TissueSample& sample, const Eigen::Vector3d& tool_position_m) {
  const Eigen::Vector3d& n = sample.contact_normal;
  const double depth_m = (sample.contact_point_m - tool_position_m).dot(n);
  return (n.dot(sample.contact_stiffness_n_per_m * n) * depth_m) * n;
}

Eigen::Vector3d contact_damping_force(const TissueSample& sample, const Eigen::Vector3d& velocity_m_per_s,
                                      const Eigen::Vector3d& sample_tool_velocity_m_per_s,
                                      double damping_n_s_per_m, double hold_s) {
  const Eigen::Vector3d& n = sample.contact_normal;
  return -(sample.contact_damping_n_s_per_m * (velocity_m_per_s - sample_tool_velocity_m_per_s)) -
         hold_s * (sample.contact_stiffness_n_per_m * velocity_m_per_s) - (damping_n_s_per_m * velocity_m_per_s.dot(n)) * n;
}

}  // namespace tissue::haptic
