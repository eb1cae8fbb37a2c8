// TwoLevelPreconditioner: aggregates, their rigid-motion coarse space, the coarse matrix and its
// factor, and the additive two-level application (two_level_preconditioner.hpp).
#include "core/solve/two_level_preconditioner.hpp"
#include "core/system/cross_matrix.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace tissue {
namespace {

double frobenius(const ShiftedSystem& system, int slot, int row, int column) {
  Eigen::Matrix3d block = system.stiffness_scale * system.stiffness->block(slot);
  if (row == column) block.diagonal() += system.diagonal->segment<3>(3L * row);
  return block.norm();
}


}  // namespace

void TwoLevelPreconditioner::setup(const ShiftedSystem& system, const Eigen::VectorXd& inverse_diagonal) {
  m_inverse_diagonal = &inverse_diagonal;
  const bool aggregated = !aggregates_fit(system);
  const bool refresh_due = m_setups_since_coarse + 1 >= COARSE_REFRESH_SETUPS;
  if (aggregated && !refresh_due && (patch_fits(system) || (patchable(system) && patch(system)))) {
    ++m_setups_since_coarse;  // the coarse level made before serves, with the local level beside it
    return;
  }
  if (aggregated) {
    m_with_rotations = system.block_positions != nullptr;
    aggregate(system);  // with this setup's basis
    m_setups_since_coarse = COARSE_REFRESH_SETUPS;  // a coarse level now
  }
  if (++m_setups_since_coarse < COARSE_REFRESH_SETUPS) return;
  m_setups_since_coarse = 0;
  if (!aggregated) make_basis(system, /*count_rotations=*/false);
  assemble_and_factorize(system);
  m_can_patch = m_coarse_ok;
}

void TwoLevelPreconditioner::setup_nearby(const ShiftedSystem& system, const Eigen::VectorXd& inverse_diagonal) {
  if (!aggregates_fit(system) && !patch_fits(system)) {
    setup(system, inverse_diagonal);
    return;
  }
  m_inverse_diagonal = &inverse_diagonal;
}

bool TwoLevelPreconditioner::aggregates_fit(const ShiftedSystem& system) const {
  const BlockSparseMatrix& k = *system.stiffness;
  return &k == m_matrix && k.pattern_revision() == m_pattern_revision && k.layout_revision() == m_layout_revision &&
         k.block_rows() == m_rows && (system.block_positions != nullptr) == m_with_rotations;
}

// Phase 1: in row order, a row whose rows within `reach` strong edges are all free becomes a root
// and takes them. Phase 2: a row left over joins the phase-1 aggregate of its strongest strong
// neighbour that has one (else the aggregate of a neighbour taken in this phase, else its own).
int TwoLevelPreconditioner::aggregate_within(int reach, int rows, const std::vector<int>& strong_begin,
                                             const std::vector<int>& strong_column,
                                             const std::vector<double>& strong_weight,
                                             std::vector<int>& aggregate_of_row) {
  aggregate_of_row.assign(static_cast<size_t>(rows), -1);
  std::vector<int> reached;
  std::vector<int> mark(static_cast<size_t>(rows), -1);
  int count = 0;
  const auto alone = [&](int i) { return strong_begin[static_cast<size_t>(i)] == strong_begin[static_cast<size_t>(i) + 1]; };
  for (int root = 0; root < rows; ++root) {
    if (aggregate_of_row[static_cast<size_t>(root)] >= 0 || alone(root)) continue;
    reached.assign(1, root);
    mark[static_cast<size_t>(root)] = root;
    bool free = true;
    size_t level_begin = 0;
    for (int level = 0; level < reach && free; ++level) {
      const size_t level_end = reached.size();
      for (size_t front = level_begin; front < level_end && free; ++front) {
        const int i = reached[front];
        for (int e = strong_begin[static_cast<size_t>(i)]; e < strong_begin[static_cast<size_t>(i) + 1]; ++e) {
          const int j = strong_column[static_cast<size_t>(e)];
          if (mark[static_cast<size_t>(j)] == root) continue;
          if (aggregate_of_row[static_cast<size_t>(j)] >= 0) {
            free = false;
            break;
          }
          mark[static_cast<size_t>(j)] = root;
          reached.push_back(j);
        }
      }
      level_begin = level_end;
    }
    if (!free) continue;
    for (const int i : reached) aggregate_of_row[static_cast<size_t>(i)] = count;
    ++count;
  }
  const std::vector<int> phase_one = aggregate_of_row;
  for (int i = 0; i < rows; ++i) {
    if (phase_one[static_cast<size_t>(i)] >= 0 || alone(i)) continue;
    double strongest = -1.0;
    for (int e = strong_begin[static_cast<size_t>(i)]; e < strong_begin[static_cast<size_t>(i) + 1]; ++e) {
      const int j = strong_column[static_cast<size_t>(e)];
      const int a = phase_one[static_cast<size_t>(j)] >= 0 ? phase_one[static_cast<size_t>(j)] : -1;
      if (a >= 0 && strong_weight[static_cast<size_t>(e)] > strongest) {
        strongest = strong_weight[static_cast<size_t>(e)];
        aggregate_of_row[static_cast<size_t>(i)] = a;
      }
    }
    if (aggregate_of_row[static_cast<size_t>(i)] >= 0) continue;
    for (int e = strong_begin[static_cast<size_t>(i)]; e < strong_begin[static_cast<size_t>(i) + 1]; ++e) {
      const int a = aggregate_of_row[static_cast<size_t>(strong_column[static_cast<size_t>(e)])];
      if (a >= 0) {
        aggregate_of_row[static_cast<size_t>(i)] = a;
        break;
      }
    }
    if (aggregate_of_row[static_cast<size_t>(i)] < 0) aggregate_of_row[static_cast<size_t>(i)] = count++;
  }
  return count;
}

