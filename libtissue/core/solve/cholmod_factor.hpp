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
// itself (Solves::without_blas), which CHOLMOD solves without BLAS.
// lower_solve() (the forward half of a solve for a right-hand side with a few non-zeros, what the
// contact stiffness needs) reads either factor with this class's own loops, no BLAS and no copy.
// factorize() never throws (it may run in a worker thread): it returns a status, and
// failure_message() says why in the caller's thread.
#pragma once

#include "core/solve/linear_solver.hpp"

#include <cholmod.h>

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace tissue {

class CholmodFactor {
 public:
  enum class Status { none, ok, not_positive_definite, failed };
  /// with_factor: solve with the factor itself (BLAS if it is supernodal); without_blas: factorize()
  /// also makes a simplicial copy of a supernodal factor (no BLAS in its solves), for solves that
  /// run beside another factorization.
  /// without_blas_on_demand: the same copy made at the first solve() instead, for a factor mostly
  /// read by lower_solve() (the copy of the organ's factor costs ~0.1 s).
  enum class Solves { with_factor, without_blas, without_blas_on_demand };
  /// automatic: supernodal (BLAS) only for dense factors, where it pays (cholmod_factor.cpp);
  /// supernodal: always (tests of the BLAS paths); quickest_factorization: supernodal from
  /// SUPERNODAL_FROM_ROWS rows, where its factorization is the faster one whatever the density, else
  /// automatic: for factors solved through lower_solve(), whose cost does not depend on the layout.
  enum class Layout { automatic, supernodal, quickest_factorization };
  static constexpr long SUPERNODAL_FROM_ROWS = 3000;
  /// automatic: AMD below METIS_FROM_ROWS rows, METIS from there (cholmod_factor.cpp); amd, metis:
  /// always that one (tests and benches compare them).
  enum class Ordering { automatic, amd, metis };
  static constexpr long METIS_FROM_ROWS = 10000;

  explicit CholmodFactor(Solves solves = Solves::with_factor, Layout layout = Layout::automatic,
                         Ordering ordering = Ordering::automatic);
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

  /// One column of a sparse right-hand side: (row, value) pairs, rows in [0, rows()), any order,
  /// repeats summed.
  using SparseColumn = std::vector<std::pair<int, double>>;
  /// Y = L^-1 (P B), the forward half of x = A^-1 b for each column b of B (A = P^T L L^T P): only
  /// the rows of Y that the elimination tree reaches from B's non-zeros, so that b^T A^-1 c = y_b^T
  /// y_c at the cost of those rows alone (a few ms where a full solve of the organ costs ~20).
  struct LowerSolution {
    std::vector<int> rows;   ///< rows of L reached, ascending (the other rows of Y are 0)
    Eigen::MatrixXd values;  ///< rows.size() x B's columns
  };
  /// Throws SolverError without a factor, std::invalid_argument for a row outside the matrix.
  void lower_solve(std::span<const SparseColumn> columns, LowerSolution& y);

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
  /// The ordering the last analysis used (CHOLMOD_AMD or CHOLMOD_METIS); -1 before one.
  [[nodiscard]] int ordering_used() const { return m_ordering_used; }
  /// Entries of L (0 before a factorization).
  [[nodiscard]] double factor_entries() const;
  [[nodiscard]] bool supernodal() const { return m_factor != nullptr && m_factor->is_super; }

 private:
  [[nodiscard]] bool pattern_current(const BlockSparseMatrix& stiffness) const;
  void build_pattern(const BlockSparseMatrix& stiffness);
  void free_pattern();
  void throw_if_failed(const char* what) const;
  /// The simplicial copy of a supernodal factor the solves of Solves::without_blas use.
  [[nodiscard]] cholmod_factor* solve_factor();
  /// The node of L's elimination tree holding column `column` (a supernode, or the column), its
  /// parent (-1 at a root), and the forward elimination of one node on m_work.
  [[nodiscard]] int tree_node(int column) const;
  [[nodiscard]] int tree_parent(int node) const;
  void eliminate(int node);

  cholmod_common m_common{};
  cholmod_sparse* m_matrix = nullptr;    // upper triangle of A, stype = 1, sorted, packed
  cholmod_factor* m_factor = nullptr;    // symbolic analysis + numeric factor of m_matrix
  cholmod_factor* m_simplicial = nullptr;  // Solves::without_blas, supernodal m_factor: what solve() uses
  Solves m_solves = Solves::with_factor;
  Ordering m_ordering = Ordering::automatic;
  Layout m_layout = Layout::automatic;
  cholmod_dense* m_rhs = nullptr;        // b, n x 1
  cholmod_dense* m_solution = nullptr;   // x, n x 1 (owned by cholmod_solve2, reused)
  cholmod_dense* m_work_y = nullptr;     // cholmod_solve2 workspaces, reused between solves
  cholmod_dense* m_work_e = nullptr;

  // One entry per stored entry of m_matrix: index into K's value array (9 * slot + column-major
  // offset in the block); and per scalar column j the position of A(j, j).
  std::vector<int> m_value_index;
  std::vector<int> m_diagonal_entry;

  // lower_solve(): the inverse of the factor's permutation (of the analysis it was built for), the
  // reach's marks and list, and the dense work rows (n x columns, kept zero between calls).
  std::vector<int> m_inverse_perm;
  int m_inverse_perm_analysis = -1;
  std::vector<char> m_reached;
  std::vector<int> m_reach;
  Eigen::MatrixXd m_work;
  Eigen::MatrixXd m_update;

  const BlockSparseMatrix* m_source = nullptr;  // what the pattern was built from
  std::uint64_t m_pattern_revision = 0;
  std::uint64_t m_layout_revision = 0;
  long m_rows = -1;
  bool m_analysis_pending = false;
  int m_analysis_count = 0;
  int m_ordering_used = -1;
  double m_stiffness_scale = 1.0;
  Status m_status = Status::none;
  int m_cholmod_status = 0;  // common.status of the failed call
  std::size_t m_minor = 0;   // failed pivot
  const char* m_failed_step = "";
};

}  // namespace tissue
