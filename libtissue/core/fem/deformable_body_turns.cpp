// DeformableBody: how far a displacement increment turns its elements (the Newton corrections'
// trigger, the energy guard's rule and the rows it brakes), each uncut tet and live cut piece measured
// from its rotation at the last evaluate().
#include "core/fem/deformable_body.hpp"
#include "core/system/hot_kernel.hpp"
#include "core/system/work_team.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace tissue {
namespace {

// |axial vector of skew(R^T G)|, G = sum_i du_i grad(phi_i)^T: the angle a displacement increment
// du turns a tet of rotation R (to first order).
double turn_angle_rad(const TetRest& rest, const Eigen::Matrix3d& rotation, const TetPositions& increment_m) {
  const Eigen::Matrix3d w = rotation.transpose() * deformation_gradient(rest, increment_m);
  return 0.5 * Eigen::Vector3d(w(2, 1) - w(1, 2), w(0, 2) - w(2, 0), w(1, 0) - w(0, 1)).norm();
}

// The increments of an element's four block rows (-1: a fixed vertex, which does not move).
TetPositions row_increments(const std::array<int, 4>& rows, const Eigen::VectorXd& increment_m) {
  TetPositions increment;
  for (size_t j = 0; j < 4; ++j) {
    increment[j] = rows[j] < 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(increment_m.segment<3>(3 * rows[j]));
  }
  return increment;
}

// Each of `largest`'s two turns raised to the element's where that is larger.
void take_larger(std::array<double, 2>& largest, const std::array<double, 2>& turn_rad) {
  largest[0] = std::max(largest[0], turn_rad[0]);
  largest[1] = std::max(largest[1], turn_rad[1]);
}

}  // namespace

double DeformableBody::turn_bound_rad(const Eigen::VectorXd& increment_m) const {
  check_unknowns(increment_m);
  double largest_block_m = 0.0;
  for (Eigen::Index row = 0; row < increment_m.size() / 3; ++row) {
    largest_block_m = std::max(largest_block_m, increment_m.segment<3>(3 * row).norm());
  }
  // G = sum_{i>0} (dp_i - dp_0) grad(phi_i)^T with |dp_i - dp_0| <= 2 max|block| (a piece's vertex
  // moves by one block, du or dc), so the angle is at most |G| <= 6 max|block| max|grad(phi)|; the
  // bound below keeps the factor 12 of the shifted enrichment (du + Psi da), which is safe.
  return 12.0 * largest_block_m * m_largest_shape_gradient_per_m;
}

double DeformableBody::largest_turn_rad(const Eigen::VectorXd& increment_m, double resolution_rad) const {
  const double bound_rad = turn_bound_rad(increment_m);
  if (bound_rad <= resolution_rad) return bound_rad;
  return largest_element_turns_rad({&increment_m})[0];
}

std::array<double, 2> DeformableBody::largest_turns_rad(const Eigen::VectorXd& first_m, const Eigen::VectorXd& second_m,
                                                        std::array<double, 2> resolution_rad) const {
  const std::array<double, 2> bound_rad{turn_bound_rad(first_m), turn_bound_rad(second_m)};
  const bool first_past = bound_rad[0] > resolution_rad[0];
  const bool second_past = bound_rad[1] > resolution_rad[1];
  if (first_past && second_past) return largest_element_turns_rad({&first_m, &second_m});
  if (first_past) return {largest_element_turns_rad({&first_m})[0], bound_rad[1]};
  if (second_past) return {bound_rad[0], largest_element_turns_rad({&second_m})[0]};
  return bound_rad;
}

