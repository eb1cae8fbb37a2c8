// Material parameters of a specimen, in SI units, with their range checks.
#pragma once

#include "core/named_items.hpp"
#include "core/parameter_error.hpp"

#include <optional>
#include <string_view>

namespace tissue {

/// Homogeneous isotropic linear-elastic material.
struct Material {
  double young_modulus_pa = 1.0e5;
  double poisson_ratio = 0.4;
  double density_kg_per_m3 = 1000.0;
  /// Rayleigh mass damping alpha of this material [1/s] (a region's own, issue 25); none: the body's
  /// (RayleighDamping::mass_damping_per_s). Stiffness damping beta is the body's alone.
  std::optional<double> mass_damping_per_s = std::nullopt;
};

struct LameParameters {
  double lambda_pa = 0.0;
  double mu_pa = 0.0;  ///< shear modulus
};

/// Throws ParameterError unless E > 0, 0 <= nu < 0.5, rho > 0 and alpha (if set) >= 0 (all finite).
void validate(const Material& material);
/// Throws ParameterError unless the mass damping alpha [1/s] is finite and >= 0 (a material's or a
/// body's, RayleighDamping).
void validate_mass_damping(double alpha_per_s);

/// lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
LameParameters lame_parameters(const Material& material);

/// How the body's tets answer a deformation (issue 25; one for the whole body): co-rotational linear
/// elasticity (the dissertation's, the default) or stable Neo-Hookean (core/fem/stable_neo_hookean.hpp),
/// both with each region's (E, nu).
enum class MaterialModel { corotational_linear, stable_neo_hookean };

inline constexpr ItemNames<MaterialModel, 2> MATERIAL_MODEL_NAMES{
    "material model",
    {{{"corotationalLinear", "Co-rotational linear elasticity (the dissertation's; one linear solve a step)"},
      {"stableNeoHookean",
       "Stable Neo-Hookean hyperelasticity (Smith, de Goes and Kim 2018): inversion-safe, its tangent projected to "
       "positive semi-definite per element"}}}};

/// "corotationalLinear", "stableNeoHookean" (MATERIAL_MODEL_NAMES).
std::string_view to_string(MaterialModel model);
/// The inverse; throws ParameterError naming the accepted names.
MaterialModel parse_material_model(std::string_view name);

}  // namespace tissue
