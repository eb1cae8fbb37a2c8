// Tests of the CHOLMOD solver: agreement with dense LLT and with PCG, reuse of the symbolic
// analysis while the pattern is unchanged (and redoing it when it changes), and refusal of an
// indefinite matrix.
#include "core/solve/cholmod_factor.hpp"
#include "core/solve/linear_solver.hpp"

#include "solve/test_systems.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace tissue {
namespace {

void expect_matches_dense(CholmodSolver& solver, const test::TestSystem& system, double scale, std::mt19937& rng) {
  const ShiftedSystem shifted = system.shifted(scale);
  const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
  const Eigen::VectorXd expected = system.dense(scale).llt().solve(b);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
  const SolveReport report = solver.solve(shifted, b, x);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.iterations, 0);
  EXPECT_LE(report.relative_residual, 1e-12);
  // The true residual, up to the rounding of the two products.
  const double true_residual = (b - system.dense(scale) * x).norm() / b.norm();
  EXPECT_NEAR(report.relative_residual, true_residual, 0.2 * true_residual + 1e-15);
  EXPECT_LE((x - expected).norm(), 1e-10 * expected.norm());
}

TEST(Cholmod, ANearbySetupIteratesWithTheFactorAndFactorizesWhenTooFar) {
  // A Newton correction's matrix is the step's moved a little (setup_nearby): the solve iterates on
  // it with the step's factor, to NEARBY_TOLERANCE, and so lands within that of the exact solution
  // but not on it (it did not refactorize). A matrix far from the factor's (stiff random springs
  // added along the grid's rows, the same pattern) is not reached in NEARBY_ITERATIONS, so the
  // solver factorizes it and solves exactly.
  std::mt19937 rng(5);
  for (const bool far : {false, true}) {
    test::TestSystem system = test::make_grid_system(5, 5, 5, 21);
    const Eigen::VectorXd b = test::random_vector(system.shifted(1.0).rows(), rng);
    CholmodSolver solver;
    solver.setup(system.shifted(1.0));
    const double scale = far ? 1.0 : 1.05;
    if (far) {
      for (int i = 0; i + 1 < system.stiffness.block_rows(); i += 2) {
        if (i % 5 == 4) continue;  // the last vertex of a grid row has no neighbour i + 1
        system.add_edge(i, i + 1, 1e4 * test::random_spd_block(rng, 0.1, 10.0));
      }
    }
    solver.setup_nearby(system.shifted(scale));
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    const SolveReport report = solver.solve(b, x);
    const Eigen::VectorXd exact = system.dense(scale).llt().solve(b);
    const double true_residual = (b - system.dense(scale) * x).norm() / b.norm();
    const double error = (x - exact).norm() / exact.norm();
    std::printf("  %s: %d iterations, true residual %.2e, error %.2e\n", far ? "far" : "nearby", report.iterations,
                true_residual, error);
    EXPECT_TRUE(report.converged);
    if (!far) {
      EXPECT_GE(report.iterations, 1);
      EXPECT_LE(true_residual, 2.0 * CholmodSolver::NEARBY_TOLERANCE);
      EXPECT_GT(error, 1e-13);  // iterated, not refactorized
      EXPECT_LE(error, 1e-4);
    } else {
      EXPECT_EQ(report.iterations, 0);  // the direct solve of a new factor: round-off only (the
      EXPECT_LE(true_residual, 1e-9);   // stiff springs make A ill-conditioned)
      EXPECT_LE(error, 1e-8);
    }
  }
}

TEST(Cholmod, AgreesWithDenseLlt) {
  const test::TestSystem system = test::make_grid_system(5, 5, 5, 21);  // 375 unknowns
  CholmodSolver solver;
  EXPECT_EQ(solver.name(), "cholmod");
  std::mt19937 rng(22);
  for (const double scale : {1.0, 0.01, 100.0}) expect_matches_dense(solver, system, scale, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 1);
}

