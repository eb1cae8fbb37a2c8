// tissue-convergence: how the step's CG solve converges, iteration by iteration, under the
// preconditioners a real-time setting can use: Jacobi (pcg), the lagged Cholesky factor
// (pcgCholesky) made --lag-steps steps earlier, beside a factor of the step's own matrix, and the
// two-level one (pcgTwoLevel). The body
// falls from rest under gravity with exact (CHOLMOD) steps; the measured solve is the one of the
// step after --lag-steps. CSV out (preconditioner, iteration, relative residual), a summary with
// the cost per iteration on stderr; tests/bench/solver_convergence.py plots it.
#include "app_main.hpp"
#include "scene_options.hpp"

#include "core/fem/deformable_body.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/solve/linear_solver.hpp"

#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using tissue::ShiftedSystem;

struct Options {
  tissue::apps::SceneOptions scene;
  int lag_steps = 10;
  int max_iterations = 2000;
  double tolerance = 1e-10;
  std::string output = "convergence.csv";
};

// The step's matrix (1 + h alpha) M + (h beta + h^2) K and right side
// h (f_ext - f_int - alpha M v - (beta + h) K v) at `state` (backward_euler.cpp).
struct StepSystem {
  Eigen::VectorXd diagonal, rhs;
  ShiftedSystem system{nullptr, 1.0, nullptr};

  StepSystem(tissue::DeformableBody& body, const tissue::DynamicState& state, double h) {
    Eigen::VectorXd internal_force;
    body.evaluate(state.displacement_m, internal_force, /*update_tangent=*/true);
    Eigen::VectorXd stiffness_times_velocity(body.dof_count());
    body.tangent().multiply(state.velocity_m_per_s, stiffness_times_velocity);
    rhs = h * (body.external_force_n() - internal_force -
               body.mass_damping_kg_per_s().cwiseProduct(state.velocity_m_per_s) -
               (body.stiffness_damping_s() + h) * stiffness_times_velocity);
    diagonal = body.mass_kg() + h * body.mass_damping_kg_per_s();
    system = ShiftedSystem{&body.tangent(), h * body.stiffness_damping_s() + h * h, &diagonal, nullptr,
                           body.block_positions(state.displacement_m)};
  }
};

struct Run {
  std::string name;
  std::vector<double> history;
  double setup_ms = 0.0, solve_ms = 0.0;
};

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Solver>
void solve(Solver& solver, const StepSystem& step, Run& run) {
  solver.record_residuals(&run.history);
  auto start = std::chrono::steady_clock::now();
  solver.setup(step.system);
  run.setup_ms = ms_since(start);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(step.rhs.size());
  start = std::chrono::steady_clock::now();
  solver.solve(step.rhs, x);
  run.solve_ms = ms_since(start);
  solver.record_residuals(nullptr);
}

int run(const Options& options) {
  std::ofstream csv(options.output);  // first: a file that cannot be written is said before the work
  if (!csv) throw std::runtime_error("cannot write " + options.output);
  tissue::apps::Scene scene = tissue::apps::make_scene(options.scene);
  tissue::DeformableBody body(scene.mesh, scene.settings.body);
  const double h = options.scene.step_size_s;
  tissue::DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count()), 0.0};
  tissue::BackwardEuler exact(std::make_unique<tissue::CholmodSolver>());

  const tissue::PcgSolver::Settings strict{options.tolerance, options.max_iterations,
                                           tissue::MatrixPrecision::double_precision};
  tissue::CholeskyPcgSolver::Refresh never_refresh;
  never_refresh.refresh_iterations = std::numeric_limits<int>::max();
  never_refresh.refactor_on_growth = false;
  tissue::CholeskyPcgSolver lagged(strict, never_refresh);
  {
    const StepSystem first(body, state, h);
    lagged.setup(first.system);  // factorizes the first step's matrix
  }
  for (int n = 0; n < options.lag_steps; ++n) {
    exact.step(body, state, h);
    std::fprintf(stderr, "\r  exact step %d / %d", n + 1, options.lag_steps);
  }
  std::fprintf(stderr, "\n");
  const StepSystem step(body, state, h);

  std::vector<Run> runs(4);
  runs[0].name = "pcg (Jacobi)";
  tissue::PcgSolver jacobi(strict);
  solve(jacobi, step, runs[0]);
  runs[1].name = "pcgCholesky, factor " + std::to_string(options.lag_steps) + " steps old";
  solve(lagged, step, runs[1]);  // keeps its factor: same pattern, no refresh asked for
  runs[2].name = "pcgCholesky, factor of this step";
  tissue::CholeskyPcgSolver fresh(strict, never_refresh);
  solve(fresh, step, runs[2]);
  runs[3].name = "pcgTwoLevel (Jacobi + rigid aggregates)";
  tissue::TwoLevelPcgSolver two_level(strict);
  solve(two_level, step, runs[3]);

  csv << "preconditioner,iteration,relative_residual,ms_per_iteration,setup_ms\n";
  for (const Run& r : runs) {
    const double iterations = static_cast<double>(r.history.size() > 1 ? r.history.size() - 1 : 1);
    for (size_t k = 0; k < r.history.size(); ++k) {
      csv << '"' << r.name << "\"," << k << ',' << r.history[k] << ',' << r.solve_ms / iterations << ','
          << r.setup_ms << '\n';
    }
    std::fprintf(stderr, "  %-40s %5zu iterations to %.2e, %.3f ms per iteration, setup %.1f ms\n", r.name.c_str(),
                 r.history.size() - 1, r.history.back(), r.solve_ms / iterations, r.setup_ms);
  }
  if (!csv) throw std::runtime_error("cannot write " + options.output);
  std::fprintf(stderr, "  %d unknowns, %d tets, two-level: %d aggregates, %d coarse columns; wrote %s\n",
               body.dof_count(), body.mesh().tet_count(), two_level.aggregate_count(), two_level.coarse_size(),
               options.output.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tissue-convergence: the relative residual per CG iteration of a step's solve, Jacobi against the "
               "lagged Cholesky factor (CSV out)"};
  Options options;
  tissue::apps::add_scene_options(app, options.scene);
  app.add_option("--lag-steps", options.lag_steps, "Steps between the lagged factor's matrix and the measured solve")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  app.add_option("--cg-cap", options.max_iterations, "Iterations at most per solve")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  app.add_option("--cg-tolerance", options.tolerance, "Relative residual at which a solve stops")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("-o,--output", options.output, "CSV file")->capture_default_str();
  return tissue::apps::parse_and_run(app, argc, argv, "tissue-convergence", [&] { return run(options); });
}
