// Material and damping parameters of a specimen, in SI units, with their range checks.
#pragma once

#include <stdexcept>

namespace tissue {

/// A parameter outside its physical range (E <= 0, nu outside [0, 0.5), ...).
class ParameterError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

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

/// Rayleigh damping D = alpha M + beta K (eq. 4.21).
struct RayleighDamping {
  double mass_damping_per_s = 0.0;   ///< alpha [1/s]
  double stiffness_damping_s = 0.0;  ///< beta [s]
};

/// Throws ParameterError unless E > 0, 0 <= nu < 0.5, rho > 0 (all finite).
void validate(const Material& material);
/// Throws ParameterError unless alpha >= 0 and beta >= 0 (finite).
void validate(const RayleighDamping& damping);

/// lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
LameParameters lame_parameters(const Material& material);

}  // namespace tissue
