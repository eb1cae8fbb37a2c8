// The Tissue FMU's port schema: value references and the table of its variables (name, type,
// causality, variability, unit, start, range, dimensions, description) in the FMI layer's terms
// (fmi3/variable_table.hpp). Its parameters are the tissue's settings (core/tissue_settings_schema.hpp);
// its own switch, inputs and outputs are listed here; the tissue sample's outputs come from
// ports/tissue_sample.hpp. The build writes modelDescription.xml from
// this table (tissue-model-description). Plain C++, no FMI headers.
#pragma once

#include "core/tissue_settings_schema.hpp"
#include "fmi3/variable_table.hpp"
#include "port_variables/port_variables.hpp"
#include "ports/tissue_sample.hpp"
#include "ports/tool.hpp"

#include <array>
#include <span>

#include <cstdint>
#include <string_view>

namespace tissue::tissue_fmu {

inline constexpr std::string_view INSTANTIATION_TOKEN = "{6d0f5e2a-93b1-4c8e-a7d4-2f1b9c3e5a71}";
inline constexpr std::string_view MODEL_IDENTIFIER = "Tissue";
/// The value references of the FMU's own variables. The tissue's settings (parameters) take theirs
/// from the settings schema (core/tissue_settings_schema.hpp: value_reference), the sample's outputs
/// from ports/tissue_sample.hpp.
enum class Vr : std::uint32_t {
  time = 0,
  mesh_output_enabled = 17,
  // structural parameters
  vertex_capacity = 24,
  triangle_capacity = 25,
  // inputs
  tool_position = 30,
  tool_orientation = 31,
  tool_mode = 32,
  surface_prepare = 33,
  // outputs
  contact_active = ports::sample_field("contact.active").tissue_vr,
  contact_near = ports::sample_field("contact.near").tissue_vr,
  contact_point = ports::sample_field("contact.point").tissue_vr,
  contact_normal = ports::sample_field("contact.normal").tissue_vr,
  contact_force = ports::sample_field("contact.force").tissue_vr,
  contact_stiffness = ports::sample_field("contact.stiffness").tissue_vr,
  contact_damping = ports::sample_field("contact.damping").tissue_vr,
  contact_depth = 45,
  vertex_count = 50,
  triangle_count = 51,
  surface_revision = 52,
  vertex_positions = 53,
  triangles = 54,
  cut_triangle_count = 55,
  surface_mesh = 56,  // issue 22: the Binary surface outputs
  surface_embedding = 57,
  surface_nodes = 58,
  surface_preparing = 59,
  cut_tets = 60,
  enriched_vertices = 61,
  dofs = 62,
  kinetic_energy = 63,
  elastic_energy = 64,
  blade_depth = ports::sample_field("cut.bladeDepth").tissue_vr,
  integrator_iterations = 66,
  sample_time = 81,  // issue 24: for masters that cannot connect `time`
  tool_applied_position = ports::sample_field("tool.appliedPosition").tissue_vr
};

namespace variables_detail {
// The table in parts, one kind of variable each, in value-reference order within each; own_variables()
// merges them (fmi3::merged: by value reference).

/// The enumeration item numbers as the start attribute writes them (item k is number k + 1).
inline constexpr std::array<std::string_view, 9> ITEM_NUMBERS{"1", "2", "3", "4", "5", "6", "7", "8", "9"};

constexpr fmi3::VariableType fmu_type(SettingType type) {
  switch (type) {
    case SettingType::real:
    case SettingType::vector3:
      return fmi3::VariableType::float64;
    case SettingType::integer:
      return fmi3::VariableType::int32;
    case SettingType::boolean:
      return fmi3::VariableType::boolean;
    case SettingType::enumeration:
      return fmi3::VariableType::enumeration;
    case SettingType::text:
      return fmi3::VariableType::string;
  }
  return fmi3::VariableType::string;
}

/// A setting as an FMU parameter: the closed bounds become min and max (FMI's are inclusive); the
/// strict ones are checked when the parameters are read (tissue_settings()).
constexpr fmi3::VariableInfo fmu_parameter(const SettingInfo& setting) {
  fmi3::Entry entry = fmi3::parameter(setting.value_reference, setting.name, fmu_type(setting.type));
  if (!setting.unit.empty()) entry.unit(setting.unit);
  if (setting.type == SettingType::enumeration) {
    entry.declared_type(setting.enumeration_type).start(ITEM_NUMBERS.at(start_item(setting)));
  } else {
    entry.start(setting.start);
  }
  if (setting.type == SettingType::vector3) entry.shape(fmi3::fixed_size(3));
  if (setting.min && setting.min->inclusive) entry.min(setting.min->value);
  if (setting.max && setting.max->inclusive) entry.max(setting.max->value);
  return entry.describe(setting.description);
}

/// The tissue's settings (TISSUE_SETTINGS) as FMU parameters, in value-reference order.
constexpr auto setting_parameters() {
  std::array<fmi3::VariableInfo, TISSUE_SETTINGS.size()> parameters{};
  for (std::size_t k = 0; k < TISSUE_SETTINGS.size(); ++k) parameters[k] = fmu_parameter(TISSUE_SETTINGS[k]);
  return fmi3::merged(parameters, std::array<fmi3::VariableInfo, 0>{});
}

/// The FMU's own switch: whether the surface arrays are filled (17).
constexpr auto output_parameters() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  return std::to_array<VariableInfo>({
    parameter(Vr::mesh_output_enabled, "scene.meshOutput", boolean)
        .start("true")
        .describe("Surface-mesh output on; when false surface.vertexPositions and surface.triangles are not filled"),
});
}

/// The surface output's capacities (24-25).
constexpr auto structural_parameters() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  return std::to_array<VariableInfo>({
    structural_parameter(Vr::vertex_capacity, "surface.vertexCapacity", uint64)
        .start("8192")
        .min("1")
        .describe("Rows of surface.vertexPositions: the most surface vertices the arrays hold (surface.mesh "
                  "always holds all of them)"),
    structural_parameter(Vr::triangle_capacity, "surface.triangleCapacity", uint64)
        .start("8192")
        .min("1")
        .describe("Rows of surface.triangles: the most surface triangles the arrays hold (surface.mesh always "
                  "holds all of them)"),
});
}

