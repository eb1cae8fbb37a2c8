// TwoLevelPreconditioner's local level (two_level_preconditioner.hpp): after a cut between coarse
// refreshes, the rows of the aggregates the cut touched (that hold a row it added blocks to) and
// the cut's new rows are aggregated anew and get a coarse matrix of their own, instead of a new
// aggregation of the whole matrix; the coarse level made before serves beside them:
//   P^-1 r = D^-1 r + Pc Ac^-1 Pc^T r + Pl Al^-1 Pl^T r,
// each term positive (semi)definite, so P stays positive definite. At the next coarse refresh
// (every COARSE_REFRESH_SETUPS setups) the local level's aggregates take the place of those it
// replaced in the coarse level (merge_local_level): the whole matrix is not aggregated anew.
#include "core/solve/two_level_preconditioner.hpp"

#include <algorithm>
#include <cmath>

namespace tissue {
namespace {

// A patch serves up to this many rows (else the whole matrix is aggregated anew at once).
constexpr int MIN_PATCH_ROWS_LIMIT = 64;
constexpr int PATCH_ROWS_DIVISOR = 2;  // ... or half the rows, if more

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

bool TwoLevelPreconditioner::aggregate_changed_rows(const ShiftedSystem& system) {
  const BlockSparseMatrix& k = *system.stiffness;
  const int rows = k.block_rows();
  LocalLevel& level = m_local;  // made in place (its vectors keep their room)
  level.ok = false;
  // The rows the cuts since the aggregation added, or gave blocks (their couplings changed), and
  // every row of an aggregate that holds one of those: aggregated anew here, either side of the cut
  // apart (the changed rows alone left the freed frog 2.7% behind the exact fall after 0.2 s
  // instead of 1.6%; leaving those aggregates out of the coarse level instead, 11%).
  std::vector<int>& local_rows = level.rows;
  local_rows.clear();
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
  level.local_of.assign(static_cast<size_t>(rows), -1);
  for (int l = 0; l < count; ++l) level.local_of[static_cast<size_t>(local_rows[static_cast<size_t>(l)])] = l;

  // Strong couplings among them (as aggregate() judges them), their aggregates and rigid motions.
  const StrongGraph graph(system, local_rows, level.local_of, STRENGTH);
  const int aggregates = aggregate_rows(AGGREGATE_REACH, graph, level.aggregate_of);
  level.aggregates.group(local_rows, level.aggregate_of, aggregates, level.entry_of);
  level.aggregates.make_basis(system.block_positions, /*count_rotations=*/true);  // given as at the aggregation (patchable)
  return true;
}

// Al = Pl^T A Pl, dense (RigidAggregates::basis); factorized (LDL^T). Row i of aggregate a, per
// aggregate b its blocks reach: S_b = sum_j A_ij P_j over the rows j of b, then Al_ab += P_i^T S_b.
bool TwoLevelPreconditioner::factorize_local(const ShiftedSystem& system) {
  const BlockSparseMatrix& k = *system.stiffness;
  LocalLevel& local = m_local;
  const RigidAggregates& level = local.aggregates;
  const int count = static_cast<int>(local.rows.size());
  const int columns = level.columns();
  const auto width = [&](int a) { return 3 + level.rotation_count[static_cast<size_t>(a)]; };
  Eigen::MatrixXd matrix = Eigen::MatrixXd::Zero(columns, columns);
  std::vector<Eigen::Matrix<double, 3, 6>> sums(static_cast<size_t>(level.count()));
  std::vector<int> reached;  // the aggregates b row i reaches, each once
  std::vector<char> is_reached(static_cast<size_t>(level.count()), 0);
  for (int l = 0; l < count; ++l) {
    const int a = local.aggregate_of[static_cast<size_t>(l)];
    if (a < 0) continue;
    const int i = local.rows[static_cast<size_t>(l)];
    reached.clear();
    for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
      const int j = k.slot_column(s);
      const int m = j >= 0 ? local.local_of[static_cast<size_t>(j)] : -1;
      const int b = m >= 0 ? local.aggregate_of[static_cast<size_t>(m)] : -1;
      if (b < 0) continue;
      if (is_reached[static_cast<size_t>(b)] == 0) {
        is_reached[static_cast<size_t>(b)] = 1;
        reached.push_back(b);
        sums[static_cast<size_t>(b)].setZero();
      }
      sums[static_cast<size_t>(b)].noalias() +=
          system_block(system, s, i, j) * level.basis(b, local.entry_of[static_cast<size_t>(m)]);
    }
    const Eigen::Matrix<double, 3, 6> p_i = level.basis(a, local.entry_of[static_cast<size_t>(l)]);
    for (const int b : reached) {
      is_reached[static_cast<size_t>(b)] = 0;
      const Eigen::Matrix<double, 6, 6> block = p_i.transpose() * sums[static_cast<size_t>(b)];
      matrix.block(level.column_begin[static_cast<size_t>(a)], level.column_begin[static_cast<size_t>(b)], width(a), width(b)) +=
          block.topLeftCorner(width(a), width(b));
    }
  }
  local.factor.compute(matrix);
  local.ok = columns > 0 && local.factor.info() == Eigen::Success && (local.factor.vectorD().array() > 0.0).all();
  local.rhs.resize(columns);
  local.solution.resize(columns);
  local.pattern_revision = k.pattern_revision();
  local.layout_revision = k.layout_revision();
  local.rows_of_k = k.block_rows();
  return local.ok;
}

}  // namespace tissue
