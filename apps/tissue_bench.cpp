// tissue-bench: runs N backward-Euler steps of one mesh on one thread and prints one JSON object
// with the sizes and the per-step timings (medians), for users and for scripts.
#include "app_main.hpp"
#include "run_statistics.hpp"
#include "scene_options.hpp"

#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>

#include <nlohmann/json.hpp>

namespace {

using tissue::apps::Summary;

nlohmann::ordered_json summary_json(const Summary& s) {
  return {{"median", s.median}, {"p90", s.p90}, {"max", s.max}};
}

// pcgCholesky's counters (how often its lagged factor was rebuilt), when that is the solver.
void add_lagged_factor(const tissue::Tissue& tissue, nlohmann::ordered_json& out) {
  const auto* integrator = dynamic_cast<const tissue::BackwardEuler*>(&tissue.integrator());
  const auto* solver =
      integrator != nullptr ? dynamic_cast<const tissue::CholeskyPcgSolver*>(&integrator->solver()) : nullptr;
  if (solver == nullptr) return;
  const tissue::CholeskyPcgSolver::Counters& c = solver->counters();
  out["lagged_factor"] = {{"setups", c.setups},
                          {"factorizations", c.factorizations},
                          {"refreshes_started", c.refreshes_started},
                          {"refreshes_picked_up", c.refreshes_picked_up},
                          {"refresh_failures", c.refresh_failures},
                          {"pickups_waited", c.pickups_waited},
                          {"iterations", c.iterations}};
}

int run(const tissue::apps::SceneOptions& options) {
  tissue::apps::Scene scene = tissue::apps::make_scene(options);
  const int vertices = scene.mesh.vertex_count();
  const int tets = scene.mesh.tet_count();
  const int fixed = static_cast<int>(scene.settings.body.fixed_vertices.size());
  tissue::Tissue tissue(std::move(scene.mesh), scene.settings);

  std::vector<double> step_ms, assembly_ms, solve_ms, iterations;
  long newton_iterations = 0, guarded_steps = 0;
  step_ms.reserve(static_cast<size_t>(options.steps));
  assembly_ms.reserve(static_cast<size_t>(options.steps));
  solve_ms.reserve(static_cast<size_t>(options.steps));
  iterations.reserve(static_cast<size_t>(options.steps));
  for (int step = 0; step < options.steps; ++step) {
    const auto start = std::chrono::steady_clock::now();
    const tissue::StepReport report = tissue.step().dynamics;
    step_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    assembly_ms.push_back(1e3 * report.assembly_s);
    solve_ms.push_back(1e3 * report.solve_s);
    iterations.push_back(report.solve.iterations);
    newton_iterations += report.newton_iterations;
    guarded_steps += report.energy_guarded ? 1 : 0;
  }
  const Summary iteration_summary = tissue::apps::summarize(iterations);
  nlohmann::ordered_json out;
  out["mesh"] = scene.mesh_name;
  out["solver"] = options.solver;
  out["tolerance"] = options.tolerance;
  out["max_iterations"] = options.max_iterations;
  out["dt_s"] = options.step_size_s;
  out["steps"] = options.steps;
  out["vertices"] = vertices;
  out["tets"] = tets;
  out["fixed_vertices"] = fixed;
  out["dofs"] = tissue.body().dof_count();
  out["nonzeros"] = tissue.body().tangent().nonzeros();
  out["ms_per_step"] = summary_json(tissue::apps::summarize(step_ms));
  out["assembly_ms"] = tissue::apps::summarize(assembly_ms).median;
  out["solve_ms"] = tissue::apps::summarize(solve_ms).median;
  out["cg_iterations"] = {{"mean", iteration_summary.mean}, {"max", iteration_summary.max}};
  out["large_turn_protection"] = options.large_turn_protection;
  out["threads"] = options.threads;
  out["newton_iterations"] = newton_iterations;
  out["energy_guarded_steps"] = guarded_steps;
  add_lagged_factor(tissue, out);
  out["final_kinetic_energy_J"] = tissue.kinetic_energy_j();
  std::printf("%s\n", out.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tissue-bench: time backward-Euler steps of a co-rotational FEM mesh (one thread, JSON out)"};
  tissue::apps::SceneOptions options;
  tissue::apps::add_scene_options(app, options);
  return tissue::apps::parse_and_run(app, argc, argv, "tissue-bench", [&] { return run(options); });
}
