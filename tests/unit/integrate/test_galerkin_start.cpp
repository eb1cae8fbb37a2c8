// The warm start's projection onto earlier solutions (core/integrate/galerkin_start.hpp), against
// the dense solution of a random SPD system of the solver tests' kind.
#include "core/integrate/galerkin_start.hpp"

#include "../solve/test_systems.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace tissue {
namespace {

double energy_norm(const Eigen::MatrixXd& a, const Eigen::VectorXd& v) { return std::sqrt(v.dot(a * v)); }

TEST(GalerkinStart, IsTheNearestPointOfTheSpanInTheEnergyNorm) {
  // Columns near the solution (it plus noise of 1-30%, as the last steps' velocity changes are near
  // this one's): x0 leaves a residual orthogonal to every column (the Galerkin condition, to
  // rounding) and is nearer the solution in the A-norm than zero and than any column.
  const test::TestSystem system = test::make_grid_system(4, 4, 4, 31);
  const Eigen::MatrixXd a = system.dense(0.3);
  std::mt19937 rng(7);
  const Eigen::VectorXd b = test::random_vector(a.rows(), rng);
  const Eigen::VectorXd solution = a.llt().solve(b);
  Eigen::MatrixXd columns(a.rows(), 4);
  const double noise[] = {0.01, 0.05, 0.1, 0.3};
  for (int k = 0; k < 4; ++k) {
    columns.col(k) = solution + noise[k] * solution.norm() * test::random_vector(a.rows(), rng).normalized();
  }
  Eigen::VectorXd x0;
  GalerkinStartWork work;
  galerkin_start(system.shifted(0.3), b, columns, x0, work);
  const Eigen::VectorXd residual = b - a * x0;
  EXPECT_LE((columns.transpose() * residual).norm(), 1e-12 * (columns.transpose() * b).norm());
  const double error = energy_norm(a, x0 - solution);
  EXPECT_LT(error, energy_norm(a, solution));
  for (int k = 0; k < 4; ++k) EXPECT_LT(error, energy_norm(a, columns.col(k) - solution)) << "column " << k;
}

TEST(GalerkinStart, EqualColumnsGiveTheOneColumnsProjection) {
  // A free fall's velocity changes are equal: X^T A X is singular, and the start is that of one
  // column (finite, not NaN from a singular solve).
  const test::TestSystem system = test::make_grid_system(3, 3, 3, 32);
  std::mt19937 rng(8);
  const Eigen::VectorXd b = test::random_vector(system.shifted(1.0).rows(), rng);
  const Eigen::VectorXd column = test::random_vector(b.size(), rng);
  Eigen::MatrixXd repeated(b.size(), 3);
  repeated << column, column, 2.0 * column;
  Eigen::VectorXd from_one, from_repeated;
  GalerkinStartWork work;
  galerkin_start(system.shifted(1.0), b, column, from_one, work);
  galerkin_start(system.shifted(1.0), b, repeated, from_repeated, work);
  ASSERT_TRUE(from_repeated.allFinite());
  EXPECT_LE((from_repeated - from_one).norm(), 1e-10 * from_one.norm());
  const Eigen::MatrixXd a = system.dense(1.0);
  EXPECT_NEAR(from_one.dot(a * from_one), column.dot(b) * column.dot(b) / column.dot(a * column),
              1e-10 * std::abs(from_one.dot(a * from_one)));
}

TEST(GalerkinStart, NothingUsableGivesZero) {
  const test::TestSystem system = test::make_grid_system(3, 3, 3, 33);
  std::mt19937 rng(9);
  const Eigen::VectorXd b = test::random_vector(system.shifted(1.0).rows(), rng);
  GalerkinStartWork work;
  Eigen::VectorXd x0 = Eigen::VectorXd::Ones(b.size());
  galerkin_start(system.shifted(1.0), b, Eigen::MatrixXd(b.size(), 0), x0, work);
  EXPECT_EQ(x0, Eigen::VectorXd::Zero(b.size()));
  Eigen::MatrixXd poisoned = Eigen::MatrixXd::Random(b.size(), 2);
  poisoned(5, 1) = std::numeric_limits<double>::quiet_NaN();
  galerkin_start(system.shifted(1.0), b, poisoned, x0, work);
  EXPECT_EQ(x0, Eigen::VectorXd::Zero(b.size()));
  galerkin_start(system.shifted(1.0), b, Eigen::MatrixXd::Zero(b.size(), 2), x0, work);
  EXPECT_EQ(x0, Eigen::VectorXd::Zero(b.size()));
  galerkin_start(system.shifted(1.0), b, Eigen::MatrixXd::Random(b.size(), GALERKIN_MAX_COLUMNS + 1), x0, work);
  EXPECT_EQ(x0, Eigen::VectorXd::Zero(b.size()));
}

TEST(GalerkinStart, TakesTheSolversProductsWhenSetUpForTheSystem) {
  // With the solver that was set up for the system, its compact copy's products: the same start to
  // rounding with double entries, to the entries' rounding with single ones (a different product,
  // so it was used); a solver set up for another system is not asked.
  const test::TestSystem system = test::make_grid_system(4, 4, 3, 34);
  const ShiftedSystem shifted = system.shifted(0.6);
  std::mt19937 rng(10);
  const Eigen::VectorXd b = test::random_vector(shifted.rows(), rng);
  Eigen::MatrixXd columns(b.size(), 3);
  for (Eigen::Index k = 0; k < columns.cols(); ++k) columns.col(k) = test::random_vector(b.size(), rng);
  GalerkinStartWork work;
  Eigen::VectorXd expected, x0;
  galerkin_start(shifted, b, columns, expected, work);
  PcgSolver strict({1e-8, 100});  // double entries
  strict.setup(shifted);
  galerkin_start(shifted, b, columns, x0, work, &strict);
  EXPECT_LE((x0 - expected).norm(), 1e-12 * expected.norm());
  PcgSolver real_time({1e-3, 10});  // single entries
  real_time.setup(shifted);
  galerkin_start(shifted, b, columns, x0, work, &real_time);
  const double difference = (x0 - expected).norm() / expected.norm();
  EXPECT_GT(difference, 0.0);
  EXPECT_LE(difference, 1e-5);
  real_time.setup(system.shifted(0.7));
  galerkin_start(shifted, b, columns, x0, work, &real_time);
  EXPECT_EQ(x0, expected);
}

}  // namespace
}  // namespace tissue
