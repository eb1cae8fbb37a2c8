// Tests of CG with the two-level preconditioner (TwoLevelPcgSolver, TwoLevelPreconditioner): it
// reaches the tolerance and CHOLMOD's solution; its coarse space holds every rigid motion of the
// body (translations always, rotations with the rows' points); aggregates never join rows a cut
// decoupled; rows alone (a parked part's) join no aggregate; within the real-time cap it resolves a
// cantilever's sag that Jacobi leaves; a Newton correction's setup keeps the coarse level; two
// threads give bitwise one thread's iterates.
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/solve/two_level_preconditioner.hpp"
#include "core/system/work_team.hpp"

#include "fem/body_pieces.hpp"
#include "fem/xfem_test_helpers.hpp"
#include "solve/test_systems.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include <map>
#include <memory>
#include <random>
#include <set>
#include <vector>

namespace tissue {
namespace {

// The grid's points (make_grid_system numbers rows x + nx (y + ny z)), 1 cm apart.
std::vector<Eigen::Vector3d> grid_points(int nx, int ny, int nz) {
  std::vector<Eigen::Vector3d> points;
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) points.emplace_back(0.01 * x, 0.01 * y, 0.01 * z);
    }
  }
  return points;
}

double condition_number(const Eigen::MatrixXd& a) {
  const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a).eigenvalues();
  return eigenvalues.maxCoeff() / eigenvalues.minCoeff();
}

TEST(TwoLevelPcg, ReachesTheToleranceAndAgreesWithCholmod) {
  const test::TestSystem system = test::make_grid_system(8, 5, 4, 7);  // 480 unknowns
  const std::vector<Eigen::Vector3d> points = grid_points(8, 5, 4);
  std::mt19937 rng(3);
  const double tolerance = 1e-10;
  for (const bool with_points : {false, true}) {
    TwoLevelPcgSolver solver({tolerance, 500});
    EXPECT_EQ(solver.name(), "pcgTwoLevel");
    ShiftedSystem shifted = system.shifted(1.0);
    if (with_points) shifted.block_positions = &points;
    const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
    Eigen::VectorXd direct = Eigen::VectorXd::Zero(shifted.rows());
    const SolveReport report = solver.solve(shifted, b, x);
    CholmodSolver().solve(shifted, b, direct);
    EXPECT_TRUE(report.converged);
    EXPECT_LE(report.relative_residual, tolerance);
    EXPECT_GT(solver.aggregate_count(), 1);
    EXPECT_EQ(solver.coarse_size() > 3 * solver.aggregate_count(), with_points);  // rotations only with points
    const Eigen::MatrixXd dense = system.dense(1.0);
    EXPECT_LE((b - dense * x).norm() / b.norm(), 2 * tolerance);
    EXPECT_LE((x - direct).norm(), condition_number(dense) * tolerance * direct.norm());
  }
}

// For x in the coarse space, P^-1 A x = D^-1 A x + x: the coarse solve is the A-orthogonal
// projection onto its space. Any rigid motion of the whole grid is a sum of the aggregates'
// rigid motions, so it is in the space when the points are given; without them, only translations.
TEST(TwoLevelPcg, TheCoarseSpaceHoldsEveryRigidMotion) {
  const int nx = 9, ny = 4, nz = 3;
  const test::TestSystem system = test::make_grid_system(nx, ny, nz, 11);
  const std::vector<Eigen::Vector3d> points = grid_points(nx, ny, nz);
  const Eigen::MatrixXd dense = system.dense(1.0);
  const Eigen::VectorXd inverse_diagonal = dense.diagonal().cwiseInverse();
  const long n = dense.rows();
  const auto motion = [&](const Eigen::Vector3d& translation, const Eigen::Vector3d& spin) {
    Eigen::VectorXd x(n);
    for (size_t i = 0; i < points.size(); ++i) {
      x.segment<3>(3 * static_cast<long>(i)) = translation + spin.cross(points[i] - Eigen::Vector3d(0.04, 0.015, 0.01));
    }
    return x;
  };
  const auto coarse_part = [&](TwoLevelPreconditioner& preconditioner, const Eigen::VectorXd& x) {
    const Eigen::VectorXd r = dense * x;
    Eigen::VectorXd z(n);
    preconditioner.apply(r, z);
    return Eigen::VectorXd(z - inverse_diagonal.cwiseProduct(r));
  };
  ShiftedSystem with_points = system.shifted(1.0);
  with_points.block_positions = &points;
  TwoLevelPreconditioner rigid;
  rigid.setup(with_points, inverse_diagonal);
  TwoLevelPreconditioner translations;
  translations.setup(system.shifted(1.0), inverse_diagonal);
  const Eigen::VectorXd slide = motion(Eigen::Vector3d(0.3, -1.0, 0.2), Eigen::Vector3d::Zero());
  const Eigen::VectorXd turn = motion(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.5, 2.0, -1.0));
  EXPECT_LT((coarse_part(rigid, slide) - slide).norm(), 1e-9 * slide.norm());
  EXPECT_LT((coarse_part(rigid, turn) - turn).norm(), 1e-9 * turn.norm());
  EXPECT_LT((coarse_part(translations, slide) - slide).norm(), 1e-9 * slide.norm());
  EXPECT_GT((coarse_part(translations, turn) - turn).norm(), 0.01 * turn.norm());  // a turn is not a translation
}

