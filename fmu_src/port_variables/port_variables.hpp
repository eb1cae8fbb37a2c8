// The shared ports as the FMUs' schema entries: the tissue sample's fields (ports/tissue_sample.hpp)
// as the Tissue FMU's outputs and the HapticLoop FMU's inputs, each made from the one field; the
// tool modes (ports/tool.hpp) as both FMUs' ToolMode enumeration.
#pragma once

#include "fmi3/variable_table.hpp"
#include "ports/tissue_sample.hpp"
#include "ports/tool.hpp"

#include <array>
#include <cstddef>

namespace tissue::ports {

constexpr fmi3::VariableType variable_type(SampleType type) {
  return type == SampleType::boolean ? fmi3::VariableType::boolean : fmi3::VariableType::float64;
}

constexpr fmi3::Variability variability(SampleType type) {
  return type == SampleType::boolean ? fmi3::Variability::discrete : fmi3::Variability::continuous;
}

constexpr fmi3::Entry& shaped(fmi3::Entry& entry, const SampleField& field) {
  if (field.rank() == 1) entry.shape(fmi3::fixed_size(field.rows));
  if (field.rank() == 2) entry.shape(fmi3::fixed_size(field.rows), fmi3::fixed_size(field.columns));
  return entry;
}

/// The Tissue FMU's output of `field`.
constexpr fmi3::VariableInfo tissue_output(const SampleField& field) {
  fmi3::Entry entry = fmi3::output(field.tissue_vr, field.tissue_output, variable_type(field.type),
                                   variability(field.type));
  entry.unit(field.unit).describe(field.tissue_description);
  return shaped(entry, field);
}

/// The HapticLoop FMU's input of `field`.
constexpr fmi3::VariableInfo haptic_input(const SampleField& field) {
  fmi3::Entry entry =
      fmi3::input(field.haptic_vr, field.haptic_input, variable_type(field.type), variability(field.type));
  entry.unit(field.unit).start(field.haptic_start).min(field.haptic_min).describe(field.haptic_description);
  return shaped(entry, field);
}

/// One entry per field, made by `entry` (tissue_output or haptic_input).
template <std::size_t N>
constexpr std::array<fmi3::VariableInfo, N> entries(const std::array<SampleField, N>& fields,
                                                    fmi3::VariableInfo (*entry)(const SampleField&)) {
  std::array<fmi3::VariableInfo, N> made{};
  for (std::size_t k = 0; k < N; ++k) made[k] = entry(fields[k]);
  return made;
}

inline constexpr std::string_view TOOL_MODE_DESCRIPTION = "What the tool does";

/// The ToolMode enumeration's items, from the one list of tool modes.
constexpr std::array<fmi3::EnumerationItem, TOOL_MODE_ITEMS.size()> tool_mode_items() {
  std::array<fmi3::EnumerationItem, TOOL_MODE_ITEMS.size()> items{};
  for (std::size_t k = 0; k < items.size(); ++k) {
    items[k] = {TOOL_MODE_ITEMS[k].name, static_cast<std::int64_t>(TOOL_MODE_ITEMS[k].mode),
                TOOL_MODE_ITEMS[k].description};
  }
  return items;
}

}  // namespace tissue::ports
