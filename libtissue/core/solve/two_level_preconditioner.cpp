// TwoLevelPreconditioner: aggregates, their rigid-motion coarse space, the coarse matrix and its
// factor, and the additive two-level application (two_level_preconditioner.hpp).
#include "core/solve/two_level_preconditioner.hpp"
#include "core/system/cross_matrix.hpp"
#include "core/system/hot_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace tissue {

void TwoLevelPreconditioner::setup(const ShiftedSystem& system, const Eigen::VectorXd& inverse_diagonal,
                                   WorkTeam* team) {
  m_inverse_diagonal = &inverse_diagonal;
  const bool aggregated = !aggregates_fit(system);
  const bool refresh_due = m_setups_since_coarse + 1 >= COARSE_REFRESH_SETUPS;
  if (aggregated) {
    // The rows the cuts since the aggregation changed, aggregated apart (the local level), if they can be.
    const bool local = patch_fits(system) || (patchable(system) && aggregate_changed_rows(system));
    if (local && !refresh_due && (m_local.ok || factorize_local(system))) {
      ++m_setups_since_coarse;  // the coarse level made before serves, with the local level beside it
      return;
    }
    // A refresh due (or the local level's matrix not positive definite): the local level's
    // aggregates join the coarse level; else (too many rows changed) every row is aggregated anew.
    if (local) {
      merge_local_level(system);
    } else {
      m_with_rotations = system.block_positions != nullptr;
      aggregate(system);  // with this setup's basis
    }
    m_setups_since_coarse = COARSE_REFRESH_SETUPS;  // a coarse level now
  }
  if (++m_setups_since_coarse < COARSE_REFRESH_SETUPS) return;
  m_setups_since_coarse = 0;
  if (!aggregated) m_coarse.make_basis(system.block_positions, /*count_rotations=*/false);
  assemble_and_factorize(system, team);
  m_can_patch = m_coarse_ok;
}

void TwoLevelPreconditioner::setup_nearby(const ShiftedSystem& system, const Eigen::VectorXd& inverse_diagonal,
                                          WorkTeam* team) {
  if (!aggregates_fit(system) && !patch_fits(system)) {
    setup(system, inverse_diagonal, team);
    return;
  }
  m_inverse_diagonal = &inverse_diagonal;
}

bool TwoLevelPreconditioner::aggregates_fit(const ShiftedSystem& system) const {
  const BlockSparseMatrix& k = *system.stiffness;
  return &k == m_matrix && k.pattern_revision() == m_pattern_revision && k.layout_revision() == m_layout_revision &&
         k.block_rows() == m_rows && (system.block_positions != nullptr) == m_with_rotations;
}

namespace {

std::vector<int> every_row(int rows) {
  std::vector<int> all(static_cast<size_t>(rows));
  std::iota(all.begin(), all.end(), 0);
  return all;
}

}  // namespace

void TwoLevelPreconditioner::aggregate(const ShiftedSystem& system) {
  const std::vector<int> all = every_row(system.stiffness->block_rows());
  const StrongGraph graph(system, all, all, STRENGTH);
  adopt_aggregates(system, aggregate_rows(AGGREGATE_REACH, graph, m_aggregate_of_row));
}

void TwoLevelPreconditioner::merge_local_level(const ShiftedSystem& system) {
  const int rows = system.stiffness->block_rows();
  // The earlier aggregates none of whose rows is the local level's keep their rows, renumbered in
  // order; the local level's follow. (A touched aggregate's rows are all the local level's.)
  std::vector<int> kept_as(static_cast<size_t>(aggregate_count()), 0);
  for (const int i : m_local.rows) {
    const int a = i < m_rows ? m_aggregate_of_row[static_cast<size_t>(i)] : -1;
    if (a >= 0) kept_as[static_cast<size_t>(a)] = -1;
  }
  int count = 0;
  for (int& a : kept_as) a = a < 0 ? -1 : count++;
  m_aggregate_of_row.resize(static_cast<size_t>(rows), -1);
  for (int i = 0; i < rows; ++i) {
    int& a = m_aggregate_of_row[static_cast<size_t>(i)];
    const int l = m_local.local_of[static_cast<size_t>(i)];
    if (l >= 0) {
      const int b = m_local.aggregate_of[static_cast<size_t>(l)];
      a = b < 0 ? -1 : count + b;
    } else if (a >= 0) {
      a = kept_as[static_cast<size_t>(a)];
    }
  }
  adopt_aggregates(system, count + m_local.aggregates.count());
}

