// Tests of CompactRowsSolver (issue 41, item 3): the block rows nothing couples are solved apart,
// exactly, and the inner solver gets the rest, once they are a quarter of the rows it would get; the
// solution is the whole system's (against a dense solve); a row left out that is coupled again is
// solved with the others; rows appended keep the others' numbers; a cut beam's parked end leaves the
// two-level solver's system.
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/solve/compact_rows_solver.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/system/block_sparse_matrix.hpp"

#include "fem/body_pieces.hpp"
#include "fem/xfem_test_helpers.hpp"
#include "solve/test_systems.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

namespace tissue {
namespace {

// A grid of nx * ny * nz coupled rows, then `uncoupled` rows with their diagonal block only: K_ii = 0
// (a parked row: its mass alone) for all but the last, whose K_ii is SPD (a row alone whose
// elements still act on it).
test::TestSystem grid_with_uncoupled_rows(int nx, int ny, int nz, int uncoupled, unsigned seed) {
  test::TestSystem system = test::make_grid_system(nx, ny, nz, seed);
  std::mt19937 rng(seed + 1);
  for (int k = 0; k < uncoupled; ++k) {
    const int row = system.stiffness.append_block_row();
    const long n = system.stiffness.rows();
    Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(n, n);
    grown.topLeftCorner(n - 3, n - 3) = system.dense_stiffness;
    system.dense_stiffness = grown;
    system.diagonal.conservativeResize(n);
    system.diagonal.tail<3>().setConstant(0.03 + 0.01 * k);
    if (k + 1 == uncoupled) {
      const Eigen::Matrix3d block = test::random_spd_block(rng);
      system.stiffness.block(system.stiffness.diagonal_slot(row)) = block;
      system.dense_stiffness.block<3, 3>(3L * row, 3L * row) = block;
    }
  }
  return system;
}

Eigen::VectorXd dense_solution(const test::TestSystem& system, double scale, const Eigen::VectorXd& b) {
  return system.dense(scale).ldlt().solve(b);
}

double relative_error(const Eigen::VectorXd& x, const Eigen::VectorXd& exact) {
  return (x - exact).norm() / exact.norm();
}

TEST(CompactRowsSolver, SolvesTheWholeSystemWithTheUncoupledRowsApart) {
  constexpr double SCALE = 0.3;
  const test::TestSystem system = grid_with_uncoupled_rows(4, 4, 4, 80, 5);  // 64 coupled rows, 80 alone
  std::mt19937 rng(3);
  const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
  const Eigen::VectorXd exact = dense_solution(system, SCALE, b);
  std::vector<std::unique_ptr<LinearSolver>> inners;
  inners.push_back(std::make_unique<PcgSolver>(PcgSolver::Settings{1e-12, 2000}));
  inners.push_back(std::make_unique<TwoLevelPcgSolver>(PcgSolver::Settings{1e-12, 2000}));
  inners.push_back(std::make_unique<CholmodSolver>());
  for (auto& inner : inners) {
    CompactRowsSolver solver(std::move(inner));
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    const SolveReport report = solver.solve(system.shifted(SCALE), b, x);
    EXPECT_EQ(solver.kept_block_rows(), 64) << solver.name();
    EXPECT_LT(relative_error(x, exact), 1e-9) << solver.name();
    // The residual it reports is the whole system's: relative to the whole b.
    const double residual = (system.dense(SCALE) * x - b).norm() / b.norm();
    EXPECT_NEAR(report.relative_residual, residual, 1e-12 + 0.01 * residual) << solver.name();
    // The rows alone exactly: x_i = (s K_ii + d_i)^-1 b_i.
    for (int row = 64; row < 144; ++row) {
      const Eigen::Vector3d exact_row = exact.segment<3>(3L * row);
      EXPECT_LT((x.segment<3>(3L * row) - exact_row).norm(), 1e-13 * exact_row.norm()) << solver.name() << " " << row;
    }
  }
}

// Below a quarter of the rows (or MIN_DECOUPLED_ROWS rows) the inner solver gets the system as it is.
TEST(CompactRowsSolver, LeavesRowsOutOnlyOnceTheyAreAQuarter) {
  constexpr double SCALE = 0.3;
  // 240 coupled rows: 4 u >= 240 + u from u = 80 uncoupled rows.
  for (const int uncoupled : {79, 80}) {
    const test::TestSystem system = grid_with_uncoupled_rows(6, 5, 8, uncoupled, 9);
    CompactRowsSolver solver(std::make_unique<PcgSolver>(PcgSolver::Settings{1e-10, 2000}));
    std::mt19937 rng(4);
    const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    solver.solve(system.shifted(SCALE), b, x);
    EXPECT_EQ(solver.kept_block_rows(), uncoupled == 79 ? 240 + 79 : 240);
    EXPECT_LT(relative_error(x, dense_solution(system, SCALE, b)), 1e-7) << uncoupled;
  }
}

// A row left out that a later pattern couples again is solved with the others; rows appended since
// the compaction are kept, after the others, without compacting anew.
TEST(CompactRowsSolver, FollowsThePatternAsItChanges) {
  constexpr double SCALE = 0.3;
  test::TestSystem system = grid_with_uncoupled_rows(4, 4, 4, 80, 11);
  CompactRowsSolver solver(std::make_unique<CholmodSolver>());
  std::mt19937 rng(6);
  Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
  Eigen::VectorXd x;
  solver.solve(system.shifted(SCALE), b, x);
  ASSERT_EQ(solver.kept_block_rows(), 64);

  test::append_coupled_row(system, 5, rng);  // row 144, coupled to row 5
  b = test::random_vector(system.stiffness.rows(), rng);
  solver.solve(system.shifted(SCALE), b, x);
  EXPECT_EQ(solver.kept_block_rows(), 65);
  EXPECT_LT(relative_error(x, dense_solution(system, SCALE, b)), 1e-10);

  // Row 70 (left out) coupled to row 3: solved with them again.
  system.stiffness.insert_block(70, 3);
  system.stiffness.insert_block(3, 70);
  system.add_edge(70, 3, test::random_spd_block(rng));
  solver.solve(system.shifted(SCALE), b, x);
  EXPECT_EQ(solver.kept_block_rows(), 66);
  EXPECT_LT(relative_error(x, dense_solution(system, SCALE, b)), 1e-10);
}

// A pattern that is not symmetric (row 3 has a block with row 70, row 70 none with row 3): row 70 is
// kept, as every row a block reaches, and the solution is still the system's.
TEST(CompactRowsSolver, KeepsEveryRowABlockReaches) {
  constexpr double SCALE = 0.3;
  test::TestSystem system = grid_with_uncoupled_rows(4, 4, 4, 80, 13);
  CompactRowsSolver solver(std::make_unique<CholmodSolver>());
  std::mt19937 rng(7);
  const Eigen::VectorXd b = test::random_vector(system.stiffness.rows(), rng);
  Eigen::VectorXd x;
  solver.solve(system.shifted(SCALE), b, x);
  ASSERT_EQ(solver.kept_block_rows(), 64);
  system.stiffness.insert_block(3, 70);  // its value zero: A is unchanged
  solver.solve(system.shifted(SCALE), b, x);
  EXPECT_EQ(solver.kept_block_rows(), 65);
  EXPECT_LT(relative_error(x, dense_solution(system, SCALE, b)), 1e-10);
}

TEST(CompactRowsSolver, RefusesWhatItCannotSolve) {
  const test::TestSystem system = grid_with_uncoupled_rows(4, 4, 4, 80, 2);
  CompactRowsSolver solver(std::make_unique<PcgSolver>(PcgSolver::Settings{1e-8, 100}));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(system.stiffness.rows());
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Zero(system.stiffness.rows()), x), SolverError);  // no setup
  solver.setup(system.shifted(0.3));
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Zero(7), x), SolverError);
  EXPECT_THROW(CompactRowsSolver(nullptr), SolverError);
  // A row kept with a block to a row left out: the matrix of the kept rows refuses it.
  BlockSparseMatrix kept;
  std::vector<int> index_of_row(static_cast<size_t>(system.stiffness.block_rows()), -1);
  index_of_row[0] = 0;
  EXPECT_THROW(kept.view_rows_of(system.stiffness, {0}, index_of_row), std::invalid_argument);
}

