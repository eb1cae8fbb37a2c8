// Tests of the Jacobi-PCG solver: it reaches the dense solution, honours warm start, the
// tolerance and the iteration cap, and refuses systems it cannot solve.
#include "core/solve/linear_solver.hpp"
#include "core/system/work_team.hpp"

#include "solve/test_systems.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>
#include <vector>

namespace tissue {
namespace {

TEST(Pcg, ConvergesToTheDenseSolution) {
  const test::TestSystem system = test::make_grid_system(5, 5, 5, 1);  // 375 unknowns
  std::mt19937 rng(2);
  for (const double scale : {1.0, 0.01, 100.0}) {
    const ShiftedSystem shifted = system.shifted(scale);
    const Eigen::MatrixXd dense = system.dense(scale);
    const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
    const Eigen::VectorXd expected = dense.llt().solve(b);

    PcgSolver solver({1e-10, 10000});
    Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
    const SolveReport report = solver.solve(shifted, b, x);
    EXPECT_TRUE(report.converged) << "scale " << scale;
    EXPECT_GT(report.iterations, 0);
    EXPECT_LT(report.iterations, shifted.rows());  // Jacobi-CG on this well-posed system needs far fewer
    EXPECT_LE(report.relative_residual, 1e-10);
    // The reported (recursive) residual agrees with the true one up to rounding.
    EXPECT_LE((b - dense * x).norm() / b.norm(), 2e-10);
    EXPECT_LE((x - expected).norm(), 1e-6 * expected.norm()) << "scale " << scale;
  }
}

TEST(Pcg, WarmStartFromTheSolutionTakesNoIteration) {
  const test::TestSystem system = test::make_grid_system(4, 4, 4, 3);
  const ShiftedSystem shifted = system.shifted(1.0);
  std::mt19937 rng(4);
  const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
  Eigen::VectorXd x = system.dense(1.0).llt().solve(b);
  const Eigen::VectorXd exact = x;

  PcgSolver solver({1e-8, 100});
  const SolveReport report = solver.solve(shifted, b, x);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.iterations, 0);
  EXPECT_LE(report.relative_residual, 1e-8);
  EXPECT_EQ(x, exact);  // untouched

  // A guess close to the solution needs fewer iterations than a cold start.
  Eigen::VectorXd near = exact + 1e-4 * test::random_vector(shifted.rows(), rng);
  Eigen::VectorXd cold = Eigen::VectorXd::Zero(shifted.rows());
  const SolveReport warm_report = solver.solve(shifted, b, near);
  const SolveReport cold_report = solver.solve(shifted, b, cold);
  EXPECT_TRUE(warm_report.converged);
  EXPECT_TRUE(cold_report.converged);
  EXPECT_LT(warm_report.iterations, cold_report.iterations);
}

TEST(Pcg, IterationCapIsObeyedAndReported) {
  const test::TestSystem system = test::make_grid_system(5, 5, 5, 5);
  const ShiftedSystem shifted = system.shifted(1.0);
  std::mt19937 rng(6);
  const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
  PcgSolver solver({1e-12, 3});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
  const SolveReport report = solver.solve(shifted, b, x);
  EXPECT_FALSE(report.converged);
  EXPECT_EQ(report.iterations, 3);
  EXPECT_GT(report.relative_residual, 1e-12);
  EXPECT_LT(report.relative_residual, 1.0);  // the last iterate is still an improvement on x = 0
  EXPECT_NEAR(report.relative_residual, (b - system.dense(1.0) * x).norm() / b.norm(), 1e-12);

  PcgSolver no_iterations({1e-12, 0});
  x.setZero();
  const SolveReport none = no_iterations.solve(shifted, b, x);
  EXPECT_FALSE(none.converged);
  EXPECT_EQ(none.iterations, 0);
  EXPECT_DOUBLE_EQ(none.relative_residual, 1.0);
  EXPECT_TRUE(x.isZero(0.0));
}

TEST(Pcg, ZeroRightHandSideGivesZero) {
  const test::TestSystem system = test::make_grid_system(3, 3, 3, 7);
  const ShiftedSystem shifted = system.shifted(1.0);
  Eigen::VectorXd x = Eigen::VectorXd::Ones(shifted.rows());
  PcgSolver solver({1e-8, 100});
  const SolveReport report = solver.solve(shifted, Eigen::VectorXd::Zero(shifted.rows()), x);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.iterations, 0);
  EXPECT_EQ(report.relative_residual, 0.0);
  EXPECT_TRUE(x.isZero(0.0));
}