void TwoLevelPreconditioner::adopt_aggregates(const ShiftedSystem& system, int count) {
  const BlockSparseMatrix& k = *system.stiffness;
  const int rows = k.block_rows();
  m_aggregated_row_size.resize(static_cast<size_t>(rows));
  for (int i = 0; i < rows; ++i) m_aggregated_row_size[static_cast<size_t>(i)] = k.row_size(i);
  m_local.ok = false;
  m_coarse.group(every_row(rows), m_aggregate_of_row, count, m_entry_of_row);
  m_coarse.make_basis(system.block_positions, /*count_rotations=*/true);
  for (int part = 0; part <= MAX_STEP_THREADS; ++part) {
    m_aggregate_split[static_cast<size_t>(part)] = m_coarse.split(part, MAX_STEP_THREADS);
  }

  make_coarse_pattern(k);
  m_matrix = &k;
  m_pattern_revision = k.pattern_revision();
  m_layout_revision = k.layout_revision();
  m_rows = rows;
}

// The coarse block pattern (aggregate pairs that share a fine block), each fine slot's block, and
// the coarse factor's analysis of it.
void TwoLevelPreconditioner::make_coarse_pattern(const BlockSparseMatrix& k) {
  const int count = aggregate_count();
  // Per aggregate a (its rows in m_coarse.rows): the aggregates its rows' blocks reach, in
  // ascending order, and each of those slots' coarse block; `position[b]` is b's block in a's row
  // while `seen[b] == a`.
  std::vector<int> seen(static_cast<size_t>(count), -1);
  std::vector<int> position(static_cast<size_t>(count), -1);
  m_coarse_row_begin.assign(static_cast<size_t>(count) + 1, 0);
  m_coarse_column.clear();
  m_coarse_block_of_slot.assign(static_cast<size_t>(k.slot_capacity()), -1);
  for (int a = 0; a < count; ++a) {
    const size_t first = m_coarse_column.size();
    for (int p = m_coarse.aggregate_begin[static_cast<size_t>(a)]; p < m_coarse.aggregate_begin[static_cast<size_t>(a) + 1]; ++p) {
      const int i = m_coarse.rows[static_cast<size_t>(p)];
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
    for (int p = m_coarse.aggregate_begin[static_cast<size_t>(a)]; p < m_coarse.aggregate_begin[static_cast<size_t>(a) + 1]; ++p) {
      const int i = m_coarse.rows[static_cast<size_t>(p)];
      for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
        const int j = k.slot_column(s);
        const int b = j >= 0 ? m_aggregate_of_row[static_cast<size_t>(j)] : -1;
        if (b >= 0) m_coarse_block_of_slot[static_cast<size_t>(s)] = position[static_cast<size_t>(b)];
      }
    }
    m_coarse_row_begin[static_cast<size_t>(a) + 1] = static_cast<int>(m_coarse_column.size());
  }
  m_coarse_blocks.assign(m_coarse_column.size(), {});
  m_coarse_factor.analyze(m_coarse_row_begin, m_coarse_column, m_coarse.column_begin);
  m_coarse_rhs.resize(m_coarse.columns());
  m_coarse_solution.resize(m_coarse.columns());
}

namespace {

// to -= b [r]x, column by column: ([r]x)'s columns are (0, rz, -ry), (-rz, 0, rx), (ry, -rx, 0).
[[gnu::always_inline]] inline void subtract_times_cross(const Eigen::Matrix3d& b, const Eigen::Vector3d& r,
                                                        Eigen::Matrix3d& to) {
  to.col(0) -= r.z() * b.col(1) - r.y() * b.col(2);
  to.col(1) -= r.x() * b.col(2) - r.z() * b.col(0);
  to.col(2) -= r.y() * b.col(0) - r.x() * b.col(1);
}

}  // namespace

