// CholmodFactor: the one CHOLMOD wrapper (core/solve, and the contact stiffness of core/contact). Holds the upper
// triangle of A = s K + diag(d) in compressed columns, the value map from K's slots to it (built
// once per pattern), the symbolic analysis and the numeric factor, and the dense buffers of the
// solves. CholmodSolver factorizes with one every setup; CholeskyPcgSolver keeps two (the factor
// in use and the one being refreshed, possibly in another thread).
//
// Each object has its own cholmod_common, so two objects may be used from two threads at once;
// one object is not thread-safe. CHOLMOD's supernodal factorization and solves call BLAS, and the
// serial OpenBLAS of Debian is not safe to call from two threads at once (it hands both the same
// work buffer: a lagged-factor run whose refresh overlapped the solves differed from run to run),
// so a factor whose solves run beside another factorization solves with a simplicial copy of
// itself (Solves::without_blas), which CHOLMOD solves without BLAS. factorize() never throws (it may run in a worker thread): it
// returns a status, and failure_message() says why in the caller's thread.
#pragma once

#include "core/solve/linear_solver.hpp"

#include <cholmod.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace tissue {

class CholmodFactor {
 public:
  enum class Status { none, ok, not_positive_definite, failed };
  /// with_factor: solve with the factor itself (BLAS if it is supernodal); without_blas: factorize()
  /// also makes a simplicial copy of a supernodal factor (no BLAS in its solves), for solves that
  /// run beside another factorization.
  enum class Solves { with_factor, without_blas };
  /// automatic: supernodal (BLAS) only for dense factors, where it pays (cholmod_factor.cpp);
  /// supernodal: always (tests of the BLAS paths).
  enum class Layout { automatic, supernodal };

  explicit CholmodFactor(Solves solves = Solves::with_factor, Layout layout = Layout::automatic);
  ~CholmodFactor();
  CholmodFactor(const CholmodFactor&) = delete;
  CholmodFactor& operator=(const CholmodFactor&) = delete;

  /// Copies A's upper triangle (only the blocks in use) into the object: the pattern and value map
  /// are rebuilt first when K is another matrix or its size, pattern or layout changed (then the
  /// next factorize() redoes the symbolic analysis). Drops the numeric factor. The caller checked
  /// the sizes. Throws SolverError when CHOLMOD cannot allocate.
  void load(const ShiftedSystem& system);
  /// Symbolic analysis when the pattern is new, then the numeric factorization of the loaded values.
  /// No exception; status() == ok when the factor can be used.
  Status factorize() noexcept;
  /// Why the last factorize() failed, for a SolverError ("<who>: ... not positive definite ...").
  [[nodiscard]] std::string failure_message(const std::string& who) const;

  /// x = A^-1 b with the factor; b and x have rows() entries (x may alias nothing of b). Reuses the
  /// dense buffers: no allocation after the first solve of a size. Throws SolverError.
  void solve(std::span<const double> b, std::span<double> x);

  [[nodiscard]] Status status() const { return m_status; }
  [[nodiscard]] bool factored() const { return m_status == Status::ok; }
  /// Rows of the loaded A (-1 before the first load).
  [[nodiscard]] long rows() const { return m_rows; }
  /// The matrix and pattern revision the loaded A was taken from.
  [[nodiscard]] const BlockSparseMatrix* source() const { return m_source; }
  [[nodiscard]] std::uint64_t pattern_revision() const { return m_pattern_revision; }
  [[nodiscard]] double stiffness_scale() const { return m_stiffness_scale; }
  /// Symbolic analyses so far (tests check they are reused).
  [[nodiscard]] int analysis_count() const { return m_analysis_count; }

 private:
  [[nodiscard]] bool pattern_current(const BlockSparseMatrix& stiffness) const;
  void build_pattern(const BlockSparseMatrix& stiffness);
  void free_pattern();
  void throw_if_failed(const char* what) const;

  cholmod_common m_common{};
  cholmod_sparse* m_matrix = nullptr;    // upper triangle of A, stype = 1, sorted, packed
  cholmod_factor* m_factor = nullptr;    // symbolic analysis + numeric factor of m_matrix
  cholmod_factor* m_simplicial = nullptr;  // Solves::without_blas, supernodal m_factor: what solve() uses
  Solves m_solves = Solves::with_factor;
  cholmod_dense* m_rhs = nullptr;        // b, n x 1
  cholmod_dense* m_solution = nullptr;   // x, n x 1 (owned by cholmod_solve2, reused)
  cholmod_dense* m_work_y = nullptr;     // cholmod_solve2 workspaces, reused between solves
  cholmod_dense* m_work_e = nullptr;

  // One entry per stored entry of m_matrix: index into K's value array (9 * slot + column-major
  // offset in the block); and per scalar column j the position of A(j, j).
  std::vector<int> m_value_index;
  std::vector<int> m_diagonal_entry;

  const BlockSparseMatrix* m_source = nullptr;  // what the pattern was built from
  std::uint64_t m_pattern_revision = 0;
  std::uint64_t m_layout_revision = 0;
  long m_rows = -1;
  bool m_analysis_pending = false;
  int m_analysis_count = 0;
  double m_stiffness_scale = 1.0;
  Status m_status = Status::none;
  int m_cholmod_status = 0;  // common.status of the failed call
  std::size_t m_minor = 0;   // failed pivot
  const char* m_failed_step = "";
};

}  // namespace tissue
