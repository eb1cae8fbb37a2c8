// CholmodSolver: sparse Cholesky of A = s K + diag(d) with SuiteSparse CHOLMOD, the accurate
// (reference) solver: every setup refactorizes (CholmodFactor, whose header and source give the
// CHOLMOD choices), every solve back-substitutes and checks the true residual.
#include "core/solve/cholmod_factor.hpp"
#include "core/solve/linear_solver.hpp"

#include <cmath>
#include <span>
#include <string>

namespace tissue {

struct CholmodSolver::Impl {
  CholmodFactor factor;
  Eigen::VectorXd product;                               // A x for the residual check
  ShiftedSystem factored_system{nullptr, 1.0, nullptr};  // of the valid factor, stiffness == nullptr without one
};

CholmodSolver::CholmodSolver() : m_impl(std::make_unique<Impl>()) {}

CholmodSolver::~CholmodSolver() = default;

int CholmodSolver::symbolic_analysis_count() const { return m_impl->factor.analysis_count(); }

bool CholmodSolver::is_set_up() const { return m_impl->factored_system.stiffness != nullptr; }

void CholmodSolver::setup(const ShiftedSystem& system) {
  Impl& impl = *m_impl;
  impl.factored_system = ShiftedSystem{nullptr, 1.0, nullptr};
  system.check("CholmodSolver");
  impl.factor.load(system);
  if (impl.factor.factorize() != CholmodFactor::Status::ok) {
    throw SolverError(impl.factor.failure_message("CholmodSolver"));
  }
  impl.factored_system = system;
}

SolveReport CholmodSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Impl& impl = *m_impl;
  if (!is_set_up()) throw SolverError("CholmodSolver: solve() without a factor (call setup())");
  const long n = impl.factor.rows();
  if (b.size() != n) {
    throw SolverError("CholmodSolver: the right-hand side b has length " + std::to_string(b.size()) +
                      ", the factor has " + std::to_string(n) + " rows");
  }
  SolveReport report;
  report.converged = true;
  const double b_norm = b.norm();
  if (b_norm == 0.0) {  // x = 0 whatever A is
    x.setZero(n);
    return report;
  }
  x.resize(n);
  impl.factor.solve(std::span<const double>(b.data(), static_cast<size_t>(n)),
                    std::span<double>(x.data(), static_cast<size_t>(n)));
  // The true residual: one product, cheap next to the factorization, and it catches a solve
  // spoiled by non-finite input.
  impl.product.resize(n);
  impl.factored_system.multiply(x, impl.product);
  report.relative_residual = (b - impl.product).norm() / b_norm;
  if (!std::isfinite(report.relative_residual)) {
    throw SolverError("CholmodSolver: the solution is not finite (non-finite values in K, d or b)");
  }
  return report;
}

}  // namespace tissue