TEST(Pcg, RejectsSizeMismatchAndNonPositiveDiagonal) {
  const test::TestSystem system = test::make_grid_system(3, 3, 3, 8);
  const ShiftedSystem shifted = system.shifted(1.0);
  const long n = shifted.rows();
  PcgSolver solver({1e-8, 100});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd short_x = Eigen::VectorXd::Zero(n - 1);
  EXPECT_THROW(solver.solve(shifted, Eigen::VectorXd::Ones(n + 3), x), SolverError);
  EXPECT_THROW(solver.solve(shifted, Eigen::VectorXd::Ones(n), short_x), SolverError);
  const Eigen::VectorXd short_d = Eigen::VectorXd::Ones(n - 3);
  EXPECT_THROW(solver.solve({&system.stiffness, 1.0, &short_d}, Eigen::VectorXd::Ones(n), x), SolverError);
  EXPECT_THROW(solver.solve({nullptr, 1.0, &system.diagonal}, Eigen::VectorXd::Ones(n), x), SolverError);
  // s = -1: diag(A) = -diag(K) + d < 0, A is certainly not positive definite.
  EXPECT_THROW(solver.solve(system.shifted(-1.0), Eigen::VectorXd::Ones(n), x), SolverError);
  EXPECT_THROW(PcgSolver({-1.0, 10}), SolverError);
  EXPECT_THROW(PcgSolver({1e-6, -1}), SolverError);
}

TEST(Pcg, BreakdownOnIndefiniteMatrixIsNotConvergence) {
  // K = [I 2I; 2I I] has a positive diagonal but the eigenvalue -1 on (e, -e).
  BlockSparseMatrix stiffness(std::vector<std::vector<int>>{{0, 1}, {0, 1}});
  stiffness.block(stiffness.find_slot(0, 0)) = Eigen::Matrix3d::Identity();
  stiffness.block(stiffness.find_slot(1, 1)) = Eigen::Matrix3d::Identity();
  stiffness.block(stiffness.find_slot(0, 1)) = 2.0 * Eigen::Matrix3d::Identity();
  stiffness.block(stiffness.find_slot(1, 0)) = 2.0 * Eigen::Matrix3d::Identity();
  const Eigen::VectorXd d = Eigen::VectorXd::Constant(6, 0.01);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(6);
  b[0] = 1.0;
  b[3] = -1.0;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(6);
  PcgSolver solver({1e-10, 100});
  const SolveReport report = solver.solve({&stiffness, 1.0, &d}, b, x);
  EXPECT_FALSE(report.converged);
  EXPECT_EQ(report.iterations, 0);
  EXPECT_TRUE(x.allFinite());
}

TEST(Pcg, FollowsTheSystemWhenItGrows) {
  // The same solver object on two sizes in turn (XFEM growth): buffers follow the size.
  const test::TestSystem small = test::make_grid_system(3, 3, 2, 9);
  const test::TestSystem large = test::make_grid_system(4, 4, 3, 10);
  PcgSolver solver({1e-10, 1000});
  std::mt19937 rng(11);
  for (const test::TestSystem* system : {&small, &large, &small}) {
    const ShiftedSystem shifted = system->shifted(1.0);
    const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
    const SolveReport report = solver.solve(shifted, b, x);
    EXPECT_TRUE(report.converged);
    EXPECT_LE((x - system->dense(1.0).llt().solve(b)).norm(), 1e-6 * x.norm());
  }
}

