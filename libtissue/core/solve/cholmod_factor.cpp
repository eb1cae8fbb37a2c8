// CholmodFactor (see cholmod_factor.hpp). The block matrix is converted to CHOLMOD's
// compressed-column form through a value map built once per pattern, so a refactorization is:
// refill values, factorize; a solve: back-substitute.
//
// Choices, each for the real-time case of small to medium meshes (10^3 - 10^4 unknowns):
// * Ordering: one method (nmethods = 1), no trial of several. AMD below METIS_FROM_ROWS rows: on
//   the frog (2433 unknowns) METIS and NESDIS give more fill than AMD, and the analysis is redone
//   whenever a cut changes the pattern. METIS from there: on the organ's static K (meshes/
//   liver_tumour.veg, 25 479 unknowns) METIS gives 9.1e6 entries of L and 6.8e9 flops against AMD's
//   1.21e7 and 1.29e10, and factorizes in 0.67-0.72 s against 1.09-1.24 s (Debian's serial
//   OpenBLAS, one core of the 2-core VM of docs/BENCHMARKS.md).
// * Supernodal vs simplicial: CHOLMOD_AUTO (CHOLMOD's flops-per-nonzero switch), which picks
//   supernodal for 3D tet-mesh stiffness from ~10^3 unknowns on. Measured on a 2430-unknown
//   Kuhn-grid stiffness (14 neighbours per vertex, 1e8 flops per factorization, Debian's
//   reference BLAS): simplicial and supernodal both take ~45 ms, within timing noise, and AMD
//   alone gives the same fill as the default AMD/METIS trial.
// * Layout::quickest_factorization (the contact stiffness's factors, read by lower_solve()):
//   supernodal from SUPERNODAL_FROM_ROWS rows. Minimum of five refactorizations of the static K:
//   meshes/liver_coarse.veg (4008 unknowns) 27-30 ms supernodal against 45-80 simplicial,
//   bar_40x8x8 (6642) 33 against 56; the frog (2433) is faster simplicial (above).
// * final_ll = TRUE: a simplicial factorization is LL' as well. CHOLMOD's simplicial LDL' only
//   stops at a zero pivot, so an indefinite A would be factorized and "solved" silently.
// * print = 0: failures come back as a status and a message, not as text on stdout.
#include "core/solve/cholmod_factor.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cstddef>
#include <stdexcept>
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

CholmodFactor::CholmodFactor(Solves solves, Layout layout, Ordering ordering)
    : m_solves(solves), m_ordering(ordering), m_layout(layout) {
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
    const bool metis = m_ordering == Ordering::metis || (m_ordering == Ordering::automatic && m_rows >= METIS_FROM_ROWS);
    m_common.method[0].ordering = metis ? CHOLMOD_METIS : CHOLMOD_AMD;
    m_ordering_used = m_common.method[0].ordering;
    if (m_layout == Layout::quickest_factorization) {
      m_common.supernodal = m_rows >= SUPERNODAL_FROM_ROWS ? CHOLMOD_SUPERNODAL : CHOLMOD_AUTO;
    }
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
  m_status = Status::ok;
  if (m_solves == Solves::without_blas && m_factor->is_super) {
    try {
      (void)solve_factor();
    } catch (const SolverError&) {
      m_status = Status::failed;
      m_failed_step = "simplicial copy of the factor";
      m_cholmod_status = m_common.status;
    }
  }
  return m_status;
}

double CholmodFactor::factor_entries() const {
  if (!factored()) return 0.0;
  if (!m_factor->is_super) {
    double entries = 0.0;
    const int* counts = static_cast<const int*>(m_factor->nz);
    for (size_t j = 0; j < m_factor->n; ++j) entries += counts[j];
    return entries;
  }
  const int* super = static_cast<const int*>(m_factor->super);
  const int* pi = static_cast<const int*>(m_factor->pi);
  double entries = 0.0;  // the lower trapezoid of each supernode
  for (size_t s = 0; s < m_factor->nsuper; ++s) {
    const double columns = super[s + 1] - super[s];
    const double rows = pi[s + 1] - pi[s];
    entries += columns * rows - columns * (columns - 1.0) / 2.0;
  }
  return entries;
}

