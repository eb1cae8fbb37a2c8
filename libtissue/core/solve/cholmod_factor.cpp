// CholmodFactor (see cholmod_factor.hpp). The block matrix is converted to CHOLMOD's
// compressed-column form through a value map built once per pattern, so a refactorization is:
// refill values, factorize; a solve: back-substitute.
//
// Choices, each for the real-time case of small to medium meshes (10^3 - 10^4 unknowns):
// * Ordering: AMD only (nmethods = 1). The default also tries METIS/NESDIS when AMD fills much,
//   which costs far more than it saves at this size (on the frog, 2433 unknowns, METIS and NESDIS
//   give more fill than AMD), and the analysis is redone whenever a cut changes the pattern.
// * Supernodal vs simplicial: CHOLMOD_AUTO (CHOLMOD's flops-per-nonzero switch), which picks
//   supernodal for 3D tet-mesh stiffness from ~10^3 unknowns on. Measured on a 2430-unknown
//   Kuhn-grid stiffness (14 neighbours per vertex, 1e8 flops per factorization, Debian's
//   reference BLAS): simplicial and supernodal both take ~45 ms, within timing noise, and AMD
//   alone gives the same fill as the default AMD/METIS trial.
// * final_ll = TRUE: a simplicial factorization is LL' as well. CHOLMOD's simplicial LDL' only
//   stops at a zero pivot, so an indefinite A would be factorized and "solved" silently.
// * print = 0: failures come back as a status and a message, not as text on stdout.
#include "core/solve/cholmod_factor.hpp"

#include <algorithm>
#include <mutex>
#include <utility>

