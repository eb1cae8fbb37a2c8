// Rayleigh damping D = alpha M + beta K (eq. 4.21): part of the equations of motion every
// integrator sees, so it lives with the DynamicsModel, not with the FEM that implements it.
#pragma once

#include "core/parameter_error.hpp"

namespace tissue {

struct RayleighDamping {
  double mass_damping_per_s = 0.0;   ///< alpha [1/s]
  double stiffness_damping_s = 0.0;  ///< beta [s]
};

/// Throws ParameterError unless alpha >= 0 and beta >= 0 (finite).
void validate(const RayleighDamping& damping);

}  // namespace tissue