/// The tool pose and mode, and the surface's preparation (30-33).
constexpr auto inputs() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  using enum Variability;
  return std::to_array<VariableInfo>({
    input(Vr::tool_position, "tool.position", float64, continuous)
        .unit("m")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("Position of the tool tip (x y z)"),
    input(Vr::tool_orientation, "tool.orientation", float64, continuous)
        .unit("1")
        .start("1 0 0 0")
        .shape(fixed_size(4))
        .min_norm(MIN_ORIENTATION_NORM)
        .describe("Orientation of the tool as a unit quaternion (w x y z), local to world; the tool axis is the "
                  "local +z axis, from the tip toward the handle"),
    input(Vr::tool_mode, "tool.mode", enumeration, discrete)
        .declared_type("ToolMode")
        .start("0")
        .describe("What the tool does: none, probe or scalpel"),
    input(Vr::surface_prepare, "surface.prepareAfterStep", boolean, discrete)
        .start("false")
        .describe("When true at a doStep that changes the surface's topology (a cut), the FMU prepares "
                  "surface.embedding after the step in a thread of normal priority, so that a real-time "
                  "importer reading it in its next slot finds it ready; every other call waits for it"),
});
}

/// The contact depth, the surface, the cut counters, the energies, the iterations (45-66; the
/// outputs the tissue sample carries come from ports/tissue_sample.hpp).
constexpr auto outputs() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  using enum Variability;
  return std::to_array<VariableInfo>({
    output(Vr::contact_depth, "contact.depth", float64, continuous)
        .unit("m")
        .describe("Penetration depth: distance from the tool tip to contact.point"),
    output(Vr::vertex_count, "surface.vertexCount", uint64, discrete)
        .describe("Rows of surface.vertexPositions in use (at most surface.vertexCapacity)"),
    output(Vr::triangle_count, "surface.triangleCount", uint64, discrete)
        .describe("Rows of surface.triangles in use (at most surface.triangleCapacity)"),
    output(Vr::surface_revision, "surface.revision", uint64, discrete)
        .describe("Changes when the surface topology changes (a cut); re-read surface.triangles and "
                  "surface.embedding then"),
    output(Vr::vertex_positions, "surface.vertexPositions", float64, continuous)
        .unit("m")
        .shape(sized_by(Vr::vertex_capacity), fixed_size(3))
        .describe("Deformed surface vertex positions (x y z per row): for the tet skin the mesh vertices in mesh "
                  "order, then the corners of the cut faces; for a render surface its vertices, then the points "
                  "its cuts added; rows from surface.vertexCount on are 0"),
    output(Vr::triangles, "surface.triangles", uint32, discrete)
        .shape(sized_by(Vr::triangle_capacity), fixed_size(3))
        .describe("Surface triangles as 0-based rows of surface.vertexPositions, counter-clockwise seen from "
                  "outside: the mesh's surface (where a cut crosses a surface triangle, its pieces either side of "
                  "the cut), then the faces the cuts opened; rows from surface.triangleCount on are 0"),
    output(Vr::cut_triangle_count, "surface.cutTriangleCount", uint64, discrete)
        .describe("How many of the surface.triangleCount rows, at the end, are faces the cuts opened"),
    output(Vr::surface_mesh, "surface.mesh", binary, discrete)
        .describe("The whole drawn surface, never truncated (docs/FMU_VARIABLES.md, \"Binary surface outputs\"): "
                  "\"TSM1\", version, vertex, triangle and cut-face counts, then Float64 positions [m] and UInt32 "
                  "triangles, little-endian"),
    output(Vr::surface_embedding, "surface.embedding", binary, discrete)
        .describe("The drawn surface's points as weighted sums of four nodes each, and its triangles (\"TSE1\"); "
                  "changes with surface.revision"),
    output(Vr::surface_nodes, "surface.nodes", binary, discrete)
        .describe("The nodes' positions for surface.embedding (\"TSN1\"): a viewer maps the points itself, reading "
                  "the coarse nodes every step and the embedding once per revision"),
    output(Vr::surface_preparing, "surface.preparing", boolean, discrete)
        .describe("True while the preparation of surface.embedding after a step (surface.prepareAfterStep) "
                  "still runs: reading the surface then waits for it, so a real-time importer may read it a "
                  "slot later; reading this never waits"),
    output(Vr::cut_tets, "cutTets", uint64, discrete).describe("Number of tetrahedra cut so far"),
    output(Vr::enriched_vertices, "enrichedVertices", uint64, discrete)
        .describe("Number of enriched (XFEM) vertex unknowns the cuts added"),
    output(Vr::dofs, "dofs", uint64, discrete)
        .describe("Number of degrees of freedom of the system (3 per free vertex and per enriched unknown)"),
    output(Vr::kinetic_energy, "kineticEnergy", float64, continuous).unit("J").describe("Kinetic energy of the body"),
    output(Vr::elastic_energy, "elasticEnergy", float64, continuous)
        .unit("J")
        .describe("Elastic strain energy of the body"),
    output(Vr::integrator_iterations, "integrator.iterations", uint64, discrete)
        .describe("Iterations of the integrator so far: PCG iterations (backward Euler with PCG), IDA's Newton "
                  "iterations plus its GMRES iterations (IDA); a direct solve counts none"),
    output(Vr::sample_time, "sample.time", float64, continuous)
        .unit("s")
        .describe("The tissue time the outputs are for (the communication point reached), as an output: a "
                  "co-simulation master that cannot connect the independent variable (FMI 2.0, SSP) connects "
                  "this to the haptic loop's tissue.time"),
});
}

/// The Tissue FMU's own variables: the independent time and the parts above.
constexpr auto own_variables() {
  using fmi3::merged;
  const auto independent = std::to_array<fmi3::VariableInfo>({fmi3::independent_time(Vr::time)});
  const auto parameters = merged(setting_parameters(), output_parameters());
  return merged(merged(merged(merged(independent, parameters), structural_parameters()), inputs()), outputs());
}
}  // namespace variables_detail

/// The Tissue FMU's variables with the tissue sample `sample` (ports::TISSUE_SAMPLE; a test adds a
/// field), in value-reference order.
template <std::size_t N>
constexpr auto tissue_variables(const std::array<ports::SampleField, N>& sample) {
  return fmi3::merged(variables_detail::own_variables(), ports::entries(sample, ports::tissue_output));
}

/// The Tissue FMU's description: identity, variables, enumeration types, log categories.
const fmi3::ModelDescription& tissue_model_description();
/// The same description over other variables (tissue_variables() of another sample; for tests).
fmi3::ModelDescription tissue_model_description(std::span<const fmi3::VariableInfo> variables);

}  // namespace tissue::tissue_fmu
