#include "haptic/cutting_force.hpp"

#include "core/parameter_error.hpp"

#include <cmath>
#include <string>

namespace tissue::haptic {

void validate(const CuttingSettings& settings) {
  constexpr const char* WHO = "CuttingSettings";
  require_finite_non_negative(WHO, "fracture_toughness_j_per_m2", settings.fracture_toughness_j_per_m2);
  require_finite_non_negative(WHO, "blade_friction_n_per_m", settings.blade_friction_n_per_m);
  require_finite_positive(WHO, "smoothing_speed_m_per_s", settings.smoothing_speed_m_per_s);
}

Eigen::Vector3d cutting_force(const CuttingSettings& settings, double blade_depth_m,
                              const Eigen::Vector3d& velocity_m_per_s, const Eigen::Vector3d& motion_m_per_s) {
  const double speed = velocity_m_per_s.norm();
  if (!(blade_depth_m > 0.0) || speed == 0.0) return Eigen::Vector3d::Zero();
  const double full_n = (settings.fracture_toughness_j_per_m2 + settings.blade_friction_n_per_m) * blade_depth_m;
  Eigen::Vector3d force = -(full_n * std::tanh(speed / settings.smoothing_speed_m_per_s) / speed) * velocity_m_per_s;
  const double along_motion = force.dot(motion_m_per_s);
  if (along_motion > 0.0) force -= (along_motion / motion_m_per_s.squaredNorm()) * motion_m_per_s;
  return force;
}

}  // namespace tissue::haptic
