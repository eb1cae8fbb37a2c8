// The table of the HapticLoop FMU's variables: modelDescription/HapticLoop.xml in code, one entry per
// variable in value-reference order. Edit both together; tests/fmu/test_model_description.cpp fails,
// naming the variable and attribute, when they differ. Start values are the renderer's defaults
// (haptic_loop/core/haptic_renderer.hpp, where their sources are given).
#include "haptic_loop/variables.hpp"

#include <array>

namespace tissue::haptic_fmu {
namespace {

using fmi3::EnumerationItem;
using fmi3::EnumerationType;
using fmi3::fixed_size;
using fmi3::input;
using fmi3::output;
using fmi3::parameter;
using fmi3::VariableInfo;

using enum fmi3::VariableType;
using enum fmi3::Variability;

constexpr auto VARIABLES = std::to_array<VariableInfo>({
    fmi3::independent_time(Vr::time),

    // Parameters.
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
        .start("300")
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

    // Inputs: the device.
    input(Vr::device_position, "device.position", float64, continuous)
        .unit("m")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("Position of the device's end effector (x y z) in the device frame"),
    input(Vr::device_orientation, "device.orientation", float64, continuous)
        .unit("1")
        .start("1 0 0 0")
        .shape(fixed_size(4))
        .describe("Orientation of the device's stylus as a quaternion (w x y z); the tool axis is its local +z"),
    input(Vr::device_tool_mode, "device.toolMode", enumeration, discrete)
        .declared_type("ToolMode")
        .start("0")
        .describe("The tool the buttons select: none, probe or scalpel"),

    // Inputs: the tissue's latest outputs.
    input(Vr::tissue_time, "tissue.time", float64, continuous)
        .unit("s")
        .start("0")
        .describe("Tissue time the tissue inputs are for; a new value marks a new tissue sample"),
    input(Vr::tissue_contact_active, "tissue.contactActive", boolean, discrete)
        .start("false")
        .describe("The tissue's contact.active"),
    input(Vr::tissue_contact_point, "tissue.contactPoint", float64, continuous)
        .unit("m")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("The tissue's contact.point (god-object on the deformed surface)"),
    input(Vr::tissue_contact_normal, "tissue.contactNormal", float64, continuous)
        .unit("1")
        .start("0 0 1")
        .shape(fixed_size(3))
        .describe("The tissue's contact.normal (unit outward normal)"),
    input(Vr::tissue_contact_force, "tissue.contactForce", float64, continuous)
        .unit("N")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("The tissue's contact.force: f0, the force on the tool at tissue.toolPosition"),
    input(Vr::tissue_contact_stiffness, "tissue.contactStiffness", float64, continuous)
        .unit("N/m")
        .start("0 0 0 0 0 0 0 0 0")
        .shape(fixed_size(3), fixed_size(3))
        .describe("The tissue's contact.stiffness K_c (row-major 3x3): the force on the tool is rendered as "
                  "f0 - K_c (x - x0) against the contact plane"),
    input(Vr::tissue_tool_position, "tissue.toolPosition", float64, continuous)
        .unit("m")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("x0: the tool position the tissue computed its outputs for (the Tissue FMU's tool.position)"),
    input(Vr::tissue_blade_depth, "tissue.bladeDepth", float64, continuous)
        .unit("m")
        .start("0")
        .min("0")
        .describe("The tissue's cut.bladeDepth: length of the scalpel's edge inside the tissue"),

    // Outputs.
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
static_assert(fmi3::strictly_ordered(VARIABLES), "the variable table must be in increasing value-reference order");

constexpr auto TOOL_MODE_ITEMS = std::to_array<EnumerationItem>({
    {"none", 0, "No tool: nothing is rendered"},
    {"probe", 1, "The probe: the contact force is rendered"},
    {"scalpel", 2, "The scalpel: the cutting force is rendered"},
});
const auto ENUMERATIONS = std::to_array<EnumerationType>({
    {"ToolMode", "The tool the user holds", TOOL_MODE_ITEMS},
});

}  // namespace

const fmi3::ModelDescription& haptic_loop_model_description() {
  static const fmi3::ModelDescription description{MODEL_IDENTIFIER, INSTANTIATION_TOKEN, VARIABLES, ENUMERATIONS};
  return description;
}

}  // namespace tissue::haptic_fmu
