// The record of one setting, written once: its name in the FMU and the scenario files, its Python
// keyword, the Tissue FMU's value reference, type, unit, default, range, description and the member
// it sets. tissue_settings_schema.hpp lists the tissue's settings in these terms; this file holds the
// record, its builder and the parameters it sets.
#pragma once

#include "core/named_items.hpp"
#include "core/tissue.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>

namespace tissue {

/// What a product sets by name: the tissue's settings, and the scene's choices that need the mesh (the
/// fixed slab, the regions' materials by name) or the product (the files).
/// default_parameters() gives every setting its schema default.
struct TissueParameters {
  TissueSettings settings;
  std::string mesh;              ///< "frog" (the embedded frog) or a mesh file
  int fixed_axis = -1;           ///< -1: nothing fixed; 0, 1, 2: the slab at the minimum of x, y, z
  double fixed_fraction = 0.0;   ///< the slab's thickness, a fraction of the mesh's extent
  std::string material_regions;  ///< the regions' materials as text (parse_region_materials)
  std::string render_surface;    ///< "none", "frog" (the embedded frog's) or an OBJ file
};

enum class SettingType { real, integer, boolean, enumeration, vector3, text };

/// A setting's value: real, integer, boolean, vector3, or text (an enumeration's is its item's name).
using SettingValue = std::variant<double, std::int64_t, bool, std::array<double, 3>, std::string>;

/// An enumeration member of any enum type whose values are its items' indices (ItemNames).
struct EnumMember {
  void* object = nullptr;
  std::size_t (*get)(const void* object) = nullptr;
  void (*set)(void* object, std::size_t item) = nullptr;
};

template <class E>
EnumMember enum_member(E& value) {
  return {&value, [](const void* object) { return static_cast<std::size_t>(*static_cast<const E*>(object)); },
          [](void* object, std::size_t item) { *static_cast<E*>(object) = static_cast<E>(item); }};
}

/// Where a setting lands in TissueParameters.
using SettingMember = std::variant<double*, int*, bool*, Eigen::Vector3d*, std::string*, EnumMember>;

/// A range bound, as text (the FMU's min/max attributes write it), inclusive or strict.
struct SettingBound {
  std::string_view value;
  bool inclusive = true;
};

/// Whether a setting is one of the tissue's settings (TissueSettings: validated by validate() and
/// part of the model fingerprint) or a choice of the scene (resolved with the mesh, or the product's).
enum class SettingScope { tissue, scene };

struct SettingInfo {
  std::string_view name;              ///< the FMU variable and the scenario key: "tool.probeRadius"
  std::string_view python_keyword;    ///< empty: Python sets it in its own way, or not at all
  std::uint32_t value_reference = 0;  ///< in the Tissue FMU
  SettingType type = SettingType::real;
  SettingScope scope = SettingScope::tissue;
  std::string_view unit;   ///< the FMU's unit name ("m", "Pa", "1"); empty: none
  std::string_view start;  ///< the one default, as text ("1e5", "0 0 -9.81", an enumeration item's name)
  std::optional<SettingBound> min;
  std::optional<SettingBound> max;
  std::string_view enumeration_type;         ///< the FMU's enumeration type name
  std::string_view enumeration_description;  ///< and its description
  std::span<const NamedItem> items;          ///< an enumeration's items, value k = items[k]
  std::string_view description;
  /// Why TissueSettings{}'s own member default differs from `start`, where it does (the core's
  /// defaults serve its tests and benches; the products share `start`). Empty: they agree (tested).
  std::string_view core_default_note;
  SettingMember (*member)(TissueParameters& parameters) = nullptr;
};

/// Builds a SettingInfo by named steps, as fmi3::Entry does for the FMU's variables.
class Setting {
 public:
  constexpr Setting(std::string_view name, std::uint32_t value_reference, SettingType type) {
    m_info.name = name;
    m_info.value_reference = value_reference;
    m_info.type = type;
  }
  constexpr Setting& python(std::string_view keyword) {
    m_info.python_keyword = keyword;
    return *this;
  }
  constexpr Setting& scene() {
    m_info.scope = SettingScope::scene;
    return *this;
  }
  constexpr Setting& unit(std::string_view unit) {
    m_info.unit = unit;
    return *this;
  }
  constexpr Setting& start(std::string_view start) {
    m_info.start = start;
    return *this;
  }
  constexpr Setting& at_least(std::string_view min) {
    m_info.min = SettingBound{min, true};
    return *this;
  }
  constexpr Setting& above(std::string_view min) {
    m_info.min = SettingBound{min, false};
    return *this;
  }
  constexpr Setting& at_most(std::string_view max) {
    m_info.max = SettingBound{max, true};
    return *this;
  }
  constexpr Setting& below(std::string_view max) {
    m_info.max = SettingBound{max, false};
    return *this;
  }
  constexpr Setting& items(std::string_view type, std::string_view type_description, std::span<const NamedItem> items) {
    m_info.enumeration_type = type;
    m_info.enumeration_description = type_description;
    m_info.items = items;
    return *this;
  }
  constexpr Setting& describe(std::string_view description) {
    m_info.description = description;
    return *this;
  }
  constexpr Setting& core_default(std::string_view why) {
    m_info.core_default_note = why;
    return *this;
  }
  constexpr Setting& member(SettingMember (*where)(TissueParameters&)) {
    m_info.member = where;
    return *this;
  }
  // Implicit so that a table can list entries directly.
  constexpr operator SettingInfo() const { return m_info; }  // NOLINT(google-explicit-constructor)

 private:
  SettingInfo m_info;
};

/// The index of an enumeration's start item (its FMU item number is one more).
constexpr std::size_t start_item(const SettingInfo& setting) {
  for (std::size_t k = 0; k < setting.items.size(); ++k) {
    if (setting.items[k].name == setting.start) return k;
  }
  return setting.items.size();
}

/// The value `setting` has in `parameters`.
SettingValue value_of(const SettingInfo& setting, const TissueParameters& parameters);
/// Sets `setting` in `parameters` to `value`: throws ParameterError, naming the setting, its range and
/// unit, for a value of the wrong type, outside the range, not finite, or an unknown item.
void set_value(const SettingInfo& setting, TissueParameters& parameters, const SettingValue& value);
/// The setting's default (its start text parsed).
SettingValue start_value(const SettingInfo& setting);
/// Throws ParameterError unless `value` is of the setting's type, finite and in its range.
void check_value(const SettingInfo& setting, const SettingValue& value);
/// "> 0", "[0, 0.5)", "[-1, 2]", ">= 1", or "" for none (the docs' and the messages' notation).
std::string range_text(const SettingInfo& setting);
/// The value as the start attribute writes it ("0 0 -9.81", "true", an item's name).
std::string to_text(const SettingValue& value);

}  // namespace tissue
