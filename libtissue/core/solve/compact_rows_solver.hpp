// CompactRowsSolver: hands another LinearSolver the system without the block rows nothing couples
// (issue 41, item 3: "the matrix compacted"). A cut body leaves rows that no element uses: the
// ghosts a later cut replaced (orphans) and the rows of parts parked out of the field. Each keeps its
// mass and only its diagonal block, so its equation is a 3 x 3 system of its own, solved exactly
// here; but every vector of an iterative solve still ran over it. After the extremes suite's 30 + 30
// careless strokes 6716 of the frog's 11 319 block rows were such rows (docs/BENCHMARKS.md).
//
// The rows kept are those of the system as it was when the solver last compacted, plus every row
// appended since (XFEM rows grow at the end). It compacts again, at a setup, when a quarter of the
// rows it keeps have only their diagonal block (or a row it left out gained a block, or another row
// one with it: only rows no block reaches go): rows that fall
// out one cut at a time keep their numbers until then, so that what the inner solver made of the
// rows (the two-level preconditioner's aggregates, CHOLMOD's analysis) serves from cut to cut as on
// the full matrix. The compacted matrix is a view of K's kept rows in K's own slots
// (BlockSparseMatrix::view_rows_of): nothing copied at a setup but d's kept rows. While it leaves no
// row out the inner solver gets the system itself, untouched.
//
// The inner solver's tolerance is met on the rows it solves, relative to their part of b: at least
// as strict as on the whole system (the rows left out are solved exactly). The relative residual
// reported is that of the whole system.
#pragma once

#include "core/solve/linear_solver.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

namespace tissue {

class CompactRowsSolver final : public LinearSolver {
 public:
  /// Compacts when this share of the rows kept has only its diagonal block.
  static constexpr int DECOUPLED_SHARE_DIVISOR = 4;
  /// ... and at least this many rows would go (a few rows cost nothing).
  static constexpr int MIN_DECOUPLED_ROWS = 32;

  explicit CompactRowsSolver(std::unique_ptr<LinearSolver> inner);

  void setup(const ShiftedSystem& system) override;
  void setup_nearby(const ShiftedSystem& system) override;
  SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  using LinearSolver::solve;
  SolveReport solve_roughly(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  SolveReport refine(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] bool solves_roughly() const override { return m_inner->solves_roughly(); }
  [[nodiscard]] bool is_set_up() const override { return m_system.stiffness != nullptr && m_inner->is_set_up(); }
  bool multiply_set_up(const ShiftedSystem& system, const Eigen::Ref<const Eigen::MatrixXd>& x,
                       RowMajorMatrix& y) const override;
  void lend_work_team(WorkTeam* team) override { m_inner->lend_work_team(team); }
  void forget_earlier_setups() override;
  [[nodiscard]] bool follows_block_frames() const override { return m_inner->follows_block_frames(); }
  [[nodiscard]] bool uses_block_positions() const override { return m_inner->uses_block_positions(); }
  [[nodiscard]] std::string_view name() const override { return m_inner->name(); }

  /// The block rows the inner solver got at the last setup (all of them while none is left out).
  [[nodiscard]] int kept_block_rows() const;

 private:
  enum class Pass { full, rough, refine };
  // The kept rows for `system`'s K, compacting anew when due; true when the inner solver gets a
  // compacted system.
  bool keep_rows(const ShiftedSystem& system);
  void compact_all(const BlockSparseMatrix& k);
  [[nodiscard]] bool compaction_due(const BlockSparseMatrix& k) const;
  void gather_system(const ShiftedSystem& system);
  void set_up(const ShiftedSystem& system, bool nearby);
  SolveReport solve_pass(const Eigen::VectorXd& b, Eigen::VectorXd& x, Pass pass);

  std::unique_ptr<LinearSolver> m_inner;
  ShiftedSystem m_system;  // the caller's, as last set up
  bool m_compacted = false;
  // Per block row of K its row in the compacted system (-1: left out), and the kept rows in order.
  std::vector<int> m_index_of_row;
  std::vector<int> m_kept_rows;
  std::vector<int> m_left_rows;
  std::vector<std::uint8_t> m_reached;  // compact_all's: per row, whether another row has a block with it
  // K's identity and revisions when the kept rows' pattern was taken.
  const BlockSparseMatrix* m_source = nullptr;
  std::uint64_t m_pattern_revision = 0, m_layout_revision = 0;
  // Two compacted matrices, taken in turn at each compaction: a new matrix object for the inner
  // solver, which then makes what it keeps of a matrix (aggregates, analyses) anew.
  std::array<BlockSparseMatrix, 2> m_compact_stiffness;
  int m_current = 0;
  Eigen::VectorXd m_compact_diagonal;
  std::vector<Eigen::Matrix3d> m_compact_frames;
  std::vector<Eigen::Vector3d> m_compact_positions;
  std::vector<std::uint8_t> m_compact_rows_left;
  ShiftedSystem m_compact;
  Eigen::VectorXd m_compact_b, m_compact_x;
};

}  // namespace tissue
