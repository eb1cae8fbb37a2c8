// CompactRowsSolver (compact_rows_solver.hpp).
#include "core/solve/compact_rows_solver.hpp"

#include <Eigen/Cholesky>

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace tissue {

CompactRowsSolver::CompactRowsSolver(std::unique_ptr<LinearSolver> inner) : m_inner(std::move(inner)) {
  if (!m_inner) throw SolverError("CompactRowsSolver: no inner solver");
}

void CompactRowsSolver::setup(const ShiftedSystem& system) { set_up(system, /*nearby=*/false); }

void CompactRowsSolver::setup_nearby(const ShiftedSystem& system) { set_up(system, /*nearby=*/true); }

void CompactRowsSolver::set_up(const ShiftedSystem& system, bool nearby) {
  m_system = ShiftedSystem{nullptr, 1.0, nullptr};
  system.check(m_inner->name());
  if (!keep_rows(system)) {
    nearby ? m_inner->setup_nearby(system) : m_inner->setup(system);
  } else {
    gather_system(system);
    nearby ? m_inner->setup_nearby(m_compact) : m_inner->setup(m_compact);
  }
  m_system = system;
}

bool CompactRowsSolver::keep_rows(const ShiftedSystem& system) {
  const BlockSparseMatrix& k = *system.stiffness;
  const int rows = k.block_rows();
  if (&k == m_source && k.pattern_revision() == m_pattern_revision && k.layout_revision() == m_layout_revision &&
      rows == static_cast<int>(m_index_of_row.size())) {
    return m_compacted;
  }
  if (&k != m_source || rows < static_cast<int>(m_index_of_row.size())) {
    // Another matrix (or fewer rows): every row kept until compaction_due says otherwise.
    m_index_of_row.clear();
    m_kept_rows.clear();
    m_left_rows.clear();
    m_compacted = false;
  }
  // Rows appended since are kept, numbered after the others.
  for (int r = static_cast<int>(m_index_of_row.size()); r < rows; ++r) {
    m_index_of_row.push_back(static_cast<int>(m_kept_rows.size()));
    m_kept_rows.push_back(r);
  }
  bool viewed = false;
  if (m_compacted && !compaction_due(k)) {
    try {
      m_compact_stiffness[static_cast<size_t>(m_current)].view_rows_of(k, m_kept_rows, m_index_of_row);
      viewed = true;
    } catch (const std::invalid_argument&) {
      // A row kept has a block with a row left out whose own row has none (a pattern not symmetric):
      // compacted anew, leaving out only rows no block reaches.
    }
  }
  if (!viewed && (m_compacted || compaction_due(k))) compact_all(k);
  m_source = &k;
  m_pattern_revision = k.pattern_revision();
  m_layout_revision = k.layout_revision();
  return m_compacted;
}

bool CompactRowsSolver::compaction_due(const BlockSparseMatrix& k) const {
  for (const int r : m_left_rows) {
    if (k.row_size(r) > 1) return true;  // coupled again: it must be solved with the others
  }
  int decoupled = 0;
  for (const int r : m_kept_rows) decoupled += k.row_size(r) == 1 ? 1 : 0;
  return decoupled >= MIN_DECOUPLED_ROWS && DECOUPLED_SHARE_DIVISOR * decoupled >= static_cast<int>(m_kept_rows.size());
}

void CompactRowsSolver::compact_all(const BlockSparseMatrix& k) {
  const int rows = k.block_rows();
  m_index_of_row.assign(static_cast<size_t>(rows), -1);
  m_kept_rows.clear();
  m_left_rows.clear();
  // A row goes when its only block is its diagonal and no other row has a block with it.
  std::vector<std::uint8_t>& reached = m_reached;
  reached.assign(static_cast<size_t>(rows), 0);
  for (int r = 0; r < rows; ++r) {
    for (int slot = k.row_begin(r); slot < k.row_begin(r) + k.row_size(r); ++slot) {
      const int column = k.slot_column(slot);
      if (column != r) reached[static_cast<size_t>(column)] = 1;
    }
  }
  for (int r = 0; r < rows; ++r) {
    if (k.row_size(r) > 1 || reached[static_cast<size_t>(r)] != 0) {
      m_index_of_row[static_cast<size_t>(r)] = static_cast<int>(m_kept_rows.size());
      m_kept_rows.push_back(r);
    } else {
      m_left_rows.push_back(r);
    }
  }
  // Nothing to leave out, or nothing left to solve but 3 x 3 systems: the system as it is.
  if (m_left_rows.empty() || m_kept_rows.empty()) {
    std::iota(m_index_of_row.begin(), m_index_of_row.end(), 0);
    m_kept_rows = m_index_of_row;
    m_left_rows.clear();
    m_compacted = false;
    return;
  }
  m_current = 1 - m_current;
  m_compact_stiffness[static_cast<size_t>(m_current)].view_rows_of(k, m_kept_rows, m_index_of_row);
  m_compacted = true;
}

void CompactRowsSolver::gather_system(const ShiftedSystem& system) {
  const BlockSparseMatrix& stiffness = m_compact_stiffness[static_cast<size_t>(m_current)];
  const auto kept = m_kept_rows.size();
  m_compact_diagonal.resize(3 * static_cast<Eigen::Index>(kept));
  for (size_t c = 0; c < kept; ++c) {
    m_compact_diagonal.segment<3>(3 * static_cast<Eigen::Index>(c)) = system.diagonal->segment<3>(3L * m_kept_rows[c]);
  }
  m_compact = ShiftedSystem{&stiffness, system.stiffness_scale, &m_compact_diagonal};
  if (system.block_frames != nullptr) {
    m_compact_frames.resize(kept);
    for (size_t c = 0; c < kept; ++c) m_compact_frames[c] = (*system.block_frames)[static_cast<size_t>(m_kept_rows[c])];
    m_compact.block_frames = &m_compact_frames;
  }
  if (system.block_positions != nullptr) {
    m_compact_positions.resize(kept);
    for (size_t c = 0; c < kept; ++c) {
      m_compact_positions[c] = (*system.block_positions)[static_cast<size_t>(m_kept_rows[c])];
    }
    m_compact.block_positions = &m_compact_positions;
  }
  if (system.rows_left != nullptr) {
    const std::vector<std::uint8_t>& left = *system.rows_left;
    m_compact_rows_left.assign(kept, 0);
    for (size_t c = 0; c < kept; ++c) {
      const auto r = static_cast<size_t>(m_kept_rows[c]);
      m_compact_rows_left[c] = r < left.size() ? left[r] : 0;
    }
    m_compact.rows_left = &m_compact_rows_left;
  }
}

SolveReport CompactRowsSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  return solve_pass(b, x, Pass::full);
}

