// TwoLevelPreconditioner's local level (two_level_preconditioner.hpp): after a cut between coarse
// refreshes, the rows of the aggregates the cut touched (that hold a row it added blocks to) and
// the cut's new rows are aggregated anew and get a coarse matrix of their own, instead of a new
// aggregation of the whole matrix; the coarse level made before serves beside them:
//   P^-1 r = D^-1 r + Pc Ac^-1 Pc^T r + Pl Al^-1 Pl^T r,
// each term positive (semi)definite, so P stays positive definite. The full aggregation waits for
// the next coarse refresh (every COARSE_REFRESH_SETUPS setups).
#include "core/solve/two_level_preconditioner.hpp"
#include "core/system/cross_matrix.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace tissue {
namespace {

// A patch serves up to this many rows (else the whole matrix is aggregated anew at once).
constexpr int MIN_PATCH_ROWS_LIMIT = 64;
constexpr int PATCH_ROWS_DIVISOR = 2;  // ... or half the rows, if more


Eigen::Matrix3d system_block(const ShiftedSystem& system, int slot, int row, int column) {
  Eigen::Matrix3d block = system.stiffness_scale * system.stiffness->block(slot);
  if (row == column) block.diagonal() += system.diagonal->segment<3>(3L * row);
  return block;
}

// The strong couplings among `local_rows` (local_of: row -> its index there, or -1), CSR over
// those indices, as TwoLevelPreconditioner::aggregate() judges them.
void strong_graph(const ShiftedSystem& system, const std::vector<int>& local_rows, const std::vector<int>& local_of,
                  std::vector<int>& strong_begin, std::vector<int>& strong_column, std::vector<double>& strong_weight) {
  const BlockSparseMatrix& k = *system.stiffness;
  const int count = static_cast<int>(local_rows.size());
  constexpr double STRENGTH = TwoLevelPreconditioner::STRENGTH;
  std::vector<double> diagonal_norm(static_cast<size_t>(count));
  for (int l = 0; l < count; ++l) {
    const int i = local_rows[static_cast<size_t>(l)];
    diagonal_norm[static_cast<size_t>(l)] = system_block(system, k.diagonal_slot(i), i, i).norm();
  }
  strong_begin.assign(static_cast<size_t>(count) + 1, 0);
  for (int l = 0; l < count; ++l) {
    const int i = local_rows[static_cast<size_t>(l)];
    for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
      const int j = k.slot_column(s);
      const int m = j >= 0 ? local_of[static_cast<size_t>(j)] : -1;
      if (m < 0 || m == l) continue;
      const double coupling_squared = system.stiffness_scale * system.stiffness_scale * k.block(s).squaredNorm();
      if (coupling_squared >
          STRENGTH * STRENGTH * diagonal_norm[static_cast<size_t>(l)] * diagonal_norm[static_cast<size_t>(m)]) {
        strong_column.push_back(m);
        strong_weight.push_back(coupling_squared);
      }
    }
    strong_begin[static_cast<size_t>(l) + 1] = static_cast<int>(strong_column.size());
  }
}

}  // namespace

bool TwoLevelPreconditioner::patchable(const ShiftedSystem& system) const {
  const BlockSparseMatrix& k = *system.stiffness;
  return m_can_patch && m_coarse_ok && &k == m_matrix && k.block_rows() >= m_rows &&
         (system.block_positions != nullptr) == m_with_rotations;
}

bool TwoLevelPreconditioner::patch_fits(const ShiftedSystem& system) const {
  const BlockSparseMatrix& k = *system.stiffness;
  return m_local.ok && m_can_patch && &k == m_matrix && k.pattern_revision() == m_local.pattern_revision &&
         k.layout_revision() == m_local.layout_revision && k.block_rows() == m_local.rows_of_k &&
         (system.block_positions != nullptr) == m_with_rotations;
}

