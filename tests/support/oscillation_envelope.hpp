// The amplitude of a mass-spring oscillation about z_eq from its states (z, dz/dt), one per tick:
// sqrt((z - z_eq)^2 + (v / omega)^2), constant for an undamped oscillation at omega, averaged over
// one period from time t_s. Two of them a second apart give the decay rate (tests of the simulated
// hand on a sampled wall and of the haptic loop's contact damping).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

namespace tissue::test_support {

inline double oscillation_envelope(const std::vector<std::array<double, 2>>& states, double t_s, double tick_s,
                                   double omega_rad_per_s, double z_eq_m) {
  const auto first = static_cast<std::size_t>(std::lround(t_s / tick_s));
  const auto period = static_cast<std::size_t>(std::lround(2.0 * std::numbers::pi / omega_rad_per_s / tick_s));
  double sum = 0.0;
  for (std::size_t n = first; n < first + period; ++n) {
    sum += std::hypot(states.at(n)[0] - z_eq_m, states.at(n)[1] / omega_rad_per_s);
  }
  return sum / static_cast<double>(period);
}

}  // namespace tissue::test_support
