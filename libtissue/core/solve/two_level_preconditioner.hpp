// A two-level preconditioner for A = s K + diag(d) (internal to core/solve): Jacobi on the fine
// rows plus an exact solve on a coarse space of the rigid motions of small aggregates of block rows,
//   P^-1 r = D^-1 r + Pc (Pc^T A Pc)^-1 Pc^T r     (additive two-level Schwarz),
// so that CG resolves the slow motions (a piece falling, a body swinging or sagging as a whole),
// which Jacobi alone reaches only after hundreds of iterations, in every iteration.
//
// Aggregates (Vanek, Mandel and Brezina 1996, "Algebraic multigrid by smoothed aggregation",
// phases 1 and 2): in row order, a row whose strong neighbours (within AGGREGATE_REACH edges) are all
// unassigned becomes a root and takes them; a row left over joins the aggregate of its strongest
// assigned neighbour (or becomes one of its own). A row with no strong neighbour (an orphaned ghost,
// a part taken out of the dynamics: nothing but its mass) joins none: its coarse columns would only
// repeat Jacobi's solve of it, and the thousands a hatched body leaves grew the coarse level. A coupling is strong when
// ||A_ij||_F > STRENGTH sqrt(||A_ii||_F ||A_jj||_F): the blocks a cut left in the pattern at zero never join the two
// sides of a cut. Made at the first setup and whenever K's pattern or layout changed in a way no local level serves,
// from that setup's values; a cut between refreshes gets a local level meanwhile (the rows it changed aggregated anew
// beside the coarse level made before: two_level_local_level.cpp), and at the next coarse refresh the local level's
// aggregates take the place of those it replaced in the coarse level (the rest kept: only the cut's rows are aggregated
// anew, not the whole matrix).
//
// Coarse space: per aggregate, the translations and the rotations about its centroid of the rows'
// points (ShiftedSystem::block_positions at each setup; translations only without them),
// orthonormal over the aggregate (rotations along the principal axes of its points, those about
// which the points do not all lie: a two-row aggregate keeps two), so at most 6 columns per
// aggregate. The coarse matrix Pc^T A Pc is assembled and factorized (BlockCholesky, on its 6 x 6
// blocks of aggregate pairs) after aggregating and every COARSE_REFRESH_SETUPS setups.
#pragma once

#include "core/solve/block_cholesky.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/solve/rigid_aggregates.hpp"
#include "core/system/work_team.hpp"

#include <Eigen/Core>
#include <Eigen/Cholesky>

#include <array>
#include <cstdint>
#include <vector>

namespace tissue {

class TwoLevelPreconditioner {
 public:
  /// A coupling weaker than this (relative, Frobenius norms) does not join two rows in an aggregate.
  static constexpr double STRENGTH = 0.08;
  /// Aggregates take the rows within this many strong edges of their root (~40-60 rows on a tet
  /// mesh). The coarse solve (a scalar sparse triangular pair) costs ~10x a fine mat-vec's time per
  /// entry, and its factor fills faster than it grows: one edge gave the 2.4k-tet frog 408 columns
  /// whose solve took 16% of a step (two: 132 columns, 1950 factor entries, 30% off a cut-heavy
  /// session), the 52k-tet organ 3828 columns and a 4.7M-entry factor (two: 950, 87k); three
  /// saves no more on the organ and needs 1.6x the iterations on the frog.
  static constexpr int AGGREGATE_REACH = 2;
  /// The coarse level (its points and matrix, assembled and factorized) is made anew every this many
  /// setups, and at once after aggregating; in between the last one serves (Pc and Pc^T A Pc of
  /// the same earlier setup: still a positive definite P). Translations do not depend on the points,
  /// and A changes little in a few steps.
  static constexpr int COARSE_REFRESH_SETUPS = 4;

  /// Takes the Jacobi diagonal `inverse_diagonal` (1 / diag A, the caller's, kept until the next
  /// setup) and, when due, makes the coarse level of `system` (aggregating anew when K's pattern,
  /// layout or size changed). Never throws for a positive definite A; if the coarse factorization
  /// fails all the same (rounding), the preconditioner is Jacobi alone until the next coarse level.
  /// With `team`, its members share the coarse matrix's assembly (halves of the aggregates): bitwise
  /// the same with a team or without.
  void setup(const ShiftedSystem& system, const Eigen::VectorXd& inverse_diagonal, WorkTeam* team = nullptr);
  /// For an A near the last setup's (a Newton correction's): when it is of the same K object,
  /// pattern, layout and size, takes the new Jacobi diagonal and keeps the coarse level (its space
  /// and factor are the last setup's; still a positive definite P); else setup().
  void setup_nearby(const ShiftedSystem& system, const Eigen::VectorXd& inverse_diagonal, WorkTeam* team = nullptr);
  /// z = P^-1 r (lengths rows() of the last setup). No allocation. With `team`, its members share
  /// the Jacobi rows and the coarse level's restriction and prolongation (halves of the aggregates);
  /// the coarse solve and the local level run on the caller. Bitwise the same with a team or without.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z, WorkTeam* team = nullptr);
  /// Aggregate anew at the next setup (a saved or restored run continues bitwise).
  void forget() {
    m_pattern_revision = UINT64_MAX;
    m_setups_since_coarse = 0;
    m_can_patch = false;
    m_local.ok = false;
  }

  [[nodiscard]] int aggregate_count() const { return m_coarse.count(); }
  /// Columns of the coarse space (0 after a failed coarse factorization).
  [[nodiscard]] int coarse_size() const { return m_coarse_ok ? m_coarse.columns() : 0; }
  /// Aggregate of each block row of the last setup's A, or -1 for a row with no strong neighbour.
  [[nodiscard]] const std::vector<int>& aggregate_of_row() const { return m_aggregate_of_row; }

