// The Tissue FMU's description: its variable table (variables.hpp) with the tissue sample, its
// enumeration types, log categories and default experiment.
#include "tissue_fmu/variables.hpp"

#include <algorithm>
#include <vector>

namespace tissue::tissue_fmu {
namespace {

using fmi3::EnumerationItem;
using fmi3::EnumerationType;

constexpr auto VARIABLES = tissue_variables(ports::TISSUE_SAMPLE);
static_assert(fmi3::strictly_ordered(VARIABLES), "the variable table must be in increasing value-reference order");

constexpr auto TOOL_MODE_ITEMS = ports::tool_mode_items();

// The enumeration types: the settings' (from the schema, items numbered from 1), then the tool mode.
struct Enumerations {
  std::vector<std::vector<EnumerationItem>> items;
  std::vector<EnumerationType> types;
};

const Enumerations& enumerations() {
  static const Enumerations all = [] {
    Enumerations e;
    std::vector<const SettingInfo*> settings;
    for (const SettingInfo& setting : TISSUE_SETTINGS) {
      if (setting.type != SettingType::enumeration) continue;
      settings.push_back(&setting);
      std::vector<EnumerationItem>& items = e.items.emplace_back();
      for (std::size_t k = 0; k < setting.items.size(); ++k) {
        items.push_back({setting.items[k].name, static_cast<std::int64_t>(k + 1), setting.items[k].description});
      }
    }
    for (std::size_t k = 0; k < settings.size(); ++k) {
      e.types.push_back({settings[k]->enumeration_type, settings[k]->enumeration_description, e.items[k]});
    }
    e.types.push_back({"ToolMode", ports::TOOL_MODE_DESCRIPTION, TOOL_MODE_ITEMS});
    return e;
  }();
  return all;
}

constexpr auto LOG_CATEGORIES = fmi3::layer_log_categories(
    "Calls that returned fmi3Warning, and recoverable problems such as a surface that outgrew its capacity",
    "Cuts made and contacts started/ended");

}  // namespace

fmi3::ModelDescription tissue_model_description(std::span<const fmi3::VariableInfo> variables) {
  return {MODEL_IDENTIFIER,
          INSTANTIATION_TOKEN,
          variables,
          enumerations().types,
          "Real-time XFEM soft-tissue simulation: a co-rotational tetrahedral body cut by a scalpel and touched by a "
          "probe, with the contact force, contact stiffness and deformed surface mesh as outputs",
          LOG_CATEGORIES,
          {0.0, 1.0, 0.01}};
}

const fmi3::ModelDescription& tissue_model_description() {
  static const fmi3::ModelDescription description = tissue_model_description(VARIABLES);
  return description;
}

}  // namespace tissue::tissue_fmu
