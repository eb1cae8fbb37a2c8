// The settings schema's values, range checks and resolution (see setting_schema.hpp and
// tissue_settings_schema.hpp).
#include "core/tissue_settings_schema.hpp"

#include "core/fixed_region.hpp"
#include "core/material/region_materials.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>

namespace tissue {

namespace {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;  // clang 14 (the fuzz preset) deduces aggregates only with a guide

double parse_real(std::string_view text) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) {
    throw std::logic_error("settings schema: '" + std::string(text) + "' is not a number");
  }
  return value;
}

std::string_view type_name(SettingType type) {
  switch (type) {
    case SettingType::real:
      return "a number";
    case SettingType::integer:
      return "an integer";
    case SettingType::boolean:
      return "a boolean";
    case SettingType::enumeration:
      return "an item name";
    case SettingType::vector3:
      return "three numbers";
    case SettingType::text:
      return "a text";
  }
  return "a value";
}

// The setting's value as a number for its range check (real or integer), or nothing.
std::optional<double> as_number(const SettingValue& value) {
  if (const auto* real = std::get_if<double>(&value)) return *real;
  if (const auto* integer = std::get_if<std::int64_t>(&value)) return static_cast<double>(*integer);
  return std::nullopt;
}

bool holds_type(SettingType type, const SettingValue& value) {
  switch (type) {
    case SettingType::real:
      return std::holds_alternative<double>(value);
    case SettingType::integer:
      return std::holds_alternative<std::int64_t>(value);
    case SettingType::boolean:
      return std::holds_alternative<bool>(value);
    case SettingType::vector3:
      return std::holds_alternative<std::array<double, 3>>(value);
    case SettingType::enumeration:
    case SettingType::text:
      return std::holds_alternative<std::string>(value);
  }
  return false;
}

[[noreturn]] void refuse(const SettingInfo& setting, const std::string& what, const SettingValue& value) {
  throw ParameterError(std::string(setting.name) + " must be " + what + ", got " + to_text(value));
}

// "finite and >= 0 m": what a numeric setting must be (its unit after the range, "1" left out).
std::string numeric_requirement(const SettingInfo& setting) {
  std::string text = "finite";
  const std::string range = range_text(setting);
  if (range.empty()) return text;
  text.append(setting.min && setting.max ? " and in " : " and ").append(range);
  if (!setting.unit.empty() && setting.unit != "1") text.append(" ").append(setting.unit);
  return text;
}

}  // namespace

std::string to_text(const SettingValue& value) {
  return std::visit(Overloaded{[](double v) {
                                 std::ostringstream out;
                                 out << v;
                                 return out.str();
                               },
                               [](std::int64_t v) { return std::to_string(v); },
                               [](bool v) { return std::string(v ? "true" : "false"); },
                               [](const std::array<double, 3>& v) {
                                 std::ostringstream out;
                                 out << v[0] << ' ' << v[1] << ' ' << v[2];
                                 return out.str();
                               },
                               [](const std::string& v) { return v; }},
                    value);
}

std::string range_text(const SettingInfo& setting) {
  const auto& min = setting.min;
  const auto& max = setting.max;
  std::string text;
  if (min && max) {
    text.append(min->inclusive ? "[" : "(").append(min->value).append(", ").append(max->value);
    text.append(max->inclusive ? "]" : ")");
  } else if (min) {
    text.append(min->inclusive ? ">= " : "> ").append(min->value);
  } else if (max) {
    text.append(max->inclusive ? "<= " : "< ").append(max->value);
  }
  return text;
}

std::string expected_value_text(const SettingInfo& setting) {
  if (setting.type == SettingType::enumeration) return list_names(setting.items);
  return std::string(type_name(setting.type));
}

void check_value(const SettingInfo& setting, const SettingValue& value) {
  if (!holds_type(setting.type, value)) refuse(setting, expected_value_text(setting), value);
  if (const auto* vector = std::get_if<std::array<double, 3>>(&value)) {
    for (const double v : *vector) {
      if (!std::isfinite(v)) refuse(setting, "finite", value);
    }
  }
  if (setting.type == SettingType::enumeration) {
    const std::string& name = std::get<std::string>(value);
    for (const NamedItem& item : setting.items) {
      if (item.name == name) return;
    }
    refuse(setting, list_names(setting.items), value);
  }
  const std::optional<double> number = as_number(value);
  if (!number) return;
  const std::string what = numeric_requirement(setting);
  if (!std::isfinite(*number)) refuse(setting, what, value);
  if (setting.min) {
    const double min = parse_real(setting.min->value);
    if (setting.min->inclusive ? *number < min : *number <= min) refuse(setting, what, value);
  }
  if (setting.max) {
    const double max = parse_real(setting.max->value);
    if (setting.max->inclusive ? *number > max : *number >= max) refuse(setting, what, value);
  }
}

