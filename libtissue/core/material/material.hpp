// Material parameters of a specimen, in SI units, with their range checks.
#pragma once

#include "core/parameter_error.hpp"

namespace tissue {

/// Homogeneous isotropic linear-elastic material.
struct Material {
  double young_modulus_pa = 1.0e5;
  double poisson_ratio = 0.4;
  double density_kg_per_m3 = 1000.0;
};

struct LameParameters {
  double lambda_pa = 0.0;
  double mu_pa = 0.0;  ///< shear modulus
};

/// Throws ParameterError unless E > 0, 0 <= nu < 0.5, rho > 0 (all finite).
void validate(const Material& material);

/// lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
LameParameters lame_parameters(const Material& material);

}  // namespace tissue