 private:
  /// Whether the aggregates are of `system`'s K: the same object, pattern, layout and size, and
  /// points given as when they were made.
  [[nodiscard]] bool aggregates_fit(const ShiftedSystem& system) const;
  /// Aggregates every row of `system` anew.
  void aggregate(const ShiftedSystem& system);
  /// Aggregates made of the local level's (of `system`'s K as it is) and the earlier ones it did not
  /// replace: the rows of the aggregates a cut touched get the local level's aggregates.
  void merge_local_level(const ShiftedSystem& system);
  /// The coarse space and pattern of m_aggregate_of_row (`count` aggregates) over `system`'s K.
  void adopt_aggregates(const ShiftedSystem& system, int count);
  /// Between coarse refreshes, a cut's rows get a local level when patchable().
  [[nodiscard]] bool patchable(const ShiftedSystem& system) const;
  /// Whether the local level is of `system`'s K as it is (no cut since it was made).
  [[nodiscard]] bool patch_fits(const ShiftedSystem& system) const;
  /// The local level's rows (those added or changed in block count since the aggregation, and the
  /// rest of their aggregates) and their aggregates, not its matrix; false when the rows are none or
  /// too many for it.
  bool aggregate_changed_rows(const ShiftedSystem& system);
  /// The local level's matrix over its rows, assembled and factorized into m_local, which then fits
  /// `system`; whether it serves (positive definite).
  bool factorize_local(const ShiftedSystem& system);
  void make_coarse_pattern(const BlockSparseMatrix& k);
  /// An aggregated row's point minus its aggregate's centroid.
  [[nodiscard]] const Eigen::Vector3d& offset_of_row(int row) const {
    return m_coarse.offset[static_cast<size_t>(m_entry_of_row[static_cast<size_t>(row)])];
  }
  void assemble_and_factorize(const ShiftedSystem& system, WorkTeam* team);
  struct AssemblyScratch;
  /// The coarse blocks of aggregates [first, end): each row's terms, the rows in order.
  void assemble_coarse_rows(const ShiftedSystem& system, int first_aggregate, int end_aggregate,
                            AssemblyScratch& scratch);
  // The aggregates of the whole matrix and their columns; per block row its aggregate and its
  // entry in m_coarse.rows (-1: none).
  RigidAggregates m_coarse;
  std::vector<int> m_aggregate_of_row;
  std::vector<int> m_entry_of_row;
  std::vector<int> m_aggregated_row_size;  // each row's block count when aggregated
  // Coarse matrix: dense blocks of (aggregate, aggregate) pairs, CSR by aggregate; each fine slot's
  // coarse block.
  std::vector<int> m_coarse_row_begin;
  std::vector<int> m_coarse_column;
  std::vector<int> m_coarse_block_of_slot;  // per fine slot (-1: unused slot)
  std::vector<BlockCholesky::BlockValues> m_coarse_blocks;  // 6x6 column-major, used up to the columns
  // assemble_coarse_rows's scratch for one row i: per coarse block (a, b) of its aggregate's row,
  // sum_j A_ij and sum_j A_ij C_j over the rows j of b; the blocks it touched.
  struct RowSums {
    Eigen::Matrix3d force;
    Eigen::Matrix3d moment;
    bool used = false;
  };
  // ... and over the rows i of a, per coarse block: those two sums, and each with C_i^T in front.
  struct AggregateSums {
    Eigen::Matrix3d force, moment, turned_force, turned_moment;
  };
  struct AssemblyScratch {
    std::vector<RowSums> row_sums;
    std::vector<AggregateSums> aggregate_sums;
    std::vector<int> touched;
  };
  std::array<AssemblyScratch, MAX_STEP_THREADS> m_assembly_scratch;  // one per part
  // The parts of apply() and of the coarse assembly: aggregates in halves balanced by rows.
  std::array<int, MAX_STEP_THREADS + 1> m_aggregate_split{};
  BlockCholesky m_coarse_factor;  // of the blocks, its pattern fixed per aggregation
  bool m_coarse_ok = false;
  Eigen::VectorXd m_coarse_rhs, m_coarse_solution;
  const Eigen::VectorXd* m_inverse_diagonal = nullptr;
  const BlockSparseMatrix* m_matrix = nullptr;  // the K aggregated
  std::uint64_t m_pattern_revision = UINT64_MAX;
  std::uint64_t m_layout_revision = UINT64_MAX;
  int m_rows = -1;
  int m_setups_since_coarse = 0;
  bool m_with_rotations = false;
  // The rows a cut made or changed since the aggregation, between coarse refreshes: the rigid
  // motions of small aggregates of them, with their own (dense) coarse matrix from the setup that
  // made them, added to the coarse level made before (additive, so P stays positive definite).
  struct LocalLevel {
    std::vector<int> rows;          // its block rows, ascending
    std::vector<int> local_of;      // per block row of K: its index in rows, or -1
    std::vector<int> aggregate_of;  // per index in rows: its aggregate, or -1 (no strong neighbour)
    std::vector<int> entry_of;      // per index in rows: its entry in aggregates.rows, or -1
    RigidAggregates aggregates;
    Eigen::LDLT<Eigen::MatrixXd> factor;
    Eigen::VectorXd rhs, solution;
    bool ok = false;
    std::uint64_t pattern_revision = UINT64_MAX;
    std::uint64_t layout_revision = UINT64_MAX;
    int rows_of_k = -1;
  };
  LocalLevel m_local;
  bool m_can_patch = false;  // a coarse level of a full aggregation serves (not after forget())
};

}  // namespace tissue