SettingValue value_of(const SettingInfo& setting, const TissueParameters& parameters) {
  // The member function takes a non-const reference to serve set_value too; it only takes an address.
  const SettingMember member = setting.member(const_cast<TissueParameters&>(parameters));  // NOLINT
  return std::visit(
      Overloaded{[](double* v) -> SettingValue { return *v; },
                 [](int* v) -> SettingValue { return static_cast<std::int64_t>(*v); },
                 [](bool* v) -> SettingValue { return *v; },
                 [](Eigen::Vector3d* v) -> SettingValue {
                   return std::array<double, 3>{v->x(), v->y(), v->z()};
                 },
                 [](std::string* v) -> SettingValue { return *v; },
                 [&](const EnumMember& e) -> SettingValue { return std::string(setting.items[e.get(e.object)].name); }},
      member);
}

void set_value(const SettingInfo& setting, TissueParameters& parameters, const SettingValue& value) {
  check_value(setting, value);
  std::visit(Overloaded{[&](double* v) { *v = std::get<double>(value); },
                        [&](int* v) { *v = static_cast<int>(std::get<std::int64_t>(value)); },
                        [&](bool* v) { *v = std::get<bool>(value); },
                        [&](Eigen::Vector3d* v) {
                          const auto& a = std::get<std::array<double, 3>>(value);
                          *v = Eigen::Vector3d(a[0], a[1], a[2]);
                        },
                        [&](std::string* v) { *v = std::get<std::string>(value); },
                        [&](const EnumMember& e) {
                          const std::string& name = std::get<std::string>(value);
                          for (std::size_t k = 0; k < setting.items.size(); ++k) {
                            if (setting.items[k].name == name) e.set(e.object, k);
                          }
                        }},
             setting.member(parameters));
}

SettingValue start_value(const SettingInfo& setting) {
  const std::string_view start = setting.start;
  switch (setting.type) {
    case SettingType::real:
      return parse_real(start);
    case SettingType::integer:
      return static_cast<std::int64_t>(parse_real(start));
    case SettingType::boolean:
      return start == "true";
    case SettingType::vector3: {
      std::array<double, 3> v{};
      std::size_t at = 0;
      for (double& component : v) {
        const std::size_t end = std::min(start.find(' ', at), start.size());
        component = parse_real(start.substr(at, end - at));
        at = end + 1;
      }
      return v;
    }
    case SettingType::enumeration:
    case SettingType::text:
      return std::string(start);
  }
  return std::string(start);
}

const SettingInfo* find_setting(std::string_view name) {
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (setting.name == name) return &setting;
  }
  return nullptr;
}

const SettingInfo* find_python_setting(std::string_view keyword) {
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (!setting.python_keyword.empty() && setting.python_keyword == keyword) return &setting;
  }
  return nullptr;
}

TissueParameters default_parameters() {
  TissueParameters parameters;
  for (const SettingInfo& setting : TISSUE_SETTINGS) set_value(setting, parameters, start_value(setting));
  return parameters;
}

TissueSettings resolve_settings(const TissueParameters& parameters, const TetMesh* mesh) {
  // The scene's settings here; the tissue's are validate()'s (check_setting_ranges), below.
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (setting.scope == SettingScope::scene) check_value(setting, value_of(setting, parameters));
  }
  TissueSettings settings = parameters.settings;
  settings.body.region_materials = parse_region_materials(parameters.material_regions, settings.body.material);
  if (parameters.fixed_axis != -1 && mesh != nullptr) {
    settings.body.fixed_vertices = vertices_at_minimum(*mesh, parameters.fixed_axis, parameters.fixed_fraction);
  }
  validate(settings);
  return settings;
}

void check_setting_ranges(const TissueSettings& settings) {
  for_each_tissue_setting(settings,
                          [](const SettingInfo& setting, const SettingValue& value) { check_value(setting, value); });
}

}  // namespace tissue
