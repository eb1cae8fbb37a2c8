// Shared command-line options of the apps.
#include "scene_options.hpp"

#include "core/fixed_region.hpp"
#include "core/material/material.hpp"
#include "core/mesh/mesh_io.hpp"
#include "resources/default_mesh.hpp"

#include <limits>
#include <sstream>

namespace tissue::apps {
namespace {

Eigen::Vector3d parse_vector(const std::string& text, const std::string& what) {
  Eigen::Vector3d value;
  std::stringstream stream(text);
  std::string item;
  int count = 0;
  while (std::getline(stream, item, ',')) {
    if (count == 3) break;
    try {
      size_t used = 0;
      value[count] = std::stod(item, &used);
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw ParameterError(what + ": '" + item + "' is not a number");
    }
    ++count;
  }
  if (count != 3 || std::getline(stream, item))
    throw ParameterError(what + ": expected three numbers X,Y,Z, got '" + text + "'");
  return value;
}

}  // namespace

void add_scene_options(CLI::App& app, SceneOptions& options) {
  app.add_option("--mesh", options.mesh, "Mesh file (.veg, .node/.ele, .msh) or 'frog' for the embedded frog")
      ->capture_default_str();
  app.add_option("--fixed", options.fixed_bou, "Vega .bou file of fixed vertices (1-indexed); default: minimum x");
  app.add_option("--fixed-fraction", options.fixed_fraction,
                 "Without --fixed: fix vertices within this fraction of the x extent of the minimum x")
      ->capture_default_str();
  app.add_option("--steps", options.steps, "Number of time steps")->capture_default_str();
  app.add_option("--dt", options.step_size_s, "Time step [s]")->capture_default_str();
  app.add_option("--solver", options.solver, "Linear solver: " + LINEAR_SOLVER_NAMES.names())
      ->capture_default_str();
  app.add_option("--tolerance", options.tolerance, "PCG (and pcgCholesky) relative residual tolerance")
      ->capture_default_str();
  app.add_flag("--double-matrix", options.double_matrix,
               "PCG products stream A in double precision (default: single for tolerances >= 1e-5; sums in double)");
  app.add_option("--max-iterations", options.max_iterations, "PCG (and pcgCholesky) iteration cap")
      ->capture_default_str();
  app.add_option("--refresh-iterations", options.refresh.refresh_iterations,
                 "pcgCholesky: a solve needing more iterations starts a refactorization")
      ->capture_default_str();
  app.add_option("--pickup-setups", options.refresh.pickup_setups,
                 "pcgCholesky: a refactorization is used this many solver setups after it started")
      ->capture_default_str();
  app.add_flag("!--no-background-refactor", options.refresh.background_refactor,
               "pcgCholesky: refactorize at pick-up in the stepping thread instead of a worker thread");
  app.add_flag("--follow-rotations", options.refresh.follow_rotations,
               "pcgCholesky: turn the lagged factor with the vertices' rotations since it was made");
  app.add_flag("!--no-refactor-on-growth", options.refresh.refactor_on_growth,
               "pcgCholesky: when a cut grows the system, Jacobi on the new rows until a refresh lands "
               "(default: factorize at once)");
  app.add_flag("--warm-start", options.warm_start, "PCG starts from the previous step's velocity change");
  app.add_option("--young", options.material.young_modulus_pa, "Young's modulus [Pa]")->capture_default_str();
  app.add_option("--poisson", options.material.poisson_ratio, "Poisson's ratio")->capture_default_str();
  app.add_option("--density", options.material.density_kg_per_m3, "Density [kg/m^3]")->capture_default_str();
  app.add_option("--material-model", options.material_model,
                 "Elasticity: corotationalLinear or stableNeoHookean (Smith, de Goes and Kim 2018)")
      ->capture_default_str();
  app.add_flag("--single-material", options.single_material,
               "Ignore the mesh file's regions and materials (Vega *REGION, Gmsh physical groups, TetGen region "
               "attributes): --young, --poisson, --density everywhere");
  app.add_option("--mass-damping", options.damping.mass_damping_per_s, "Rayleigh alpha [1/s]")->capture_default_str();
  app.add_option("--stiffness-damping", options.damping.stiffness_damping_s, "Rayleigh beta [s]")
      ->capture_default_str();
  app.add_option("--gravity", options.gravity, "Gravity GX,GY,GZ [m/s^2]")->capture_default_str();
  app.add_flag("!--no-large-turn-protection", options.large_turn_protection,
               "Backward Euler without Newton corrections and energy guard (the linearized step alone, as Vega's)");
  app.add_option("--newton-max-iterations", options.newton_max_iterations,
                 "Newton corrections at most in a step (0: the core's 5; the FMU, tissue-host and Python default to 1)")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
  app.add_option("--newton-trigger-angle", options.newton_trigger_angle_rad,
                 "Newton corrections in a step whose linearized solve turns some element further than this [rad] "
                 "(0: the core's 0.05; a tiny angle converges every step's Newton iterations)")
      ->check(CLI::Range(0.0, 10.0));
  app.add_flag("--predicted-end", options.linearize_at_predicted_end,
               "Backward Euler linearizes each step at its predicted end u0 + h v0 (the FMU, tissue-host and "
               "Python default) instead of at its start");
  app.add_option("--threads", options.threads, "Threads per step, 1 or 2 (a team made and joined by each step)")
      ->capture_default_str();
}

Scene make_scene(const SceneOptions& options) {
  Scene scene;
  scene.mesh_name = options.mesh;
  scene.mesh = load_mesh(options.mesh);
  if (options.single_material) {
    scene.mesh.regions.clear();
    scene.mesh.tet_regions.clear();
  }
  if (options.steps < 1) throw ParameterError("--steps must be >= 1");
  TissueSettings& settings = scene.settings;
  settings.step_size_s = options.step_size_s;
  settings.solver.kind = parse_linear_solver_kind(options.solver);
  settings.solver.pcg = PcgSolver::Settings{options.tolerance, options.max_iterations,
                                           options.double_matrix ? MatrixPrecision::double_precision
                                                                 : MatrixPrecision::automatic};
  settings.solver.refresh = options.refresh;
  settings.solver.warm_start = options.warm_start;
  settings.body.material = options.material;
  settings.body.material_model = parse_material_model(options.material_model);
  settings.body.damping = options.damping;
  if (options.newton_max_iterations > 0) settings.integrator.newton.max_iterations = options.newton_max_iterations;
  if (!options.large_turn_protection) {
    settings.integrator.newton.trigger_angle_rad = std::numeric_limits<double>::infinity();
    settings.integrator.newton.energy_guard_angle_rad = std::numeric_limits<double>::infinity();
  }
  settings.integrator.newton.linearize_at_predicted_end = options.linearize_at_predicted_end;
  if (options.newton_trigger_angle_rad > 0.0) {
    settings.integrator.newton.trigger_angle_rad = options.newton_trigger_angle_rad;
  }
  settings.integrator.threads = options.threads;
  settings.body.gravity_m_per_s2 = parse_vector(options.gravity, "--gravity");
  settings.body.fixed_vertices = options.fixed_bou.empty() ? vertices_at_minimum(scene.mesh, 0, options.fixed_fraction)
                                                           : read_bou(options.fixed_bou, scene.mesh.vertex_count());
  return scene;
}

}  // namespace tissue::apps