TEST(Pcg, RecordsTheResidualOfEveryIterate) {
  // The history of one solve (tissue-convergence's plots): entry k is the relative residual of
  // iterate k, which a solve capped at k iterations reports (CG from the same start is the same
  // sequence); entry 0 is 1 from a zero start. And the lagged-factor solver records its own.
  const test::TestSystem system = test::make_grid_system(5, 5, 5, 1);
  const ShiftedSystem shifted = system.shifted(1.0);
  std::mt19937 rng(4);
  const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
  std::vector<double> history;
  PcgSolver recorded({1e-10, 10000});
  recorded.record_residuals(&history);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
  const SolveReport full = recorded.solve(shifted, b, x);
  ASSERT_EQ(history.size(), static_cast<size_t>(full.iterations) + 1);
  EXPECT_EQ(history.front(), 1.0);
  EXPECT_EQ(history.back(), full.relative_residual);
  for (const int cap : {1, 5, 20}) {
    PcgSolver capped({1e-10, cap});
    x.setZero();
    EXPECT_EQ(capped.solve(shifted, b, x).relative_residual, history[static_cast<size_t>(cap)]) << cap;
  }
  recorded.record_residuals(nullptr);  // stops recording
  x.setZero();
  recorded.solve(shifted, b, x);
  EXPECT_EQ(history.size(), static_cast<size_t>(full.iterations) + 1);

  std::vector<double> lagged_history;
  CholeskyPcgSolver lagged({1e-10, 100}, CholeskyPcgSolver::Refresh{});
  lagged.record_residuals(&lagged_history);
  x.setZero();
  const SolveReport lagged_report = lagged.solve(shifted, b, x);
  ASSERT_EQ(lagged_history.size(), static_cast<size_t>(lagged_report.iterations) + 1);
  EXPECT_EQ(lagged_history.back(), lagged_report.relative_residual);
}

TEST(ShiftedSystem, MultiplyIsScaledStiffnessPlusDiagonal) {
  const test::TestSystem system = test::make_grid_system(3, 2, 2, 12);
  std::mt19937 rng(13);
  const Eigen::VectorXd x = test::random_vector(system.diagonal.size(), rng);
  Eigen::VectorXd y;
  system.shifted(0.37).multiply(x, y);
  const Eigen::VectorXd expected = system.dense(0.37) * x;
  EXPECT_LE((y - expected).norm(), 1e-12 * expected.norm());
}

TEST(Pcg, ProductOfTheLastSetupIsTheSystemsThroughTheSolversCopy) {
  // multiply_set_up streams the compact copy the CG products use: A x to rounding with double
  // entries (a strict tolerance), to the entries' rounding (6e-8) with single ones (the real-time
  // 1e-3), bitwise the same on a team of two; refused before a setup and for another system.
  // Three columns at once, each as alone.
  const test::TestSystem system = test::make_grid_system(6, 5, 4, 9);
  const ShiftedSystem shifted = system.shifted(0.4);
  std::mt19937 rng(13);
  Eigen::MatrixXd x(shifted.rows(), 3);
  Eigen::MatrixXd expected(shifted.rows(), 3);
  for (int column = 0; column < 3; ++column) {
    const Eigen::VectorXd x_column = test::random_vector(shifted.rows(), rng);
    Eigen::VectorXd product;
    shifted.multiply(x_column, product);
    x.col(column) = x_column;
    expected.col(column) = product;
  }
  for (const double tolerance : {1e-6, 1e-3}) {
    PcgSolver jacobi({tolerance, 100});
    TwoLevelPcgSolver two_level({tolerance, 100});
    for (LinearSolver* solver : std::vector<LinearSolver*>{&jacobi, &two_level}) {
      RowMajorMatrix y;
      EXPECT_FALSE(solver->multiply_set_up(shifted, x, y)) << solver->name() << " before its setup";
      solver->setup(shifted);
      EXPECT_FALSE(solver->multiply_set_up(system.shifted(0.5), x, y)) << solver->name() << ", another scale";
      ASSERT_TRUE(solver->multiply_set_up(shifted, x, y)) << solver->name();
      for (int column = 0; column < 3; ++column) {
        const double error = (y.col(column) - expected.col(column)).norm() / expected.col(column).norm();
        EXPECT_LE(error, tolerance < 1e-5 ? 1e-14 : 1e-6) << solver->name() << ", tolerance " << tolerance;
      }
      WorkTeam team(2);
      solver->lend_work_team(&team);
      RowMajorMatrix together;
      ASSERT_TRUE(solver->multiply_set_up(shifted, x, together));
      solver->lend_work_team(nullptr);
      EXPECT_EQ(together, y) << solver->name() << ", tolerance " << tolerance;
    }
  }
}

}  // namespace
}  // namespace tissue
