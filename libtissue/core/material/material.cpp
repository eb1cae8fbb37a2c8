// Range checks and Lame parameters for Material.
#include "core/material/material.hpp"

#include <cmath>
#include <string>

namespace tissue {

void validate(const Material& material) {
  const auto fail = [](const std::string& what) { throw ParameterError("material: " + what); };
  if (!std::isfinite(material.young_modulus_pa) || material.young_modulus_pa <= 0.0) {
    fail("Young's modulus must be finite and > 0 Pa, got " + std::to_string(material.young_modulus_pa));
  }
  if (!std::isfinite(material.poisson_ratio) || material.poisson_ratio < 0.0 || material.poisson_ratio >= 0.5) {
    fail("Poisson's ratio must be in [0, 0.5), got " + std::to_string(material.poisson_ratio));
  }
  if (!std::isfinite(material.density_kg_per_m3) || material.density_kg_per_m3 <= 0.0) {
    fail("density must be finite and > 0 kg/m^3, got " + std::to_string(material.density_kg_per_m3));
  }
  if (material.mass_damping_per_s) validate_mass_damping(*material.mass_damping_per_s);
}

void validate_mass_damping(double alpha_per_s) {
  if (!std::isfinite(alpha_per_s) || alpha_per_s < 0.0) {
    throw ParameterError("damping: mass damping alpha must be finite and >= 0 1/s, got " +
                         std::to_string(alpha_per_s));
  }
}

std::string_view to_string(MaterialModel model) { return MATERIAL_MODEL_NAMES.name(model); }

MaterialModel parse_material_model(std::string_view name) { return MATERIAL_MODEL_NAMES.parse(name); }

LameParameters lame_parameters(const Material& material) {
  const double e = material.young_modulus_pa;
  const double nu = material.poisson_ratio;
  return {e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu))};
}

}  // namespace tissue
