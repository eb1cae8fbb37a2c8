// The table of the Tissue FMU's variables: modelDescription/Tissue.xml in code, one entry
// per variable in value-reference order. Edit both together; tests/fmu/test_model_description.cpp
// fails, naming the variable and attribute, when they differ.
#include "tissue_fmu/variables.hpp"

#include <algorithm>

namespace tissue::tissue_fmu {
namespace {

using fmi3::Causality;
using fmi3::Entry;
using fmi3::EnumerationItem;
using fmi3::EnumerationType;
using fmi3::fixed_size;
using fmi3::input;
using fmi3::output;
using fmi3::parameter;
using fmi3::sized_by;
using fmi3::structural_parameter;
using fmi3::Variability;
using fmi3::VariableInfo;
using fmi3::VariableType;

using enum VariableType;
using enum Variability;

constexpr auto VARIABLES = std::to_array<VariableInfo>({
    fmi3::independent_time(Vr::time),

    // Parameters.
    parameter(Vr::mesh, "mesh", string)
        .start("frog")
        .describe("Tetrahedral mesh of the specimen: \"frog\" for the embedded default frog (also shipped as "
                  "resources/frog.veg), otherwise a file name in the FMU's resources folder or an absolute path "
                  "(.veg, .node/.ele, or Gmsh .msh 4.1)"),
    parameter(Vr::young_modulus, "material.youngModulus", float64)
        .unit("Pa")
        .start("1e5")
        .describe("Young's modulus E of the co-rotational linear material; must be > 0"),
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

    // Structural parameters.
    structural_parameter(Vr::vertex_capacity, "surface.vertexCapacity", uint64)
        .start("8192")
        .min("1")
        .describe("Rows of surface.vertexPositions: the most surface vertices that can be output"),
    structural_parameter(Vr::triangle_capacity, "surface.triangleCapacity", uint64)
        .start("8192")
        .min("1")
        .describe("Rows of surface.triangles: the most surface triangles that can be output"),

    // Inputs.
    input(Vr::tool_position, "tool.position", float64, continuous)
        .unit("m")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("Position of the tool tip (x y z)"),
    input(Vr::tool_orientation, "tool.orientation", float64, continuous)
        .unit("1")
        .start("1 0 0 0")
        .shape(fixed_size(4))
        .describe("Orientation of the tool as a unit quaternion (w x y z), local to world; the tool axis is the "
                  "local +z axis, from the tip toward the handle"),
    input(Vr::tool_mode, "tool.mode", enumeration, discrete)
        .declared_type("ToolMode")
        .start("0")
        .describe("What the tool does: none, probe or scalpel"),

    // Outputs.
    output(Vr::contact_active, "contact.active", boolean, discrete).describe("The probe is in contact with the tissue"),
    output(Vr::contact_point, "contact.point", float64, continuous)
        .unit("m")
        .shape(fixed_size(3))
        .describe("Contact point on the deformed surface (the god-object position); meaningful while contact.active"),
    output(Vr::contact_normal, "contact.normal", float64, continuous)
        .unit("1")
        .shape(fixed_size(3))
        .describe("Unit outward surface normal at contact.point; meaningful while contact.active"),
    output(Vr::contact_force, "contact.force", float64, continuous)
        .unit("N")
        .shape(fixed_size(3))
        .describe("Force of the tissue on the tool"),
    output(Vr::contact_stiffness, "contact.stiffness", float64, continuous)
        .unit("N/m")
        .shape(fixed_size(3), fixed_size(3))
        .describe("Contact stiffness K_c (row-major 3x3) for rendering f = f0 + K_c (x - x0) between tissue updates"),
    output(Vr::contact_depth, "contact.depth", float64, continuous)
        .unit("m")
        .describe("Penetration depth: distance from the tool tip to contact.point"),
    output(Vr::vertex_count, "surface.vertexCount", uint64, discrete)
        .describe("Rows of surface.vertexPositions in use (at most surface.vertexCapacity)"),
    output(Vr::triangle_count, "surface.triangleCount", uint64, discrete)
        .describe("Rows of surface.triangles in use (at most surface.triangleCapacity)"),
    output(Vr::surface_revision, "surface.revision", uint64, discrete)
        .describe("Changes when the surface topology changes (a cut); re-read surface.triangles then"),
    output(Vr::vertex_positions, "surface.vertexPositions", float64, continuous)
        .unit("m")
        .shape(sized_by(Vr::vertex_capacity), fixed_size(3))
        .describe("Deformed surface vertex positions (x y z per row): the mesh vertices in mesh order, then the "
                  "corners of the cut faces; rows from surface.vertexCount on are 0"),
    output(Vr::triangles, "surface.triangles", uint32, discrete)
        .shape(sized_by(Vr::triangle_capacity), fixed_size(3))
        .describe("Surface triangles as 0-based rows of surface.vertexPositions, counter-clockwise seen from "
                  "outside: the mesh's surface (where a cut crosses a surface triangle, its pieces either side of "
                  "the cut), then the faces the cuts opened; rows from surface.triangleCount on are 0"),
    output(Vr::cut_triangle_count, "surface.cutTriangleCount", uint64, discrete)
        .describe("How many of the surface.triangleCount rows, at the end, are faces the cuts opened"),
    output(Vr::cut_tets, "cutTets", uint64, discrete).describe("Number of tetrahedra cut so far"),
    output(Vr::enriched_vertices, "enrichedVertices", uint64, discrete)
        .describe("Number of enriched (XFEM) vertex unknowns the cuts added"),
    output(Vr::dofs, "dofs", uint64, discrete)
        .describe("Number of degrees of freedom of the system (3 per free vertex and per enriched unknown)"),
    output(Vr::kinetic_energy, "kineticEnergy", float64, continuous).unit("J").describe("Kinetic energy of the body"),
    output(Vr::elastic_energy, "elasticEnergy", float64, continuous)
        .unit("J")
        .describe("Elastic strain energy of the body"),
    output(Vr::blade_depth, "cut.bladeDepth", float64, continuous)
        .unit("m")
        .describe("Length of the scalpel's cutting edge inside the tissue while it cuts (0 otherwise): the haptic "
                  "loop's cutting force is proportional to it"),
    output(Vr::integrator_iterations, "integrator.iterations", uint64, discrete)
        .describe("Iterations of the integrator so far: PCG iterations (backward Euler with PCG), IDA's Newton "
                  "iterations plus its GMRES iterations (IDA); a direct solve counts none"),

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
});

static_assert(fmi3::strictly_ordered(VARIABLES), "the variable table must be in increasing value-reference order");

constexpr auto LINEAR_SOLVER_ITEMS = std::to_array<EnumerationItem>({
    {"pcg", 1,
     "Jacobi-preconditioned conjugate gradients (iterative; integrator.pcgTolerance, integrator.pcgMaxIterations)"},
    {"cholmod", 2, "Sparse Cholesky factorization (CHOLMOD, direct, exact)"},
    {"pcgCholesky", 3,
     "CG preconditioned by a lagged CHOLMOD factor, refactorized when the iterations grow or a cut changes the pattern; in the FMU without a worker thread (integrator.pcgTolerance, integrator.pcgMaxIterations)"},
});
constexpr auto INTEGRATOR_ITEMS = std::to_array<EnumerationItem>({
    {"backwardEuler", 1, "Semi-implicit backward Euler, one linear solve per internal step (integrator.linearSolver)"},
    {"ida", 2, "SUNDIALS IDA: variable-order, variable-step BDF with error control (integrator.ida*)"},
});
constexpr auto IDA_LINEAR_SOLVER_ITEMS = std::to_array<EnumerationItem>({
    {"klu", 1, "Sparse LU factorization of the Newton matrix (KLU, direct)"},
    {"krylov", 2, "GMRES, preconditioned by eliminating the velocities and the diagonal of the rest (iterative)"},
});
constexpr auto CONTACT_STIFFNESS_ITEMS = std::to_array<EnumerationItem>({
    {"effectiveStatic", 1,
     "Stiffness of the whole constrained body at the contact point (static condensation; the reference)"},
    {"elementLocal", 2, "Stiffness of the contacted tetrahedron alone (cheap, approximate)"},
});
constexpr auto TOOL_MODE_ITEMS = std::to_array<EnumerationItem>({
    {"none", 0, "The tool does not interact"},
    {"probe", 1, "The tool tip pushes the surface (god-object contact)"},
    {"scalpel", 2, "The blade cuts the tissue"},
});
const auto ENUMERATIONS = std::to_array<EnumerationType>({
    {"LinearSolver", "Linear solver of the backward-Euler step", LINEAR_SOLVER_ITEMS},
    {"ContactStiffnessModel", "How the 3x3 contact stiffness K_c is computed", CONTACT_STIFFNESS_ITEMS},
    {"Integrator", "Time integrator of the tissue", INTEGRATOR_ITEMS},
    {"IdaLinearSolver", "Linear solver of IDA's Newton iteration", IDA_LINEAR_SOLVER_ITEMS},
    {"ToolMode", "What the tool does to the tissue", TOOL_MODE_ITEMS},
});

}  // namespace

const fmi3::ModelDescription& tissue_model_description() {
  static const fmi3::ModelDescription description{MODEL_IDENTIFIER, INSTANTIATION_TOKEN, VARIABLES, ENUMERATIONS};
  return description;
}

}  // namespace tissue::tissue_fmu
