// A Cholesky factor of an earlier matrix, turned with its rows' rotations since (internal to
// core/solve): P^-1 = Q (L L^T)^-1 Q^T with Q block-diagonal, Q_i = F_now,i F_then,i^T, F the rows'
// frames (ShiftedSystem::block_frames) now and when the factor's matrix was copied. A part that
// turns keeps its stiffness in its own frame, so the turned factor preconditions the turned matrix
// as the factor did its own. Used by the lagged factor (pcgCholesky's follow_rotations) and by
// CHOLMOD's Newton corrections (CholmodSolver::setup_nearby).
#pragma once

#include "core/solve/cholmod_factor.hpp"
#include "core/solve/linear_solver.hpp"

#include <Eigen/Core>

#include <span>
#include <vector>

namespace tissue {

/// The per-block-row frames of `a` into `frames` (cleared when `a` has none).
inline void copy_frames(const ShiftedSystem& a, std::vector<Eigen::Matrix3d>& frames) {
  if (a.block_frames == nullptr) {
    frames.clear();
  } else {
    frames.assign(a.block_frames->begin(), a.block_frames->begin() + a.stiffness->block_rows());
  }
}

struct TurnedFactor {
  std::vector<Eigen::Matrix3d> frames;  // of the factor's matrix, per block row (empty: made without)
  std::vector<Eigen::Matrix3d> turns;   // Q_i since then (empty: no turn)
  Eigen::VectorXd turned_residual, turned_solution;

  /// The frames of `a`, whose matrix the factor is made of (none when `a` has none).
  void record_frames(const ShiftedSystem& a) { copy_frames(a, frames); }
  /// The turns of the factor's `rows` rows (a multiple of 3) to `a`'s frames; none unless both have frames.
  void update_turns(const ShiftedSystem& a, long rows) {
    const auto block_rows = static_cast<size_t>(rows / 3);
    if (a.block_frames == nullptr || frames.size() < block_rows || a.block_frames->size() < block_rows) {
      turns.clear();
      return;
    }
    turns.resize(block_rows);
    for (size_t i = 0; i < block_rows; ++i) turns[i].noalias() = (*a.block_frames)[i] * frames[i].transpose();
    turned_residual.resize(rows);
    turned_solution.resize(rows);
  }
  /// z = Q (L L^T)^-1 Q^T r on the factor's rows (its first rows of r and z; none other touched).
  void solve(CholmodFactor& factor, const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    const auto m = static_cast<size_t>(factor.rows());
    if (turns.empty()) {
      factor.solve(std::span<const double>(r.data(), m), std::span<double>(z.data(), m));
      return;
    }
    for (size_t i = 0; i < turns.size(); ++i) {
      const auto row = static_cast<Eigen::Index>(3 * i);
      turned_residual.segment<3>(row).noalias() = turns[i].transpose() * r.segment<3>(row);
    }
    factor.solve(std::span<const double>(turned_residual.data(), m), std::span<double>(turned_solution.data(), m));
    for (size_t i = 0; i < turns.size(); ++i) {
      const auto row = static_cast<Eigen::Index>(3 * i);
      z.segment<3>(row).noalias() = turns[i] * turned_solution.segment<3>(row);
    }
  }
};

}  // namespace tissue