TEST(Cholmod, ReusesTheAnalysisUntilThePatternChanges) {
  test::TestSystem system = test::make_grid_system(4, 4, 3, 23, 0.05, {0.5, 2});  // rows with room
  CholmodSolver solver;
  std::mt19937 rng(24);
  EXPECT_EQ(solver.symbolic_analysis_count(), 0);
  expect_matches_dense(solver, system, 1.0, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 1);

  // New values (as after a step's reassembly), new scale, new diagonal: same analysis.
  system.add_edge(0, 1, test::random_spd_block(rng));
  system.diagonal *= 2.0;
  expect_matches_dense(solver, system, 3.0, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 1);

  // A new coupling (a cut joins blocks 0 and 40) fits in the spare room: same layout, new pattern.
  const auto layout = system.stiffness.layout_revision();
  system.stiffness.insert_block(0, 40);
  system.stiffness.insert_block(40, 0);
  ASSERT_EQ(system.stiffness.layout_revision(), layout);
  system.add_edge(0, 40, test::random_spd_block(rng));
  expect_matches_dense(solver, system, 1.0, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 2);
  expect_matches_dense(solver, system, 0.5, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 2);
}

TEST(Cholmod, FollowsRelayoutAndAppendedRows) {
  test::TestSystem system = test::make_grid_system(3, 3, 3, 25, 0.05, {0.5, 1});  // rows are full
  CholmodSolver solver;
  std::mt19937 rng(26);
  expect_matches_dense(solver, system, 1.0, rng);

  // Overflow: the slots move (layout changes); the solver must not read through stale slots.
  const auto layout = system.stiffness.layout_revision();
  system.stiffness.insert_block(0, 26);
  system.stiffness.insert_block(26, 0);
  ASSERT_NE(system.stiffness.layout_revision(), layout);
  system.add_edge(0, 26, test::random_spd_block(rng));
  expect_matches_dense(solver, system, 1.0, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 2);

  // An enriched DOF: a new block row coupled to row 13.
  test::append_coupled_row(system, 13, rng);
  expect_matches_dense(solver, system, 1.0, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 3);
}

TEST(Cholmod, DistinguishesMatricesWithTheSameRevision) {
  // Two matrices of the same size, both at pattern revision 0, with different patterns.
  const test::TestSystem grid = test::make_grid_system(4, 3, 2, 27);
  const test::TestSystem other = test::make_grid_system(2, 3, 4, 28);
  ASSERT_EQ(grid.stiffness.rows(), other.stiffness.rows());
  ASSERT_EQ(grid.stiffness.pattern_revision(), other.stiffness.pattern_revision());
  CholmodSolver solver;
  std::mt19937 rng(29);
  expect_matches_dense(solver, grid, 1.0, rng);
  expect_matches_dense(solver, other, 1.0, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 2);
}

TEST(Cholmod, RefusesIndefiniteMatrixAndRecovers) {
  const test::TestSystem system = test::make_grid_system(4, 4, 4, 30);
  CholmodSolver solver;
  std::mt19937 rng(31);
  const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
  EXPECT_THROW(solver.solve(system.shifted(-1.0), b, x), SolverError);
  try {
    solver.solve(system.shifted(-1.0), b, x);
  } catch (const SolverError& error) {
    EXPECT_NE(std::string(error.what()).find("not positive definite"), std::string::npos) << error.what();
  }
  // The same solver still works once the matrix is SPD again.
  expect_matches_dense(solver, system, 1.0, rng);
  EXPECT_EQ(solver.symbolic_analysis_count(), 1);

  // Non-finite input is refused, not returned as a solution.
  test::TestSystem poisoned = test::make_grid_system(2, 2, 2, 32);
  poisoned.diagonal[4] = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd y = Eigen::VectorXd::Zero(poisoned.diagonal.size());
  EXPECT_THROW(solver.solve(poisoned.shifted(1.0), Eigen::VectorXd::Ones(y.size()), y), SolverError);
}

TEST(Cholmod, LargerSystemRefusesIndefiniteAndRecovers) {
  // 3000 unknowns: large enough for CHOLMOD's supernodal path, whose failure handling differs
  // from the simplicial one. Checked through the true residual (no dense reference).
  const test::TestSystem system = test::make_grid_system(10, 10, 10, 36, 0.05, {}, false);
  CholmodSolver solver;
  std::mt19937 rng(37);
  const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
  EXPECT_THROW(solver.solve(system.shifted(-1.0), b, x), SolverError);
  for (const double scale : {1.0, 2.0}) {
    const SolveReport report = solver.solve(system.shifted(scale), b, x);
    EXPECT_TRUE(report.converged);
    EXPECT_LE(report.relative_residual, 1e-12);
    Eigen::VectorXd product;
    system.shifted(scale).multiply(x, product);
    EXPECT_LE((b - product).norm(), 1e-12 * b.norm());
  }
  EXPECT_EQ(solver.symbolic_analysis_count(), 1);
}