// Blocks a cut leaves in the pattern at zero (the two sides of a cut tet's vertices no longer
// couple) are not strong couplings: no aggregate takes rows from both sides.
TEST(TwoLevelPcg, AggregatesNeverJoinRowsACutDecoupled) {
  const int nx = 10, ny = 4, nz = 3;
  test::TestSystem system = test::make_grid_system(nx, ny, nz, 5, 0.05, {}, /*with_dense=*/false);
  const auto side = [nx](int row) { return row % nx < nx / 2; };
  BlockSparseMatrix& k = system.stiffness;
  for (int i = 0; i < k.block_rows(); ++i) {
    for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
      const int j = k.slot_column(s);
      if (j < 0 || side(i) == side(j)) continue;
      // Take the edge term out: subtract it from both diagonals, zero the coupling block.
      const Eigen::Matrix3d coupling = k.block(s);
      k.block(k.find_slot(i, i)) += coupling;  // the edge added -B here and +B to the diagonal
      k.block(s).setZero();
    }
  }
  const std::vector<Eigen::Vector3d> points = grid_points(nx, ny, nz);
  ShiftedSystem shifted = system.shifted(1.0);
  shifted.block_positions = &points;
  Eigen::VectorXd inverse_diagonal(shifted.rows());
  for (int i = 0; i < k.block_rows(); ++i) {
    inverse_diagonal.segment<3>(3L * i) =
        (k.block(k.find_slot(i, i)).diagonal() + system.diagonal.segment<3>(3L * i)).cwiseInverse();
  }
  TwoLevelPreconditioner preconditioner;
  preconditioner.setup(shifted, inverse_diagonal);
  std::vector<std::set<bool>> sides(static_cast<size_t>(preconditioner.aggregate_count()));
  for (int i = 0; i < k.block_rows(); ++i) {
    const int aggregate = preconditioner.aggregate_of_row()[static_cast<size_t>(i)];
    if (aggregate >= 0) sides[static_cast<size_t>(aggregate)].insert(side(i));
  }
  for (const std::set<bool>& s : sides) EXPECT_EQ(s.size(), 1u);
}

// A 10 x 2 x 2 cm beam of 1 cm cubes held at x = 0, at rest.
struct HeldBeam {
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  DeformableBody body{mesh, settings_of(mesh)};
  DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count())};

  Eigen::VectorXd forces{}, diagonal{}, inverse_diagonal{};

  /// The step matrix (10 ms)^2 K + M at the state as it is; A's inverse diagonal into inverse_diagonal.
  ShiftedSystem system() {
    body.evaluate(state.displacement_m, forces, true);
    diagonal = body.mass_kg();
    ShiftedSystem shifted{&body.tangent(), 1e-4, &diagonal};
    shifted.block_positions = body.block_positions(state.displacement_m);
    body.tangent().diagonal(inverse_diagonal);
    inverse_diagonal = (shifted.stiffness_scale * inverse_diagonal + diagonal).cwiseInverse();
    return shifted;
  }

  static BodySettings settings_of(const TetMesh& mesh) {
    BodySettings settings;
    settings.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
    return settings;
  }
};