// Coarse block (a, b), a <= b, is the sum over rows i of a and j of b of P_i^T A_ij P_j, with
// P_j = [t_b I, C_j W_b] and C_j = -[r_j]x. Row by row, over the aggregates b >= a its blocks reach:
// S = sum_j A_ij and T = sum_j A_ij C_j (of K's blocks, 18 multiply-adds each; s and row i's d_i,
// in (a, a), once per pair); over a's rows, per block: F = sum_i S, M = sum_i T, G = sum_i C_i^T S
// and H = sum_i C_i^T T (C_i^T = [r_i]x), so that each block is made once:
//   [t_a t_b F, t_a M W_b; t_b W_a^T G, W_a^T H W_b].
// K's rows hold both halves, so every pair (i, j) of a block with a <= b is met from row i.
TISSUE_HOT_KERNEL void TwoLevelPreconditioner::assemble_coarse_rows(const ShiftedSystem& system, int first_aggregate,
                                                                    int end_aggregate, AssemblyScratch& scratch) {
  const BlockSparseMatrix& k = *system.stiffness;
  const auto first_block = static_cast<size_t>(m_coarse_row_begin[static_cast<size_t>(first_aggregate)]);
  const auto end_block = static_cast<size_t>(m_coarse_row_begin[static_cast<size_t>(end_aggregate)]);
  for (size_t block = first_block; block < end_block; ++block) m_coarse_blocks[block].fill(0.0);
  for (int a = first_aggregate; a < end_aggregate; ++a) {
    const int first_block_of_a = m_coarse_row_begin[static_cast<size_t>(a)];
    const auto reach = static_cast<size_t>(m_coarse_row_begin[static_cast<size_t>(a) + 1] - first_block_of_a);
    if (scratch.row_sums.size() < reach) scratch.row_sums.resize(reach);
    if (scratch.aggregate_sums.size() < reach) scratch.aggregate_sums.resize(reach);
    for (size_t q = 0; q < reach; ++q) {
      AggregateSums& total = scratch.aggregate_sums[q];
      total.force.setZero();
      total.moment.setZero();
      total.turned_force.setZero();
      total.turned_moment.setZero();
    }
    for (int p = m_coarse.aggregate_begin[static_cast<size_t>(a)]; p < m_coarse.aggregate_begin[static_cast<size_t>(a) + 1];
         ++p) {
      const int i = m_coarse.rows[static_cast<size_t>(p)];
      scratch.touched.clear();
      for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
        const int j = k.slot_column(s);
        if (j < 0) continue;
        const int coarse_block = m_coarse_block_of_slot[static_cast<size_t>(s)];
        if (coarse_block < 0 || m_coarse_column[static_cast<size_t>(coarse_block)] < a) continue;
        const Eigen::Matrix3d& block = k.block(s);  // K's; s K + diag(d) applied once per pair below
        RowSums& sums = scratch.row_sums[static_cast<size_t>(coarse_block - first_block_of_a)];
        if (!sums.used) {
          sums = RowSums{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero(), true};
          scratch.touched.push_back(coarse_block);
        }
        sums.force += block;
        if (m_with_rotations) subtract_times_cross(block, offset_of_row(j), sums.moment);
      }
      const Eigen::Vector3d& r_i = offset_of_row(i);
      const Eigen::Matrix3d c_i_transpose = cross_matrix(r_i);  // C_i^T = [r_i]x
      for (const int coarse_block : scratch.touched) {
        RowSums& sums = scratch.row_sums[static_cast<size_t>(coarse_block - first_block_of_a)];
        sums.used = false;
        sums.force *= system.stiffness_scale;
        sums.moment *= system.stiffness_scale;
        if (m_coarse_column[static_cast<size_t>(coarse_block)] == a) {  // row i's diagonal block is in (a, a)
          const Eigen::Matrix3d d = system.diagonal->segment<3>(3L * i).asDiagonal();
          sums.force += d;
          if (m_with_rotations) subtract_times_cross(d, r_i, sums.moment);
        }
        AggregateSums& total = scratch.aggregate_sums[static_cast<size_t>(coarse_block - first_block_of_a)];
        total.force += sums.force;
        total.turned_force.noalias() += c_i_transpose * sums.force;
        if (m_with_rotations) {
          total.moment += sums.moment;
          total.turned_moment.noalias() += c_i_transpose * sums.moment;
        }
      }
    }
    // The blocks (a, b): [t_a t_b F, t_a M W_b; t_b W_a^T G, W_a^T H W_b].
    const double t_a = m_coarse.translation_scale[static_cast<size_t>(a)];
    const int rotations_a = m_coarse.rotation_count[static_cast<size_t>(a)];
    const Eigen::Matrix3d& w_a = m_coarse.axes[static_cast<size_t>(a)];
    for (size_t q = 0; q < reach; ++q) {
      const size_t coarse_block = static_cast<size_t>(first_block_of_a) + q;
      const auto b = static_cast<size_t>(m_coarse_column[coarse_block]);
      const double t_b = m_coarse.translation_scale[b];
      const Eigen::Matrix3d& w_b = m_coarse.axes[b];
      const AggregateSums& total = scratch.aggregate_sums[q];
      Eigen::Map<Eigen::Matrix<double, 6, 6>> coarse(m_coarse_blocks[coarse_block].data());
      coarse.topLeftCorner<3, 3>() = (t_a * t_b) * total.force;
      if (m_with_rotations) coarse.topRightCorner<3, 3>() = t_a * (total.moment * w_b);
      if (rotations_a > 0) {
        coarse.bottomLeftCorner<3, 3>() = t_b * (w_a.transpose() * total.turned_force);
        if (m_with_rotations) coarse.bottomRightCorner<3, 3>() = w_a.transpose() * (total.turned_moment * w_b);
      }
    }
  }
}

