// The HapticLoop FMU's variables: value references and the table of modelDescription/HapticLoop.xml
// in the FMI layer's terms (fmi3/variable_table.hpp). The XML is the contract;
// tests/fmu/test_model_description.cpp keeps this table equal to it. Plain C++, no FMI headers.
#pragma once

#include "fmi3/variable_table.hpp"

#include <cstdint>
#include <string_view>

namespace tissue::haptic_fmu {

inline constexpr std::string_view INSTANTIATION_TOKEN = "{b3c1e7d4-5a29-4f0e-9c6b-8d2a71f4e0c5}";
inline constexpr std::string_view MODEL_IDENTIFIER = "HapticLoop";

enum class Vr : std::uint32_t {
  time = 0,
  // parameters
  step_size = 1,
  max_force = 2,
  max_force_rate = 3,
  passivity_control = 4,
  velocity_cutoff = 5,
  fracture_toughness = 6,
  blade_friction = 7,
  cutting_smoothing_speed = 8,
  workspace_scale = 9,
  workspace_offset = 10,
  // inputs: the device
  device_position = 20,
  device_orientation = 21,
  device_tool_mode = 22,
  // inputs: the tissue's latest outputs
  tissue_time = 23,
  tissue_contact_active = 24,
  tissue_contact_point = 25,
  tissue_contact_normal = 26,
  tissue_contact_force = 27,
  tissue_contact_stiffness = 28,
  tissue_tool_position = 29,
  tissue_blade_depth = 30,
  // outputs
  tool_position = 40,
  tool_orientation = 41,
  tool_mode = 42,
  device_force = 43,
  contact_force = 44,
  cutting_force = 45,
  passivity_force = 46,
  observed_energy = 47,
  dissipated_energy = 48,
  force_clamped = 49,
  force_rate_limited = 50,
  passivity_acted = 51,
  samples_received = 52,
  samples_refused = 53
};

/// The HapticLoop FMU's description: identity, variables, enumeration types.
const fmi3::ModelDescription& haptic_loop_model_description();

}  // namespace tissue::haptic_fmu