// A 10 x 2 x 2 cm beam held at x = 0 and cut through at x = 5.5 cm, its free end parked
// (DeformableBody::park_rows, as a part fallen out of the operating field): the end's rows keep
// only their mass, each a row alone. They join no aggregate (a singleton's coarse columns would only
// repeat Jacobi's exact solve of it; a hatched body has thousands), and CG still reaches CHOLMOD's
// solution (to the tolerance times the system's condition, ~1e3 here).
TEST(TwoLevelPcg, RowsAloneJoinNoAggregate) {
  HeldBeam beam;
  const TetMesh& mesh = beam.mesh;
  DeformableBody& body = beam.body;
  DynamicState& state = beam.state;
  body.enrich(xfem_test::plane_cuts(mesh, xfem_test::Plane{Eigen::Vector3d::UnitX(), 0.055}), state);
  std::vector<int> free_rows;
  for (const xfem_test::BodyPiece& piece : xfem_test::body_pieces(body)) {
    if (!piece.held) free_rows = piece.rows;
  }
  ASSERT_GT(free_rows.size(), 20u);
  body.park_rows(free_rows);
  Eigen::VectorXd forces;
  body.evaluate(state.displacement_m, forces, true);
  const Eigen::VectorXd diagonal = body.mass_kg();
  ShiftedSystem system{&body.tangent(), 1e-4, &diagonal};  // (10 ms)^2 K + M
  system.block_positions = body.block_positions(state.displacement_m);

  Eigen::VectorXd inverse_diagonal;
  body.tangent().diagonal(inverse_diagonal);
  inverse_diagonal = (system.stiffness_scale * inverse_diagonal + diagonal).cwiseInverse();
  TwoLevelPreconditioner preconditioner;
  preconditioner.setup(system, inverse_diagonal);
  for (const int row : free_rows) EXPECT_EQ(preconditioner.aggregate_of_row()[static_cast<size_t>(row)], -1) << row;
  int aggregated = 0;
  for (const int aggregate : preconditioner.aggregate_of_row()) aggregated += aggregate >= 0 ? 1 : 0;
  EXPECT_EQ(aggregated + static_cast<int>(free_rows.size()), body.dof_count() / 3) << "every held row is aggregated";

  std::mt19937 rng(5);
  const Eigen::VectorXd b = test::random_vector(system.rows(), rng);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(system.rows());
  Eigen::VectorXd direct = Eigen::VectorXd::Zero(system.rows());
  TwoLevelPcgSolver solver({1e-10, 500});
  EXPECT_TRUE(solver.solve(system, b, x).converged);
  CholmodSolver().solve(system, b, direct);
  EXPECT_LE((x - direct).norm(), 1e-6 * direct.norm());
}

// The same parked end within an iteration cap, as a real-time step solves it: rows no block joins
// to another are each their own 3 x 3 system, solved exactly whatever the cap, by each CG solver,
// from a zero start (the step's) or a warm one. Before, CG left each off by p_k(1) times its start's
// error; nothing pulled the rows back together, so a parked piece swelled as it fell (the hatched
// frog at Young's modulus x 1.06 through tissue-host: 9.7 -> 36.7 cm^3 in 1.3 s).
TEST(TwoLevelPcg, RowsNoBlockJoinsAreSolvedExactlyWithinTheCap) {
  HeldBeam beam;
  DeformableBody& body = beam.body;
  DynamicState& state = beam.state;
  body.enrich(xfem_test::plane_cuts(beam.mesh, xfem_test::Plane{Eigen::Vector3d::UnitX(), 0.055}), state);
  std::vector<int> free_rows;
  for (const xfem_test::BodyPiece& piece : xfem_test::body_pieces(body)) {
    if (!piece.held) free_rows = piece.rows;
  }
  ASSERT_GT(free_rows.size(), 20u);
  Eigen::VectorXd forces;
  const Eigen::VectorXd diagonal = body.mass_kg();
  const auto system_of = [&] {
    body.evaluate(state.displacement_m, forces, true);
    ShiftedSystem system{&body.tangent(), 1e-4, &diagonal};
    system.block_positions = body.block_positions(state.displacement_m);
    system.rows_left = body.rows_left();  // (none before the park)
    return system;
  };
  const PcgSolver::Settings capped{1e-3, 3};
  std::vector<std::unique_ptr<LinearSolver>> solvers;
  solvers.push_back(std::make_unique<PcgSolver>(capped));
  solvers.push_back(std::make_unique<TwoLevelPcgSolver>(capped));
  // (Its factor, made before the park and refreshed at the pattern's change, may converge at once.)
  solvers.push_back(std::make_unique<CholeskyPcgSolver>(capped, CholeskyPcgSolver::Refresh{}));
  solvers.back()->setup(system_of());
  body.park_rows(free_rows);
  const ShiftedSystem system = system_of();
  std::mt19937 rng(17);
  const Eigen::VectorXd b = test::random_vector(system.rows(), rng);
  const Eigen::VectorXd warm = test::random_vector(system.rows(), rng);
  for (const auto& solver : solvers) {
    for (const Eigen::VectorXd& start : {Eigen::VectorXd(Eigen::VectorXd::Zero(system.rows())), warm}) {
      Eigen::VectorXd x = start;
      const SolveReport report = solver->solve(system, b, x);
      if (solver != solvers.back()) {
        EXPECT_FALSE(report.converged) << solver->name() << ": the cap is what this tests";
      }
      for (const int row : free_rows) {
        // A parked row keeps only its mass: A_ii = m_i I.
        const Eigen::Vector3d exact = b.segment<3>(3L * row).cwiseQuotient(diagonal.segment<3>(3L * row));
        EXPECT_LT((x.segment<3>(3L * row) - exact).norm(), 1e-12 * exact.norm()) << solver->name() << " row " << row;
      }
    }
  }
}