TEST(Cholmod, ZeroRightHandSideAndSizeChecks) {
  const test::TestSystem system = test::make_grid_system(3, 3, 3, 33);
  const long n = system.stiffness.rows();
  CholmodSolver solver;
  Eigen::VectorXd x = Eigen::VectorXd::Ones(n);
  const SolveReport report = solver.solve(system.shifted(1.0), Eigen::VectorXd::Zero(n), x);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.relative_residual, 0.0);
  EXPECT_TRUE(x.isZero(0.0));
  EXPECT_THROW(solver.solve(system.shifted(1.0), Eigen::VectorXd::Ones(n - 1), x), SolverError);
  Eigen::VectorXd long_x = Eigen::VectorXd::Zero(n + 1);
  solver.solve(system.shifted(1.0), Eigen::VectorXd::Ones(n), long_x);  // a direct solver resizes x
  EXPECT_EQ(long_x.size(), n);
}

TEST(Cholmod, AgreesWithPcg) {
  const test::TestSystem system = test::make_grid_system(6, 5, 4, 34);
  std::mt19937 rng(35);
  const ShiftedSystem shifted = system.shifted(1.0);
  const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
  CholmodSolver cholmod;
  PcgSolver pcg({1e-12, 10000});
  Eigen::VectorXd direct = Eigen::VectorXd::Zero(shifted.rows());
  Eigen::VectorXd iterative = Eigen::VectorXd::Zero(shifted.rows());
  cholmod.solve(shifted, b, direct);
  const SolveReport report = pcg.solve(shifted, b, iterative);
  EXPECT_TRUE(report.converged);
  EXPECT_LE((direct - iterative).norm(), 1e-8 * direct.norm());
}

}  // namespace
}  // namespace tissue

