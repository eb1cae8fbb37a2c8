// The settings' Markdown tables (see settings_doc.hpp).
#include "tissue_fmu/settings_doc.hpp"

#include "core/tissue_settings_schema.hpp"
#include "tissue_fmu/variables.hpp"

#include <stdexcept>

namespace tissue::tissue_fmu {
namespace {

// (Strings are built with append: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.)
std::string code(std::string_view text) {
  std::string out = "`";
  return out.append(text).append("`");
}

std::string fmi_type(const fmi3::VariableInfo& variable) {
  std::string type(fmi3::to_string(variable.type));
  if (variable.type == fmi3::VariableType::enumeration) {
    type = "Enumeration ";
    return type.append(code(variable.declared_type));
  }
  if (variable.rank == 1) type.append("[").append(std::to_string(variable.dimensions[0].size)).append("]");
  return type;
}

// The setting's default as the FMU starts it (`variable`'s start): an enumeration's item number, with
// the item's name.
std::string fmu_start(const SettingInfo& setting, const fmi3::VariableInfo& variable) {
  std::string start(variable.start);
  if (setting.type == SettingType::enumeration) start.append(" (").append(setting.start).append(")");
  return start;
}

std::string setting_range(const SettingInfo& setting) {
  return setting.type == SettingType::enumeration ? list_names(setting.items) : range_text(setting);
}

std::string row(std::initializer_list<std::string> cells) {
  std::string line = "|";
  for (const std::string& cell : cells)
    line.append(cell.empty() ? " |" : " ").append(cell).append(cell.empty() ? "" : " |");
  return line + "\n";
}

}  // namespace

std::string fmu_parameter_table() {
  std::string table = "| name | vr | type | unit | start | range | what it does |\n|---|---:|---|---|---|---|---|\n";
  const fmi3::ModelDescription& description = tissue_model_description();
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    const fmi3::VariableInfo& variable = *description.find(setting.value_reference);
    table +=
        row({code(setting.name), std::to_string(setting.value_reference), fmi_type(variable), std::string(setting.unit),
             fmu_start(setting, variable), setting_range(setting), std::string(setting.description)});
  }
  for (const fmi3::VariableInfo& variable : description.variables) {
    if (variable.causality != fmi3::Causality::parameter || find_setting(variable.name) != nullptr) continue;
    std::string range;
    if (!variable.min.empty()) range.append(">= ").append(variable.min);
    table += row({code(variable.name), std::to_string(variable.vr), fmi_type(variable), std::string(variable.unit),
                  std::string(variable.start), range, std::string(variable.description)});
  }
  return table;
}

std::string python_keyword_table() {
  std::string table =
      "| keyword | default | unit | range | FMU parameter | meaning |\n|---|---|---|---|---|---|\n"
      "| `box`, `box_edge_m` | none, 0.01 | m | | | instead of a mesh: `(nx, ny, nz)` cubes of that edge, 5 tets each "
      "|\n"
      "| `fixed_vertices` | none | | | | vertex indices held at rest, instead of `fixed_axis` and `fixed_fraction` |\n"
      "| `regions` | `{}` | | | `material.regions` | materials of the mesh file's regions by name: `{\"tumour\": "
      "{\"young_modulus_pa\": 1e6, \"damping_alpha_per_s\": 20}}` (keys `young_modulus_pa`, `poisson_ratio`, "
      "`density_kg_per_m3`, `damping_alpha_per_s`); a key left out keeps the body's value |\n";
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (setting.python_keyword.empty()) continue;
    const bool quoted = setting.type == SettingType::enumeration || setting.type == SettingType::text;
    const std::string start = to_text(start_value(setting));
    table += row({code(setting.python_keyword), quoted ? code(std::string("\"").append(start).append("\"")) : start,
                  setting.unit == "1" ? std::string() : std::string(setting.unit), setting_range(setting),
                  code(setting.name), std::string(setting.description)});
  }
  return table;
}

std::string with_generated_section(const std::string& text, std::string_view name, const std::string& content) {
  const std::string begin = std::string("<!-- generated: ").append(name).append(" -->\n");
  const std::string end = std::string("<!-- end generated: ").append(name).append(" -->");
  const std::size_t from = text.find(begin);
  const std::size_t to = text.find(end);
  if (from == std::string::npos || to == std::string::npos || to < from) {
    throw std::invalid_argument(std::string("no section '")
                                    .append(name)
                                    .append("' (")
                                    .append(begin, 0, begin.size() - 1)
                                    .append(" ... ")
                                    .append(end)
                                    .append(")"));
  }
  return text.substr(0, from + begin.size()) + content + text.substr(to);
}

}  // namespace tissue::tissue_fmu
