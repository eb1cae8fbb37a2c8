#include "haptic/passivity.hpp"

#include <algorithm>

namespace tissue::haptic {

namespace {
/// Below this speed the device is at rest: 1 nm per 1 ms tick, far under any encoder's resolution.
constexpr double REST_SPEED_M_PER_S = 1e-9;
}  // namespace

void PassivityObserver::book(const Eigen::Vector3d& held_force_n, const Eigen::Vector3d& held_damping_n,
                             const Eigen::Vector3d& displacement_m) {
  m_energy_j -= held_force_n.dot(displacement_m);
  m_dissipated_j -= held_damping_n.dot(displacement_m);
}

void PassivityObserver::drop_credit() { m_energy_j = std::min(m_energy_j, 0.0); }

PassivityAction passivity_damping(double energy_j, const Eigen::Vector3d& force_n,
                                  const Eigen::Vector3d& velocity_m_per_s, double dt_s,
                                  double max_damping_n_s_per_m) {
  PassivityAction action;
  action.predicted_energy_j = energy_j - force_n.dot(velocity_m_per_s) * dt_s;
  const double speed_squared = velocity_m_per_s.squaredNorm();
  if (action.predicted_energy_j >= 0.0 || speed_squared < REST_SPEED_M_PER_S * REST_SPEED_M_PER_S) return action;
  action.damping_n_s_per_m = std::min(-action.predicted_energy_j / (dt_s * speed_squared), max_damping_n_s_per_m);
  action.damping_force_n = -action.damping_n_s_per_m * velocity_m_per_s;
  return action;
}

}  // namespace tissue::haptic
