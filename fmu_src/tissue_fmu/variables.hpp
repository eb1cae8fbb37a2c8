// The Tissue FMU's port schema: value references and the table of its variables (name, type,
// causality, variability, unit, start, range, dimensions, description) in the FMI layer's terms
// (fmi3/variable_table.hpp), written once. The FMU's own variables are listed here; the tissue
// sample's outputs come from ports/tissue_sample.hpp. The build writes modelDescription.xml from
// this table (tissue-model-description). Plain C++, no FMI headers.
#pragma once

#include "fmi3/variable_table.hpp"
#include "ports/sample_entries.hpp"
#include "ports/tissue_sample.hpp"
#include "ports/tool.hpp"

#include <array>
#include <span>

#include <cstdint>
#include <string_view>

namespace tissue::tissue_fmu {

inline constexpr std::string_view INSTANTIATION_TOKEN = "{6d0f5e2a-93b1-4c8e-a7d4-2f1b9c3e5a71}";
inline constexpr std::string_view MODEL_IDENTIFIER = "Tissue";
enum class Vr : std::uint32_t {
  time = 0,
  // parameters
  mesh = 1,
  young_modulus = 2,
  poisson_ratio = 3,
  density = 4,
  damping_alpha = 5,
  damping_beta = 6,
  gravity = 7,
  fixed_axis = 8,
  fixed_fraction = 9,
  linear_solver = 10,
  pcg_tolerance = 11,
  pcg_max_iterations = 12,
  warm_start = 13,
  step_size = 14,
  contact_enabled = 15,
  cutting_enabled = 16,
  mesh_output_enabled = 17,
  probe_radius = 18,
  blade_length = 19,
  contact_spring_stiffness = 20,
  contact_stiffness_model = 21,
  contact_stiffness_refresh_steps = 22,
  min_volume_fraction = 23,
  // structural parameters
  vertex_capacity = 24,
  triangle_capacity = 25,
  // inputs
  tool_position = 30,
  tool_orientation = 31,
  tool_mode = 32,
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
  surface_mesh = 56,       // issue 22: the Binary surface outputs
  surface_embedding = 57,
  surface_nodes = 58,
  cut_tets = 60,
  enriched_vertices = 61,
  dofs = 62,
  kinetic_energy = 63,
  elastic_energy = 64,
  blade_depth = ports::sample_field("cut.bladeDepth").tissue_vr,
  integrator_iterations = 66,
  // parameters added with issue 10 (the integrator choice, the hand's speed limit)
  integrator_method = 70,
  ida_relative_tolerance = 71,
  ida_absolute_tolerance = 72,
  ida_max_order = 73,
  ida_max_step = 74,
  ida_linear_solver = 75,
  tool_max_speed = 76,
  contact_near_margin = 77,  // issue 20
  render_surface = 78,       // issue 22
  step_threads = 79,         // issue 23
  contact_stiffness_in_background = 80,  // issue 23
  sample_time = 81,                      // issue 24: for masters that cannot connect `time`
  material_regions = 82,                 // issue 25
  material_model = 83,                   // issue 25
  tool_applied_position = ports::sample_field("tool.appliedPosition").tissue_vr
};

namespace variables_detail {
// The table in parts, one kind of variable each, in value-reference order within each; own_variables()
// merges them (fmi3::merged: by value reference).

/// The body: mesh, material, damping, gravity, the fixed region (value references 1-9), the regions'
/// materials (82), the material model (83).
constexpr auto body_parameters() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  return std::to_array<VariableInfo>({
    parameter(Vr::mesh, "mesh", string)
        .start("frog")
        .describe("Tetrahedral mesh of the specimen: \"frog\" for the embedded default frog (also shipped as "
                  "resources/frog.veg), otherwise a file name in the FMU's resources folder or an absolute path "
                  "(.veg, .node/.ele, or Gmsh .msh 4.1)"),
    parameter(Vr::young_modulus, "material.youngModulus", float64)
        .unit("Pa")
        .start("1e5")
        .describe("Young's modulus E (of either material.model); must be > 0"),
    parameter(Vr::poisson_ratio, "material.poissonRatio", float64)
        .unit("1")
        .start("0.4")
        .min("0")
        .describe("Poisson's ratio nu; must be < 0.5"),
    parameter(Vr::density, "material.density", float64)
        .unit("kg/m3")
        .start("1000")
        .describe("Mass density rho; must be > 0"),
    parameter(Vr::damping_alpha, "damping.alpha", float64)
        .unit("1/s")
        .start("1")
        .min("0")
        .describe("Rayleigh damping D = alpha M + beta K: the mass-proportional coefficient alpha"),
    parameter(Vr::damping_beta, "damping.beta", float64)
        .unit("s")
        .start("0.001")
        .min("0")
        .describe("Rayleigh damping D = alpha M + beta K: the stiffness-proportional coefficient beta"),
    parameter(Vr::gravity, "gravity", float64)
        .unit("m/s2")
        .start("0 0 -9.81")
        .shape(fixed_size(3))
        .describe("Gravitational acceleration (x y z)"),
    parameter(Vr::fixed_axis, "fixedRegion.axis", int32)
        .start("2")
        .min("-1")
        .max("2")
        .describe("Which vertices are held at their rest positions: -1 none; 0, 1, 2 those whose x, y, z lies within "
                  "fixedRegion.fraction of the mesh's extent from its minimum"),
    parameter(Vr::fixed_fraction, "fixedRegion.fraction", float64)
        .unit("1")
        .start("0.25")
        .min("0")
        .max("1")
        .describe("Thickness of the fixed slab as a fraction of the mesh's extent along fixedRegion.axis"),
    parameter(Vr::material_regions, "material.regions", string)
        .start("none")
        .describe("Materials by region name (the mesh's Vega *REGION sets, Gmsh physical groups or TetGen region "
                  "numbers), replacing the file's: \"name: youngModulus=1e6, poissonRatio=0.45, density=1050; "
                  "name2: ...\" (keys youngModulus [Pa], poissonRatio, density [kg/m^3], dampingAlpha [1/s]); a key "
                  "left out takes material.* (dampingAlpha: damping.alpha). A region neither the file nor this gives "
                  "a material has material.*. \"none\": none"),
    parameter(Vr::material_model, "material.model", enumeration)
        .declared_type("MaterialModel")
        .start("1")
        .describe("Elasticity of every region: co-rotational linear (the default) or stable Neo-Hookean "
                  "(hyperelastic, inversion-safe; Smith, de Goes and Kim 2018), with the same E and nu"),
});
}

/// The backward-Euler step: its linear solver, PCG's settings, the internal step, its threads (10-14, 79).
constexpr auto solver_parameters() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  return std::to_array<VariableInfo>({
    parameter(Vr::linear_solver, "integrator.linearSolver", enumeration)
        .declared_type("LinearSolver")
        .start("1")
        .describe("Linear solver of the backward-Euler step"),
    parameter(Vr::pcg_tolerance, "integrator.pcgTolerance", float64)
        .unit("1")
        .start("0.001")
        .describe("PCG stopping tolerance on the relative residual; must be > 0"),
    parameter(Vr::pcg_max_iterations, "integrator.pcgMaxIterations", int32)
        .start("10")
        .min("1")
        .describe("PCG iteration cap per step"),
    parameter(Vr::warm_start, "integrator.warmStart", boolean)
        .start("false")
        .describe("PCG starts from the previous step's velocity change instead of zero"),
    parameter(Vr::step_size, "stepSize", float64)
        .unit("s")
        .start("0.001")
        .describe("Internal backward-Euler step; must be > 0. A communication step must be a whole multiple of it"),
    parameter(Vr::step_threads, "integrator.threads", int32)
        .start("1")
        .min("1")
        .max("2")
        .describe("Threads of a backward-Euler step: 1, or 2 to let a doStep run a second thread for its own duration "
                  "(made and joined by each step; the results are bitwise the same)"),
});
}

