// The tissue's settings, each declared once (setting_schema.hpp): the Tissue FMU's parameters and
// enumeration types, the scenario files' [tissue.parameters] keys, the Python module's keywords and
// their defaults, the range checks, the model fingerprint and docs/FMU_VARIABLES.md's parameter table
// all come from TISSUE_SETTINGS. A new setting is one entry here plus the code that uses it.
#pragma once

#include "core/setting_schema.hpp"

#include <array>
#include <optional>
#include <string_view>

namespace tissue {

namespace settings_detail {
using enum SettingType;
// A member of TissueParameters, for Setting::member.
#define TISSUE_MEMBER(path) [](TissueParameters& p) -> SettingMember { return &p.path; }
#define TISSUE_ENUM_MEMBER(path) [](TissueParameters& p) -> SettingMember { return enum_member(p.path); }

/// The body: its mesh, material, damping, gravity and fixed region.
constexpr auto body_settings() {
  return std::to_array<SettingInfo>({
      Setting("mesh", 1, text)
          .python("mesh")
          .scene()
          .start("frog")
          .describe("The specimen's tetrahedral mesh: frog = the embedded default frog (also shipped as "
                    "resources/frog.veg); otherwise a file name in the FMU's resources folder or an absolute path "
                    "(.veg, .node/.ele, Gmsh .msh 4.1)")
          .member(TISSUE_MEMBER(mesh)),
      Setting("material.youngModulus", 2, real)
          .python("young_modulus_pa")
          .unit("Pa")
          .start("1e5")
          .above("0")
          .describe("Young's modulus E (of either material.model)")
          .member(TISSUE_MEMBER(settings.body.material.young_modulus_pa)),
      Setting("material.poissonRatio", 3, real)
          .python("poisson_ratio")
          .unit("1")
          .start("0.4")
          .at_least("0")
          .below("0.5")
          .describe("Poisson's ratio nu")
          .member(TISSUE_MEMBER(settings.body.material.poisson_ratio)),
      Setting("material.density", 4, real)
          .python("density_kg_per_m3")
          .unit("kg/m3")
          .start("1000")
          .above("0")
          .describe("Mass density rho")
          .member(TISSUE_MEMBER(settings.body.material.density_kg_per_m3)),
      Setting("material.regions", 82, text)
          .scene()
          .start("none")
          .describe("Materials by region name (the mesh's Vega *REGION sets, Gmsh physical groups, TetGen region "
                    "numbers), replacing the file's: \"tumour: youngModulus=1e6, poissonRatio=0.45, density=1050, "
                    "dampingAlpha=20; skin: youngModulus=3e5\"; the keys youngModulus [Pa], poissonRatio, density "
                    "[kg/m^3] and dampingAlpha [1/s] (the region's own Rayleigh alpha; damping.beta stays one for the "
                    "body); a key left out takes material.* (dampingAlpha: damping.alpha); a region neither the file "
                    "nor this gives a material has material.*; a name the mesh does not have is refused, naming the "
                    "mesh's regions. none: none. (Python: the regions keyword, a dict by region)")
          .member(TISSUE_MEMBER(material_regions)),
      Setting("material.model", 83, enumeration)
          .python("material_model")
          .start("corotationalLinear")
          .items("MaterialModel", "Elasticity of the tissue", MATERIAL_MODEL_NAMES.all())
          .describe("Elasticity of every region, with the same E and nu: co-rotational linear (one linear solve a "
                    "step) or stable Neo-Hookean (Smith, de Goes and Kim 2018: hyperelastic, inversion-safe, its "
                    "tangent projected to positive semi-definite per element); docs/BENCHMARKS.md weighs them")
          .member(TISSUE_ENUM_MEMBER(settings.body.material_model)),
      Setting("damping.alpha", 5, real)
          .python("damping_alpha_per_s")
          .unit("1/s")
          .start("1")
          .at_least("0")
          .core_default("the core's bodies are undamped unless a test or bench asks; a product's tissue settles")
          .describe("Rayleigh damping D = alpha M + beta K, mass-proportional part (a region's dampingAlpha "
                    "replaces it there)")
          .member(TISSUE_MEMBER(settings.body.damping.mass_damping_per_s)),
      Setting("damping.beta", 6, real)
          .python("damping_beta_s")
          .unit("s")
          .start("0.001")
          .at_least("0")
          .core_default("the core's bodies are undamped unless a test or bench asks; a product's tissue settles")
          .describe("Rayleigh damping, stiffness-proportional part")
          .member(TISSUE_MEMBER(settings.body.damping.stiffness_damping_s)),
      Setting("gravity", 7, vector3)
          .python("gravity_m_per_s2")
          .unit("m/s2")
          .start("0 0 -9.81")
          .core_default("the core's tests and benches are written with y up; the products' scenes, the frog's "
                        "tray and the organ's ligament, with z up")
          .describe("Gravitational acceleration (x y z)")
          .member(TISSUE_MEMBER(settings.body.gravity_m_per_s2)),
      Setting("fixedRegion.axis", 8, integer)
          .python("fixed_axis")
          .scene()
          .start("2")
          .at_least("-1")
          .at_most("2")
          .describe("-1: nothing fixed; 0, 1, 2: the vertices within fixedRegion.fraction of the extent from the "
                    "minimum along x, y, z keep their rest positions, and the material between them (tets whose "
                    "four vertices are fixed) stays held when cut (Python: fixed_vertices lists them instead)")
          .member(TISSUE_MEMBER(fixed_axis)),
      Setting("fixedRegion.fraction", 9, real)
          .python("fixed_fraction")
          .scene()
          .unit("1")
          .start("0.25")
          .at_least("0")
          .at_most("1")
          .describe("Thickness of that slab as a fraction of the mesh's extent")
          .member(TISSUE_MEMBER(fixed_fraction)),
  });
}

/// The time integration: the integrator, backward Euler's linear solver and PCG (IDA's: below).
constexpr auto integrator_settings() {
  return std::to_array<SettingInfo>({
      Setting("integrator.linearSolver", 10, enumeration)
          .python("linear_solver")
          .start("pcgTwoLevel")
          .items("LinearSolver", "Linear solver of the backward-Euler step", LINEAR_SOLVER_NAMES.all())
          .core_default("the core's solver is Jacobi PCG (pcg) to its tolerance unless a caller picks one")
          .describe("Linear solver of the backward-Euler step. pcgTwoLevel (the default; issue 40) adds to Jacobi an "
                    "exact solve on the rigid motions of small aggregates of vertices, so that the slow motions "
                    "converge within the 10-iteration cap: a piece cut free falls, a cantilever sags and swings, a "
                    "held probe's force is steady, as with exact solves. pcg (Jacobi alone, the default before) "
                    "capped at 10 iterations leaves them unconverged: a freed piece sinks in slow motion, a "
                    "cantilever swings at a third of its frequency. pcgCholesky (CG preconditioned by a lagged "
                    "Cholesky factor) converges too, at a large factorization per cut (docs/BENCHMARKS.md)")
          .member(TISSUE_ENUM_MEMBER(settings.solver.kind)),
      Setting("integrator.pcgTolerance", 11, real)
          .python("pcg_tolerance")
          .unit("1")
          .start("0.001")
          .above("0")
          .core_default("the core solves to 1e-6 unless a caller asks for the real-time setting")
          .describe("PCG stopping tolerance on the relative residual")
          .member(TISSUE_MEMBER(settings.solver.pcg.tolerance)),
      Setting("integrator.pcgMaxIterations", 12, integer)
          .python("pcg_max_iterations")
          .start("10")
          .at_least("1")
          .core_default("the core's PCG runs to its tolerance (10000) unless a caller caps it for a real-time slot")
          .describe("PCG iteration cap per step")
          .member(TISSUE_MEMBER(settings.solver.pcg.max_iterations)),
      Setting("integrator.warmStart", 13, boolean)
          .python("warm_start")
          .start("false")
          .describe("PCG starts from the combination of the last 8 steps' velocity changes nearest the solution in the "
                    "energy norm (their Galerkin projection: one product with the matrix each) instead of zero")
          .member(TISSUE_MEMBER(settings.solver.warm_start)),
      Setting("integrator.refactorInBackground", 85, boolean)
          .python("refactor_in_background")
          .start("false")
          .describe(
              "pcgCholesky: its lagged factor is refactorized in a worker thread beside the steps (started "
              "by a solver setup, installed two setups later) instead of in the setup that installs it. The results "
              "are the same with or without the thread. Off: no thread unless asked (an importer has no "
              "FMI switch that allows threads); tissue-host turns it on for its own Tissue.fmu")
          .member(TISSUE_MEMBER(settings.solver.refresh.background_refactor)),
      Setting("stepSize", 14, real)
          .python("step_size_s")
          .unit("s")
          .start("0.001")
          .above("0")
          .describe("Internal step (IDA: the interval of one step, which IDA covers in as many steps as its "
                    "tolerances need). A communication step must be a whole multiple of it")
          .member(TISSUE_MEMBER(settings.step_size_s)),
      Setting("integrator.threads", 79, integer)
          .python("threads")
          .start("1")
          .at_least("1")
          .at_most("2")
          .describe("Threads of a backward-Euler step: 2 lets a step run a second thread for its own duration "
                    "(made and joined by each step); the results are bitwise the same as with 1")
          .member(TISSUE_MEMBER(settings.integrator.threads)),
      Setting("integrator.newtonMaxIterations", 86, integer)
          .python("newton_max_iterations")
          .start("1")
          .at_least("1")
          .at_most("100")
          .core_default("the core takes up to 5 corrections unless a caller bounds them for a real-time slot")
          .describe("Backward Euler: Newton corrections at most in a step whose linearized solve turns some element "
                    "further than 0.05 rad (each halved until the step's incremental potential falls; the energy "
                    "guard still keeps the step from gaining energy). 1 (the default) bounds a tumbling piece's step "
                    "to about twice a plain one; more converge the turn further at a solve each")
          .member(TISSUE_MEMBER(settings.integrator.newton.max_iterations)),
      Setting("integrator.linearizeAtPredictedEnd", 92, boolean)
          .python("linearize_at_predicted_end")
          .start("true")
          .core_default("the core takes the dissertation's step, linearized at the start, unless a caller asks")
          .describe("Backward Euler: each step is linearized at the predicted end u0 + h v0 (Newton's first "
                    "iteration from the last velocity) instead of at its start u0 (false: the dissertation's step). "
                    "One assembly and one solve a step, as before; a beam swinging on a hinge is then followed to "
                    "within 0.2% of the "
                    "converged equations at 1 ms steps without Newton corrections (linearized at the start: 23%, "
                    "and corrections in most of its steps at 4 ms: docs/DESIGN.md)")
          .member(TISSUE_MEMBER(settings.integrator.newton.linearize_at_predicted_end)),
      Setting("integrator.method", 70, enumeration)
          .python("integrator")
          .start("backwardEuler")
          .items("Integrator", "Time integrator of the tissue", INTEGRATOR_NAMES.all())
          .describe("Time integrator: backward Euler (one linear solve per internal step) or SUNDIALS IDA "
                    "(variable-order BDF with error control)")
          .member(TISSUE_ENUM_MEMBER(settings.integrator.kind)),
  });
}

/// SUNDIALS IDA's settings.
constexpr auto ida_settings() {
  return std::to_array<SettingInfo>({
      Setting("integrator.idaRelativeTolerance", 71, real)
          .python("ida_relative_tolerance")
          .unit("1")
          .start("0.0001")
          .above("0")
          .describe("IDA's relative error tolerance")
          .member(TISSUE_MEMBER(settings.integrator.ida.relative_tolerance)),
      Setting("integrator.idaAbsoluteTolerance", 72, real)
          .python("ida_absolute_tolerance")
          .start("1e-08")
          .above("0")
          .describe("IDA's absolute error tolerance, in m on displacements and m/s on velocities")
          .member(TISSUE_MEMBER(settings.integrator.ida.absolute_tolerance)),
      Setting("integrator.idaMaxOrder", 73, integer)
          .python("ida_max_order")
          .start("5")
          .at_least("1")
          .at_most("5")
          .describe("Highest BDF order IDA may use")
          .member(TISSUE_MEMBER(settings.integrator.ida.max_order)),
      Setting("integrator.idaMaxStep", 74, real)
          .python("ida_max_step_s")
          .unit("s")
          .start("0")
          .at_least("0")
          .describe("Largest internal step IDA may take; 0: no limit below stepSize")
          .member(TISSUE_MEMBER(settings.integrator.ida.max_step_s)),
      Setting("integrator.idaLinearSolver", 75, enumeration)
          .python("ida_linear_solver")
          .start("klu")
          .items("IdaLinearSolver", "Linear solver of IDA's Newton iteration", IDA_LINEAR_SOLVER_NAMES.all())
          .describe("Linear solver of IDA's Newton iteration: KLU (sparse LU) or GMRES preconditioned by "
                    "eliminating the velocities")
          .member(TISSUE_ENUM_MEMBER(settings.integrator.ida.linear_solver)),
  });
}

/// What the scene builds, and the tool.
constexpr auto interaction_settings() {
  return std::to_array<SettingInfo>({
      Setting("scene.contact", 15, boolean)
          .python("contact")
          .start("true")
          .describe("Probe contact; off: the probe touches nothing, and the surface BVH is built only if cutting "
                    "is on")
          .member(TISSUE_MEMBER(settings.interaction.contact_enabled)),
      Setting("scene.cutting", 16, boolean)
          .python("cutting")
          .start("true")
          .describe("Cutting; off: the scalpel does not cut; the cutter and the edge adjacency are not built")
          .member(TISSUE_MEMBER(settings.interaction.cutting_enabled)),
      Setting("scene.fieldMargin", 87, real)
          .python("field_margin_fraction")
          .unit("1")
          .start("0.5")
          .at_least("0")
          .describe("The operating field: the body's rest box grown by this fraction of its largest size on every side. A "
                    "part cut free that has fallen wholly outside it leaves the dynamics (looked for every 10 steps): "
                    "its elements add nothing, its rows fall on freely as one rigid body (spin dropped). A large "
                    "value (1e6) keeps every part")
          .member(TISSUE_MEMBER(settings.field_margin_fraction)),
      Setting("tool.probeRadius", 18, real)
          .python("probe_radius_m")
          .unit("m")
          .start("0")
          .at_least("0")
          .describe("Radius of a ball-ended probe: tool.position is then the ball's centre and the ball's pole "
                    "along the tool axis (position - r x axis) touches; exact for pushes along the axis; 0 = a "
                    "point probe")
          .member(TISSUE_MEMBER(settings.interaction.probe_radius_m)),
      Setting("tool.bladeLength", 19, real)
          .python("blade_length_m")
          .unit("m")
          .start("0.03")
          .above("0")
          .describe("Length of the scalpel's cutting edge, from the tip along the tool axis")
          .member(TISSUE_MEMBER(settings.interaction.blade_length_m)),
      Setting("tool.maxSpeed", 76, real)
          .python("max_tool_speed_m_per_s")
          .unit("m/s")
          .start("5")
          .above("0")
          .describe("Fastest a hand moves the tool: a pose farther than this times stepSize from the last is "
                    "approached at this speed (the tool is clamped; a scalpel sweeps its path in sub-sweeps)")
          .member(TISSUE_MEMBER(settings.interaction.max_tool_speed_m_per_s)),
  });
}

/// The probe's contact.
constexpr auto contact_settings() {
  return std::to_array<SettingInfo>({
      Setting("contact.nearMargin", 77, real)
          .python("near_surface_margin_m")
          .unit("m")
          .start("0.01")
          .at_least("0")
          .describe("A probe not in contact but this close to the surface reports it (contact.near): the nearest "
                    "surface point, its normal and stiffness, so that a haptic loop feels the surface from the tick "
                    "the tool crosses it; 0: never")
          .member(TISSUE_MEMBER(settings.interaction.contact.near_surface_margin_m)),
      Setting("contact.springStiffness", 20, real)
          .python("contact_spring_stiffness_n_per_m")
          .unit("N/m")
          .start("0")
          .at_least("0")
          .describe("Spring tying the god-object to the probe tip; 0 = automatic (100 x the body's contact "
                    "stiffness scale)")
          .member(TISSUE_MEMBER(settings.interaction.contact.spring_stiffness_n_per_m)),
      Setting("contact.stiffnessModel", 21, enumeration)
          .python("contact_stiffness_model")
          .start("effectiveStatic")
          .items("ContactStiffnessModel", "How the 3x3 contact stiffness K_c is computed",
                 CONTACT_STIFFNESS_MODEL_NAMES.all())
          .describe("How contact.stiffness is computed")
          .member(TISSUE_ENUM_MEMBER(settings.interaction.contact.stiffness_model)),
      Setting("contact.stiffnessRefreshSteps", 22, integer)
          .python("contact_stiffness_refresh_steps")
          .start("10")
          .at_least("1")
          .describe("effectiveStatic K_c is recomputed when a contact starts, then every this many internal steps")
          .member(TISSUE_MEMBER(settings.interaction.contact.stiffness_refresh_steps)),
      Setting("contact.stiffnessInBackground", 80, boolean)
          .python("contact_stiffness_in_background")
          .start("false")
          .describe("The effectiveStatic K_c's factorization runs in a worker thread beside the step (started by a "
                    "step, joined and rendered by the next) instead of in it: a refresh reaches contact.stiffness "
                    "one internal step later, and a new contact's first step renders the elementLocal estimate. The "
                    "results are the same with or without the thread. Off: no thread unless asked (an importer "
                    "has no FMI switch that allows threads); tissue-host turns it on for its own Tissue.fmu, whose "
                    "step shares its slot with nothing else")
          .member(TISSUE_MEMBER(settings.interaction.contact.stiffness_in_background)),
      Setting("contact.stiffnessLatencySteps", 88, integer)
          .python("contact_stiffness_latency_steps")
          .start("1")
          .at_least("1")
          .describe("With contact.stiffnessInBackground: a K_c refresh started at a step is rendered this many "
                    "internal steps later (the worker has that long before the step waits for it; a new contact "
                    "renders the elementLocal estimate until then), and the next refresh starts then: K_c is "
                    "refreshed every max(contact.stiffnessRefreshSteps, this) steps. For bodies whose "
                    "factorization takes longer than a step (the 52k-tet organ: ~1-1.5 s on one core). A refresh "
                    "that condenses from the last factor (contact.stiffnessRefactorRefreshes) lands at the next "
                    "step")
          .member(TISSUE_MEMBER(settings.interaction.contact.stiffness_latency_steps)),
      Setting("contact.friction", 89, real)
          .python("contact_friction")
          .start("0")
          .at_least("0")
          .at_most("2")
          .describe("Coulomb friction coefficient mu of the probe on the tissue. 0: frictionless, the probe slides "
                    "and presses along the surface's normal only. Above 0 the contact sticks (the tissue dragged "
                    "with the tool, contact.stiffness the bonded one) until the force along the surface would "
                    "exceed mu times the normal force, then slips with that force against the tool's motion")
          .member(TISSUE_MEMBER(settings.interaction.contact.friction_coefficient)),
      Setting("contact.padRadius", 91, real)
          .python("contact_pad_radius_m")
          .unit("m")
          .start("0")
          .at_least("0")
          .at_most("0.05")
          .describe("The probe ends in a flat pad of this radius across the surface's normal (a fingertip, a blunt "
                    "palpation probe) instead of a point: the force no longer follows the mesh's edge length under "
                    "the point, and a coarser mesh feels as the fine one does once its edges are shorter than the "
                    "radius. The pad slides (frictionless: contact.friction must be 0) and needs the effectiveStatic "
                    "contact.stiffnessModel (contact.stiffness is then the pad's, along the normal). 0: a point")
          .member(TISSUE_MEMBER(settings.interaction.contact.pad_radius_m)),
      Setting("contact.stiffnessRefactorRefreshes", 90, integer)
          .python("contact_stiffness_refactor_refreshes")
          .start("1")
          .at_least("1")
          .describe("effectiveStatic K_c: the matrix is factorized anew at every this many refreshes (and always "
                    "after a cut or a restore); the refreshes between condense the contact's current point from "
                    "the last factor, the body as it was then (forward solves: ~8 ms on the 52k-tet organ against "
                    "a 0.6-1.5 s factorization). 1: every refresh factorizes. For bodies whose factorization "
                    "takes far longer than a step")
          .member(TISSUE_MEMBER(settings.interaction.contact.stiffness_refactor_refreshes)),
  });
}

/// The cutter, and what is drawn.
constexpr auto cutter_and_surface_settings() {
  return std::to_array<SettingInfo>({
      Setting("cutter.minVolumeFraction", 23, real)
          .python("min_volume_fraction")
          .unit("1")
          .start("0.001")
          .at_least("1e-12")
          .below("0.5")
          .describe("Smallest volume fraction either side of a cut tet is given (keeps slivers stiff and massive "
                    "enough)")
          .member(TISSUE_MEMBER(settings.interaction.cutter.min_volume_fraction)),
      Setting("cutter.vertexSnapFraction", 84, real)
          .python("vertex_snap_fraction")
          .unit("1")
          .start("0.001")
          .at_least("0")
          .below("0.5")
          .describe("An edge the blade crosses within this fraction of its length from an end is cut through that "
                    "vertex (a cut within eps of a vertex passes through it: docs/DESIGN.md, \"Cutting\"); 0 takes the "
                    "crossings as "
                    "computed")
          .member(TISSUE_MEMBER(settings.interaction.cutter.vertex_snap_fraction)),
      Setting("surface.renderSurface", 78, text)
          .python("render_surface")
          .scene()
          .start("none")
          .describe("What is drawn: none the tet mesh's own skin; frog the embedded frog's fine render surface "
                    "(meshes/frog_surface.obj, 23 240 triangles); otherwise an OBJ file (in the FMU: in its "
                    "resources folder, or an absolute path). It rides on the tets and is cut with them (closed "
                    "pieces, capped openings). A surface outside the mesh, not closed, not manifold or with a NaN is "
                    "refused, naming the file and the element")
          .member(TISSUE_MEMBER(render_surface)),
  });
}

#undef TISSUE_MEMBER
#undef TISSUE_ENUM_MEMBER

template <class T, std::size_t A, std::size_t B>
constexpr std::array<T, A + B> joined(const std::array<T, A>& a, const std::array<T, B>& b) {
  std::array<T, A + B> out{};
  for (std::size_t k = 0; k < A; ++k) out[k] = a[k];
  for (std::size_t k = 0; k < B; ++k) out[A + k] = b[k];
  return out;
}
}  // namespace settings_detail

/// Every setting of the tissue, in the docs' order.
inline constexpr auto TISSUE_SETTINGS = settings_detail::joined(
    settings_detail::joined(settings_detail::joined(settings_detail::body_settings(), settings_detail::integrator_settings()),
                            settings_detail::ida_settings()),
    settings_detail::joined(
        settings_detail::joined(settings_detail::interaction_settings(), settings_detail::contact_settings()),
        settings_detail::cutter_and_surface_settings()));

/// The setting of an FMU / scenario name, or nullptr.
const SettingInfo* find_setting(std::string_view name);
/// The setting of a Python keyword, or nullptr.
const SettingInfo* find_python_setting(std::string_view keyword);

/// What a value of the setting's type is, for a message: "a number", "an integer", "a boolean",
/// "three numbers", "a text", or for an enumeration its items' names, "a, b or c".
std::string expected_value_text(const SettingInfo& setting);

/// Every setting at its default (the schema's start values).
TissueParameters default_parameters();

/// The tissue's settings for `mesh` (nullptr: only checked, the fixed vertices left empty): the fixed
/// slab's vertices and the regions' materials resolved, everything validated. Throws ParameterError.
TissueSettings resolve_settings(const TissueParameters& parameters, const TetMesh* mesh);

/// Throws ParameterError, naming the setting, for a member of `settings` outside its schema range (the
/// settings' one range check; validate(TissueSettings) calls it).
void check_setting_ranges(const TissueSettings& settings);

/// Calls visit(setting, value) for each tissue-scope setting (those TissueSettings holds), in the
/// table's order: the model fingerprint's share of the settings.
template <class Visit>
void for_each_tissue_setting(const TissueSettings& settings, Visit&& visit) {
  TissueParameters parameters;
  parameters.settings = settings;
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (setting.scope == SettingScope::tissue) visit(setting, value_of(setting, parameters));
  }
}

}  // namespace tissue
