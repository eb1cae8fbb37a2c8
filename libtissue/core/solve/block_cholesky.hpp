// BlockCholesky: a sparse Cholesky factorization L L^T of a symmetric positive definite matrix made
// of dense 6 x 6 blocks (internal to core/solve): the two-level preconditioner's coarse matrix, one
// block per aggregate, whose translations and rotations are its columns. A block may stand for
// fewer than 6 columns (an aggregate whose points lie on a line keeps two rotations; no points, none):
// its leading ones, the rest padded with the identity, which decouples them.
//
// The blocks are ordered by approximate minimum degree (Amestoy, Davis and Duff, on the graph of the
// blocks), the factor's block pattern found once per pattern (the elimination tree), and each
// factorization and solve works on whole blocks with fixed-size kernels. The organ's coarse matrix
// (159 aggregates, 950 columns) took 4.3 ms to factorize by Eigen's scalar simplicial LDL^T, and its
// two triangular solves, once per CG iteration, a fifth of an iteration (docs/BENCHMARKS.md).
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

namespace tissue {

class BlockCholesky {
 public:
  static constexpr int BLOCK = 6;
  using Block = Eigen::Matrix<double, BLOCK, BLOCK>;
  using BlockValues = std::array<double, BLOCK * BLOCK>;  ///< a block, column-major

  /// The pattern of a symmetric matrix of n x n blocks (n = column_begin.size() - 1): block row a
  /// holds the block columns row_column[row_begin[a] .. row_begin[a + 1]) (any order; those below a
  /// are ignored; the diagonal must be among them). Block a stands for the scalar columns
  /// [column_begin[a], column_begin[a + 1]), at most BLOCK. Orders the blocks and finds the factor's
  /// pattern; the values come with factorize().
  void analyze(const std::vector<int>& row_begin, const std::vector<int>& row_column,
               const std::vector<int>& column_begin);
  /// Factorizes the matrix whose block (a, b), b >= a, is blocks[e] for the pattern's entry e
  /// (row_column[e] == b in block row a): its leading rows and columns, as many as a's and b's
  /// scalar columns (the rest is not read). False if it is not positive definite (then solve()
  /// must not be called until a factorization succeeds). No allocation.
  bool factorize(const std::vector<BlockValues>& blocks);
  /// x = A^-1 b (lengths: the scalar columns). No allocation once x has its size.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);

  [[nodiscard]] int block_count() const { return static_cast<int>(m_order.size()); }
  /// Blocks stored in the factor (its diagonal ones included).
  [[nodiscard]] int factor_blocks() const { return static_cast<int>(m_factor.size()); }

 private:
  // analyze()'s parts: the elimination order (approximate minimum degree on the blocks' graph), the
  // factor's block pattern (the elimination tree) and where each pattern entry goes in the factor.
  void order_blocks(const std::vector<int>& row_begin, const std::vector<int>& row_column,
                    const std::vector<int>& column_begin);
  void find_factor_pattern(const std::vector<int>& row_begin, const std::vector<int>& row_column);
  void map_entries(const std::vector<int>& row_begin, const std::vector<int>& row_column);

  // In elimination order: block column j of L holds the inverse of its diagonal block at
  // m_column_begin[j] and the blocks of rows m_row[s] > j (ascending) after it.
  std::vector<int> m_order;         // elimination position -> block
  std::vector<int> m_position;      // block -> elimination position
  std::vector<int> m_used;          // per elimination position: the block's scalar columns
  std::vector<int> m_first_column;  // per elimination position: the block's first scalar column
  std::vector<int> m_column_begin;  // per elimination position + 1: its slots in m_factor
  std::vector<int> m_row;           // per slot: its row's elimination position
  // Left-looking: per column j, the slots (in earlier columns k) of L's blocks (j, k).
  std::vector<int> m_row_slots_begin;
  std::vector<int> m_row_slots;
  std::vector<int> m_row_slot_column;  // the column k of each
  // Per pattern entry (a, b >= a): its slot and a's and b's elimination positions (-1 below a); the
  // slot holds its transpose when a's position comes first.
  std::vector<int> m_entry_slot;
  std::vector<int> m_entry_row_block, m_entry_column_block;
  std::vector<Block> m_factor;
  std::vector<int> m_slot_of_row;  // factorize()'s scatter of one column: per position, its slot or -1
  Eigen::VectorXd m_work;
};

}  // namespace tissue