void TwoLevelPreconditioner::aggregate(const ShiftedSystem& system) {
  const BlockSparseMatrix& k = *system.stiffness;
  const int rows = k.block_rows();
  std::vector<double> diagonal_norm(static_cast<size_t>(rows));
  for (int i = 0; i < rows; ++i) {
    diagonal_norm[static_cast<size_t>(i)] = frobenius(system, k.diagonal_slot(i), i, i);
  }
  // The strong neighbours of each row (CSR).
  std::vector<int> strong_begin(static_cast<size_t>(rows) + 1, 0);
  std::vector<int> strong_column;
  std::vector<double> strong_weight;
  strong_column.reserve(static_cast<size_t>(k.nonzero_blocks()));
  strong_weight.reserve(static_cast<size_t>(k.nonzero_blocks()));
  for (int i = 0; i < rows; ++i) {
    for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
      const int j = k.slot_column(s);
      if (j < 0 || j == i) continue;
      // Off the diagonal A_ij = s K_ij: compared squared, without forming the block.
      const double coupling_squared = system.stiffness_scale * system.stiffness_scale * k.block(s).squaredNorm();
      if (coupling_squared >
          STRENGTH * STRENGTH * diagonal_norm[static_cast<size_t>(i)] * diagonal_norm[static_cast<size_t>(j)]) {
        strong_column.push_back(j);
        strong_weight.push_back(coupling_squared);  // only compared
      }
    }
    strong_begin[static_cast<size_t>(i) + 1] = static_cast<int>(strong_column.size());
  }
  const int count = aggregate_within(AGGREGATE_REACH, rows, strong_begin, strong_column, strong_weight, m_aggregate_of_row);
  m_aggregated_row_size.resize(static_cast<size_t>(rows));
  for (int i = 0; i < rows; ++i) m_aggregated_row_size[static_cast<size_t>(i)] = k.row_size(i);
  m_local.ok = false;
  // Rows of each aggregate, in row order.
  m_aggregate_rows_begin.assign(static_cast<size_t>(count) + 1, 0);
  for (const int a : m_aggregate_of_row) {
    if (a >= 0) ++m_aggregate_rows_begin[static_cast<size_t>(a) + 1];
  }
  for (int a = 0; a < count; ++a) m_aggregate_rows_begin[static_cast<size_t>(a) + 1] += m_aggregate_rows_begin[static_cast<size_t>(a)];
  m_aggregate_rows.resize(static_cast<size_t>(m_aggregate_rows_begin.back()));
  std::vector<int> fill(m_aggregate_rows_begin.begin(), m_aggregate_rows_begin.end() - 1);
  for (int i = 0; i < rows; ++i) {
    const int a = m_aggregate_of_row[static_cast<size_t>(i)];
    if (a >= 0) m_aggregate_rows[static_cast<size_t>(fill[static_cast<size_t>(a)]++)] = i;
  }

  // Columns per aggregate: 3 translations, and the rotations the points then span.
  m_centroid.assign(static_cast<size_t>(count), Eigen::Vector3d::Zero());
  m_translation_scale.assign(static_cast<size_t>(count), 0.0);
  m_rotation_axes.assign(static_cast<size_t>(count), Eigen::Matrix3d::Zero());
  m_rotation_count.assign(static_cast<size_t>(count), 0);
  m_offset.assign(static_cast<size_t>(rows), Eigen::Vector3d::Zero());
  m_column_begin.assign(static_cast<size_t>(count) + 1, 0);
  make_basis(system, /*count_rotations=*/true);
  for (int a = 0; a < count; ++a) {
    m_column_begin[static_cast<size_t>(a) + 1] = m_column_begin[static_cast<size_t>(a)] + 3 + m_rotation_count[static_cast<size_t>(a)];
  }
  m_coarse_size = m_column_begin.back();

  make_coarse_pattern(k);
  m_matrix = &k;
  m_pattern_revision = k.pattern_revision();
  m_layout_revision = k.layout_revision();
  m_rows = rows;
}

