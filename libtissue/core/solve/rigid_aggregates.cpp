// Aggregates and their rigid-motion columns (rigid_aggregates.hpp).
#include "core/solve/rigid_aggregates.hpp"
#include "core/system/cross_matrix.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace tissue {
namespace {

// W's columns from the second moment J = sum |r|^2 I - r r^T of the points about their centroid:
// principal axes over sqrt(moment), the largest first; `rotations` counted anew when
// `count_rotations` (those whose moment is above ROTATION_RANK_TOLERANCE of the largest).
void rotation_axes(const Eigen::Matrix3d& moment, bool count_rotations, int& rotations, Eigen::Matrix3d& axes) {
  constexpr double TOLERANCE = RigidAggregates::ROTATION_RANK_TOLERANCE;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(moment);
  const Eigen::Vector3d moments = eigen.eigenvalues();  // increasing
  const double largest = moments[2];
  if (count_rotations) {
    rotations = 0;
    for (int c = 0; c < 3; ++c) {
      if (largest > 0.0 && moments[c] > TOLERANCE * largest) ++rotations;
    }
  }
  axes.setZero();
  for (int c = 0; c < rotations; ++c) {
    const int e = 2 - c;  // the largest moments first
    const double moment_e = std::max(moments[e], TOLERANCE * largest);
    axes.col(c) = eigen.eigenvectors().col(e) / std::sqrt(moment_e);
  }
}

}  // namespace

Eigen::Matrix3d system_block(const ShiftedSystem& system, int slot, int row, int column) {
  Eigen::Matrix3d block = system.stiffness_scale * system.stiffness->block(slot);
  if (row == column) block.diagonal() += system.diagonal->segment<3>(3L * row);
  return block;
}

StrongGraph::StrongGraph(const ShiftedSystem& system, const std::vector<int>& rows, const std::vector<int>& local_of,
                         double strength) {
  const BlockSparseMatrix& k = *system.stiffness;
  const int count = static_cast<int>(rows.size());
  std::vector<double> diagonal_norm(static_cast<size_t>(count));
  for (int l = 0; l < count; ++l) {
    const int i = rows[static_cast<size_t>(l)];
    diagonal_norm[static_cast<size_t>(l)] = system_block(system, k.diagonal_slot(i), i, i).norm();
  }
  begin.assign(static_cast<size_t>(count) + 1, 0);
  for (int l = 0; l < count; ++l) {
    const int i = rows[static_cast<size_t>(l)];
    for (int s = k.row_begin(i); s < k.row_begin(i) + k.row_size(i); ++s) {
      const int j = k.slot_column(s);
      const int m = j >= 0 ? local_of[static_cast<size_t>(j)] : -1;
      if (m < 0 || m == l) continue;
      // Off the diagonal A_ij = s K_ij: compared squared, without forming the block.
      const double coupling_squared = system.stiffness_scale * system.stiffness_scale * k.block(s).squaredNorm();
      if (coupling_squared >
          strength * strength * diagonal_norm[static_cast<size_t>(l)] * diagonal_norm[static_cast<size_t>(m)]) {
        column.push_back(m);
        weight.push_back(coupling_squared);  // only compared
      }
    }
    begin[static_cast<size_t>(l) + 1] = static_cast<int>(column.size());
  }
}