// A cut between coarse refreshes: the coarse level made before serves, and the rows the cut added
// or gave blocks get a local level of their own (issue 41: a cutting step no longer aggregates the
// whole matrix anew). P stays symmetric positive definite, CG reaches CHOLMOD's solution, and at the
// next refresh every row of the grown matrix has its place. A 10 x 2 x 2 cm beam held at x = 0, cut at x = 5.5 cm.
TEST(TwoLevelPcg, ACutBetweenRefreshesAddsALocalLevelAndKeepsPPositiveDefinite) {
  HeldBeam beam;
  const TetMesh& mesh = beam.mesh;
  DeformableBody& body = beam.body;
  DynamicState& state = beam.state;
  const Eigen::VectorXd& inverse_diagonal = beam.inverse_diagonal;
  const auto system_of = [&] { return beam.system(); };
  TwoLevelPreconditioner preconditioner;
  preconditioner.setup(system_of(), inverse_diagonal);  // aggregates and makes the coarse level
  const std::size_t uncut_rows = preconditioner.aggregate_of_row().size();
  body.enrich(xfem_test::plane_cuts(mesh, xfem_test::Plane{Eigen::Vector3d::UnitX(), 0.055}), state);
  const ShiftedSystem cut = system_of();
  ASSERT_GT(cut.rows(), static_cast<Eigen::Index>(3 * uncut_rows));
  preconditioner.setup(cut, inverse_diagonal);
  EXPECT_EQ(preconditioner.aggregate_of_row().size(), uncut_rows);  // not aggregated anew

  std::mt19937 rng(11);
  const Eigen::Index n = cut.rows();
  Eigen::MatrixXd p_inverse(n, n);
  Eigen::VectorXd z;
  for (Eigen::Index c = 0; c < n; ++c) {
    preconditioner.apply(Eigen::VectorXd::Unit(n, c), z);
    p_inverse.col(c) = z;
  }
  EXPECT_LE((p_inverse - p_inverse.transpose()).norm(), 1e-12 * p_inverse.norm());
  const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(p_inverse).eigenvalues();
  EXPECT_GT(eigenvalues.minCoeff(), 0.0);
  // The local level is what resolves the cut rows: without it (Jacobi there) P^-1 is smaller on them.
  Eigen::VectorXd new_rows = Eigen::VectorXd::Zero(n);
  new_rows.tail(n - static_cast<Eigen::Index>(3 * uncut_rows)).setOnes();
  preconditioner.apply(new_rows, z);
  EXPECT_GT(new_rows.dot(z), 1.01 * new_rows.dot(inverse_diagonal.cwiseProduct(new_rows)));

  const Eigen::VectorXd b = test::random_vector(n, rng);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd direct = Eigen::VectorXd::Zero(n);
  TwoLevelPcgSolver solver({1e-10, 500});
  EXPECT_TRUE(solver.solve(cut, b, x).converged);
  CholmodSolver().solve(cut, b, direct);
  EXPECT_LE((x - direct).norm(), 1e-6 * direct.norm());

  for (int k = 0; k < TwoLevelPreconditioner::COARSE_REFRESH_SETUPS; ++k) preconditioner.setup(cut, inverse_diagonal);
  EXPECT_EQ(preconditioner.aggregate_of_row().size(), static_cast<std::size_t>(n / 3));  // the refresh aggregated
}