// The coarse block pattern (aggregate pairs that share a fine block), each fine slot's block, and
// the scalar lower triangle of the coarse matrix with its symbolic analysis.
void TwoLevelPreconditioner::make_coarse_pattern(const BlockSparseMatrix& k) {
  const int count = aggregate_count();
  // Per aggregate a (its rows in m_aggregate_rows): the aggregates its rows' blocks reach, in
  // ascending order, and each of those slots' coarse block; `position[b]` is b's block in a's row
  // while `seen[b] == a`.
  std::vector<int> seen(static_cast<size_t>(count), -1);
  std::vector<int> position(static_cast<size_t>(count), -1);
  m_coarse_row_begin.assign(static_cast<size_t>(count) + 1, 0);
  m_coarse_column.clear();
  m_coarse_block_of_slot.assign(static_cast<size_t>(k.slot_capacity()), -1);
  for (int a = 0; a < count; ++a) {
    const size_t first = m_coarse_column.size();
    for (int p = m_aggregate_rows_begin[static_cast<size_t>(a)]; p < m_aggregate_rows_begin[static_cast<size_t>(a) + 1]; ++p) {
      const int i = m_aggregate_rows[static_cast<size_t>(p)];
      for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
        const int j = k.slot_column(s);
        if (j < 0) continue;
        const int b = m_aggregate_of_row[static_cast<size_t>(j)];
        if (b < 0 || seen[static_cast<size_t>(b)] == a) continue;
        seen[static_cast<size_t>(b)] = a;
        m_coarse_column.push_back(b);
      }
    }
    std::sort(m_coarse_column.begin() + static_cast<long>(first), m_coarse_column.end());
    for (size_t q = first; q < m_coarse_column.size(); ++q) position[static_cast<size_t>(m_coarse_column[q])] = static_cast<int>(q);
    for (int p = m_aggregate_rows_begin[static_cast<size_t>(a)]; p < m_aggregate_rows_begin[static_cast<size_t>(a) + 1]; ++p) {
      const int i = m_aggregate_rows[static_cast<size_t>(p)];
      for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
        const int j = k.slot_column(s);
        const int b = j >= 0 ? m_aggregate_of_row[static_cast<size_t>(j)] : -1;
        if (b >= 0) m_coarse_block_of_slot[static_cast<size_t>(s)] = position[static_cast<size_t>(b)];
      }
    }
    m_coarse_row_begin[static_cast<size_t>(a) + 1] = static_cast<int>(m_coarse_column.size());
  }
  m_coarse_blocks.assign(m_coarse_column.size(), {});

  // The scalar lower triangle of the coarse matrix (compressed columns), made in the order
  // for_each_lower_entry visits it.
  long entries = 0;
  for_each_lower_entry([&](int, int, int, int, int) { ++entries; });
  m_coarse_matrix = Eigen::SparseMatrix<double>(m_coarse_size, m_coarse_size);
  m_coarse_matrix.makeCompressed();
  m_coarse_matrix.resizeNonZeros(entries);
  int* column_start = m_coarse_matrix.outerIndexPtr();
  int* row = m_coarse_matrix.innerIndexPtr();
  long next = 0;
  for_each_lower_entry([&](int column, int entry_row, int, int, int) {
    column_start[column + 1] = static_cast<int>(++next);
    row[next - 1] = entry_row;
  });
  for (int column = 0; column < m_coarse_size; ++column) {  // a column without entries (none here) keeps its start
    column_start[column + 1] = std::max(column_start[column + 1], column_start[column]);
  }
  m_coarse_factor.analyzePattern(m_coarse_matrix);
  m_coarse_rhs.resize(m_coarse_size);
  m_coarse_solution.resize(m_coarse_size);
}

