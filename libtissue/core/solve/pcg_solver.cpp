// PcgSolver: Jacobi-preconditioned conjugate gradients on A = s K + diag(d), the cheap and
// interruptible solver of the real-time loop (an iteration cap bounds the step time).
//
// The reported relative_residual is that of the recursively updated residual r_k, which CG
// carries anyway; it drifts from the true b - A x_k only by rounding (relative ~1e-15 * cond),
// far below any tolerance a real-time step uses, and checking it would cost one more product.
#include "core/solve/linear_solver.hpp"

#include <cmath>
#include <string>

namespace tissue {

PcgSolver::PcgSolver(Settings settings) : m_settings(settings) {
  if (!(settings.tolerance >= 0.0) || !std::isfinite(settings.tolerance)) {
    throw SolverError("PcgSolver: tolerance must be finite and >= 0");
  }
  if (settings.max_iterations < 0) throw SolverError("PcgSolver: max_iterations must be >= 0");
}

void PcgSolver::setup(const ShiftedSystem& system) {
  m_system = ShiftedSystem{nullptr, 1.0, nullptr};
  if (system.stiffness == nullptr || system.diagonal == nullptr)
    throw SolverError("PcgSolver: the system has no stiffness or no diagonal");
  const long n = system.rows();
  if (system.diagonal->size() != n) {
    throw SolverError("PcgSolver: the diagonal d has length " + std::to_string(system.diagonal->size()) +
                      ", the system has " + std::to_string(n) + " rows");
  }
  if (m_residual.size() != n) {  // the only allocations: when the system grows
    m_residual.resize(n);
    m_direction.resize(n);
    m_preconditioned.resize(n);
    m_product.resize(n);
    m_inverse_diagonal.resize(n);
  }
  // Jacobi preconditioner from the diagonal of A; taken at each setup as K changes every step.
  system.stiffness->diagonal(m_inverse_diagonal);
  m_inverse_diagonal = system.stiffness_scale * m_inverse_diagonal + *system.diagonal;
  for (long i = 0; i < n; ++i) {
    const double a_ii = m_inverse_diagonal[i];
    if (!(a_ii > 0.0) || !std::isfinite(a_ii)) {
      throw SolverError("PcgSolver: A is not positive definite: diagonal entry " + std::to_string(i) + " is " +
                        std::to_string(a_ii));
    }
    m_inverse_diagonal[i] = 1.0 / a_ii;
  }
  m_system = system;
}

SolveReport PcgSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  if (!is_set_up()) throw SolverError("PcgSolver: solve() without a setup()");
  const ShiftedSystem& system = m_system;
  system.check_sizes(b, x);

  SolveReport report;
  const double b_norm = b.norm();
  if (b_norm == 0.0) {
    x.setZero();
    report.converged = true;
    return report;
  }

  // r = b - A x, warm-started from the caller's x; a non-finite guess is replaced by zero.
  system.multiply(x, m_product);
  m_residual = b - m_product;
  double r_norm = m_residual.norm();
  if (!std::isfinite(r_norm)) {
    x.setZero();
    m_residual = b;
    r_norm = b_norm;
  }
  const double threshold = m_settings.tolerance * b_norm;
  report.relative_residual = r_norm / b_norm;
  if (r_norm <= threshold) {
    report.converged = true;
    return report;
  }

  m_preconditioned = m_inverse_diagonal.cwiseProduct(m_residual);
  m_direction = m_preconditioned;
  double rz = m_residual.dot(m_preconditioned);
  for (int k = 1; k <= m_settings.max_iterations; ++k) {
    system.multiply(m_direction, m_product);
    const double curvature = m_direction.dot(m_product);
    // Breakdown: A is not positive definite along p (or the values are not finite). Keep the
    // last iterate and say so; the caller decides whether to accept it.
    if (!(curvature > 0.0) || !std::isfinite(curvature)) break;
    const double alpha = rz / curvature;
    x += alpha * m_direction;
    m_residual -= alpha * m_product;
    r_norm = m_residual.norm();
    report.iterations = k;
    report.relative_residual = r_norm / b_norm;
    if (r_norm <= threshold) {
      report.converged = true;
      break;
    }
    if (!std::isfinite(r_norm)) break;
    m_preconditioned = m_inverse_diagonal.cwiseProduct(m_residual);
    const double rz_next = m_residual.dot(m_preconditioned);
    const double beta = rz_next / rz;
    rz = rz_next;
    m_direction = m_preconditioned + beta * m_direction;
  }
  return report;
}

}  // namespace tissue