/// What the scene builds, the tool, the contact and the cutter (15-23).
constexpr auto scene_parameters() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  return std::to_array<VariableInfo>({
    parameter(Vr::contact_enabled, "scene.contact", boolean)
        .start("true")
        .describe("Probe contact on; when false the contact structures are not built and the probe does not touch "
                  "the tissue"),
    parameter(Vr::cutting_enabled, "scene.cutting", boolean)
        .start("true")
        .describe("Cutting on; when false the scalpel does not cut and the cutter is not built"),
    parameter(Vr::mesh_output_enabled, "scene.meshOutput", boolean)
        .start("true")
        .describe("Surface-mesh output on; when false surface.vertexPositions and surface.triangles are not filled"),
    parameter(Vr::probe_radius, "tool.probeRadius", float64)
        .unit("m")
        .start("0")
        .min("0")
        .describe("Radius of the probe's spherical tip; 0 = a point probe"),
    parameter(Vr::blade_length, "tool.bladeLength", float64)
        .unit("m")
        .start("0.03")
        .describe("Length of the scalpel's cutting edge, from the tip along the tool axis; must be > 0"),
    parameter(Vr::contact_spring_stiffness, "contact.springStiffness", float64)
        .unit("N/m")
        .start("0")
        .min("0")
        .describe("Stiffness of the implicit spring that ties the god-object to the probe tip; 0 = automatic (100 "
                  "times the body's contact stiffness scale)"),
    parameter(Vr::contact_stiffness_model, "contact.stiffnessModel", enumeration)
        .declared_type("ContactStiffnessModel")
        .start("1")
        .describe("How contact.stiffness is computed"),
    parameter(Vr::contact_stiffness_refresh_steps, "contact.stiffnessRefreshSteps", int32)
        .start("10")
        .min("1")
        .describe("The effectiveStatic contact stiffness is recomputed when a contact starts and then every this "
                  "many internal steps"),
    parameter(Vr::min_volume_fraction, "cutter.minVolumeFraction", float64)
        .unit("1")
        .start("0.001")
        .describe("Smallest volume fraction either side of a cut tetrahedron is given (keeps slivers stiff and "
                  "massive enough); in [1e-12, 0.5)"),
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

/// The tool pose and mode (30-32).
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

/// The integrator choice and IDA's settings, the hand's speed limit (issue 10; 70-76).
constexpr auto integrator_parameters() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  return std::to_array<VariableInfo>({
    parameter(Vr::integrator_method, "integrator.method", enumeration)
        .declared_type("Integrator")
        .start("1")
        .describe("Time integrator: backward Euler (one linear solve per internal step) or SUNDIALS IDA "
                  "(variable-order BDF with error control)"),
    parameter(Vr::ida_relative_tolerance, "integrator.idaRelativeTolerance", float64)
        .unit("1")
        .start("0.0001")
        .describe("IDA's relative error tolerance; must be > 0"),
    parameter(Vr::ida_absolute_tolerance, "integrator.idaAbsoluteTolerance", float64)
        .start("1e-08")
        .describe("IDA's absolute error tolerance, in m on displacements and m/s on velocities; must be > 0"),
    parameter(Vr::ida_max_order, "integrator.idaMaxOrder", int32)
        .start("5")
        .min("1")
        .max("5")
        .describe("Highest BDF order IDA may use"),
    parameter(Vr::ida_max_step, "integrator.idaMaxStep", float64)
        .unit("s")
        .start("0")
        .min("0")
        .describe("Largest internal step IDA may take; 0: no limit below stepSize"),
    parameter(Vr::ida_linear_solver, "integrator.idaLinearSolver", enumeration)
        .declared_type("IdaLinearSolver")
        .start("1")
        .describe("Linear solver of IDA's Newton iteration"),
    parameter(Vr::tool_max_speed, "tool.maxSpeed", float64)
        .unit("m/s")
        .start("5")
        .describe("Fastest a hand moves the tool; a pose farther than this times the internal step from the last is "
                  "approached at this speed (the tool is clamped, a scalpel sweeps the path in sub-steps); must be > 0"),
    parameter(Vr::contact_near_margin, "contact.nearMargin", float64)
        .unit("m")
        .start("0.01")
        .min("0")
        .describe("A probe not in contact but this close to the surface reports it (contact.near): the nearest surface "
                  "point, its normal and stiffness, so that a haptic loop feels the surface from the tick the tool "
                  "crosses it; 0: never"),
    parameter(Vr::contact_stiffness_in_background, "contact.stiffnessInBackground", boolean)
        .start("false")
        .describe("The effectiveStatic contact stiffness's factorization runs in a worker thread beside the step "
                  "(started by a step, joined by the next, which renders it) instead of in the step: a refresh reaches "
                  "contact.stiffness one internal step later, and a new contact starts with the elementLocal estimate "
                  "for its first step. The results are the same with or without the thread"),
});
}

/// What is drawn (issue 22; 78).
constexpr auto surface_parameters() {
  using namespace fmi3;  // NOLINT(google-build-using-namespace): the table reads as the XML
  using enum VariableType;
  return std::to_array<VariableInfo>({
    parameter(Vr::render_surface, "surface.renderSurface", string)
        .start("none")
        .describe("The surface the surface.* outputs draw: \"none\" for the tet mesh's own skin, \"frog\" for the "
                  "embedded frog's fine render surface (meshes/frog_surface.obj), otherwise an OBJ file in the FMU's "
                  "resources folder or an absolute path; it rides on the tets and is cut with them"),
});
}

/// The Tissue FMU's own variables: the independent time and the parts above.
constexpr auto own_variables() {
  using fmi3::merged;
  const auto independent = std::to_array<fmi3::VariableInfo>({fmi3::independent_time(Vr::time)});
  const auto parameters =
      merged(merged(merged(merged(body_parameters(), solver_parameters()), scene_parameters()), integrator_parameters()),
             surface_parameters());
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