int aggregate_rows(int reach, const StrongGraph& graph, std::vector<int>& aggregate_of_row) {
  const int rows = static_cast<int>(graph.begin.size()) - 1;
  const std::vector<int>& strong_begin = graph.begin;
  const std::vector<int>& strong_column = graph.column;
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
      const int a = phase_one[static_cast<size_t>(strong_column[static_cast<size_t>(e)])];
      if (a >= 0 && graph.weight[static_cast<size_t>(e)] > strongest) {
        strongest = graph.weight[static_cast<size_t>(e)];
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

void RigidAggregates::group(const std::vector<int>& row_of, const std::vector<int>& aggregate_of, int count,
                            std::vector<int>& entry_of) {
  aggregate_begin.assign(static_cast<size_t>(count) + 1, 0);
  for (const int a : aggregate_of) {
    if (a >= 0) ++aggregate_begin[static_cast<size_t>(a) + 1];
  }
  for (int a = 0; a < count; ++a) aggregate_begin[static_cast<size_t>(a) + 1] += aggregate_begin[static_cast<size_t>(a)];
  rows.resize(static_cast<size_t>(aggregate_begin.back()));
  std::vector<int> fill(aggregate_begin.begin(), aggregate_begin.end() - 1);
  entry_of.assign(aggregate_of.size(), -1);
  for (size_t l = 0; l < aggregate_of.size(); ++l) {
    const int a = aggregate_of[l];
    if (a < 0) continue;
    entry_of[l] = fill[static_cast<size_t>(a)];
    rows[static_cast<size_t>(fill[static_cast<size_t>(a)]++)] = row_of[l];
  }
  offset.assign(rows.size(), Eigen::Vector3d::Zero());
  translation_scale.assign(static_cast<size_t>(count), 0.0);
  axes.assign(static_cast<size_t>(count), Eigen::Matrix3d::Zero());
  rotation_count.assign(static_cast<size_t>(count), 0);
  column_begin.assign(static_cast<size_t>(count) + 1, 0);
}

void RigidAggregates::make_basis(const std::vector<Eigen::Vector3d>* points, bool count_rotations) {
  for (int a = 0; a < count(); ++a) {
    const int begin = aggregate_begin[static_cast<size_t>(a)];
    const int end = aggregate_begin[static_cast<size_t>(a) + 1];
    translation_scale[static_cast<size_t>(a)] = 1.0 / std::sqrt(static_cast<double>(end - begin));
    if (points != nullptr) {
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int p = begin; p < end; ++p) centroid += (*points)[static_cast<size_t>(rows[static_cast<size_t>(p)])];
      centroid /= static_cast<double>(end - begin);
      Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
      for (int p = begin; p < end; ++p) {
        const Eigen::Vector3d r = (*points)[static_cast<size_t>(rows[static_cast<size_t>(p)])] - centroid;
        offset[static_cast<size_t>(p)] = r;
        moment += r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose();
      }
      rotation_axes(moment, count_rotations, rotation_count[static_cast<size_t>(a)], axes[static_cast<size_t>(a)]);
    }
    if (count_rotations) {
      column_begin[static_cast<size_t>(a) + 1] = column_begin[static_cast<size_t>(a)] + 3 + rotation_count[static_cast<size_t>(a)];
    }
  }
}

Eigen::Matrix<double, 3, 6> RigidAggregates::basis(int a, int p) const {
  Eigen::Matrix<double, 3, 6> columns = Eigen::Matrix<double, 3, 6>::Zero();
  columns.leftCols<3>() = translation_scale[static_cast<size_t>(a)] * Eigen::Matrix3d::Identity();
  columns.rightCols<3>() = -cross_matrix(offset[static_cast<size_t>(p)]) * axes[static_cast<size_t>(a)];
  return columns;
}

void RigidAggregates::restrict_to(const Eigen::VectorXd& r, Eigen::VectorXd& rhs, int first_aggregate,
                                  int end_aggregate) const {
  for (int a = first_aggregate; a < end_aggregate; ++a) {
    const int rotations = rotation_count[static_cast<size_t>(a)];
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (int p = aggregate_begin[static_cast<size_t>(a)]; p < aggregate_begin[static_cast<size_t>(a) + 1]; ++p) {
      const Eigen::Vector3d r_i = r.segment<3>(3L * rows[static_cast<size_t>(p)]);
      force += r_i;
      if (rotations > 0) moment += offset[static_cast<size_t>(p)].cross(r_i);
    }
    const int first = column_begin[static_cast<size_t>(a)];
    rhs.segment<3>(first) = translation_scale[static_cast<size_t>(a)] * force;
    // (-[r]x W)^T v = W^T (r x v)
    for (int c = 0; c < rotations; ++c) rhs[first + 3 + c] = axes[static_cast<size_t>(a)].col(c).dot(moment);
  }
}

void RigidAggregates::prolong_add(const Eigen::VectorXd& x, Eigen::VectorXd& z, int first_aggregate,
                                  int end_aggregate) const {
  for (int a = first_aggregate; a < end_aggregate; ++a) {
    const int first = column_begin[static_cast<size_t>(a)];
    const Eigen::Vector3d translation = translation_scale[static_cast<size_t>(a)] * x.segment<3>(first);
    Eigen::Vector3d spin = Eigen::Vector3d::Zero();
    for (int c = 0; c < rotation_count[static_cast<size_t>(a)]; ++c) {
      spin += x[first + 3 + c] * axes[static_cast<size_t>(a)].col(c);
    }
    for (int p = aggregate_begin[static_cast<size_t>(a)]; p < aggregate_begin[static_cast<size_t>(a) + 1]; ++p) {
      // -[r]x w = w x r
      z.segment<3>(3L * rows[static_cast<size_t>(p)]) += translation + spin.cross(offset[static_cast<size_t>(p)]);
    }
  }
}

int RigidAggregates::split(int part, int parts) const {
  if (part >= parts) return count();
  const long rows_before = static_cast<long>(rows.size()) * part / parts;
  // The first aggregate that starts at or after the part's share of the rows.
  const auto at = std::lower_bound(aggregate_begin.begin(), aggregate_begin.end() - 1, rows_before);
  return static_cast<int>(at - aggregate_begin.begin());
}

}  // namespace tissue
