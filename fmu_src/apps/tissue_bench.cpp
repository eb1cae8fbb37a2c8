// tissue-bench: runs N backward-Euler steps of one mesh on one thread and prints one JSON object
// with the sizes and the per-step timings (medians), for users and for scripts.
#include "apps/run_statistics.hpp"
#include "apps/scene_options.hpp"

#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>

namespace {

using tissue::apps::Summary;

void print_summary(const char* name, const Summary& s, bool last = false) {
  std::printf("  \"%s\": {\"median\": %.6g, \"p90\": %.6g, \"max\": %.6g}%s\n", name, s.median, s.p90, s.max,
              last ? "" : ",");
}

// pcg-cholesky's counters (how often its lagged factor was rebuilt), when that is the solver.
void print_lagged_factor(const tissue::Tissue& tissue) {
  const auto* integrator = dynamic_cast<const tissue::BackwardEuler*>(&tissue.integrator());
  const auto* solver =
      integrator != nullptr ? dynamic_cast<const tissue::CholeskyPcgSolver*>(&integrator->solver()) : nullptr;
  if (solver == nullptr) return;
  const tissue::CholeskyPcgSolver::Counters& c = solver->counters();
  std::printf(
      "  \"lagged_factor\": {\"setups\": %ld, \"factorizations\": %ld, \"refreshes_started\": %ld, "
      "\"refreshes_picked_up\": %ld, \"refresh_failures\": %ld, \"pickups_waited\": %ld, \"iterations\": %ld},\n",
      c.setups, c.factorizations, c.refreshes_started, c.refreshes_picked_up, c.refresh_failures, c.pickups_waited,
      c.iterations);
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
  std::printf("{\n");
  std::printf("  \"mesh\": \"%s\",\n", scene.mesh_name.c_str());
  std::printf("  \"solver\": \"%s\",\n", options.solver.c_str());
  std::printf("  \"tolerance\": %.3g,\n  \"max_iterations\": %d,\n", options.tolerance, options.max_iterations);
  std::printf("  \"dt_s\": %.6g,\n  \"steps\": %d,\n", options.step_size_s, options.steps);
  std::printf("  \"vertices\": %d,\n  \"tets\": %d,\n  \"fixed_vertices\": %d,\n", vertices, tets, fixed);
  std::printf("  \"dofs\": %d,\n", tissue.body().dof_count());
  std::printf("  \"nonzeros\": %ld,\n", tissue.body().tangent().nonzeros());
  print_summary("ms_per_step", tissue::apps::summarize(step_ms));
  std::printf("  \"assembly_ms\": %.6g,\n", tissue::apps::summarize(assembly_ms).median);
  std::printf("  \"solve_ms\": %.6g,\n", tissue::apps::summarize(solve_ms).median);
  std::printf("  \"cg_iterations\": {\"mean\": %.4g, \"max\": %.0f},\n", iteration_summary.mean, iteration_summary.max);
  std::printf("  \"large_turn_protection\": %s,\n", options.large_turn_protection ? "true" : "false");
  std::printf("  \"threads\": %d,\n", options.threads);
  std::printf("  \"newton_iterations\": %ld,\n  \"energy_guarded_steps\": %ld,\n", newton_iterations, guarded_steps);
  print_lagged_factor(tissue);
  std::printf("  \"final_kinetic_energy_J\": %.6g\n", tissue.kinetic_energy_j());
  std::printf("}\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tissue-bench: time backward-Euler steps of a co-rotational FEM mesh (one thread, JSON out)"};
  tissue::apps::SceneOptions options;
  tissue::apps::add_scene_options(app, options);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  }
  try {
    return run(options);
  } catch (const tissue::IntegrationError& error) {
    std::cerr << "tissue-bench: step failed: " << error.what() << '\n';
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "tissue-bench: " << error.what() << '\n';
    return 2;
  }
}