// A 10 x 2 x 2 cm beam of 1 cm cubes held at x = 0, cut through at x = 2.5, 4.5, 6.5 and 8.5 cm, its
// four free parts parked (as parts fallen out of the field): their ghost rows keep their mass alone
// and leave the two-level solver's system, which still gives CHOLMOD's solution of the whole.
TEST(CompactRowsSolver, ACutBeamsParkedEndLeavesTheSystem) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  BodySettings settings;
  settings.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  DeformableBody body(mesh, settings);
  DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count())};
  for (int cut = 0; cut < 4; ++cut) {
    const xfem_test::Plane plane{Eigen::Vector3d::UnitX(), 0.025 + 0.02 * cut};
    body.enrich(xfem_test::plane_cuts(mesh, plane, cut), state);
  }
  std::vector<int> free_rows;
  for (const xfem_test::BodyPiece& piece : xfem_test::body_pieces(body)) {
    if (!piece.held) free_rows.insert(free_rows.end(), piece.rows.begin(), piece.rows.end());
  }
  body.park_rows(free_rows);
  Eigen::VectorXd forces;
  body.evaluate(state.displacement_m, forces, true);
  const Eigen::VectorXd diagonal = body.mass_kg();
  ShiftedSystem system{&body.tangent(), 1e-4, &diagonal};
  system.block_positions = body.block_positions(state.displacement_m);
  system.rows_left = body.rows_left();
  std::mt19937 rng(8);
  const Eigen::VectorXd b = test::random_vector(system.rows(), rng);
  CompactRowsSolver solver(std::make_unique<TwoLevelPcgSolver>(PcgSolver::Settings{1e-10, 1000}));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
  const SolveReport report = solver.solve(system, b, x);
  EXPECT_TRUE(report.converged);
  // The parts' ghost rows go; their vertex rows keep the blocks of their uncut tets (zero now).
  int ghost_rows = 0;
  for (const int row : free_rows) ghost_rows += row >= body.dofs().free_vertex_count() ? 1 : 0;
  ASSERT_GE(ghost_rows, CompactRowsSolver::MIN_DECOUPLED_ROWS);
  EXPECT_EQ(solver.kept_block_rows(), body.dof_count() / 3 - ghost_rows);
  CholmodSolver cholmod;
  Eigen::VectorXd exact;
  cholmod.solve(system, b, exact);
  EXPECT_LT(relative_error(x, exact), 1e-6);
}

}  // namespace
}  // namespace tissue
