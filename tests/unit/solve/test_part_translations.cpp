// Tests of PartTranslations: the parts of A found through its nonzero blocks, and the Galerkin
// correction over their translations that keeps a free part's momentum balance after an inexact
// solve (CholmodSolver's Newton corrections; the physics: FreeFall.PiecesFreedByCrossingCutsFallAtG).
#include "core/solve/part_translations.hpp"

#include "solve/test_systems.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

namespace tissue {
namespace {

constexpr int NX = 4, NY = 3, NZ = 3;

// The grid system with every spring across x = 1.5 taken out: its blocks zeroed but left in the
// pattern (as a cut leaves them), the diagonal blocks given back their share, so K stays a sum of
// springs and its rows still sum to zero: two parts that nothing holds.
test::TestSystem two_free_halves() {
  test::TestSystem system = test::make_grid_system(NX, NY, NZ, 11);
  BlockSparseMatrix& k = system.stiffness;
  for (int row = 0; row < k.block_rows(); ++row) {
    for (int slot = k.row_begin(row); slot < k.row_begin(row) + k.row_size(row); ++slot) {
      const int column = k.slot_column(slot);
      if ((row % NX < 2) == (column % NX < 2)) continue;
      const Eigen::Matrix3d spring = -k.block(slot);
      k.block(k.diagonal_slot(row)) -= spring;
      system.dense_stiffness.block<3, 3>(3 * row, 3 * row) -= spring;
      k.block(slot).setZero();
      system.dense_stiffness.block<3, 3>(3 * row, 3 * column).setZero();
    }
  }
  return system;
}

TEST(PartTranslations, TheResidualSumsToZeroOverEveryPartAndTheEnergyErrorDoesNotGrow) {
  const test::TestSystem system = two_free_halves();
  const double scale = 3.0;
  const ShiftedSystem a = system.shifted(scale);
  PartTranslations parts;
  parts.setup(a);
  ASSERT_EQ(parts.part_count(), 2);  // the zeroed blocks join nothing
  for (int row = 0; row < system.stiffness.block_rows(); ++row) {
    EXPECT_EQ(parts.part_of_block_row(row), row % NX < 2 ? parts.part_of_block_row(0) : parts.part_of_block_row(2));
  }
  EXPECT_NE(parts.part_of_block_row(0), parts.part_of_block_row(2));

  std::mt19937 rng(3);
  const Eigen::MatrixXd dense = system.dense(scale);
  const Eigen::VectorXd b = test::random_vector(a.rows(), rng);
  const Eigen::VectorXd exact = dense.llt().solve(b);
  // An inexact solve: the exact one with an error of 10% of its size, translations included.
  Eigen::VectorXd x = exact + 0.1 * exact.norm() / std::sqrt(static_cast<double>(a.rows())) *
                                  test::random_vector(a.rows(), rng);
  const auto energy_error = [&](const Eigen::VectorXd& v) { return std::sqrt((v - exact).dot(dense * (v - exact))); };
  const double error_before = energy_error(x);
  parts.correct(b - dense * x, x);
  EXPECT_LE(energy_error(x), error_before);
  // Each part's residual sums to zero, so its momentum balance sum d x = sum b holds (K sums to zero
  // over a free part).
  for (int part = 0; part < 2; ++part) {
    Eigen::Vector3d residual_sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
    Eigen::Vector3d load = Eigen::Vector3d::Zero();
    for (int row = 0; row < system.stiffness.block_rows(); ++row) {
      if (parts.part_of_block_row(row) != parts.part_of_block_row(part == 0 ? 0 : 2)) continue;
      residual_sum += (b - dense * x).segment<3>(3 * row);
      momentum += system.diagonal.segment<3>(3 * row).cwiseProduct(x.segment<3>(3 * row));
      load += b.segment<3>(3 * row);
    }
    EXPECT_LE(residual_sum.norm(), 1e-12 * b.norm());
    EXPECT_LE((momentum - load).norm(), 1e-12 * b.norm());
  }
  // The exact solution stays where it is.
  Eigen::VectorXd solved = exact;
  parts.correct(b - dense * solved, solved);
  EXPECT_LE((solved - exact).norm(), 1e-12 * exact.norm());
}

}  // namespace
}  // namespace tissue