// (A hot kernel: GCC cannot clone the virtual largest_turn_rad itself.) One pass over the elements
// for one or two increments (a null second): each element's rotation and rest data read once.
TISSUE_HOT_KERNEL std::array<double, 2> DeformableBody::largest_element_turns_rad(
    std::array<const Eigen::VectorXd*, 2> increments_m) const {
  // The uncut tets (those the co-rotational model has not handed to XFEM) in halves of its storage
  // order, which streams its per-tet data, and the cut tets in halves of theirs, side by side with a
  // team (a maximum: the same in any order).
  std::array<std::array<double, 2>, MAX_STEP_THREADS> largest_of_part{};
  const int parts = team_parts(m_team);
  run_parts(m_team, parts, [&](int member) {
    std::array<double, 2> largest{};
    const auto share = [&](size_t count, int end_member) {
      return count * static_cast<size_t>(end_member) / static_cast<size_t>(parts);
    };
    const auto take = [&](const std::array<int, 4>& /*rows*/, const std::array<double, 2>& turn_rad) {
      take_larger(largest, turn_rad);
    };
    const auto tets = static_cast<size_t>(m_elasticity.tet_count());
    for_each_tet_turn(share(tets, member), share(tets, member + 1), increments_m, take);
    const auto cut_tets = static_cast<size_t>(m_xfem.cut_tet_count());
    for_each_piece_turn(share(cut_tets, member), share(cut_tets, member + 1), increments_m, take);
    largest_of_part[static_cast<size_t>(member)] = largest;
  });
  std::array<double, 2> largest_rad{};
  for (int member = 0; member < parts; ++member) take_larger(largest_rad, largest_of_part[static_cast<size_t>(member)]);
  return largest_rad;
}

template <class Visit>
void DeformableBody::for_each_tet_turn(size_t first, size_t end, std::array<const Eigen::VectorXd*, 2> increments_m,
                                       Visit&& visit) const {
  m_elasticity.for_each_included(first, end, [&](const Tet& tet, const TetRest& rest, const Eigen::Matrix3d& rotation) {
    const std::array<int, 4> rows{vertex_block_row(tet[0]), vertex_block_row(tet[1]), vertex_block_row(tet[2]),
                                  vertex_block_row(tet[3])};
    std::array<double, 2> turn_rad{};
    for (size_t i = 0; i < 2 && increments_m[i] != nullptr; ++i) {
      turn_rad[i] = turn_angle_rad(rest, rotation, row_increments(rows, *increments_m[i]));
    }
    visit(rows, turn_rad);
  });
}

template <class Visit>
void DeformableBody::for_each_piece_turn(size_t first, size_t end, std::array<const Eigen::VectorXd*, 2> increments_m,
                                         Visit&& visit) const {
  for (int k = static_cast<int>(first); k < static_cast<int>(end); ++k) {
    if (m_xfem.retired(k)) continue;
    for (int p = 0; p < static_cast<int>(m_xfem.piece_count(k)); ++p) {
      if (m_xfem.parked(k, p)) continue;
      const std::array<int, 4> rows = piece_rows(k, p);
      const double share = std::sqrt(m_xfem.piece(k, p).weight);
      std::array<double, 2> turn_rad{};
      for (size_t i = 0; i < 2 && increments_m[i] != nullptr; ++i) {
        turn_rad[i] =
            share * turn_angle_rad(m_xfem.rest(k), m_xfem.rotation(k, p), row_increments(rows, *increments_m[i]));
      }
      visit(rows, turn_rad);
    }
  }
}

void DeformableBody::mark_turning_rows(const Eigen::VectorXd& increment_m, double angle_rad,
                                       std::vector<std::uint8_t>& turning) const {
  check_unknowns(increment_m);
  turning.assign(static_cast<size_t>(dof_count() / 3), 0);
  const auto mark = [&](const std::array<int, 4>& rows, const std::array<double, 2>& turn_rad) {
    if (!(turn_rad[0] > angle_rad)) return;
    for (const int row : rows) {
      if (row >= 0) turning[static_cast<size_t>(row)] = 1;
    }
  };
  for_each_tet_turn(0, static_cast<size_t>(m_elasticity.tet_count()), {&increment_m, nullptr}, mark);
  for_each_piece_turn(0, static_cast<size_t>(m_xfem.cut_tet_count()), {&increment_m, nullptr}, mark);
}

}  // namespace tissue
