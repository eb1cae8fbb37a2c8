// The HapticLoop FMU's port schema: value references and the table of its variables in the FMI
// layer's terms (fmi3/variable_table.hpp), written once. Its own variables are listed here; the
// tissue.* inputs come from the tissue sample (ports/tissue_sample.hpp). The build writes
// modelDescription.xml from this table (tissue-model-description). Plain C++, no FMI headers.
#pragma once

#include "fmi3/variable_table.hpp"
#include "port_variables/port_variables.hpp"
#include "ports/tissue_sample.hpp"
#include "ports/tool.hpp"

#include <array>
#include <span>

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
  passivity_min_hand_mass = 11,
  contact_damping = 12,
  contact_hold_damping = 13,
  // inputs: the device
  device_position = 20,
  device_orientation = 21,
  device_tool_mode = 22,
  // inputs: the tissue's latest outputs
  tissue_time = 23,
  tissue_contact_active = ports::sample_field("contact.active").haptic_vr,
  tissue_contact_near = ports::sample_field("contact.near").haptic_vr,
  tissue_contact_point = ports::sample_field("contact.point").haptic_vr,
  tissue_contact_normal = ports::sample_field("contact.normal").haptic_vr,
  tissue_contact_force = ports::sample_field("contact.force").haptic_vr,
  tissue_contact_stiffness = ports::sample_field("contact.stiffness").haptic_vr,
  tissue_contact_damping = ports::sample_field("contact.damping").haptic_vr,
  tissue_tool_position = ports::sample_field("tool.appliedPosition").haptic_vr,
  tissue_blade_depth = ports::sample_field("cut.bladeDepth").haptic_vr,
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

namespace variables_detail {
// The table in parts, one kind of variable each, in value-reference order within each; own_variables()
// merges them (fmi3::merged: by value reference).

/// The step, the device's limits, passivity, the velocity filter, cutting, the workspace, the hand
/// passivity assumes, the contact's damping (1-13).
constexpr auto parameters() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  return std::to_array<VariableInfo>({
    parameter(Vr::step_size, "stepSize", float64)
        .unit("s")
        .start("0.001")
        .describe("Haptic tick: the force is rendered once per tick; a communication step must be a whole multiple "
                  "of it; must be > 0"),
    parameter(Vr::max_force, "device.maxForce", float64)
        .unit("N")
        .start("3.3")
        .describe("Largest force magnitude ever commanded (3.3 N: peak force of a 3D Systems Touch); must be > 0"),
    parameter(Vr::max_force_rate, "device.maxForceRate", float64)
        .unit("N/s")
        .start("1000")
        .describe("Largest change of the commanded force per second, so that a cut releasing tension or a new "
                  "contact never kicks the hand; must be > 0"),
    parameter(Vr::passivity_control, "passivity.control", boolean)
        .start("true")
        .describe("Time-domain passivity controller on (Hannaford and Ryu 2002); the observer always runs"),
    parameter(Vr::velocity_cutoff, "velocityFilter.cutoff", float64)
        .unit("Hz")
        .start("30")
        .describe("Cut-off of the low-pass on the hand velocity (cutting force, passivity controller); must be > 0"),
    parameter(Vr::fracture_toughness, "cutting.fractureToughness", float64)
        .unit("J/m2")
        .start("164")
        .min("0")
        .describe("Fracture toughness J_c of the tissue: the blade is resisted by J_c times the edge length in the "
                  "tissue (Mahvash and Hayward 2005); 0 cuts without resistance"),
    parameter(Vr::blade_friction, "cutting.bladeFriction", float64)
        .unit("N/m")
        .start("0")
        .min("0")
        .describe("Friction on the blade's sides per metre of edge in the tissue"),
    parameter(Vr::cutting_smoothing_speed, "cutting.smoothingSpeed", float64)
        .unit("m/s")
        .start("0.01")
        .describe("Speed at which the cutting force reaches tanh(1) = 76% of its value (no chatter at rest); must "
                  "be > 0"),
    parameter(Vr::workspace_scale, "workspace.scale", float64)
        .unit("1")
        .start("1")
        .describe("tool.position = workspace.offset + workspace.scale * device.position; must be > 0"),
    parameter(Vr::workspace_offset, "workspace.offset", float64)
        .unit("m")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("Where the device's origin lies in the tissue's frame"),
    parameter(Vr::passivity_min_hand_mass, "passivity.minHandMass", float64)
        .unit("kg")
        .start("0.05")
        .describe("The lightest hand the passivity controller must not throw back: its damping is at most this over "
                  "twice the tick, so that it never reverses the hand's motion within a tick; must be > 0"),
    parameter(Vr::contact_damping, "contact.damping", float64)
        .unit("N.s/m")
        .start("2")
        .min("0")
        .describe("Viscous damping of a contact along its normal on top of the tissue's own (tissue.contactDamping): "
                  "a floor for a tissue that reports its force only"),
    parameter(Vr::contact_hold_damping, "contact.holdDamping", boolean)
        .start("true")
        .describe("Damp a contact by stepSize times its stiffness: twice what holding the contact's spring over a "
                  "tick gives the hand (Colgate and Schenkel 1997), so that any hand is stable on any contact (Gil "
                  "et al. 2004); off only to measure what it does"),
});
}

