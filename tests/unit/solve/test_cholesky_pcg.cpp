// Tests of CG with a lagged Cholesky factor (CholeskyPcgSolver): it reaches the tolerance and the
// direct solution, keeps its factor while it works, installs a refresh exactly at the pick-up
// setup, preconditions appended (XFEM) rows by Jacobi until the refresh lands, gives bitwise the
// same results run to run and with or without its worker thread, survives an indefinite matrix,
// and can be destroyed with a refresh in flight.
#include "core/integrate/integrator_factory.hpp"
#include "core/parameter_error.hpp"
#include "core/solve/linear_solver.hpp"

#include "solve/test_systems.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <memory>
#include <random>
#include <string>
#include <vector>

namespace tissue {
namespace {

using Refresh = CholeskyPcgSolver::Refresh;

Refresh refresh_rule(int refresh_iterations, int pickup_setups, bool background) {
  return Refresh{refresh_iterations, pickup_setups, background};
}

double condition_number(const Eigen::MatrixXd& a) {
  const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a).eigenvalues();
  return eigenvalues.maxCoeff() / eigenvalues.minCoeff();
}

TEST(CholeskyPcg, ReachesTheToleranceAndAgreesWithCholmod) {
  const test::TestSystem system = test::make_grid_system(6, 5, 4, 41);  // 360 unknowns
  std::mt19937 rng(42);
  const double tolerance = 1e-10;
  CholeskyPcgSolver solver({tolerance, 100}, refresh_rule(10, 4, true));
  EXPECT_EQ(solver.name(), "pcgCholesky");
  CholmodSolver cholmod;
  for (const double scale : {1.0, 1.3, 0.7}) {  // the factor is of scale 1: later solves use it lagged
    const ShiftedSystem shifted = system.shifted(scale);
    const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
    Eigen::VectorXd direct = Eigen::VectorXd::Zero(shifted.rows());
    const SolveReport report = solver.solve(shifted, b, x);
    cholmod.solve(shifted, b, direct);
    EXPECT_TRUE(report.converged) << "scale " << scale;
    EXPECT_LE(report.relative_residual, tolerance);
    const Eigen::MatrixXd dense = system.dense(scale);
    EXPECT_LE((b - dense * x).norm() / b.norm(), 2 * tolerance);  // recursive residual = true one, to rounding
    // ||x - x*|| / ||x*|| <= cond(A) ||r|| / ||b||: the solver's stopping rule bounds the error.
    EXPECT_LE((x - direct).norm(), condition_number(dense) * tolerance * direct.norm()) << "scale " << scale;
    if (scale == 1.0) {
      EXPECT_LE(report.iterations, 2);  // the factor of A itself: CG is done at once
    }
  }
  EXPECT_EQ(solver.counters().factorizations, 1);
  EXPECT_EQ(solver.counters().refreshes_started, 0);
  EXPECT_EQ(solver.symbolic_analysis_count(), 1);
}

// A factor of scale 1 preconditions scale 1.02 well (few iterations, kept) and scale 3 badly
// (many iterations: a refresh starts at the next setup and is installed `pickup` setups later).
void check_lagged_reuse_and_pickup(bool background) {
  const test::TestSystem system = test::make_grid_system(6, 6, 5, 43);
  std::mt19937 rng(44);
  const int pickup = 3;
  CholeskyPcgSolver solver({1e-8, 200}, refresh_rule(4, pickup, background));
  const auto solve = [&](double scale) {
    const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    const SolveReport report = solver.solve(system.shifted(scale), b, x);
    EXPECT_TRUE(report.converged);
    return report.iterations;
  };
  const CholeskyPcgSolver::Counters& c = solver.counters();
  EXPECT_LE(solve(1.0), 2);
  EXPECT_EQ(c.factorizations, 1);
  for (int k = 0; k < 5; ++k) EXPECT_LE(solve(1.02), 4);  // reused: no refresh asked
  EXPECT_EQ(c.factorizations, 1);
  EXPECT_EQ(c.refreshes_started, 0);

  EXPECT_GT(solve(3.0), 4);  // the old factor is poor now: asks for a refresh
  EXPECT_EQ(c.refreshes_started, 0);
  EXPECT_GT(solve(3.0), 4);  // this setup starts it (a factor of this A); the solve still uses the old one
  EXPECT_EQ(c.refreshes_started, 1);
  for (int k = 1; k < pickup; ++k) {
    EXPECT_GT(solve(3.0), 4) << "setup " << k << " after the start: not installed yet";
    EXPECT_EQ(c.refreshes_picked_up, 0);
    EXPECT_EQ(c.refreshes_started, 1);  // one at a time, though every solve asks
  }
  EXPECT_LE(solve(3.0), 2);  // installed by this setup: the factor of this very A
  EXPECT_EQ(c.refreshes_picked_up, 1);
  EXPECT_EQ(c.refresh_failures, 0);
  EXPECT_EQ(c.factorizations, 1);
  EXPECT_LE(solve(3.0), 2);
  EXPECT_EQ(c.refreshes_started, 1);
  EXPECT_EQ(solver.symbolic_analysis_count(), 2);  // one per factor object, pattern unchanged
}

TEST(CholeskyPcg, KeepsTheLaggedFactorAndInstallsARefreshAtThePickUp) { check_lagged_reuse_and_pickup(true); }

// follow_rotations: a factor of A turns with the rows' frames. If every block row turns by its own
// rotation Q_i (K_ij -> Q_i K_ij Q_j^T, d the same for the three unknowns of a row), the new A is
// Q A Q^T exactly, so the turned factor is exact and CG stops after one iteration; the unturned
// factor of the old A needs many.
int iterations_after_turning(bool follow_rotations) {
  test::TestSystem system = test::make_grid_system(6, 5, 5, 45, 0.05, {}, false);
  system.diagonal.setConstant(0.05);
  std::mt19937 rng(46);
  Refresh refresh = refresh_rule(1000, 1, false);  // keeps the first factor
  refresh.follow_rotations = follow_rotations;
  CholeskyPcgSolver solver({1e-10, 500}, refresh);
  const int rows = system.stiffness.block_rows();
  std::vector<Eigen::Matrix3d> frames(static_cast<size_t>(rows), Eigen::Matrix3d::Identity());
  ShiftedSystem a = system.shifted(1.0);
  a.block_frames = &frames;
  const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
  EXPECT_LE(solver.solve(a, b, x).iterations, 1);

  for (Eigen::Matrix3d& frame : frames) {
    const Eigen::Vector3d axis = Eigen::Vector3d::Random().normalized();
    frame = Eigen::AngleAxisd(std::uniform_real_distribution<double>(0.2, 2.5)(rng), axis).toRotationMatrix();
  }
  for (int i = 0; i < rows; ++i) {
    for (int slot = system.stiffness.row_begin(i); slot < system.stiffness.row_begin(i) + system.stiffness.row_size(i);
         ++slot) {
      const int j = system.stiffness.slot_column(slot);
      const Eigen::Matrix3d turned = frames[static_cast<size_t>(i)] * system.stiffness.block(slot) *
                                     frames[static_cast<size_t>(j)].transpose();
      system.stiffness.block(slot) = turned;
    }
  }
  x.setZero();
  const SolveReport report = solver.solve(a, b, x);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(solver.counters().factorizations, 1);  // the same factor, turned or not
  EXPECT_EQ(solver.counters().refreshes_started, 0);
  return report.iterations;
}

TEST(CholeskyPcg, FollowingRotationsTurnsTheFactorWithTheRows) {
  EXPECT_LE(iterations_after_turning(true), 1);
  EXPECT_GT(iterations_after_turning(false), 10);
}

TEST(CholeskyPcg, SynchronousRefreshFollowsTheSameSchedule) { check_lagged_reuse_and_pickup(false); }

TEST(CholeskyPcg, GrownSystemUsesJacobiOnAppendedRowsUntilTheRefreshLands) {
  test::TestSystem system = test::make_grid_system(5, 4, 4, 45);
  std::mt19937 rng(46);
  const int pickup = 2;
  const double tolerance = 1e-10;
  Refresh refresh = refresh_rule(50, pickup, true);
  refresh.refactor_on_growth = false;
  CholeskyPcgSolver solver({tolerance, 500}, refresh);
  const auto check_solve = [&]() {
    const ShiftedSystem shifted = system.shifted(1.0);
    const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
    const Eigen::MatrixXd dense = system.dense(1.0);
    const Eigen::VectorXd expected = dense.llt().solve(b);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
    const SolveReport report = solver.solve(shifted, b, x);
    EXPECT_TRUE(report.converged);
    EXPECT_LE((x - expected).norm(), condition_number(dense) * tolerance * expected.norm());
    return report.iterations;
  };
  const long rows_before = system.stiffness.rows();
  check_solve();
  test::append_coupled_row(system, 13, rng);
  test::append_coupled_row(system, 40, rng);
  const long rows_after = system.stiffness.rows();
  ASSERT_EQ(rows_after, rows_before + 6);

  // The pattern changed: a refresh starts; until it lands the old factor covers the first rows.
  for (int k = 0; k < pickup; ++k) {
    const int iterations = check_solve();
    EXPECT_GT(iterations, 2) << "block-diagonal preconditioner, setup " << k;
    EXPECT_EQ(solver.counters().factor_rows, rows_before);
    EXPECT_EQ(solver.counters().refreshes_started, 1);
    EXPECT_EQ(solver.counters().refreshes_picked_up, 0);
  }
  EXPECT_LE(check_solve(), 2);  // the factor of the grown A
  EXPECT_EQ(solver.counters().factor_rows, rows_after);
  EXPECT_EQ(solver.counters().refreshes_picked_up, 1);
  EXPECT_EQ(solver.counters().factorizations, 1);
  EXPECT_EQ(solver.counters().refreshes_started, 1);  // the factor matches the pattern: no more
  check_solve();
  EXPECT_EQ(solver.counters().refreshes_started, 1);
}

// refactor_on_growth (the default): a setup whose K grew factorizes the grown A at once, so the
// first solve after the growth needs no more iterations than one with a fresh factor.
TEST(CholeskyPcg, GrownSystemIsFactorizedAtOnceByDefault) {
  test::TestSystem system = test::make_grid_system(5, 4, 4, 45);
  std::mt19937 rng(46);
  CholeskyPcgSolver solver({1e-10, 500}, refresh_rule(50, 2, true));
  const auto solve = [&]() {
    const ShiftedSystem shifted = system.shifted(1.0);
    const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
    const SolveReport report = solver.solve(shifted, b, x);
    EXPECT_TRUE(report.converged);
    return report.iterations;
  };
  EXPECT_LE(solve(), 2);
  test::append_coupled_row(system, 13, rng);
  test::append_coupled_row(system, 40, rng);
  EXPECT_LE(solve(), 2);
  EXPECT_EQ(solver.counters().factor_rows, system.stiffness.rows());
  EXPECT_EQ(solver.counters().factorizations, 2);
  EXPECT_EQ(solver.counters().refreshes_started, 0);
}

// A sequence like a simulation's: values drift every setup, rows are appended twice, the
// right-hand side is new each time; every x of the run is returned.
std::vector<Eigen::VectorXd> run_sequence(bool background) {
  test::TestSystem system = test::make_grid_system(8, 6, 5, 47, 0.05, {}, false);
  std::mt19937 rng(48);
  CholeskyPcgSolver solver({1e-6, 200}, refresh_rule(3, 4, background));
  std::vector<Eigen::VectorXd> solutions;
  for (int step = 0; step < 40; ++step) {
    if (step == 12 || step == 13) {
      const int row = system.stiffness.append_block_row();
      system.stiffness.insert_block(row, 7 + step);
      system.stiffness.insert_block(7 + step, row);
      system.diagonal.conservativeResize(system.stiffness.rows());
      system.diagonal.tail<3>().setConstant(0.06);
    }
    const int i = 8 * static_cast<int>(rng() % 30) + static_cast<int>(rng() % 7);  // an x-edge (i, i + 1) of the grid
    system.add_edge(i, i + 1, test::random_spd_block(rng, 0.05, 0.3));
    const double scale = 1.0 + 0.05 * step;
    const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    solver.solve(system.shifted(scale), b, x);
    solutions.push_back(x);
  }
  EXPECT_GE(solver.counters().refreshes_picked_up, 2);  // the run exercises refreshes
  return solutions;
}

TEST(CholeskyPcg, BitwiseDeterministicWithAndWithoutTheWorker) {
  const std::vector<Eigen::VectorXd> first = run_sequence(true);
  const std::vector<Eigen::VectorXd> second = run_sequence(true);
  const std::vector<Eigen::VectorXd> synchronous = run_sequence(false);
  ASSERT_EQ(first.size(), second.size());
  ASSERT_EQ(first.size(), synchronous.size());
  for (size_t k = 0; k < first.size(); ++k) {
    EXPECT_TRUE(first[k] == second[k]) << "solve " << k << " differs between two runs";
    EXPECT_TRUE(first[k] == synchronous[k]) << "solve " << k << " differs with the worker off";
  }
}

TEST(CholeskyPcg, IndefiniteMatrixIsRefusedOrFallsBackToTheOldFactor) {
  test::TestSystem system = test::make_grid_system(4, 4, 4, 49);
  std::mt19937 rng(50);
  const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
  // A strong coupling of blocks 0 and 1 (neighbours): the diagonal stays positive, but
  // (e_0 - e_1)' A (e_0 - e_1) < 0.
  test::TestSystem indefinite = system;
  indefinite.stiffness.block(indefinite.stiffness.find_slot(0, 1)) += 50.0 * Eigen::Matrix3d::Identity();
  indefinite.stiffness.block(indefinite.stiffness.find_slot(1, 0)) += 50.0 * Eigen::Matrix3d::Identity();

  // No factor yet: the setup factorizes at once and refuses.
  {
    CholeskyPcgSolver solver({1e-8, 100}, refresh_rule(0, 2, true));
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    try {
      solver.solve(indefinite.shifted(1.0), b, x);
      ADD_FAILURE() << "no SolverError";
    } catch (const SolverError& error) {
      EXPECT_NE(std::string(error.what()).find("not positive definite"), std::string::npos) << error.what();
    }
    EXPECT_FALSE(solver.is_set_up());
    const SolveReport report = solver.solve(system.shifted(1.0), b, x);  // recovers
    EXPECT_TRUE(report.converged);
  }
  // A refresh of an indefinite A fails at pick-up: counted, the old factor kept, no throw, no hang.
  for (const bool background : {true, false}) {
    CholeskyPcgSolver solver({1e-8, 100}, refresh_rule(0, 2, background));
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    EXPECT_TRUE(solver.solve(system.shifted(1.0), b, x).converged);
    const BlockSparseMatrix good = system.stiffness;
    system.stiffness = indefinite.stiffness;  // the same matrix object's values go bad, as in a step
    for (int k = 0; k < 4; ++k) {
      x.setZero();
      const SolveReport report = solver.solve(system.shifted(1.0), b, x);  // CG may break down: reported
      EXPECT_LE(report.iterations, 100);
    }
    EXPECT_GE(solver.counters().refreshes_started, 1);
    EXPECT_GE(solver.counters().refresh_failures, 1);
    EXPECT_EQ(solver.counters().refreshes_picked_up, 0);
    EXPECT_NE(solver.last_refresh_failure().find("not positive definite"), std::string::npos)
        << solver.last_refresh_failure();
    // Good values again: the kept factor still works, the next refresh succeeds.
    system.stiffness = good;
    for (int k = 0; k < 6; ++k) {
      x.setZero();
      EXPECT_TRUE(solver.solve(system.shifted(1.0), b, x).converged);
    }
    EXPECT_GE(solver.counters().refreshes_picked_up, 1);
  }
}

TEST(CholeskyPcg, DestroyedWithARefreshInFlight) {
  // 3000 unknowns: the refresh takes long enough to be running when the solver goes.
  const test::TestSystem system = test::make_grid_system(10, 10, 10, 51, 0.05, {}, false);
  std::mt19937 rng(52);
  const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
  for (const bool background : {true, false}) {
    auto solver =
        std::make_unique<CholeskyPcgSolver>(PcgSolver::Settings{1e-8, 100}, refresh_rule(0, 1000, background));
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    solver->solve(system.shifted(1.0), b, x);  // factorizes; asks for a refresh (refresh_iterations 0)
    solver->solve(system.shifted(2.0), b, x);  // starts it
    EXPECT_EQ(solver->counters().refreshes_started, 1);
    solver.reset();  // joins the worker
  }
}

TEST(CholeskyPcg, SettingsAndNameThroughTheFactory) {
  EXPECT_EQ(parse_linear_solver_kind("pcgCholesky"), LinearSolverKind::pcg_cholesky);
  EXPECT_EQ(to_string(LinearSolverKind::pcg_cholesky), "pcgCholesky");
  EXPECT_THROW(parse_linear_solver_kind("cholesky"), ParameterError);
  SolverSettings settings;
  settings.kind = LinearSolverKind::pcg_cholesky;
  EXPECT_EQ(make_linear_solver(settings)->name(), "pcgCholesky");
  settings.refresh.pickup_setups = 0;
  EXPECT_THROW(validate(settings), ParameterError);
  settings.refresh.pickup_setups = 1;
  settings.refresh.refresh_iterations = -1;
  EXPECT_THROW(validate(settings), ParameterError);
  EXPECT_THROW(CholeskyPcgSolver({1e-6, 10}, refresh_rule(5, 0, true)), SolverError);
}

}  // namespace
}  // namespace tissue
