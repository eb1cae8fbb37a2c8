// PartTranslations: the Galerkin correction of an approximate solution of A x = b (A = s K + diag(d))
// over the rigid translations of each part of A: the block rows joined by nonzero blocks. After it
// the residual b - A x sums to zero over every part, so an inexact solve keeps what an exact one
// gives a part that nothing holds: K's blocks sum to zero over it (internal forces do not move a
// free body), so sum_part d x = sum_part b, its momentum balance to round-off. For a part that is
// held, the same correction is the energy-norm best translation of it (Z^T A Z includes s K).
// Used by CholmodSolver's Newton corrections, whose CG stops at a forcing term (docs/DESIGN.md,
// "A correction's solve keeps the step's factor").
#pragma once

#include "core/solve/linear_solver.hpp"

#include <Eigen/Core>

#include <vector>

namespace tissue {

class PartTranslations {
 public:
  /// Finds A's parts (the rows joined by blocks with a nonzero entry) and each part's 3 x 3
  /// Z^T A Z = sum of its rows' d + s times the sum of its blocks. Requires d > 0 (A positive definite).
  void setup(const ShiftedSystem& a);
  /// x += Z (Z^T A Z)^-1 Z^T r, Z the parts' translations, r = b - A x (the caller's product).
  void correct(const Eigen::VectorXd& residual, Eigen::VectorXd& x);
  [[nodiscard]] int part_count() const { return static_cast<int>(m_inverse.size()); }
  [[nodiscard]] int part_of_block_row(int row) const { return m_part_of_row[static_cast<size_t>(row)]; }

 private:
  std::vector<int> m_part_of_row;
  std::vector<int> m_stack;
  std::vector<Eigen::Matrix3d> m_inverse;  // per part: (Z^T A Z)^-1
  std::vector<Eigen::Vector3d> m_sums;
};

}  // namespace tissue
