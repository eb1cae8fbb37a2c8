// Tests of HalfMatrix, the compact copy of A = s K + diag(d) that CG's products stream (issue 23):
// its product equals the full matrix's (to rounding in double, to the entries' rounding in single),
// two parts side by side give bitwise the product of one thread, and a grown K is followed.
#include "core/solve/half_matrix.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/system/work_team.hpp"

#include "solve/test_systems.hpp"

#include <gtest/gtest.h>

#include <random>

namespace tissue {
namespace {

Eigen::VectorXd full_product(const ShiftedSystem& system, const Eigen::VectorXd& x) {
  Eigen::VectorXd y;
  system.multiply(x, y);
  return y;
}

TEST(HalfMatrix, ProductEqualsTheFullMatrixs) {
  const test::TestSystem system = test::make_grid_system(6, 5, 4, 7);  // 360 unknowns, both parts coupled
  std::mt19937 rng(11);
  for (const double scale : {1.0, 0.37}) {
    const ShiftedSystem shifted = system.shifted(scale);
    const Eigen::VectorXd x = test::random_vector(shifted.rows(), rng);
    const Eigen::VectorXd expected = full_product(shifted, x);

    HalfMatrix in_double(MatrixPrecision::double_precision);
    in_double.assign(shifted);
    Eigen::VectorXd y;
    in_double.multiply(x, y);
    // Double: the same terms summed in another order, so rounding only.
    EXPECT_LE((y - expected).norm(), 1e-14 * expected.norm()) << "scale " << scale;

    HalfMatrix in_single(MatrixPrecision::single);
    in_single.assign(shifted);
    in_single.multiply(x, y);
    // Single: each entry of s K rounded to 2^-24 relative (6e-8); summed over ~40 terms a row,
    // the row's error stays below 1e-6 of the row's |terms|, here of |y|'s order.
    const double error = (y - expected).norm() / expected.norm();
    std::printf("scale %g: single-precision product relative error %.3g\n", scale, error);
    EXPECT_LE(error, 1e-6) << "scale " << scale;
    EXPECT_GT(error, 0.0);  // it did round: the test compares two different things
    EXPECT_LT(in_single.streamed_bytes(), in_double.streamed_bytes());
  }
}

TEST(HalfMatrix, TwoPartsSideBySideGiveBitwiseTheProductOfOneThread) {
  const test::TestSystem system = test::make_grid_system(8, 6, 5, 3);
  const ShiftedSystem shifted = system.shifted(0.8);
  HalfMatrix matrix(MatrixPrecision::single);
  matrix.assign(shifted);
  ASSERT_GT(matrix.first_block_row(1), 0);
  ASSERT_LT(matrix.first_block_row(1), matrix.block_rows());
  std::mt19937 rng(5);
  const Eigen::VectorXd x = test::random_vector(shifted.rows(), rng);
  Eigen::VectorXd alone;
  matrix.multiply(x, alone);

  WorkTeam team(2);
  Eigen::VectorXd together = Eigen::VectorXd::Constant(shifted.rows(), 1e300);  // stale values must not leak
  auto multiply = [&](int part) { matrix.multiply_part(x, together, part); };
  team.run(multiply);
  auto finish = [&](int part) { matrix.finish_part(together, part); };
  team.run(finish);
  EXPECT_EQ(together, alone);
  // And part 0 did send terms across: without finish_part, part 1's rows are short.
  Eigen::VectorXd unfinished;
  unfinished.resize(shifted.rows());
  matrix.multiply_part(x, unfinished, 0);
  matrix.multiply_part(x, unfinished, 1);
  EXPECT_NE(unfinished, alone);
}

TEST(HalfMatrix, ColumnsTogetherAreEachColumnsProduct) {
  // multiply_columns shares each pass over the values among up to eight columns: each column of
  // the result is that column's product to rounding (double: the same terms in another order;
  // single: the same rounded entries), for fewer columns than lanes and for more (two passes), and
  // two parts side by side give bitwise one thread's.
  const test::TestSystem system = test::make_grid_system(8, 6, 5, 3);
  const ShiftedSystem shifted = system.shifted(0.8);
  std::mt19937 rng(17);
  for (const MatrixPrecision precision : {MatrixPrecision::double_precision, MatrixPrecision::single}) {
    HalfMatrix matrix(precision);
    matrix.assign(shifted);
    ASSERT_GT(matrix.first_block_row(1), 0);
    for (const int columns : {1, 3, 8, 11}) {
      Eigen::MatrixXd x(shifted.rows(), columns);
      for (int c = 0; c < columns; ++c) x.col(c) = test::random_vector(shifted.rows(), rng);
      RowMajorMatrix together;
      matrix.multiply_columns(x, together);
      ASSERT_EQ(together.rows(), shifted.rows());
      ASSERT_EQ(together.cols(), columns);
      for (int c = 0; c < columns; ++c) {
        Eigen::VectorXd alone;
        matrix.multiply(x.col(c), alone);
        EXPECT_LE((together.col(c) - alone).norm(), 1e-14 * alone.norm()) << columns << " columns, column " << c;
        EXPECT_LE((together.col(c) - full_product(shifted, x.col(c))).norm(), 1e-6 * alone.norm());
      }
      WorkTeam team(2);
      RowMajorMatrix on_team = RowMajorMatrix::Constant(shifted.rows(), columns, 1e300);
      matrix.multiply_columns(x, on_team, &team);
      EXPECT_EQ(on_team, together) << columns << " columns";
    }
  }
}

TEST(HalfMatrix, FollowsAGrownMatrix) {
  test::TestSystem system = test::make_grid_system(4, 4, 3, 9);
  HalfMatrix matrix(MatrixPrecision::double_precision);
  matrix.assign(system.shifted(1.0));
  // A cut couples the first and the last row (new blocks, symmetric) and appends a row.
  BlockSparseMatrix& k = system.stiffness;
  const int last = k.block_rows() - 1;
  const int appended = k.append_block_row();
  const Eigen::Matrix3d coupling = (Eigen::Matrix3d() << 0.1, 0.2, 0.0, -0.3, 0.05, 0.1, 0.0, 0.2, 0.4).finished();
  k.block(k.insert_block(0, last)) += coupling;
  k.block(k.insert_block(last, 0)) += coupling.transpose();
  k.block(k.insert_block(appended, 1)) += coupling;
  k.block(k.insert_block(1, appended)) += coupling.transpose();
  k.block(k.find_slot(appended, appended)) = 5.0 * Eigen::Matrix3d::Identity();
  // And a block placed after row 0's blocks of larger columns (the row out of order).
  int between = 2;
  while (k.find_slot(0, between) >= 0) ++between;
  ASSERT_LT(between, last);
  k.block(k.insert_block(0, between)) += coupling;
  k.block(k.insert_block(between, 0)) += coupling.transpose();
  Eigen::VectorXd diagonal = Eigen::VectorXd::Constant(k.rows(), 2.0);
  diagonal.head(system.diagonal.size()) = system.diagonal;
  const ShiftedSystem grown{&k, 1.0, &diagonal};
  matrix.assign(grown);
  std::mt19937 rng(1);
  const Eigen::VectorXd x = test::random_vector(grown.rows(), rng);
  Eigen::VectorXd y;
  matrix.multiply(x, y);
  const Eigen::VectorXd expected = full_product(grown, x);
  ASSERT_EQ(y.size(), expected.size());
  EXPECT_LE((y - expected).norm(), 1e-14 * expected.norm());
}

TEST(HalfMatrix, AutomaticPrecisionFollowsTheTolerance) {
  EXPECT_EQ(resolved_precision(MatrixPrecision::automatic, 1e-3), MatrixPrecision::single);
  EXPECT_EQ(resolved_precision(MatrixPrecision::automatic, SINGLE_PRECISION_TOLERANCE), MatrixPrecision::single);
  EXPECT_EQ(resolved_precision(MatrixPrecision::automatic, 1e-6), MatrixPrecision::double_precision);
  EXPECT_EQ(resolved_precision(MatrixPrecision::double_precision, 1e-3), MatrixPrecision::double_precision);
  EXPECT_EQ(resolved_precision(MatrixPrecision::single, 1e-9), MatrixPrecision::single);
}

}  // namespace
}  // namespace tissue