// Per aggregate: the centroid of its points, 1/sqrt(rows) for the translations, and the rotation
// axes (principal axes of the points' second moment J = sum |r|^2 I - r r^T, scaled by 1/sqrt of
// the moment so that each column has unit norm). The number of rotations is fixed at aggregation
// (the coarse matrix's pattern); later setups keep the largest ones.
void TwoLevelPreconditioner::make_basis(const ShiftedSystem& system, bool count_rotations) {
  const int count = static_cast<int>(m_centroid.size());
  for (int a = 0; a < count; ++a) {
    const int begin = m_aggregate_rows_begin[static_cast<size_t>(a)];
    const int end = m_aggregate_rows_begin[static_cast<size_t>(a) + 1];
    m_translation_scale[static_cast<size_t>(a)] = 1.0 / std::sqrt(static_cast<double>(end - begin));
    if (!m_with_rotations) continue;
    const std::vector<Eigen::Vector3d>& points = *system.block_positions;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int p = begin; p < end; ++p) centroid += points[static_cast<size_t>(m_aggregate_rows[static_cast<size_t>(p)])];
    centroid /= static_cast<double>(end - begin);
    Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
    for (int p = begin; p < end; ++p) {
      const int row = m_aggregate_rows[static_cast<size_t>(p)];
      const Eigen::Vector3d r = points[static_cast<size_t>(row)] - centroid;
      m_offset[static_cast<size_t>(row)] = r;
      moment += r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose();
    }
    m_centroid[static_cast<size_t>(a)] = centroid;
    rotation_axes(moment, count_rotations, m_rotation_count[static_cast<size_t>(a)], m_rotation_axes[static_cast<size_t>(a)]);
  }
}

void TwoLevelPreconditioner::rotation_axes(const Eigen::Matrix3d& moment, bool count_rotations, int& rotations,
                                           Eigen::Matrix3d& axes) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(moment);
  const Eigen::Vector3d moments = eigen.eigenvalues();  // increasing
  const double largest = moments[2];
  if (count_rotations) {
    rotations = 0;
    for (int c = 0; c < 3; ++c) {
      if (largest > 0.0 && moments[c] > ROTATION_RANK_TOLERANCE * largest) ++rotations;
    }
  }
  axes.setZero();
  for (int c = 0; c < rotations; ++c) {
    const int e = 2 - c;  // the largest moments first
    const double moment_e = std::max(moments[e], ROTATION_RANK_TOLERANCE * largest);
    axes.col(c) = eigen.eigenvectors().col(e) / std::sqrt(moment_e);
  }
}