namespace tissue {
namespace {

// The CHOLMOD calls that reach BLAS (a supernodal factorization, a solve with a supernodal factor)
// take turns across the process: Debian's serial OpenBLAS hands concurrent callers the same work
// buffers (Cholmod.TwoSolversOnTwoThreadsGiveBitwiseTheirSerialResults).
// Supernodal (BLAS) only for factors denser than this many flops per entry of L (CHOLMOD's default
// 40). Measured with Debian's serial OpenBLAS on this project's meshes (flops/lnz 50-105): the
// simplicial factorization is faster (frog 3.6 against 4.0 ms, simpleBridge 18.5 against 20.3,
// turtle 0.65 against 0.92) and so are its solves (frog 0.060 against 0.075 ms).
constexpr double SUPERNODAL_SWITCH = 500.0;

std::mutex& blas_turn() {
  static std::mutex turn;
  return turn;
}

}  // namespace

CholmodFactor::CholmodFactor(Solves solves, Layout layout) : m_solves(solves) {
  cholmod_start(&m_common);
  m_common.print = 0;
  m_common.nmethods = 1;
  m_common.method[0].ordering = CHOLMOD_AMD;
  m_common.supernodal = layout == Layout::supernodal ? CHOLMOD_SUPERNODAL : CHOLMOD_AUTO;
  m_common.supernodal_switch = SUPERNODAL_SWITCH;
  m_common.final_ll = 1;
}

CholmodFactor::~CholmodFactor() {
  free_pattern();
  cholmod_free_dense(&m_rhs, &m_common);
  cholmod_free_dense(&m_solution, &m_common);
  cholmod_free_dense(&m_work_y, &m_common);
  cholmod_free_dense(&m_work_e, &m_common);
  cholmod_finish(&m_common);
}

void CholmodFactor::free_pattern() {
  m_status = Status::none;
  cholmod_free_factor(&m_simplicial, &m_common);
  cholmod_free_factor(&m_factor, &m_common);
  cholmod_free_sparse(&m_matrix, &m_common);
  m_source = nullptr;
  m_rows = -1;
}

bool CholmodFactor::pattern_current(const BlockSparseMatrix& stiffness) const {
  return m_matrix != nullptr && m_source == &stiffness && m_pattern_revision == stiffness.pattern_revision() &&
         m_layout_revision == stiffness.layout_revision() && m_rows == stiffness.rows();
}

void CholmodFactor::throw_if_failed(const char* what) const {
  if (m_common.status < 0) {
    throw SolverError(std::string("CHOLMOD: ") + what + " failed (status " + std::to_string(m_common.status) +
                      (m_common.status == CHOLMOD_OUT_OF_MEMORY ? ", out of memory" : "") + ")");
  }
}

// Builds the pattern of the upper triangle and the value map. Column j of the upper triangle
// holds A(i, j), i <= j; by symmetry we read it from block row J = j / 3 of K, entry K(j, i), whose
// blocks are at hand without a transpose.
void CholmodFactor::build_pattern(const BlockSparseMatrix& stiffness) {
  free_pattern();
  const int block_rows = stiffness.block_rows();
  const int n = stiffness.rows();

  std::vector<int> column_start(static_cast<size_t>(n) + 1, 0);
  std::vector<int> entry_row;  // row index i of each stored entry, columns in order
  m_value_index.clear();
  m_diagonal_entry.assign(static_cast<size_t>(n), -1);
  std::vector<std::pair<int, int>> column[3];
  for (int block_row = 0; block_row < block_rows; ++block_row) {
    for (auto& c : column) c.clear();
    const int begin = stiffness.row_begin(block_row);
    for (int slot = begin; slot < begin + stiffness.row_size(block_row); ++slot) {
      const int block_col = stiffness.slot_column(slot);
      if (block_col > block_row) continue;
      for (int a = 0; a < 3; ++a) {    // scalar column j = 3 J + a of A (row of K)
        for (int b = 0; b < 3; ++b) {  // scalar row i = 3 I + b of A (column of K)
          const int i = 3 * block_col + b;
          if (i > 3 * block_row + a) continue;
          column[a].emplace_back(i, 9 * slot + a + 3 * b);  // K block (a, b), column-major
        }
      }
    }
    for (int a = 0; a < 3; ++a) {
      const int j = 3 * block_row + a;
      std::sort(column[a].begin(), column[a].end());
      for (const auto& [i, index] : column[a]) {
        if (i == j) m_diagonal_entry[static_cast<size_t>(j)] = static_cast<int>(m_value_index.size());
        m_value_index.push_back(index);
        entry_row.push_back(i);
      }
      column_start[static_cast<size_t>(j) + 1] = static_cast<int>(m_value_index.size());
    }
  }

  const size_t nnz = m_value_index.size();
  m_matrix = cholmod_allocate_sparse(static_cast<size_t>(n), static_cast<size_t>(n), nnz, /*sorted=*/1,
                                     /*packed=*/1, /*stype=*/1, CHOLMOD_REAL, &m_common);
  if (m_matrix == nullptr) throw_if_failed("allocating A");
  if (m_matrix == nullptr) throw SolverError("CHOLMOD: allocating A failed");
  std::copy(column_start.begin(), column_start.end(), static_cast<int*>(m_matrix->p));
  std::copy(entry_row.begin(), entry_row.end(), static_cast<int*>(m_matrix->i));

  m_source = &stiffness;
  m_pattern_revision = stiffness.pattern_revision();
  m_layout_revision = stiffness.layout_revision();
  m_rows = n;
  m_analysis_pending = true;
}

void CholmodFactor::load(const ShiftedSystem& system) {
  m_status = Status::none;
  if (!pattern_current(*system.stiffness)) build_pattern(*system.stiffness);
  const double* k_values = system.stiffness->block(0).data();  // slot 0 exists whenever n > 0
  const double scale = system.stiffness_scale;
  double* a_values = static_cast<double*>(m_matrix->x);
  const size_t nnz = m_value_index.size();
  for (size_t k = 0; k < nnz; ++k) a_values[k] = scale * k_values[m_value_index[k]];
  const Eigen::VectorXd& d = *system.diagonal;
  for (size_t j = 0; j < m_diagonal_entry.size(); ++j) a_values[m_diagonal_entry[j]] += d[static_cast<long>(j)];
  m_stiffness_scale = scale;
}

CholmodFactor::Status CholmodFactor::factorize() noexcept {
  m_status = Status::failed;
  m_cholmod_status = 0;
  m_minor = 0;
  cholmod_free_factor(&m_simplicial, &m_common);
  if (m_matrix == nullptr) {
    m_failed_step = "factorization without a loaded matrix";
    return m_status;
  }
  if (m_analysis_pending) {
    cholmod_free_factor(&m_factor, &m_common);
    m_factor = cholmod_analyze(m_matrix, &m_common);
    ++m_analysis_count;
    if (m_factor == nullptr || m_common.status < 0) {
      m_failed_step = "symbolic analysis";
      m_cholmod_status = m_common.status;
      return m_status;
    }
    m_analysis_pending = false;
  }
  {
    std::unique_lock<std::mutex> turn(blas_turn(), std::defer_lock);
    if (m_factor->is_super) turn.lock();  // a simplicial factorization calls no BLAS
    cholmod_factorize(m_matrix, m_factor, &m_common);
  }
  m_cholmod_status = m_common.status;
  if (m_common.status < 0) {
    m_failed_step = "numeric factorization";
    return m_status;
  }
  if (m_common.status == CHOLMOD_NOT_POSDEF || m_factor->minor < static_cast<size_t>(m_rows)) {
    m_minor = m_factor->minor;
    m_status = Status::not_positive_definite;
    return m_status;
  }
  if (m_solves == Solves::without_blas && m_factor->is_super) {
    m_simplicial = cholmod_copy_factor(m_factor, &m_common);
    if (m_simplicial == nullptr ||
        cholmod_change_factor(CHOLMOD_REAL, /*to_ll=*/1, /*to_super=*/0, /*to_packed=*/1, /*to_monotonic=*/1,
                              m_simplicial, &m_common) == 0) {
      m_failed_step = "simplicial copy of the factor";
      m_cholmod_status = m_common.status;
      return m_status;
    }
  }
  m_status = Status::ok;
  return m_status;
}

std::string CholmodFactor::failure_message(const std::string& who) const {
  if (m_status == Status::not_positive_definite) {
    return who + ": A = s K + diag(d) is not positive definite (pivot " + std::to_string(m_minor) + " of " +
           std::to_string(m_rows) + " rows, stiffness scale " + std::to_string(m_stiffness_scale) + ")";
  }
  return who + ": " + m_failed_step + " failed (CHOLMOD status " + std::to_string(m_cholmod_status) +
         (m_cholmod_status == CHOLMOD_OUT_OF_MEMORY ? ", out of memory" : "") + ")";
}

void CholmodFactor::solve(std::span<const double> b, std::span<double> x) {
  const long n = m_rows;
  if (!factored() || static_cast<long>(b.size()) != n || static_cast<long>(x.size()) != n) {
    throw SolverError("CHOLMOD: solve without a factor or with the wrong length");
  }
  if (m_rhs == nullptr || static_cast<long>(m_rhs->nrow) != n) {
    cholmod_free_dense(&m_rhs, &m_common);
    m_rhs = cholmod_allocate_dense(static_cast<size_t>(n), 1, static_cast<size_t>(n), CHOLMOD_REAL, &m_common);
    if (m_rhs == nullptr) throw SolverError("CHOLMOD: allocating b failed");
  }
  std::copy(b.begin(), b.end(), static_cast<double*>(m_rhs->x));
  cholmod_factor* factor = m_simplicial != nullptr ? m_simplicial : m_factor;
  std::unique_lock<std::mutex> turn(blas_turn(), std::defer_lock);
  if (factor->is_super) turn.lock();  // a simplicial solve calls no BLAS
  const int solved =
      cholmod_solve2(CHOLMOD_A, factor, m_rhs, nullptr, &m_solution, nullptr, &m_work_y, &m_work_e, &m_common);
  if (turn.owns_lock()) turn.unlock();
  if (solved == 0 || m_solution == nullptr) {
    throw_if_failed("solve");
    throw SolverError("CHOLMOD: solve failed");
  }
  const double* solution = static_cast<const double*>(m_solution->x);
  std::copy(solution, solution + n, x.begin());
}

}  // namespace tissue