SolveReport CompactRowsSolver::solve_roughly(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  return solve_pass(b, x, Pass::rough);
}

SolveReport CompactRowsSolver::refine(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  return solve_pass(b, x, Pass::refine);
}

SolveReport CompactRowsSolver::solve_pass(const Eigen::VectorXd& b, Eigen::VectorXd& x, Pass pass) {
  if (!is_set_up()) throw SolverError(std::string(m_inner->name()) + ": solve() without a setup()");
  const auto inner_pass = [&](const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
    switch (pass) {
      case Pass::rough:
        return m_inner->solve_roughly(rhs, solution);
      case Pass::refine:
        return m_inner->refine(rhs, solution);
      case Pass::full:
        break;
    }
    return m_inner->solve(rhs, solution);
  };
  if (!m_compacted) return inner_pass(b, x);
  const Eigen::Index n = m_system.rows();
  if (b.size() != n) {
    throw SolverError(std::string(m_inner->name()) + ": b has length " + std::to_string(b.size()) + ", expected " +
                      std::to_string(n));
  }
  if (x.size() != n) x.setZero(n);  // (a direct solver's caller may pass any x; the guess is then zero)
  const auto kept = static_cast<Eigen::Index>(m_kept_rows.size());
  m_compact_b.resize(3 * kept);
  m_compact_x.resize(3 * kept);
  for (Eigen::Index c = 0; c < kept; ++c) {
    const Eigen::Index row = 3L * m_kept_rows[static_cast<size_t>(c)];
    m_compact_b.segment<3>(3 * c) = b.segment<3>(row);
    m_compact_x.segment<3>(3 * c) = x.segment<3>(row);
  }
  SolveReport report = inner_pass(m_compact_b, m_compact_x);
  for (Eigen::Index c = 0; c < kept; ++c) {
    x.segment<3>(3L * m_kept_rows[static_cast<size_t>(c)]) = m_compact_x.segment<3>(3 * c);
  }
  // Each row left out: its own 3 x 3 system (s K_ii + diag(d_i)) x_i = b_i, exactly.
  const BlockSparseMatrix& k = *m_system.stiffness;
  const Eigen::VectorXd& d = *m_system.diagonal;
  for (const int r : m_left_rows) {
    const Eigen::Map<const Eigen::Matrix3d> k_ii = k.block(k.diagonal_slot(r));
    if ((k_ii.array() == 0.0).all()) {
      x.segment<3>(3L * r) = b.segment<3>(3L * r).cwiseQuotient(d.segment<3>(3L * r));
    } else {
      Eigen::Matrix3d a = m_system.stiffness_scale * k_ii;
      a.diagonal() += d.segment<3>(3L * r);
      x.segment<3>(3L * r) = a.ldlt().solve(Eigen::Vector3d(b.segment<3>(3L * r)));
    }
  }
  // The residual is the kept rows' alone: relative to the whole b.
  const double b_norm = b.norm();
  if (b_norm > 0.0) report.relative_residual *= m_compact_b.norm() / b_norm;
  return report;
}

bool CompactRowsSolver::multiply_set_up(const ShiftedSystem& system, const Eigen::Ref<const Eigen::MatrixXd>& x,
                                        RowMajorMatrix& y) const {
  // Compacted, the inner solver's copy is of other rows: the caller multiplies with the system.
  return !m_compacted && m_inner->multiply_set_up(system, x, y);
}

void CompactRowsSolver::forget_earlier_setups() {
  m_source = nullptr;  // (keep_rows then numbers the rows anew)
  m_compacted = false;
  m_system = ShiftedSystem{nullptr, 1.0, nullptr};
  m_inner->forget_earlier_setups();
}

int CompactRowsSolver::kept_block_rows() const {
  if (m_compacted) return static_cast<int>(m_kept_rows.size());
  return m_system.stiffness != nullptr ? m_system.stiffness->block_rows() : 0;
}

}  // namespace tissue
