// The HapticLoop FMU's description: its variable table (variables.hpp) with the tissue sample's
// inputs, its enumeration types, log categories and default experiment. Start values are the
// renderer's defaults (libtissue/haptic/haptic_renderer.hpp, where their sources are given).
#include "haptic_loop/variables.hpp"

#include <array>

namespace tissue::haptic_fmu {
namespace {

using fmi3::EnumerationType;

constexpr auto VARIABLES = haptic_loop_variables(ports::TISSUE_SAMPLE);
static_assert(fmi3::strictly_ordered(VARIABLES), "the variable table must be in increasing value-reference order");

constexpr auto TOOL_MODE_ITEMS = ports::tool_mode_items();
const auto ENUMERATIONS = std::to_array<EnumerationType>({
    {"ToolMode", ports::TOOL_MODE_DESCRIPTION, TOOL_MODE_ITEMS},
});

constexpr auto LOG_CATEGORIES = fmi3::layer_log_categories(
    "Calls that returned fmi3Warning, and recoverable problems such as a refused tissue sample",
    "Events of the haptic loop");

}  // namespace

fmi3::ModelDescription haptic_loop_model_description(std::span<const fmi3::VariableInfo> variables) {
  return {MODEL_IDENTIFIER,
          INSTANTIATION_TOKEN,
          variables,
          ENUMERATIONS,
          "Haptic rendering at 1 kHz next to a slower tissue simulation: the contact force from the tissue's "
          "intermediate representation against the contact plane, a fracture-mechanics cutting force, clamped to "
          "the device, rate limited and kept passive by a time-domain passivity observer and controller",
          LOG_CATEGORIES,
          {0.0, 1.0, 0.001}};
}

const fmi3::ModelDescription& haptic_loop_model_description() {
  static const fmi3::ModelDescription description = haptic_loop_model_description(VARIABLES);
  return description;
}

}  // namespace tissue::haptic_fmu
