// PcgSolver: Jacobi-preconditioned conjugate gradients on A = s K + diag(d), the cheap and
// interruptible solver of the real-time loop (an iteration cap bounds the step time). The loop
// itself is preconditioned_cg (pcg_iteration.hpp).
#include "core/solve/linear_solver.hpp"
#include "core/solve/pcg_iteration.hpp"

#include <cmath>
#include <sstream>
#include <string>

namespace tissue {

void validate_pcg_settings(const PcgSolver::Settings& settings, const char* who) {
  if (!(settings.tolerance >= 0.0) || !std::isfinite(settings.tolerance)) {
    throw SolverError(std::string(who) + ": tolerance must be finite and >= 0");
  }
  if (settings.max_iterations < 0) throw SolverError(std::string(who) + ": max_iterations must be >= 0");
}

void jacobi_inverse_diagonal(const ShiftedSystem& system, Eigen::VectorXd& inverse_diagonal, const char* who) {
  system.stiffness->diagonal(inverse_diagonal);
  inverse_diagonal = system.stiffness_scale * inverse_diagonal + *system.diagonal;
  for (long i = 0; i < inverse_diagonal.size(); ++i) {
    const double a_ii = inverse_diagonal[i];
    if (!(a_ii > 0.0) || !std::isfinite(a_ii)) {
      const double d_i = (*system.diagonal)[i];
      std::ostringstream what;
      what << who << ": A is not positive definite: diagonal entry " << i << " (block row " << i / 3 << ") is " << a_ii
           << " (s K_ii " << a_ii - d_i << ", d_i " << d_i << ")";
      throw SolverError(what.str());
    }
    inverse_diagonal[i] = 1.0 / a_ii;
  }
}

PcgSolver::PcgSolver(Settings settings) : m_settings(settings) {
  validate_pcg_settings(settings, "PcgSolver");
  m_work.matrix = HalfMatrix(resolved_precision(settings.matrix_precision, settings.tolerance));
}

void PcgSolver::setup(const ShiftedSystem& system) {
  m_system = ShiftedSystem{nullptr, 1.0, nullptr};
  system.check("PcgSolver");
  m_work.resize(system.rows());  // the only allocations: when the system grows
  // Jacobi preconditioner from the diagonal of A; taken at each setup as K changes every step.
  jacobi_inverse_diagonal(system, m_inverse_diagonal, "PcgSolver");
  m_work.matrix.assign(system, m_team);
  m_system = system;
}

bool PcgSolver::multiply_set_up(const ShiftedSystem& system, const Eigen::Ref<const Eigen::MatrixXd>& x,
                                RowMajorMatrix& y) const {
  return multiply_set_up_copy(m_work, m_system, m_team, system, x, y);
}

SolveReport PcgSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  if (!is_set_up()) throw SolverError("PcgSolver: solve() without a setup()");
  m_system.check_sizes(b, x);
  return preconditioned_cg</*ROW_WISE=*/true>(
      m_system, b, x, m_settings.tolerance, m_settings.max_iterations, m_work, m_team,
      [this](const Eigen::VectorXd& r, Eigen::VectorXd& z, long first, long count) {
        z.segment(first, count) = m_inverse_diagonal.segment(first, count).cwiseProduct(r.segment(first, count));
      });
}

}  // namespace tissue
