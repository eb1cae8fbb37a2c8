// CholmodSolver: sparse Cholesky of A = s K + diag(d) with SuiteSparse CHOLMOD, the accurate
// (reference) solver: every setup refactorizes (CholmodFactor, whose header and source give the
// CHOLMOD choices), every solve back-substitutes and checks the true residual. A setup_nearby (a
// Newton correction's matrix) keeps the factor and iterates on the new A with it, to a forcing term,
// then corrects each part's translation (PartTranslations).
#include "core/solve/cholmod_factor.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/solve/part_translations.hpp"
#include "core/solve/pcg_iteration.hpp"
#include "core/solve/turned_factor.hpp"

#include <cmath>
#include <span>
#include <string>

namespace tissue {

struct CholmodSolver::Impl {
  CholmodFactor factor;
  Eigen::VectorXd product;                               // A x for the residual check
  ShiftedSystem factored_system{nullptr, 1.0, nullptr};  // of the valid factor, stiffness == nullptr without one
  // setup_nearby(): the A the solves iterate on with the factor of factored_system (stiffness ==
  // nullptr: solve with the factor directly).
  ShiftedSystem nearby_system{nullptr, 1.0, nullptr};
  PcgWorkspace work;
  WorkTeam* team = nullptr;
  TurnedFactor turned;  // the factor turned with the rows' rotations since it was made
  PartTranslations parts;  // of the nearby system: its CG stops at a forcing term

  void factorize(const ShiftedSystem& system) {
    const ShiftedSystem a = system;  // a copy: it may be nearby_system, cleared here
    factored_system = ShiftedSystem{nullptr, 1.0, nullptr};
    nearby_system = ShiftedSystem{nullptr, 1.0, nullptr};
    factor.load(a);
    if (factor.factorize() != CholmodFactor::Status::ok) throw SolverError(factor.failure_message("CholmodSolver"));
    factored_system = a;
    turned.record_frames(a);
  }
};

CholmodSolver::CholmodSolver() : m_impl(std::make_unique<Impl>()) {}

CholmodSolver::~CholmodSolver() = default;

int CholmodSolver::symbolic_analysis_count() const { return m_impl->factor.analysis_count(); }

bool CholmodSolver::is_set_up() const { return m_impl->factored_system.stiffness != nullptr; }

void CholmodSolver::lend_work_team(WorkTeam* team) { m_impl->team = team; }

void CholmodSolver::setup(const ShiftedSystem& system) {
  Impl& impl = *m_impl;
  impl.factored_system = ShiftedSystem{nullptr, 1.0, nullptr};  // no factor if the check throws
  impl.nearby_system = ShiftedSystem{nullptr, 1.0, nullptr};
  system.check("CholmodSolver");
  impl.factorize(system);
}

void CholmodSolver::setup_nearby(const ShiftedSystem& system) {
  Impl& impl = *m_impl;
  system.check("CholmodSolver");
  const ShiftedSystem& factored = impl.factored_system;
  if (factored.stiffness != system.stiffness || factored.rows() != system.rows() ||
      impl.factor.pattern_revision() != system.stiffness->pattern_revision()) {
    setup(system);
    return;
  }
  impl.nearby_system = ShiftedSystem{nullptr, 1.0, nullptr};
  impl.work.resize(system.rows());
  impl.work.matrix.assign(system, impl.team);
  impl.turned.update_turns(system, impl.factor.rows());
  impl.parts.setup(system);
  impl.nearby_system = system;
}

// From x: CG on the nearby system with the turned factor, then each part's translation corrected;
// when CG does not get there, the nearby system factorized after all and solved directly.
SolveReport CholmodSolver::solve_nearby(const Eigen::VectorXd& b, Eigen::VectorXd& x, double tolerance) {
  Impl& impl = *m_impl;
  impl.nearby_system.check_sizes(b, x);
  const SolveReport report = preconditioned_cg</*ROW_WISE=*/false>(
      impl.nearby_system, b, x, tolerance, NEARBY_ITERATIONS, impl.work, impl.team,
      [&impl](const Eigen::VectorXd& r, Eigen::VectorXd& z, long, long) { impl.turned.solve(impl.factor, r, z); });
  if (!report.converged || !x.allFinite()) {
    impl.factorize(impl.nearby_system);  // too far after all: solve() solves with the new factor
    return solve(b, x);
  }
  impl.work.matrix.multiply(x, impl.product);  // the true residual (CG's is recursive)
  impl.product = b - impl.product;
  impl.parts.correct(impl.product, x);
  return report;
}

SolveReport CholmodSolver::solve_roughly(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Impl& impl = *m_impl;
  if (impl.nearby_system.stiffness == nullptr) return solve(b, x);  // a factor of this A, or none
  x.setZero(impl.nearby_system.rows());
  return solve_nearby(b, x, NEARBY_FORCING_TERM);
}

SolveReport CholmodSolver::refine(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  if (m_impl->nearby_system.stiffness == nullptr) return SolveReport{0, 0.0, true};  // solved directly
  return solve_nearby(b, x, NEARBY_TOLERANCE);
}

SolveReport CholmodSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Impl& impl = *m_impl;
  if (!is_set_up()) throw SolverError("CholmodSolver: solve() without a factor (call setup())");
  if (impl.nearby_system.stiffness != nullptr) {
    x.setZero(impl.nearby_system.rows());
    return solve_nearby(b, x, NEARBY_TOLERANCE);
  }
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
