// Aggregates of block rows and the rigid motions of their points, the columns of a two-level coarse
// space (internal to core/solve): TwoLevelPreconditioner's coarse level over the whole matrix and its
// local level over the rows a cut changed are both made of them. Per aggregate a, row i of it:
//   P_i = [t_a I, -[r_i]x W_a],   t_a = 1 / sqrt(rows of a),  r_i = x_i - centroid_a,
// W_a's columns the principal axes of the points' second moment over sqrt(moment), those about
// which the points do not all lie (a two-row aggregate keeps two), so at most 6 columns per aggregate
// (translations only without points).
#pragma once

#include "core/solve/linear_solver.hpp"

#include <Eigen/Core>

#include <vector>

namespace tissue {

/// The strong couplings among `rows` (CSR over their indices: `local_of` maps a block row to its
/// index in `rows`, or -1): ||A_ij||_F > strength sqrt(||A_ii||_F ||A_jj||_F), weight ||A_ij||_F^2.
struct StrongGraph {
  std::vector<int> begin;
  std::vector<int> column;
  std::vector<double> weight;
  StrongGraph(const ShiftedSystem& system, const std::vector<int>& rows, const std::vector<int>& local_of,
              double strength);
};

/// A = s K + diag(d)'s block in `slot` (row, column). [the system's units]
[[nodiscard]] Eigen::Matrix3d system_block(const ShiftedSystem& system, int slot, int row, int column);

/// Phases 1 and 2 of smoothed aggregation (Vanek, Mandel and Brezina 1996) over `graph`'s rows:
/// in row order, a row whose rows within `reach` strong edges are all free becomes a root and takes
/// them; a row left over joins the phase-1 aggregate of its strongest strong neighbour (else of any
/// neighbour's, else its own). A row with no strong neighbour joins none (-1). Returns the count.
int aggregate_rows(int reach, const StrongGraph& graph, std::vector<int>& aggregate_of_row);

struct RigidAggregates {
  /// Rotations about an axis whose moment of the aggregate's points is below this share of the
  /// largest are left out (the points lie (nearly) on a line through the centroid along it).
  static constexpr double ROTATION_RANK_TOLERANCE = 1e-6;

  std::vector<int> rows;                // block rows, grouped by aggregate (in row order within one)
  std::vector<int> aggregate_begin;     // into rows, aggregates + 1
  std::vector<int> column_begin;        // aggregates + 1: 3 translations, then the rotations
  std::vector<Eigen::Vector3d> offset;  // per entry of rows: its point minus its aggregate's centroid
  std::vector<double> translation_scale;
  std::vector<Eigen::Matrix3d> axes;  // W_a, as many columns as rotation_count
  std::vector<int> rotation_count;

  [[nodiscard]] int count() const { return static_cast<int>(aggregate_begin.size()) - 1; }
  [[nodiscard]] int columns() const { return column_begin.empty() ? 0 : column_begin.back(); }

  /// rows[] grouped from `row_of`[l] by `aggregate_of`[l] (-1: left out), `count` aggregates; the
  /// entry of each l in rows into `entry_of` (-1: left out).
  void group(const std::vector<int>& row_of, const std::vector<int>& aggregate_of, int count, std::vector<int>& entry_of);
  /// The translation scales and, with `points` (per block row), the offsets and rotation axes; with
  /// `count_rotations` the rotations are counted anew and column_begin made, else the counts (and the
  /// coarse pattern made of them) are kept and the largest rotations taken.
  void make_basis(const std::vector<Eigen::Vector3d>* points, bool count_rotations);
  /// P_p (3 x 6, its first 3 + rotation_count columns used) of entry p of aggregate a.
  [[nodiscard]] Eigen::Matrix<double, 3, 6> basis(int a, int p) const;
  /// rhs = P^T r (length columns()); the range form sets the entries of aggregates [first, end) only.
  void restrict_to(const Eigen::VectorXd& r, Eigen::VectorXd& rhs) const { restrict_to(r, rhs, 0, count()); }
  void restrict_to(const Eigen::VectorXd& r, Eigen::VectorXd& rhs, int first, int end) const;
  /// z += P x; the range form adds to the rows of aggregates [first, end) only.
  void prolong_add(const Eigen::VectorXd& x, Eigen::VectorXd& z) const { prolong_add(x, z, 0, count()); }
  void prolong_add(const Eigen::VectorXd& x, Eigen::VectorXd& z, int first, int end) const;
  /// The first aggregate of `part` of `parts`, the aggregates split in order so that each part holds
  /// about as many rows (parts itself: count()).
  [[nodiscard]] int split(int part, int parts) const;
};

}  // namespace tissue