/// The device's pose and buttons (20-22) and the tissue sample's time (23; the sample's fields
/// come from ports/tissue_sample.hpp).
constexpr auto inputs() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  using enum Variability;
  return std::to_array<VariableInfo>({
    input(Vr::device_position, "device.position", float64, continuous)
        .unit("m")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("Position of the device's end effector (x y z) in the device frame"),
    input(Vr::device_orientation, "device.orientation", float64, continuous)
        .unit("1")
        .start("1 0 0 0")
        .shape(fixed_size(4))
        .min_norm(MIN_ORIENTATION_NORM)
        .describe("Orientation of the device's stylus as a quaternion (w x y z); the tool axis is its local +z"),
    input(Vr::device_tool_mode, "device.toolMode", enumeration, discrete)
        .declared_type("ToolMode")
        .start("0")
        .describe("The tool the buttons select: none, probe or scalpel"),

    // Inputs: the tissue's latest outputs.
    input(Vr::tissue_time, ports::SAMPLE_TIME_INPUT, float64, continuous)
        .unit("s")
        .start("0")
        .describe("Tissue time the tissue inputs are for; a new value marks a new tissue sample"),
});
}

/// The tool command, the force and its parts, passivity, the limits acting, the samples (40-53).
constexpr auto outputs() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  using enum Variability;
  return std::to_array<VariableInfo>({
    output(Vr::tool_position, "tool.position", float64, continuous)
        .unit("m")
        .shape(fixed_size(3))
        .describe("Tool position for the tissue: workspace.offset + workspace.scale * device.position"),
    output(Vr::tool_orientation, "tool.orientation", float64, continuous)
        .unit("1")
        .shape(fixed_size(4))
        .describe("Tool orientation for the tissue (unit quaternion w x y z)"),
    output(Vr::tool_mode, "tool.mode", enumeration, discrete)
        .declared_type("ToolMode")
        .describe("Tool mode for the tissue"),
    output(Vr::device_force, "device.force", float64, continuous)
        .unit("N")
        .shape(fixed_size(3))
        .describe("Force to command on the device: contact and cutting forces, clamped, rate limited and kept "
                  "passive"),
    output(Vr::contact_force, "force.contact", float64, continuous)
        .unit("N")
        .shape(fixed_size(3))
        .describe("The contact part before the limits (intermediate representation, unilateral)"),
    output(Vr::cutting_force, "force.cutting", float64, continuous)
        .unit("N")
        .shape(fixed_size(3))
        .describe("The cutting part before the limits (fracture-mechanics resistance to the blade)"),
    output(Vr::passivity_force, "force.passivity", float64, continuous)
        .unit("N")
        .shape(fixed_size(3))
        .describe("The passivity controller's share of device.force"),
    output(Vr::observed_energy, "passivity.observedEnergy", float64, continuous)
        .unit("J")
        .describe("Energy the loop has absorbed from the hand (the passivity observer); negative means it gave "
                  "energy"),
    output(Vr::dissipated_energy, "passivity.dissipatedEnergy", float64, continuous)
        .unit("J")
        .describe("Energy the passivity controller has dissipated"),
    output(Vr::force_clamped, "force.clamped", boolean, discrete)
        .describe("The last tick's force was clamped to device.maxForce"),
    output(Vr::force_rate_limited, "force.rateLimited", boolean, discrete)
        .describe("The last tick's force change was limited to device.maxForceRate"),
    output(Vr::passivity_acted, "passivity.acted", boolean, discrete)
        .describe("The passivity controller added damping in the last tick"),
    output(Vr::samples_received, "tissue.samplesReceived", uint64, discrete)
        .describe("Tissue samples taken (a new tissue.time)"),
    output(Vr::samples_refused, "tissue.samplesRefused", uint64, discrete)
        .describe("Tissue samples refused (non-finite, a non-unit normal): the previous one is kept"),
});
}

/// The HapticLoop FMU's own variables: the independent time and the parts above.
constexpr auto own_variables() {
  using fmi3::merged;
  const auto independent = std::to_array<fmi3::VariableInfo>({fmi3::independent_time(Vr::time)});
  return merged(merged(merged(independent, parameters()), inputs()), outputs());
}
}  // namespace variables_detail

/// The HapticLoop FMU's variables with the tissue sample `sample` (ports::TISSUE_SAMPLE; a test adds
/// a field) as its tissue.* inputs, in value-reference order.
template <std::size_t N>
constexpr auto haptic_loop_variables(const std::array<ports::SampleField, N>& sample) {
  return fmi3::merged(variables_detail::own_variables(), ports::entries(sample, ports::haptic_input));
}

/// The HapticLoop FMU's description: identity, variables, enumeration types, log categories.
const fmi3::ModelDescription& haptic_loop_model_description();
/// The same description over other variables (haptic_loop_variables() of another sample; for tests).
fmi3::ModelDescription haptic_loop_model_description(std::span<const fmi3::VariableInfo> variables);

}  // namespace tissue::haptic_fmu