cholmod_factor* CholmodFactor::solve_factor() {
  if (m_solves == Solves::with_factor || !m_factor->is_super) return m_factor;
  if (m_simplicial == nullptr) {
    m_simplicial = cholmod_copy_factor(m_factor, &m_common);
    if (m_simplicial == nullptr ||
        cholmod_change_factor(CHOLMOD_REAL, /*to_ll=*/1, /*to_super=*/0, /*to_packed=*/1, /*to_monotonic=*/1,
                              m_simplicial, &m_common) == 0) {
      cholmod_free_factor(&m_simplicial, &m_common);
      throw_if_failed("simplicial copy of the factor");
      throw SolverError("CHOLMOD: simplicial copy of the factor failed");
    }
  }
  return m_simplicial;
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
  cholmod_factor* factor = solve_factor();
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

// L's elimination tree, node by node: a supernode s holds columns super[s] .. super[s + 1] - 1, a
// dense trapezoid of pi[s + 1] - pi[s] rows (the first super[s + 1] - super[s] its own columns,
// sorted) at x + px[s], column-major; its parent is the supernode of its first row below its own
// columns. A simplicial LL' column j holds nz[j] entries at p[j], the diagonal first (the rest in any
// order); its parent is the smallest row below the diagonal. A parent's index exceeds its child's.
int CholmodFactor::tree_node(int column) const {
  if (!m_factor->is_super) return column;
  const int* super = static_cast<const int*>(m_factor->super);
  const auto nsuper = static_cast<std::ptrdiff_t>(m_factor->nsuper);
  return static_cast<int>(std::upper_bound(super, super + nsuper + 1, column) - super) - 1;
}

int CholmodFactor::tree_parent(int node) const {
  if (m_factor->is_super) {
    const int* super = static_cast<const int*>(m_factor->super);
    const int* pi = static_cast<const int*>(m_factor->pi);
    const int* rows = static_cast<const int*>(m_factor->s);
    const int own = super[node + 1] - super[node];
    return pi[node + 1] - pi[node] > own ? tree_node(rows[pi[node] + own]) : -1;
  }
  const int* p = static_cast<const int*>(m_factor->p);
  const int* nz = static_cast<const int*>(m_factor->nz);
  const int* rows = static_cast<const int*>(m_factor->i);
  int parent = -1;
  for (int k = p[node] + 1; k < p[node] + nz[node]; ++k) {
    if (parent < 0 || rows[k] < parent) parent = rows[k];
  }
  return parent;
}

void CholmodFactor::eliminate(int node) {
  const double* values = static_cast<const double*>(m_factor->x);
  if (!m_factor->is_super) {
    const int* p = static_cast<const int*>(m_factor->p);
    const int* nz = static_cast<const int*>(m_factor->nz);
    const int* rows = static_cast<const int*>(m_factor->i);
    m_work.row(node) /= values[p[node]];
    for (int k = p[node] + 1; k < p[node] + nz[node]; ++k) m_work.row(rows[k]) -= values[k] * m_work.row(node);
    return;
  }
  const int* super = static_cast<const int*>(m_factor->super);
  const int* pi = static_cast<const int*>(m_factor->pi);
  const int* px = static_cast<const int*>(m_factor->px);
  const int* rows = static_cast<const int*>(m_factor->s);
  const int first = super[node];
  const int own = super[node + 1] - first;
  const int height = pi[node + 1] - pi[node];
  const Eigen::Map<const Eigen::MatrixXd> block(values + px[node], height, own);
  auto solved = m_work.middleRows(first, own);
  solved = block.topRows(own).triangularView<Eigen::Lower>().solve(solved);
  if (height == own) return;
  m_update.noalias() = block.bottomRows(height - own) * solved;
  for (int k = own; k < height; ++k) m_work.row(rows[pi[node] + k]) -= m_update.row(k - own);
}

void CholmodFactor::lower_solve(std::span<const SparseColumn> columns, LowerSolution& y) {
  if (!factored()) throw SolverError("CHOLMOD: lower solve without a factor");
  if (!m_factor->is_ll) throw SolverError("CHOLMOD: lower solve of an LDL' factor");
  const int n = static_cast<int>(m_rows);
  if (m_inverse_perm_analysis != m_analysis_count) {
    const int* perm = static_cast<const int*>(m_factor->Perm);
    m_inverse_perm.resize(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) m_inverse_perm[static_cast<size_t>(perm[k])] = k;
    m_inverse_perm_analysis = m_analysis_count;
  }
  // Every row checked before the work rows and the reach's marks are touched: a refused call leaves
  // them zero for the next.
  for (const SparseColumn& column : columns) {
    for (const auto& [row, value] : column) {
      if (row < 0 || row >= n) {
        throw std::invalid_argument("CHOLMOD lower solve: row " + std::to_string(row) + " outside [0, " +
                                    std::to_string(n) + ")");
      }
    }
  }
  const auto width = static_cast<Eigen::Index>(columns.size());
  if (m_work.rows() != n || m_work.cols() != width) m_work.setZero(n, width);
  const size_t nodes = m_factor->is_super ? m_factor->nsuper : static_cast<size_t>(n);
  if (m_reached.size() != nodes) m_reached.assign(nodes, 0);
  m_reach.clear();
  for (Eigen::Index c = 0; c < width; ++c) {
    for (const auto& [row, value] : columns[static_cast<size_t>(c)]) {
      const int k = m_inverse_perm[static_cast<size_t>(row)];
      m_work(k, c) += value;
      for (int node = tree_node(k); node >= 0 && m_reached[static_cast<size_t>(node)] == 0; node = tree_parent(node)) {
        m_reached[static_cast<size_t>(node)] = 1;
        m_reach.push_back(node);
      }
    }
  }
  std::sort(m_reach.begin(), m_reach.end());  // children before parents
  for (const int node : m_reach) eliminate(node);
  y.rows.clear();
  for (const int node : m_reach) {
    m_reached[static_cast<size_t>(node)] = 0;
    if (!m_factor->is_super) {
      y.rows.push_back(node);
      continue;
    }
    const int* super = static_cast<const int*>(m_factor->super);
    for (int j = super[node]; j < super[node + 1]; ++j) y.rows.push_back(j);
  }
  y.values.resize(static_cast<Eigen::Index>(y.rows.size()), width);
  for (size_t r = 0; r < y.rows.size(); ++r) {
    y.values.row(static_cast<Eigen::Index>(r)) = m_work.row(y.rows[r]);
    m_work.row(y.rows[r]).setZero();
  }
}

}  // namespace tissue
