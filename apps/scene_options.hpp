// Command-line options shared by tissue-demo and tissue-bench: mesh, material, damping, gravity,
// fixed vertices, step size and linear solver, turned into a mesh plus TissueSettings.
#pragma once

#include "core/tissue.hpp"

#include <CLI/CLI.hpp>

#include <string>

namespace tissue::apps {

/// The refresh rules with the worker thread asked for (the core starts none unless asked).
inline CholeskyPcgSolver::Refresh with_background_refactor() {
  CholeskyPcgSolver::Refresh refresh;
  refresh.background_refactor = true;
  return refresh;
}

struct SceneOptions {
  std::string mesh = "frog";     ///< "frog" = the embedded default, else a .veg/.node/.ele/.msh path
  std::string fixed_bou;         ///< Vega .bou (1-indexed); empty = vertices at the minimum x
  double fixed_fraction = 0.01;  ///< of the x extent, when no .bou is given
  int steps = 100;
  double step_size_s = 0.01;
  std::string solver = "pcg";
  double tolerance = 1e-6;
  int max_iterations = 10000;
  bool double_matrix = false;  ///< PCG products in double precision (MatrixPrecision)
  /// pcgCholesky's refresh rules; the benches ask for the worker thread unless told not to.
  CholeskyPcgSolver::Refresh refresh = with_background_refactor();
  bool warm_start = false;
  Material material{1.0e5, 0.4, 1000.0};
  std::string material_model{to_string(MaterialModel::corotational_linear)};  ///< parse_material_model's names
  /// Ignore the mesh file's regions and their materials (Vega *REGION, ...): `material` everywhere,
  /// as the benchmarks' side-by-side runs were measured before regions were read (issue 25).
  bool single_material = false;
  RayleighDamping damping{0.0, 0.0};
  std::string gravity = "0,-9.81,0";
  /// Backward Euler's large-turn protections (BackwardEuler::NewtonCorrections); "off" = the
  /// dissertation's (and Vega's) linearized step alone.
  bool large_turn_protection = true;
  /// Newton corrections at most in a step (BackwardEuler::NewtonCorrections::max_iterations); 0 =
  /// the core's own cap. The products (the FMU, tissue-host, Python) default to 1
  /// (`integrator.newtonMaxIterations`).
  int newton_max_iterations = 0;
  /// Each step linearized at its predicted end (NewtonCorrections::linearize_at_predicted_end; the
  /// products' default, `integrator.linearizeAtPredictedEnd`); the core's step otherwise.
  bool linearize_at_predicted_end = false;
  /// Newton corrections' trigger angle [rad] (NewtonCorrections::trigger_angle_rad); 0: the core's.
  double newton_trigger_angle_rad = 0.0;
  int threads = 1;  ///< IntegratorSettings::threads
};

/// Registers the options on `app` (values are written into `options` when parsed).
void add_scene_options(CLI::App& app, SceneOptions& options);

struct Scene {
  TetMesh mesh;
  TissueSettings settings;
  std::string mesh_name;
};

/// Loads the mesh, picks the fixed vertices and checks every setting. Throws MeshError or
/// ParameterError with a message for the user.
Scene make_scene(const SceneOptions& options);

}  // namespace tissue::apps