namespace tissue {
namespace {

// CHOLMOD's supernodal factorization and solves call BLAS, and Debian's serial OpenBLAS is not
// safe to call from two threads at once: two solvers on two threads (tissue-host compare --jobs 2,
// or pcgCholesky's refresh beside its solves) got each other's work buffers and results that
// changed from run to run. Two supernodal factors on two threads must give bitwise what each gives
// alone. (CholmodFactor goes supernodal by itself only for dense factors; forced here.)
TEST(Cholmod, TwoSupernodalFactorsOnTwoThreadsGiveBitwiseTheirSerialResults) {
  const test::TestSystem first = test::make_grid_system(14, 12, 10, 61, 0.05, {}, false);
  const test::TestSystem second = test::make_grid_system(12, 12, 12, 62, 0.05, {}, false);
  std::mt19937 rng(63);
  const Eigen::VectorXd b_first = test::random_vector(first.stiffness.rows(), rng);
  const Eigen::VectorXd b_second = test::random_vector(second.stiffness.rows(), rng);
  const auto solve = [](const test::TestSystem& system, const Eigen::VectorXd& b, int scale_step) {
    CholmodFactor factor(CholmodFactor::Solves::with_factor, CholmodFactor::Layout::supernodal);
    factor.load(system.shifted(1.0 + 0.01 * scale_step));
    EXPECT_EQ(factor.factorize(), CholmodFactor::Status::ok);
    Eigen::VectorXd x(b.size());
    factor.solve(std::span<const double>(b.data(), static_cast<size_t>(b.size())),
                 std::span<double>(x.data(), static_cast<size_t>(x.size())));
    return x;
  };
  constexpr int SOLVES = 12;
  std::vector<Eigen::VectorXd> alone_first, alone_second;
  for (int k = 0; k < SOLVES; ++k) {
    alone_first.push_back(solve(first, b_first, k));
    alone_second.push_back(solve(second, b_second, k));
  }
  std::vector<Eigen::VectorXd> beside_first(SOLVES), beside_second(SOLVES);
  std::thread other([&] {
    for (int k = 0; k < SOLVES; ++k) beside_second[static_cast<size_t>(k)] = solve(second, b_second, k);
  });
  for (int k = 0; k < SOLVES; ++k) beside_first[static_cast<size_t>(k)] = solve(first, b_first, k);
  other.join();
  for (size_t k = 0; k < SOLVES; ++k) {
    EXPECT_TRUE(beside_first[k] == alone_first[k]) << "solve " << k << " of the first system";
    EXPECT_TRUE(beside_second[k] == alone_second[k]) << "solve " << k << " of the second system";
  }
}

// The forward half of a solve for a sparse right-hand side (lower_solve, what the contact stiffness
// needs): for sparse b and c, y_b^T y_c must be b^T A^-1 c from full solves, in both layouts and
// both orderings, while reaching only part of L (the elimination tree above b's rows).
TEST(Cholmod, ALowerSolveOfSparseColumnsGivesTheFullSolvesInnerProducts) {
  const test::TestSystem system = test::make_grid_system(9, 8, 7, 64, 0.05, {}, false);  // 1512 unknowns
  const ShiftedSystem shifted = system.shifted(1.0);
  const int n = shifted.rows();
  std::mt19937 rng(65);
  std::uniform_int_distribution<int> row(0, n - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<CholmodFactor::SparseColumn> columns(4);
  for (auto& column : columns) {
    for (int k = 0; k < 5; ++k) column.emplace_back(row(rng), value(rng));
  }
  columns[3].push_back(columns[3].front());  // a repeated row: summed
  using Layout = CholmodFactor::Layout;
  using Ordering = CholmodFactor::Ordering;
  for (const Layout layout : {Layout::automatic, Layout::supernodal}) {
    for (const Ordering ordering : {Ordering::amd, Ordering::metis}) {
      CholmodFactor factor(CholmodFactor::Solves::with_factor, layout, ordering);
      factor.load(shifted);
      ASSERT_EQ(factor.factorize(), CholmodFactor::Status::ok);
      EXPECT_EQ(factor.supernodal(), layout == Layout::supernodal);
      EXPECT_EQ(factor.ordering_used(), ordering == Ordering::metis ? CHOLMOD_METIS : CHOLMOD_AMD);
      Eigen::MatrixXd dense_b = Eigen::MatrixXd::Zero(n, 4);
      for (size_t c = 0; c < columns.size(); ++c) {
        for (const auto& [r, v] : columns[c]) dense_b(r, static_cast<Eigen::Index>(c)) += v;
      }
      Eigen::MatrixXd solved(n, 4);
      for (Eigen::Index c = 0; c < 4; ++c) {
        Eigen::VectorXd b = dense_b.col(c), x(n);
        factor.solve(std::span<const double>(b.data(), static_cast<size_t>(n)),
                     std::span<double>(x.data(), static_cast<size_t>(n)));
        solved.col(c) = x;
      }
      const Eigen::MatrixXd expected = dense_b.transpose() * solved;
      CholmodFactor::LowerSolution y;
      for (int repeat = 0; repeat < 2; ++repeat) {  // the work rows are left zero for the next call
        factor.lower_solve(columns, y);
        const Eigen::MatrixXd gram = y.values.transpose() * y.values;
        EXPECT_LE((gram - expected).norm(), 1e-10 * expected.norm())
            << (layout == Layout::supernodal ? "supernodal" : "simplicial") << ", "
            << (ordering == Ordering::metis ? "METIS" : "AMD");
      }
      EXPECT_TRUE(std::is_sorted(y.rows.begin(), y.rows.end()));
      EXPECT_LT(static_cast<int>(y.rows.size()), n);
      EXPECT_GT(y.rows.size(), 0U);
      // A row outside the matrix is refused, after good columns too, and leaves nothing behind: the
      // next solve gives the same inner products.
      std::vector<CholmodFactor::SparseColumn> outside{columns[0], columns[1], {{n, 1.0}}, columns[2]};
      EXPECT_THROW(factor.lower_solve(outside, y), std::invalid_argument);
      factor.lower_solve(columns, y);
      EXPECT_LE((y.values.transpose() * y.values - expected).norm(), 1e-10 * expected.norm()) << "after a refused call";
    }
  }
  CholmodFactor unfactored;
  CholmodFactor::LowerSolution y;
  EXPECT_THROW(unfactored.lower_solve(columns, y), SolverError);
}

}  // namespace
}  // namespace tissue