void TwoLevelPreconditioner::assemble_and_factorize(const ShiftedSystem& system, WorkTeam* team) {
  // Aggregate a's rows give only its blocks (a, b >= a): the halves of the aggregates write disjoint
  // blocks, each block its rows' terms in row order, as one pass over all rows in order did.
  run_parts(team, MAX_STEP_THREADS, [&](int part) {
    assemble_coarse_rows(system, m_aggregate_split[static_cast<size_t>(part)],
                         m_aggregate_split[static_cast<size_t>(part) + 1], m_assembly_scratch[static_cast<size_t>(part)]);
  });
  m_coarse_ok = m_coarse_factor.factorize(m_coarse_blocks);
}

void TwoLevelPreconditioner::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z, WorkTeam* team) {
  constexpr int PARTS = MAX_STEP_THREADS;
  const long rows = r.size();
  z.resize(rows);  // (no allocation when it has the size already)
  // z's terms in one order whoever computes them: D^-1 r, the local level's, the coarse level's.
  run_parts(team, PARTS, [&](int part) {
    const long first = rows * part / PARTS;
    const long end = rows * (part + 1) / PARTS;
    z.segment(first, end - first) = m_inverse_diagonal->segment(first, end - first).cwiseProduct(r.segment(first, end - first));
    if (m_coarse_ok) {
      m_coarse.restrict_to(r, m_coarse_rhs, m_aggregate_split[static_cast<size_t>(part)],
                           m_aggregate_split[static_cast<size_t>(part) + 1]);
    }
  });
  if (m_local.ok) {
    m_local.aggregates.restrict_to(r, m_local.rhs);
    m_local.solution = m_local.factor.solve(m_local.rhs);
    m_local.aggregates.prolong_add(m_local.solution, z);
  }
  if (!m_coarse_ok) return;
  m_coarse_factor.solve(m_coarse_rhs, m_coarse_solution);
  run_parts(team, PARTS, [&](int part) {
    m_coarse.prolong_add(m_coarse_solution, z, m_aggregate_split[static_cast<size_t>(part)],
                         m_aggregate_split[static_cast<size_t>(part) + 1]);
  });
}

}  // namespace tissue
