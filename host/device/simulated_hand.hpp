// SimulatedHand: a hand whose motion answers the force, for closed-loop haptic tests (issue 20). Per
// axis, a mass m with damping b (the arm's viscosity), held by a grip spring k toward a target path
// and pushing with a constant force p (what the user means to do):
//   m x'' = -b x' - k (x - r(t)) + p + f(t),
// f the device's force on the hand. A device holds its force over a tick (zero-order hold) and the
// path moves linearly within a tick, so the forcing is affine in time and each tick is integrated
// exactly: the augmented state [x, v, c0, c1] with c0 = (p + f + k r) / m, c0' = c1 = k r' / m
// advances by exp(M h), computed once (Van Loan 1978, "Computing integrals involving the matrix
// exponential"). No allocation after construction, so a haptic thread may call it.
#pragma once

#include <array>

namespace tissue::host {

struct HandSettings {
  double mass_kg = 0.2;
  double damping_n_s_per_m = 2.0;
  /// Stiffness of the grip that pulls the hand toward the path [N/m]; 0: the hand is not held, only
  /// pushed (push_n) and damped.
  double grip_stiffness_n_per_m = 0.0;
  /// The constant force the hand pushes with [N] (e.g. (0, 0, -1): pressing down with 1 N).
  std::array<double, 3> push_n{0.0, 0.0, 0.0};
};

/// The allowed ranges, one place: the scenario reader and the device quote them.
struct HandLimits {
  static constexpr double min_mass_kg = 0.01, max_mass_kg = 10.0;
  static constexpr double max_damping_n_s_per_m = 100.0;
  static constexpr double max_grip_stiffness_n_per_m = 1.0e5;
  static constexpr double max_push_n = 50.0;
};

/// Throws std::invalid_argument naming the setting and its range for a value outside HandLimits (or
/// not finite).
void validate(const HandSettings& settings);

class SimulatedHand {
 public:
  /// A hand at rest at `position_m`, advanced in ticks of `tick_s` (finite, in (0, 0.1] s). Throws
  /// std::invalid_argument for bad settings, a bad tick or a non-finite position.
  SimulatedHand(const HandSettings& settings, double tick_s, const std::array<double, 3>& position_m);

  /// One tick: the device force `force_n` held on the hand, the grip's target moving linearly from
  /// `target_from_m` to `target_to_m`. A non-finite force is taken as zero (a device sends nothing).
  void advance(const std::array<double, 3>& force_n, const std::array<double, 3>& target_from_m,
               const std::array<double, 3>& target_to_m);

  [[nodiscard]] const std::array<double, 3>& position_m() const { return m_position_m; }
  [[nodiscard]] const std::array<double, 3>& velocity_m_per_s() const { return m_velocity_m_per_s; }
  /// The work the device's force did on the hand so far [J]: > 0 it gave the hand energy.
  [[nodiscard]] double device_work_j() const { return m_device_work_j; }
  [[nodiscard]] double tick_s() const { return m_tick_s; }
  [[nodiscard]] const HandSettings& settings() const { return m_settings; }

 private:
  HandSettings m_settings;
  double m_tick_s;
  /// exp(M h) of the augmented per-axis system, row-major 4 x 4 (the last two rows are trivial).
  std::array<double, 16> m_transition{};
  std::array<double, 3> m_position_m{};
  std::array<double, 3> m_velocity_m_per_s{};
  double m_device_work_j = 0.0;
};

}  // namespace tissue::host
