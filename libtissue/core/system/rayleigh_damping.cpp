// Range checks of the Rayleigh damping parameters.
#include "core/system/rayleigh_damping.hpp"

#include "core/material/material.hpp"

#include <cmath>
#include <string>

namespace tissue {

void validate(const RayleighDamping& damping) {
  validate_mass_damping(damping.mass_damping_per_s);
  if (!std::isfinite(damping.stiffness_damping_s) || damping.stiffness_damping_s < 0.0) {
    throw ParameterError("damping: stiffness damping beta must be finite and >= 0 s, got " +
                         std::to_string(damping.stiffness_damping_s));
  }
}

}  // namespace tissue
