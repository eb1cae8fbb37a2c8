// The warm start of a step's solve (BackwardEuler::Settings::warm_start): the point of the span of
// earlier solutions nearest this solve's solution in the energy norm of its matrix.
#pragma once

#include "core/solve/linear_solver.hpp"

#include <Eigen/Core>

namespace tissue {

/// The most columns galerkin_start combines (its small matrices live on the stack).
inline constexpr int GALERKIN_MAX_COLUMNS = 8;

/// galerkin_start's scratch, kept between steps so that a step allocates only while the history fills.
struct GalerkinStartWork {
  RowMajorMatrix products;  // A times each column
  Eigen::VectorXd column, product;
};

/// x0 = X c with (X^T A X) c = X^T b: the Galerkin projection of the solution of A x = b onto the
/// span of X's columns, so X^T (b - A x0) = 0 and x0 is at least as near the solution in the A-norm
/// as zero and as each column (all lie in the span). Linearly dependent columns (a free fall's equal
/// velocity changes) make X^T A X singular: c is then its pseudo-inverse's (eigenvalues below 1e-12
/// of the largest dropped), which gives the same x0. Non-finite columns, no column, or more than
/// GALERKIN_MAX_COLUMNS give zero. One product with A per column: by `solver`'s products (all columns in one pass) when
/// given and set up for `system` (LinearSolver::multiply_set_up), else ShiftedSystem::multiply. x0 is resized to b's
/// length.
void galerkin_start(const ShiftedSystem& system, const Eigen::VectorXd& b,
                    const Eigen::Ref<const Eigen::MatrixXd>& columns, Eigen::VectorXd& x0, GalerkinStartWork& work,
                    const LinearSolver* solver = nullptr);

}  // namespace tissue
