// Resolving the materials of a mesh's regions, and their text form.
#include "core/material/region_materials.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <set>

namespace tissue {
namespace {

std::string_view trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = text.find(separator, begin);
    parts.push_back(text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin));
    if (end == std::string_view::npos) return parts;
    begin = end + 1;
  }
}

std::string number_text(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return {buffer, result.ptr};
}

constexpr std::array<MaterialProperty, 4> PROPERTIES{{
    {"youngModulus", "young_modulus_pa", "Pa", [](Material& m, double value) { m.young_modulus_pa = value; },
     [](const Material& m) -> std::optional<double> { return m.young_modulus_pa; }},
    {"poissonRatio", "poisson_ratio", "", [](Material& m, double value) { m.poisson_ratio = value; },
     [](const Material& m) -> std::optional<double> { return m.poisson_ratio; }},
    {"density", "density_kg_per_m3", "kg/m^3", [](Material& m, double value) { m.density_kg_per_m3 = value; },
     [](const Material& m) -> std::optional<double> { return m.density_kg_per_m3; }},
    {"dampingAlpha", "damping_alpha_per_s", "1/s", [](Material& m, double value) { m.mass_damping_per_s = value; },
     [](const Material& m) { return m.mass_damping_per_s; }},
}};

// "youngModulus [Pa], poissonRatio, density [kg/m^3], dampingAlpha [1/s]".
std::string property_keys_text() {
  std::string text;
  for (const MaterialProperty& property : PROPERTIES) {
    if (!text.empty()) text += ", ";
    text += std::string(property.key);
    if (!property.unit.empty()) text += " [" + std::string(property.unit) + "]";
  }
  return text;
}

RegionMaterial parse_entry(std::string_view entry, const Material& base) {
  const auto fail = [&](const std::string& what) {
    throw ParameterError("material.regions: \"" + std::string(trimmed(entry)) + "\": " + what);
  };
  const std::size_t colon = entry.find(':');
  if (colon == std::string_view::npos) fail("expected 'name: key=value, ...'");
  RegionMaterial region{std::string(trimmed(entry.substr(0, colon))), base};
  if (region.region.empty()) fail("the region's name is empty");
  std::set<std::string> keys;
  for (const std::string_view pair : split(entry.substr(colon + 1), ',')) {
    if (trimmed(pair).empty()) continue;
    const std::size_t equals = pair.find('=');
    if (equals == std::string_view::npos) fail("expected key=value, got \"" + std::string(trimmed(pair)) + "\"");
    const std::string key(trimmed(pair.substr(0, equals)));
    const std::string_view value_text = trimmed(pair.substr(equals + 1));
    double value = 0.0;
    const auto [end, error] = std::from_chars(value_text.data(), value_text.data() + value_text.size(), value);
    if (error != std::errc() || end != value_text.data() + value_text.size() || !std::isfinite(value)) {
      fail(key + ": \"" + std::string(value_text) + "\" is not a finite number");
    }
    if (!keys.insert(key).second) fail(key + " given twice");
    const auto property =
        std::find_if(PROPERTIES.begin(), PROPERTIES.end(), [&](const MaterialProperty& p) { return p.key == key; });
    if (property == PROPERTIES.end()) fail("unknown key \"" + key + "\" (" + property_keys_text() + ")");
    property->set(region.material, value);
  }
  try {
    validate(region.material);
  } catch (const ParameterError& error) {
    fail(error.what());
  }
  return region;
}

}  // namespace

std::span<const MaterialProperty> material_properties() { return PROPERTIES; }

std::string quoted_region_names(const std::vector<MeshRegion>& regions) {
  std::string names;
  for (const MeshRegion& region : regions) {
    if (!names.empty()) names.append(", ");
    names.append("\"").append(region.name).append("\"");
  }
  return names;
}

std::vector<Material> resolve_region_materials(const std::vector<MeshRegion>& regions, const Material& fallback,
                                               const std::vector<RegionMaterial>& set_by_name) {
  std::vector<Material> materials;
  if (regions.empty()) materials.push_back(fallback);
  for (const MeshRegion& region : regions) materials.push_back(region.material.value_or(fallback));
  std::set<std::string> seen;
  for (const RegionMaterial& set : set_by_name) {
    if (!seen.insert(set.region).second) {
      throw ParameterError("material of region \"" + set.region + "\" set twice");
    }
    std::size_t found = regions.size();
    for (std::size_t r = 0; r < regions.size(); ++r) {
      if (regions[r].name == set.region) found = r;
    }
    if (found == regions.size()) {
      throw ParameterError(
          "material set for region \"" + set.region + "\", which the mesh does not have (" +
          (regions.empty() ? std::string("it has no regions") : "its regions: " + quoted_region_names(regions)) + ")");
    }
    materials[found] = set.material;
  }
  for (std::size_t r = 0; r < materials.size(); ++r) {
    try {
      validate(materials[r]);
    } catch (const ParameterError& error) {
      throw ParameterError("region \"" + (regions.empty() ? std::string("all") : regions[r].name) +
                           "\": " + error.what());
    }
  }
  return materials;
}

std::vector<RegionMaterial> parse_region_materials(std::string_view text, const Material& base) {
  std::vector<RegionMaterial> materials;
  if (trimmed(text) == "none") return materials;
  std::set<std::string> names;
  for (const std::string_view entry : split(text, ';')) {
    if (trimmed(entry).empty()) continue;
    RegionMaterial region = parse_entry(entry, base);
    if (!names.insert(region.region).second) {
      throw ParameterError("material.regions: region \"" + region.region + "\" given twice");
    }
    materials.push_back(std::move(region));
  }
  return materials;
}

std::string format_region_materials(const std::vector<RegionMaterial>& materials) {
  std::string text;
  for (const RegionMaterial& region : materials) {
    if (!text.empty()) text += "; ";
    text += region.region + ":";
    const char* separator = " ";
    for (const MaterialProperty& property : PROPERTIES) {
      const std::optional<double> value = property.get(region.material);
      if (!value) continue;
      text += separator + std::string(property.key) + "=" + number_text(*value);
      separator = ", ";
    }
  }
  return text;
}

}  // namespace tissue
