// Tests of BlockCholesky, the two-level preconditioner's coarse factorization: on a random sparse
// symmetric positive definite matrix of 6 x 6 blocks, some standing for fewer columns, its solve is
// the dense Cholesky solve's to rounding; the factor is made again from new values on the same
// pattern; a matrix that is not positive definite is refused.
#include "core/solve/block_cholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <random>
#include <utility>
#include <vector>

namespace tissue {
namespace {

// A chain-and-shortcut pattern of n blocks (each block row: itself, the next, and one farther),
// block sizes cycling through 6, 3, 5, 6, 4 (the two-level's translations and 0-3 rotations).
struct BlockProblem {
  std::vector<int> row_begin{0}, row_column, column_begin{0};
  std::vector<BlockCholesky::BlockValues> blocks;
  Eigen::MatrixXd dense;
};

BlockProblem make_problem(int n, std::mt19937& rng) {
  BlockProblem p;
  const int sizes[] = {6, 3, 5, 6, 4};
  for (int a = 0; a < n; ++a) p.column_begin.push_back(p.column_begin.back() + sizes[a % 5]);
  std::vector<std::vector<int>> columns(static_cast<size_t>(n));
  for (int a = 0; a < n; ++a) {
    columns[static_cast<size_t>(a)].push_back(a);
    if (a + 1 < n) columns[static_cast<size_t>(a)].push_back(a + 1);
    const int far = (a * 7 + 3) % n;
    if (far > a + 1) columns[static_cast<size_t>(a)].push_back(far);
    if (a > 0) columns[static_cast<size_t>(a)].push_back(a - 1);  // below the diagonal: ignored
  }
  const int size = p.column_begin.back();
  // B B^T + I restricted to the pattern would not be definite; instead a diagonally dominant
  // matrix with random off-diagonal blocks on the pattern.
  p.dense = Eigen::MatrixXd::Zero(size, size);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  for (int a = 0; a < n; ++a) {
    for (const int b : columns[static_cast<size_t>(a)]) {
      if (b <= a) continue;
      const int rows = sizes[a % 5];
      const int cols = sizes[b % 5];
      for (int i = 0; i < rows; ++i) {
        for (int j = 0; j < cols; ++j) {
          const double v = value(rng);
          p.dense(p.column_begin[static_cast<size_t>(a)] + i, p.column_begin[static_cast<size_t>(b)] + j) = v;
          p.dense(p.column_begin[static_cast<size_t>(b)] + j, p.column_begin[static_cast<size_t>(a)] + i) = v;
        }
      }
    }
  }
  for (int i = 0; i < size; ++i) p.dense(i, i) = p.dense.row(i).cwiseAbs().sum() + 1.0 + value(rng) * 0.5;
  for (int a = 0; a < n; ++a) {
    for (const int b : columns[static_cast<size_t>(a)]) {
      p.row_column.push_back(b);
      BlockCholesky::BlockValues block;
      block.fill(b < a ? 0.0 : 12345.0);  // entries beyond a block's columns must not be read
      if (b >= a) {
        for (int i = 0; i < sizes[a % 5]; ++i) {
          for (int j = 0; j < sizes[b % 5]; ++j) {
            block[static_cast<size_t>(i + 6 * j)] =
                p.dense(p.column_begin[static_cast<size_t>(a)] + i, p.column_begin[static_cast<size_t>(b)] + j);
          }
        }
      }
      p.blocks.push_back(block);
    }
    p.row_begin.push_back(static_cast<int>(p.row_column.size()));
  }
  return p;
}

TEST(BlockCholesky, SolvesAsTheDenseCholeskyOnTheSamePatternAgain) {
  std::mt19937 rng(5);
  BlockProblem p = make_problem(40, rng);
  BlockCholesky factor;
  factor.analyze(p.row_begin, p.row_column, p.column_begin);
  for (int round = 0; round < 2; ++round) {
    ASSERT_TRUE(factor.factorize(p.blocks));
    const Eigen::VectorXd b = Eigen::VectorXd::Random(p.dense.rows());
    Eigen::VectorXd x;
    factor.solve(b, x);
    const Eigen::VectorXd expected = p.dense.llt().solve(b);
    EXPECT_LE((x - expected).norm(), 1e-12 * expected.norm()) << "round " << round;
    EXPECT_LE((p.dense * x - b).norm(), 1e-12 * b.norm()) << "round " << round;
    // New values on the same pattern: every stored entry doubled, the solution halves.
    for (auto& block : p.blocks) {
      for (double& v : block) v *= 2.0;
    }
    p.dense *= 2.0;
  }
  EXPECT_GE(factor.factor_blocks(), 40);
}

TEST(BlockCholesky, RefusesAMatrixThatIsNotPositiveDefinite) {
  std::mt19937 rng(9);
  BlockProblem p = make_problem(12, rng);
  BlockCholesky factor;
  factor.analyze(p.row_begin, p.row_column, p.column_begin);
  ASSERT_TRUE(factor.factorize(p.blocks));
  p.blocks[static_cast<size_t>(p.row_begin[5])][0] = -1.0;  // block (5, 5)'s first diagonal entry
  EXPECT_FALSE(factor.factorize(p.blocks));
}

TEST(BlockCholesky, AnEmptyMatrixAndASingleBlockOfOneColumn) {
  BlockCholesky empty;
  empty.analyze({0}, {}, {0});  // no aggregate (every row fixed or alone)
  ASSERT_TRUE(empty.factorize({}));
  Eigen::VectorXd x;
  empty.solve(Eigen::VectorXd(0), x);
  EXPECT_EQ(x.size(), 0);

  BlockCholesky single;
  single.analyze({0, 1}, {0}, {0, 1});
  BlockCholesky::BlockValues block;
  block.fill(7.0);  // past its one column: not read
  block[0] = 4.0;
  ASSERT_TRUE(single.factorize({block}));
  single.solve(Eigen::VectorXd::Constant(1, 2.0), x);
  ASSERT_EQ(x.size(), 1);
  EXPECT_DOUBLE_EQ(x[0], 0.5);
}

}  // namespace
}  // namespace tissue
