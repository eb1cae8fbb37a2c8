// SimulatedHand (see simulated_hand.hpp).
#include "device/simulated_hand.hpp"

#include <Eigen/Core>
#include <unsupported/Eigen/MatrixFunctions>

#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue::host {
namespace {

void check_range(double value, double low, double high, const char* name, const char* unit) {
  if (!(value >= low && value <= high)) {
    throw std::invalid_argument(std::string(name) + " must be in [" + std::to_string(low) + ", " +
                                std::to_string(high) + "] " + unit + ", got " + std::to_string(value));
  }
}

}  // namespace

void validate(const HandSettings& settings) {
  check_range(settings.mass_kg, HandLimits::min_mass_kg, HandLimits::max_mass_kg, "hand mass", "kg");
  check_range(settings.damping_n_s_per_m, 0.0, HandLimits::max_damping_n_s_per_m, "hand damping", "N s/m");
  check_range(settings.grip_stiffness_n_per_m, 0.0, HandLimits::max_grip_stiffness_n_per_m, "hand grip stiffness",
              "N/m");
  for (const double p : settings.push_n) {
    check_range(p, -HandLimits::max_push_n, HandLimits::max_push_n, "hand push (each component)", "N");
  }
}

SimulatedHand::SimulatedHand(const HandSettings& settings, double tick_s, const std::array<double, 3>& position_m)
    : m_settings(settings), m_tick_s(tick_s), m_position_m(position_m) {
  validate(settings);
  check_range(tick_s, 1e-6, 0.1, "hand tick", "s");
  for (const double x : position_m) {
    if (!std::isfinite(x)) throw std::invalid_argument("hand start position must be finite");
  }
  const double m = settings.mass_kg;
  Eigen::Matrix4d augmented;
  augmented << 0.0, 1.0, 0.0, 0.0,                                                                //
      -settings.grip_stiffness_n_per_m / m, -settings.damping_n_s_per_m / m, 1.0, 0.0,            //
      0.0, 0.0, 0.0, 1.0,                                                                         //
      0.0, 0.0, 0.0, 0.0;
  const Eigen::Matrix4d transition = (augmented * tick_s).exp();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m_transition[static_cast<std::size_t>(4 * r + c)] = transition(r, c);
  }
}

void SimulatedHand::advance(const std::array<double, 3>& force_n, const std::array<double, 3>& target_from_m,
                            const std::array<double, 3>& target_to_m) {
  const double m = m_settings.mass_kg;
  const double k = m_settings.grip_stiffness_n_per_m;
  const std::array<double, 16>& e = m_transition;
  for (std::size_t a = 0; a < 3; ++a) {
    const double force = std::isfinite(force_n[a]) ? force_n[a] : 0.0;
    // The forcing (p + f + k r(t)) / m = c0 + c1 t over the tick.
    const double c0 = (m_settings.push_n[a] + force + k * target_from_m[a]) / m;
    const double c1 = k * (target_to_m[a] - target_from_m[a]) / m_tick_s / m;
    const double x = m_position_m[a], v = m_velocity_m_per_s[a];
    const double x_next = e[0] * x + e[1] * v + e[2] * c0 + e[3] * c1;
    const double v_next = e[4] * x + e[5] * v + e[6] * c0 + e[7] * c1;
    m_device_work_j += force * (x_next - x);  // a force held over the tick: exact
    m_position_m[a] = x_next;
    m_velocity_m_per_s[a] = v_next;
  }
}

}  // namespace tissue::host