// The refresh after a cut (issue 41, item 5): the aggregates the cut touched (holding a row it added
// blocks to) and its new rows get the local level's aggregates, the others keep theirs, row for
// row; the whole matrix is not aggregated anew (that cost a cutting scene's refresh steps 0.2-0.9
// ms). CG with the merged coarse level still reaches CHOLMOD's solution. The beam of the test above.
TEST(TwoLevelPcg, TheRefreshAfterACutKeepsTheAggregatesTheCutDidNotTouch) {
  HeldBeam beam;
  DeformableBody& body = beam.body;
  DynamicState& state = beam.state;
  const Eigen::VectorXd& inverse_diagonal = beam.inverse_diagonal;
  const auto system_of = [&] { return beam.system(); };
  TwoLevelPreconditioner preconditioner;
  TwoLevelPcgSolver solver({1e-10, 500});  // (its own preconditioner, set up alike)
  preconditioner.setup(system_of(), inverse_diagonal);
  solver.setup(system_of());
  const std::vector<int> before = preconditioner.aggregate_of_row();
  const int uncut_rows = static_cast<int>(before.size());
  std::vector<int> row_size(before.size());
  for (int i = 0; i < uncut_rows; ++i) row_size[static_cast<size_t>(i)] = body.tangent().row_size(i);
  body.enrich(xfem_test::plane_cuts(beam.mesh, xfem_test::Plane{Eigen::Vector3d::UnitX(), 0.055}), state);
  const ShiftedSystem cut = system_of();
  for (int k = 0; k < TwoLevelPreconditioner::COARSE_REFRESH_SETUPS; ++k) {
    preconditioner.setup(cut, inverse_diagonal);
    solver.setup(cut);
  }
  const std::vector<int>& after = preconditioner.aggregate_of_row();
  ASSERT_EQ(after.size(), static_cast<size_t>(cut.rows() / 3));

  std::set<int> touched;  // aggregates before that hold a row the cut changed
  for (int i = 0; i < uncut_rows; ++i) {
    if (body.tangent().row_size(i) != row_size[static_cast<size_t>(i)] && before[static_cast<size_t>(i)] >= 0) {
      touched.insert(before[static_cast<size_t>(i)]);
    }
  }
  // Each aggregate's rows, before and after.
  const auto rows_of = [](const std::vector<int>& aggregate_of) {
    std::map<int, std::set<int>> rows;
    for (size_t i = 0; i < aggregate_of.size(); ++i) {
      if (aggregate_of[i] >= 0) rows[aggregate_of[i]].insert(static_cast<int>(i));
    }
    return rows;
  };
  const std::map<int, std::set<int>> rows_before = rows_of(before);
  std::set<std::set<int>> aggregates_after;
  for (const auto& [aggregate, rows] : rows_of(after)) aggregates_after.insert(rows);
  ASSERT_FALSE(touched.empty());
  ASSERT_LT(touched.size(), rows_before.size());
  for (const auto& [aggregate, rows] : rows_before) {
    if (touched.count(aggregate) == 0) {
      EXPECT_EQ(aggregates_after.count(rows), 1u) << "aggregate " << aggregate << " kept";
    }
  }
  for (int i = uncut_rows; i < static_cast<int>(after.size()); ++i) {
    EXPECT_GE(after[static_cast<size_t>(i)], 0) << "the cut's new row " << i << " is aggregated";
  }

  std::mt19937 rng(13);
  const Eigen::VectorXd b = test::random_vector(cut.rows(), rng);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(cut.rows());
  Eigen::VectorXd direct = Eigen::VectorXd::Zero(cut.rows());
  EXPECT_TRUE(solver.solve(b, x).converged);
  CholmodSolver().solve(cut, b, direct);
  EXPECT_LE((x - direct).norm(), 1e-6 * direct.norm());
}