bool TwoLevelPreconditioner::patch(const ShiftedSystem& system) {
  const BlockSparseMatrix& k = *system.stiffness;
  const int rows = k.block_rows();
  // The rows the cuts since the aggregation added, or gave blocks (their couplings changed), and
  // every row of an aggregate that holds one of those: aggregated anew here, either side of the cut
  // apart (the changed rows alone left the freed frog 2.7% behind the exact fall after 0.2 s
  // instead of 1.6%; leaving those aggregates out of the coarse level instead, 11%).
  std::vector<int> local_rows;
  std::vector<char> touched(static_cast<size_t>(aggregate_count()), 0);
  for (int i = 0; i < rows; ++i) {
    if (i < m_rows && k.row_size(i) == m_aggregated_row_size[static_cast<size_t>(i)]) continue;
    local_rows.push_back(i);
    const int a = i < m_rows ? m_aggregate_of_row[static_cast<size_t>(i)] : -1;
    if (a >= 0) touched[static_cast<size_t>(a)] = 1;
  }
  for (int i = 0; i < m_rows; ++i) {
    const int a = m_aggregate_of_row[static_cast<size_t>(i)];
    if (a >= 0 && touched[static_cast<size_t>(a)] != 0 && k.row_size(i) == m_aggregated_row_size[static_cast<size_t>(i)]) {
      local_rows.push_back(i);
    }
  }
  std::sort(local_rows.begin(), local_rows.end());
  const int count = static_cast<int>(local_rows.size());
  if (count == 0 || count > std::max(MIN_PATCH_ROWS_LIMIT, rows / PATCH_ROWS_DIVISOR)) return false;
  LocalLevel& level = m_local;  // made in place (its vectors keep their room)
  level.ok = false;
  std::vector<int> local_of(static_cast<size_t>(rows), -1);
  for (int l = 0; l < count; ++l) local_of[static_cast<size_t>(local_rows[static_cast<size_t>(l)])] = l;

  // Strong couplings among them (as aggregate() judges them) and their aggregates.
  std::vector<int> strong_begin;
  std::vector<int> strong_column;
  std::vector<double> strong_weight;
  strong_graph(system, local_rows, local_of, strong_begin, strong_column, strong_weight);
  std::vector<int> aggregate_of;
  const int aggregates = aggregate_within(AGGREGATE_REACH, count, strong_begin, strong_column, strong_weight, aggregate_of);

  level.aggregate_begin.assign(static_cast<size_t>(aggregates) + 1, 0);
  for (const int a : aggregate_of) {
    if (a >= 0) ++level.aggregate_begin[static_cast<size_t>(a) + 1];
  }
  for (int a = 0; a < aggregates; ++a) level.aggregate_begin[static_cast<size_t>(a) + 1] += level.aggregate_begin[static_cast<size_t>(a)];
  level.rows.resize(static_cast<size_t>(level.aggregate_begin.back()));
  std::vector<int> fill(level.aggregate_begin.begin(), level.aggregate_begin.end() - 1);
  std::vector<int> position_of(static_cast<size_t>(count), -1);  // local row -> its entry in level.rows
  for (int l = 0; l < count; ++l) {
    const int a = aggregate_of[static_cast<size_t>(l)];
    if (a < 0) continue;
    position_of[static_cast<size_t>(l)] = fill[static_cast<size_t>(a)];
    level.rows[static_cast<size_t>(fill[static_cast<size_t>(a)]++)] = local_rows[static_cast<size_t>(l)];
  }

  // The rigid motions of each aggregate (as make_basis), its columns.
  level.offset.assign(level.rows.size(), Eigen::Vector3d::Zero());
  level.translation_scale.assign(static_cast<size_t>(aggregates), 0.0);
  level.axes.assign(static_cast<size_t>(aggregates), Eigen::Matrix3d::Zero());
  level.rotation_count.assign(static_cast<size_t>(aggregates), 0);
  level.column_begin.assign(static_cast<size_t>(aggregates) + 1, 0);
  for (int a = 0; a < aggregates; ++a) {
    const int begin = level.aggregate_begin[static_cast<size_t>(a)];
    const int end = level.aggregate_begin[static_cast<size_t>(a) + 1];
    level.translation_scale[static_cast<size_t>(a)] = 1.0 / std::sqrt(static_cast<double>(end - begin));
    if (m_with_rotations) {
      const std::vector<Eigen::Vector3d>& points = *system.block_positions;
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int p = begin; p < end; ++p) centroid += points[static_cast<size_t>(level.rows[static_cast<size_t>(p)])];
      centroid /= static_cast<double>(end - begin);
      Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
      for (int p = begin; p < end; ++p) {
        const Eigen::Vector3d r = points[static_cast<size_t>(level.rows[static_cast<size_t>(p)])] - centroid;
        level.offset[static_cast<size_t>(p)] = r;
        moment += r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose();
      }
      rotation_axes(moment, /*count_rotations=*/true, level.rotation_count[static_cast<size_t>(a)],
                    level.axes[static_cast<size_t>(a)]);
    }
    level.column_begin[static_cast<size_t>(a) + 1] =
        level.column_begin[static_cast<size_t>(a)] + 3 + level.rotation_count[static_cast<size_t>(a)];
  }

  factorize_local(system, local_rows, local_of, aggregate_of, position_of);
  const int columns = level.column_begin.back();
  level.ok = columns > 0 && level.factor.info() == Eigen::Success && (level.factor.vectorD().array() > 0.0).all();
  level.rhs.resize(columns);
  level.solution.resize(columns);
  level.pattern_revision = k.pattern_revision();
  level.layout_revision = k.layout_revision();
  level.rows_of_k = rows;
  return level.ok;
}

