#include "haptic/cutting_force.hpp"

#include "core/parameter_error.hpp"

#include <cmath>
#include <string>

namespace tissue::haptic {

void validate(const CuttingSettings& settings) {
  require_setting("CuttingSettings",
                  std::isfinite(settings.fracture_toughness_j_per_m2) && settings.fracture_toughness_j_per_m2 >= 0.0,
                  "fracture_toughness_j_per_m2", settings.fracture_toughness_j_per_m2, "finite and >= 0");
  require_setting("CuttingSettings",
                  std::isfinite(settings.blade_friction_n_per_m) && settings.blade_friction_n_per_m >= 0.0,
                  "blade_friction_n_per_m", settings.blade_friction_n_per_m, "finite and >= 0");
  require_setting("CuttingSettings",
                  std::isfinite(settings.smoothing_speed_m_per_s) && settings.smoothing_speed_m_per_s > 0.0,
                  "smoothing_speed_m_per_s", settings.smoothing_speed_m_per_s, "finite and > 0");
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