// The first backward-Euler step of a 12 cm cantilever (E 100 kPa, held at x = 0) from rest under
// gravity, solved with the real-time budget (10 iterations, the shipped cap): Jacobi leaves most
// of the step's velocity change (the sag, the slowest mode) unsolved, the two-level solver gets it
// within a few percent, as its coarse space carries the slow modes. Both converge to the same
// solution given the iterations.
TEST(TwoLevelPcg, TenIterationsResolveTheCantileversSlowMode) {
  BodySettings settings;
  settings.material.young_modulus_pa = 1e5;
  settings.gravity_m_per_s2 = Eigen::Vector3d(0.0, 0.0, -9.81);
  const TetMesh mesh = make_box_mesh(24, 4, 4, 0.005);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.rest_positions_m[static_cast<size_t>(v)].x() < 1e-9) settings.fixed_vertices.push_back(v);
  }
  DeformableBody body(mesh, settings);
  const double h = 0.01;
  Eigen::VectorXd force(body.dof_count());
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(body.dof_count());
  body.evaluate(zero, force, /*update_tangent=*/true);
  const Eigen::VectorXd diagonal = body.mass_kg();
  const Eigen::VectorXd b = h * body.external_force_n();
  const ShiftedSystem system{&body.tangent(), h * h, &diagonal, nullptr, body.block_positions(zero)};
  Eigen::VectorXd exact = zero;
  CholmodSolver().solve(system, b, exact);
  const auto error_after = [&](LinearSolver& solver) {
    Eigen::VectorXd x = zero;
    solver.solve(system, b, x);
    return (x - exact).norm() / exact.norm();
  };
  const PcgSolver::Settings real_time{1e-3, 10, MatrixPrecision::double_precision};
  PcgSolver jacobi(real_time);
  TwoLevelPcgSolver two_level(real_time);
  const double jacobi_error = error_after(jacobi);
  const double two_level_error = error_after(two_level);
  std::printf("cantilever step, 10 iterations: relative error of dv %.3g (Jacobi), %.3g (two-level)\n", jacobi_error,
              two_level_error);
  EXPECT_GT(jacobi_error, 0.3);
  EXPECT_LT(two_level_error, 0.05);
  const PcgSolver::Settings strict{1e-9, 5000, MatrixPrecision::double_precision};
  TwoLevelPcgSolver converged(strict);
  EXPECT_LT(error_after(converged), 1e-6);
}

// A Newton correction's setup (setup_nearby) keeps the step's coarse level and takes the new
// matrix: it still converges to the new matrix's solution.
TEST(TwoLevelPcg, ANearbySetupKeepsTheCoarseLevelAndSolvesTheNewMatrix) {
  const test::TestSystem system = test::make_grid_system(7, 4, 4, 23);
  const std::vector<Eigen::Vector3d> points = grid_points(7, 4, 4);
  std::mt19937 rng(8);
  TwoLevelPcgSolver solver({1e-10, 500});
  ShiftedSystem first = system.shifted(1.0);
  first.block_positions = &points;
  solver.setup(first);
  const int coarse = solver.coarse_size();
  ShiftedSystem moved = system.shifted(1.2);
  moved.block_positions = &points;
  solver.setup_nearby(moved);
  EXPECT_EQ(solver.coarse_size(), coarse);
  const Eigen::VectorXd b = test::random_vector(moved.rows(), rng);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(moved.rows());
  const SolveReport report = solver.solve(b, x);
  EXPECT_TRUE(report.converged);
  EXPECT_LE((b - system.dense(1.2) * x).norm() / b.norm(), 2e-10);
}

TEST(TwoLevelPcg, TwoThreadsGiveBitwiseOneThreadsIterates) {
  const test::TestSystem system = test::make_grid_system(12, 6, 5, 31, 0.05, {}, /*with_dense=*/false);
  const std::vector<Eigen::Vector3d> points = grid_points(12, 6, 5);
  ShiftedSystem shifted = system.shifted(1.0);
  shifted.block_positions = &points;
  std::mt19937 rng(4);
  const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
  const auto solve = [&](WorkTeam* team) {
    TwoLevelPcgSolver solver({1e-3, 10});
    solver.lend_work_team(team);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(shifted.rows());
    solver.solve(shifted, b, x);
    solver.lend_work_team(nullptr);
    return x;
  };
  WorkTeam team(2);
  const Eigen::VectorXd alone = solve(nullptr);
  const Eigen::VectorXd together = solve(&team);
  EXPECT_TRUE(alone == together);
}

TEST(TwoLevelPcg, RefusesTooFewPointsAndAnIndefiniteDiagonal) {
  test::TestSystem system = test::make_grid_system(4, 3, 3, 2);
  const std::vector<Eigen::Vector3d> points(5, Eigen::Vector3d::Zero());
  TwoLevelPcgSolver solver({1e-6, 100});
  ShiftedSystem shifted = system.shifted(1.0);
  shifted.block_positions = &points;
  EXPECT_THROW(solver.setup(shifted), SolverError);
  EXPECT_FALSE(solver.is_set_up());
  system.diagonal[4] = -1e6;
  EXPECT_THROW(solver.setup(system.shifted(1.0)), SolverError);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(system.diagonal.size());
  EXPECT_THROW(solver.solve(system.diagonal, x), SolverError);
}

}  // namespace
}  // namespace tissue