// Coarse block (a, b), a <= b, is the sum over rows i of a and j of b of P_i^T A_ij P_j, with
// P_j = [t_b I, C_j W_b] and C_j = -[r_j]x. Row by row, over the aggregates b >= a its blocks reach:
// S_b = sum_j A_ij and T_b = sum_j A_ij C_j (27 multiply-adds a block), so that
// sum_j A_ij P_j = [t_b S_b, T_b W_b] and the block takes P_i^T that = [t_a (.); W_a^T C_i^T (.)]
// once per (row, aggregate) pair instead of once per fine block. K's rows hold both halves, so
// every pair (i, j) of a block with a <= b is met from row i.
void TwoLevelPreconditioner::assemble_and_factorize(const ShiftedSystem& system) {
  const BlockSparseMatrix& k = *system.stiffness;
  for (auto& block : m_coarse_blocks) block.fill(0.0);
  for (int i = 0; i < m_rows; ++i) {
    const int a = m_aggregate_of_row[static_cast<size_t>(i)];
    if (a < 0) continue;  // a row alone: Jacobi solves it
    const int first_block = m_coarse_row_begin[static_cast<size_t>(a)];
    const size_t reach = static_cast<size_t>(m_coarse_row_begin[static_cast<size_t>(a) + 1] - first_block);
    if (m_row_sums.size() < reach) m_row_sums.resize(reach);
    m_touched.clear();
    for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
      const int j = k.slot_column(s);
      if (j < 0) continue;
      const int coarse_block = m_coarse_block_of_slot[static_cast<size_t>(s)];
      if (coarse_block < 0 || m_coarse_column[static_cast<size_t>(coarse_block)] < a) continue;
      Eigen::Matrix3d block = system.stiffness_scale * k.block(s);
      if (j == i) block.diagonal() += system.diagonal->segment<3>(3L * i);
      RowSums& sums = m_row_sums[static_cast<size_t>(coarse_block - first_block)];
      if (!sums.used) {
        sums = RowSums{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero(), true};
        m_touched.push_back(coarse_block);
      }
      sums.force += block;
      if (m_with_rotations) sums.moment -= block * cross_matrix(m_offset[static_cast<size_t>(j)]);
    }
    const double t_a = m_translation_scale[static_cast<size_t>(a)];
    const int rotations_a = m_rotation_count[static_cast<size_t>(a)];
    const Eigen::Matrix3d c_i_transpose = cross_matrix(m_offset[static_cast<size_t>(i)]);  // C_i^T = [r_i]x
    for (const int coarse_block : m_touched) {
      RowSums& sums = m_row_sums[static_cast<size_t>(coarse_block - first_block)];
      sums.used = false;
      const int b = m_coarse_column[static_cast<size_t>(coarse_block)];
      Eigen::Matrix<double, 3, 6> reached = Eigen::Matrix<double, 3, 6>::Zero();  // sum_j A_ij P_j
      reached.leftCols<3>() = m_translation_scale[static_cast<size_t>(b)] * sums.force;
      if (m_with_rotations) reached.rightCols<3>() = sums.moment * m_rotation_axes[static_cast<size_t>(b)];
      Eigen::Map<Eigen::Matrix<double, 6, 6>> coarse(m_coarse_blocks[static_cast<size_t>(coarse_block)].data());
      coarse.topRows<3>() += t_a * reached;
      if (rotations_a > 0) {
        coarse.bottomRows<3>() += m_rotation_axes[static_cast<size_t>(a)].transpose() * (c_i_transpose * reached);
      }
    }
  }
  double* values = m_coarse_matrix.valuePtr();
  long next = 0;
  for_each_lower_entry([&](int, int, int block, int column_in_block, int row_in_block) {
    // Entry (row, column) of block (a, b) is entry (column, row) of its mirror (b, a), the one visited.
    values[next++] = m_coarse_blocks[static_cast<size_t>(block)][static_cast<size_t>(6 * row_in_block + column_in_block)];
  });
  m_coarse_factor.factorize(m_coarse_matrix);
  m_coarse_ok = m_coarse_factor.info() == Eigen::Success && m_coarse_factor.vectorD().minCoeff() > 0.0;
}

void TwoLevelPreconditioner::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  z = m_inverse_diagonal->cwiseProduct(r);
  if (m_local.ok) add_local(r, z);
  if (!m_coarse_ok) return;
  const int count = aggregate_count();
  for (int a = 0; a < count; ++a) {
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (int p = m_aggregate_rows_begin[static_cast<size_t>(a)]; p < m_aggregate_rows_begin[static_cast<size_t>(a) + 1]; ++p) {
      const int row = m_aggregate_rows[static_cast<size_t>(p)];
      const Eigen::Vector3d r_i = r.segment<3>(3L * row);
      force += r_i;
      if (m_with_rotations) moment += m_offset[static_cast<size_t>(row)].cross(r_i);
    }
    const int first = m_column_begin[static_cast<size_t>(a)];
    m_coarse_rhs.segment<3>(first) = m_translation_scale[static_cast<size_t>(a)] * force;
    const int rotations = m_column_begin[static_cast<size_t>(a) + 1] - first - 3;
    // (-[r]x W)^T v = W^T (r x v)
    for (int c = 0; c < rotations; ++c) {
      m_coarse_rhs[first + 3 + c] = m_rotation_axes[static_cast<size_t>(a)].col(c).dot(moment);
    }
  }
  m_coarse_solution = m_coarse_factor.solve(m_coarse_rhs);
  for (int a = 0; a < count; ++a) {
    const int first = m_column_begin[static_cast<size_t>(a)];
    const int rotations = m_column_begin[static_cast<size_t>(a) + 1] - first - 3;
    const Eigen::Vector3d translation = m_translation_scale[static_cast<size_t>(a)] * m_coarse_solution.segment<3>(first);
    Eigen::Vector3d spin = Eigen::Vector3d::Zero();
    for (int c = 0; c < rotations; ++c) spin += m_coarse_solution[first + 3 + c] * m_rotation_axes[static_cast<size_t>(a)].col(c);
    for (int p = m_aggregate_rows_begin[static_cast<size_t>(a)]; p < m_aggregate_rows_begin[static_cast<size_t>(a) + 1]; ++p) {
      const int row = m_aggregate_rows[static_cast<size_t>(p)];
      // -[r]x w = w x r
      z.segment<3>(3L * row) += translation + spin.cross(m_offset[static_cast<size_t>(row)]);
    }
  }
}

}  // namespace tissue
