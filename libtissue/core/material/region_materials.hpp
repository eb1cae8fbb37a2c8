// Materials per region of a mesh (issue 25). A mesh file may split its tets into named regions
// (Vega *REGION, Gmsh physical groups, TetGen region attributes) and may give a region a material
// (Vega *MATERIAL); a user may set a region's material by its name (the Tissue FMU's
// material.regions, a scenario's [tissue.regions], Python). Resolved here, once, to one Material
// per region.
#pragma once

#include "core/material/material.hpp"

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tissue {

/// A named set of a mesh's tets.
struct MeshRegion {
  std::string name;
  std::optional<Material> material;  ///< as the mesh file gives it (Vega *MATERIAL), else none
};

/// The material a user sets for the region of that name; it replaces the file's.
struct RegionMaterial {
  std::string region;
  Material material;
};

/// A material property a user sets by name: its key in the text form below (the FMU's), its SI name
/// (the Python module's keyword), its unit for messages ("" for a ratio), how to set it and how to
/// read it back (none: not set, the body's value applies).
struct MaterialProperty {
  std::string_view key;
  std::string_view si_name;
  std::string_view unit;
  void (*set)(Material& material, double value);
  std::optional<double> (*get)(const Material& material);
};

/// youngModulus [Pa], poissonRatio, density [kg/m^3], dampingAlpha [1/s]: the one list every front
/// end sets them by.
[[nodiscard]] std::span<const MaterialProperty> material_properties();

/// The regions' names, quoted and comma separated, for messages: "skin", "tumour".
std::string quoted_region_names(const std::vector<MeshRegion>& regions);

/// One Material per region, in the regions' order: the one set by name, else the file's, else
/// `fallback` (the body's material). No regions: one, `fallback`. Throws ParameterError naming the
/// region for a name no region has, a region set twice, or an invalid material.
std::vector<Material> resolve_region_materials(const std::vector<MeshRegion>& regions, const Material& fallback,
                                               const std::vector<RegionMaterial>& set_by_name);

/// The region materials as written in the FMU's `material.regions` and by the other front ends:
/// entries separated by ';', each `name: key=value, key=value` with the keys youngModulus [Pa],
/// poissonRatio [1], density [kg/m^3] and dampingAlpha [1/s] (material_properties()); a key left out
/// keeps `base`'s value (for dampingAlpha, usually unset: the body's damping.alpha). Whitespace around
/// names, keys and values is ignored; an empty text, or "none", sets none. Throws ParameterError quoting the
/// entry for a missing ':', an unknown or repeated key, a value that is not a finite number, an empty
/// or repeated name, or a material out of range.
std::vector<RegionMaterial> parse_region_materials(std::string_view text, const Material& base);

/// The inverse of parse_region_materials (shortest round-trip numbers): `name: youngModulus=..,
/// poissonRatio=.., density=..[, dampingAlpha=..]; ...` (a property not set is left out).
std::string format_region_materials(const std::vector<RegionMaterial>& materials);

}  // namespace tissue
