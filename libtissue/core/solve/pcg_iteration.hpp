// The preconditioned conjugate-gradient loop (internal to core/solve), written once for every
// preconditioner: PcgSolver passes Jacobi, CholeskyPcgSolver a lagged Cholesky factor.
//
// The reported relative_residual is that of the recursively updated residual r_k, which CG
// carries anyway; it drifts from the true b - A x_k only by rounding (relative ~1e-15 * cond),
// far below any tolerance a real-time step uses, and checking it would cost one more product.
#pragma once

#include "core/solve/linear_solver.hpp"

#include <cmath>

namespace tissue {

/// Throws SolverError (prefixed by `who`) unless tolerance >= 0 (finite) and max_iterations >= 0.
void validate_pcg_settings(const PcgSolver::Settings& settings, const char* who);
/// Throws SolverError unless K and d are set and d has length rows().
void check_system(const ShiftedSystem& system, const char* who);
/// 1 / diag(A), length rows() (resized if needed); throws SolverError for an entry <= 0 or not finite.
void jacobi_inverse_diagonal(const ShiftedSystem& system, Eigen::VectorXd& inverse_diagonal, const char* who);

/// Solves A x = b from the initial guess x (a non-finite guess is replaced by zero) until
/// ||r|| <= tolerance * ||b|| or max_iterations. `precondition(r, z)` sets z = P^-1 r for an SPD
/// P (z has r's length and is not r). Sizes checked by the caller; `work` sized by it.
template <class Preconditioner>
SolveReport preconditioned_cg(const ShiftedSystem& system, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                              double tolerance, int max_iterations, PcgWorkspace& work,
                              Preconditioner&& precondition) {
  SolveReport report;
  const double b_norm = b.norm();
  if (b_norm == 0.0) {
    x.setZero();
    report.converged = true;
    return report;
  }

  // r = b - A x, warm-started from the caller's x; a non-finite guess is replaced by zero.
  system.multiply(x, work.product);
  work.residual = b - work.product;
  double r_norm = work.residual.norm();
  if (!std::isfinite(r_norm)) {
    x.setZero();
    work.residual = b;
    r_norm = b_norm;
  }
  const double threshold = tolerance * b_norm;
  report.relative_residual = r_norm / b_norm;
  if (r_norm <= threshold) {
    report.converged = true;
    return report;
  }

  precondition(work.residual, work.preconditioned);
  work.direction = work.preconditioned;
  double rz = work.residual.dot(work.preconditioned);
  for (int k = 1; k <= max_iterations; ++k) {
    system.multiply(work.direction, work.product);
    const double curvature = work.direction.dot(work.product);
    // Breakdown: A is not positive definite along p (or the values are not finite). Keep the
    // last iterate and say so; the caller decides whether to accept it.
    if (!(curvature > 0.0) || !std::isfinite(curvature)) break;
    const double alpha = rz / curvature;
    x += alpha * work.direction;
    work.residual -= alpha * work.product;
    r_norm = work.residual.norm();
    report.iterations = k;
    report.relative_residual = r_norm / b_norm;
    if (r_norm <= threshold) {
      report.converged = true;
      break;
    }
    if (!std::isfinite(r_norm)) break;
    precondition(work.residual, work.preconditioned);
    const double rz_next = work.residual.dot(work.preconditioned);
    const double beta = rz_next / rz;
    rz = rz_next;
    work.direction = work.preconditioned + beta * work.direction;
  }
  return report;
}

}  // namespace tissue