// Al = Pl^T A Pl, dense: P_i = [t_a I, -[r_i]x W_a] for row i of aggregate a; factorized (LDL^T).
void TwoLevelPreconditioner::factorize_local(const ShiftedSystem& system, const std::vector<int>& local_rows,
                                             const std::vector<int>& local_of, const std::vector<int>& aggregate_of,
                                             const std::vector<int>& position_of) {
  const BlockSparseMatrix& k = *system.stiffness;
  LocalLevel& level = m_local;
  const int count = static_cast<int>(local_rows.size());
  const int columns = level.column_begin.back();
  const auto basis_of = [&](int l) {
    const int p = position_of[static_cast<size_t>(l)];
    const int a = aggregate_of[static_cast<size_t>(l)];
    const int rotations = level.rotation_count[static_cast<size_t>(a)];
    Eigen::Matrix<double, 3, 6> basis = Eigen::Matrix<double, 3, 6>::Zero();
    basis.leftCols<3>() = level.translation_scale[static_cast<size_t>(a)] * Eigen::Matrix3d::Identity();
    basis.rightCols<3>() = -cross_matrix(level.offset[static_cast<size_t>(p)]) * level.axes[static_cast<size_t>(a)];
    return std::pair{basis, 3 + rotations};
  };
  Eigen::MatrixXd matrix = Eigen::MatrixXd::Zero(columns, columns);
  for (int l = 0; l < count; ++l) {
    const int a = aggregate_of[static_cast<size_t>(l)];
    if (a < 0) continue;
    const int i = local_rows[static_cast<size_t>(l)];
    const auto [p_i, width_i] = basis_of(l);
    for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
      const int j = k.slot_column(s);
      const int m = j >= 0 ? local_of[static_cast<size_t>(j)] : -1;
      if (m < 0 || aggregate_of[static_cast<size_t>(m)] < 0) continue;
      const int b = aggregate_of[static_cast<size_t>(m)];
      const auto [p_j, width_j] = basis_of(m);
      const Eigen::Matrix<double, 6, 6> block = p_i.transpose() * system_block(system, s, i, j) * p_j;
      matrix.block(level.column_begin[static_cast<size_t>(a)], level.column_begin[static_cast<size_t>(b)], width_i, width_j) +=
          block.topLeftCorner(width_i, width_j);
    }
  }
  level.factor.compute(matrix);
}

void TwoLevelPreconditioner::add_local(const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  const int aggregates = static_cast<int>(m_local.aggregate_begin.size()) - 1;
  for (int a = 0; a < aggregates; ++a) {
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (int p = m_local.aggregate_begin[static_cast<size_t>(a)]; p < m_local.aggregate_begin[static_cast<size_t>(a) + 1]; ++p) {
      const Eigen::Vector3d r_i = r.segment<3>(3L * m_local.rows[static_cast<size_t>(p)]);
      force += r_i;
      moment += m_local.offset[static_cast<size_t>(p)].cross(r_i);
    }
    const int first = m_local.column_begin[static_cast<size_t>(a)];
    m_local.rhs.segment<3>(first) = m_local.translation_scale[static_cast<size_t>(a)] * force;
    for (int c = 0; c < m_local.rotation_count[static_cast<size_t>(a)]; ++c) {
      m_local.rhs[first + 3 + c] = m_local.axes[static_cast<size_t>(a)].col(c).dot(moment);
    }
  }
  m_local.solution = m_local.factor.solve(m_local.rhs);
  for (int a = 0; a < aggregates; ++a) {
    const int first = m_local.column_begin[static_cast<size_t>(a)];
    const Eigen::Vector3d translation = m_local.translation_scale[static_cast<size_t>(a)] * m_local.solution.segment<3>(first);
    Eigen::Vector3d spin = Eigen::Vector3d::Zero();
    for (int c = 0; c < m_local.rotation_count[static_cast<size_t>(a)]; ++c) {
      spin += m_local.solution[first + 3 + c] * m_local.axes[static_cast<size_t>(a)].col(c);
    }
    for (int p = m_local.aggregate_begin[static_cast<size_t>(a)]; p < m_local.aggregate_begin[static_cast<size_t>(a) + 1]; ++p) {
      z.segment<3>(3L * m_local.rows[static_cast<size_t>(p)]) += translation + spin.cross(m_local.offset[static_cast<size_t>(p)]);
    }
  }
}

}  // namespace tissue
