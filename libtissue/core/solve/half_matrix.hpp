// HalfMatrix: the system matrix A = s K + diag(d) of a CG solve, stored for its products only: the
// diagonal and upper blocks of s K (K is symmetric), in single precision by default, beside d in
// double. Made at each solver setup from K's full double blocks (BlockSparseMatrix), it is what the
// ten products of a real-time step stream: on the 52k-tet organ the full double matrix is 10.2 MB per
// product, the half single one 3.0 MB (docs/BENCHMARKS.md, issue 23). Sums are taken in double;
// single precision rounds the entries of s K to 6e-8 relative, far below the solve's tolerance
// (the accuracy figure is in BENCHMARKS).
//
// Two threads: the rows are in the parts of VectorParts (balanced_row_split). A row's upper block
// (r, c) also gives the transposed term to row c; part 0 sends the terms for part 1's rows to a spill
// vector that part 1 adds after both are done (finish_part). Every entry receives its terms in the
// same order whether the parts run side by side or one after the other: bitwise the same results.
#pragma once

#include "core/system/block_sparse_matrix.hpp"
#include "core/system/work_team.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace tissue {

struct ShiftedSystem;

/// The precision of the matrix entries a CG product streams (its sums are always double).
/// `automatic`: single when the solve's relative tolerance is at least SINGLE_PRECISION_TOLERANCE
/// (entries rounded to 6e-8 relative change the residual 100x less than the tolerance allows),
/// double for tighter solves.
enum class MatrixPrecision { automatic, single, double_precision };
inline constexpr double SINGLE_PRECISION_TOLERANCE = 1e-5;
/// The precision `precision` means for a solve of relative tolerance `tolerance`.
[[nodiscard]] inline MatrixPrecision resolved_precision(MatrixPrecision precision, double tolerance) {
  if (precision != MatrixPrecision::automatic) return precision;
  return tolerance >= SINGLE_PRECISION_TOLERANCE ? MatrixPrecision::single : MatrixPrecision::double_precision;
}

/// Products of several columns, as HalfMatrix::multiply_columns writes them.
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

class HalfMatrix {
 public:
  static constexpr int PARTS = MAX_STEP_THREADS;
  static_assert(PARTS == 2, "one spill: from part 0 to part 1");

  /// `precision`: single or double_precision (automatic is resolved by the solver).
  explicit HalfMatrix(MatrixPrecision precision = MatrixPrecision::double_precision) : m_precision(precision) {}

  /// Copies s K's diagonal and upper blocks and d (the block pattern is re-derived only when K's
  /// pattern or layout changed), each part's rows by one of `team`'s members when given. The system
  /// must be checked (K and d set, sizes agreeing).
  void assign(const ShiftedSystem& system, WorkTeam* team = nullptr);

  [[nodiscard]] int block_rows() const { return static_cast<int>(m_row_begin.size()) - 1; }
  [[nodiscard]] int first_block_row(int part) const { return m_first_block_row[static_cast<size_t>(part)]; }
  [[nodiscard]] int end_block_row(int part) const { return m_first_block_row[static_cast<size_t>(part) + 1]; }

  /// y = A x on the rows of `part`, except the terms part 0 sends to later parts (finish_part adds
  /// them). Parts may run side by side; finish_part(y, p) only after every multiply_part.
  void multiply_part(const Eigen::VectorXd& x, Eigen::VectorXd& y, int part) const;
  /// Adds to the rows of `part` the terms earlier parts sent them.
  void finish_part(Eigen::VectorXd& y, int part) const;
  /// y = A x (y resized if needed): the parts side by side on `team`'s members when given, else all
  /// on this thread; bitwise the same either way.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y, WorkTeam* team = nullptr) const;

  /// Y = A X (Y resized to X's shape; row-major, as the kernel writes it) for X's columns together, up
  /// to COLUMN_LANES of them in each pass over the values (one lane each): a product per column costs
  /// that column's bytes of A, these share them (the warm start's eight products, galerkin_start).
  /// Parts as multiply's: bitwise the same on a team of two. Each column equals multiply's to rounding
  /// (the same terms, in another order).
  void multiply_columns(const Eigen::Ref<const Eigen::MatrixXd>& x, RowMajorMatrix& y, WorkTeam* team = nullptr) const;
  static constexpr int COLUMN_LANES = 8;

  /// The rows the system says left the dynamics (ShiftedSystem::rows_left) that no nonzero block of
  /// K joins to another (found by assign, ascending): a part parked out of the field, whose elements
  /// add nothing, leaves rows with only their mass. Each is its own 3 x 3 system.
  [[nodiscard]] const std::vector<int>& isolated_rows() const { return m_isolated_rows; }
  /// x_i = A_ii^-1 b_i for each of isolated_rows(), with A_ii as the products use it.
  void solve_isolated_rows(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;

  [[nodiscard]] MatrixPrecision precision() const { return m_precision; }
  /// Bytes of matrix values and column indices one product streams.
  [[nodiscard]] long streamed_bytes() const;

 private:
  template <class Real>
  void copy_part(const BlockSparseMatrix& k, double scale, std::vector<Real>& to, int part);
  template <class Real>
  [[nodiscard]] Eigen::Matrix3d diagonal_block(const std::vector<Real>& values, int row) const;
  template <class Real>
  void multiply_rows(const Real* values, const double* x, double* y, int part) const;
  template <class Real>
  void multiply_lanes_rows(const Real* values, double* y, int part) const;
  void derive_pattern(const BlockSparseMatrix& k);
  // The spill's rules, for vectors of `row_width` values a block row (3, or multiply_columns' lanes):
  // part 0 clears the rows it sends terms to; part 1 adds them to its own after both are done.
  void clear_spill(double* spill, long row_width, int part) const;
  void add_spill(double* y, const double* spill, long row_width, int part) const;

  MatrixPrecision m_precision;
  // Pattern: per block row its diagonal block first, then its upper blocks by column.
  std::vector<int> m_row_begin;   // block rows + 1
  std::vector<int> m_column;      // per stored block
  std::vector<int> m_full_slot;   // per stored block: the slot of K it copies
  std::vector<int> m_fill_cursor;                   // derive_pattern's: per row, where its next block goes
  std::vector<float> m_single;                      // 9 per stored block, row-major, s K
  std::vector<double> m_double;
  Eigen::VectorXd m_diagonal;  // d
  std::vector<int> m_isolated_rows;
  std::array<int, PARTS + 1> m_first_block_row{};
  int m_spill_end = 0;                   // 1 + the last block row part 0 sends terms to
  mutable Eigen::VectorXd m_spill;       // the terms for rows [end_block_row(0), m_spill_end)
  // multiply_columns': per block row, its three components' COLUMN_LANES lanes (24 values).
  mutable std::vector<double> m_lanes_in, m_lanes_out, m_lanes_spill;  // (out: when Y has fewer columns)
  const BlockSparseMatrix* m_source = nullptr;
  std::uint64_t m_pattern_revision = 0, m_layout_revision = 0;
};

}  // namespace tissue
