// The integrator choice: settings, their range checks and names, and the factory that builds the
// chosen integrator with its linear solver. The one place a name maps to an integrator.
#pragma once

#include "core/integrate/backward_euler.hpp"
#include "core/integrate/ida_integrator.hpp"
#include "core/integrate/integrator.hpp"
#include "core/named_items.hpp"
#include "core/solve/linear_solver.hpp"

#include <memory>
#include <string_view>

namespace tissue {

enum class LinearSolverKind { pcg, cholmod, pcg_cholesky, pcg_two_level };

inline constexpr ItemNames<LinearSolverKind, 4> LINEAR_SOLVER_NAMES{
    "linear solver",
    {{{"pcg", "Jacobi-preconditioned conjugate gradients (iterative; integrator.pcgTolerance, "
              "integrator.pcgMaxIterations)"},
      {"cholmod", "Sparse Cholesky factorization (CHOLMOD, direct, exact)"},
      {"pcgCholesky",
       "CG preconditioned by a lagged CHOLMOD factor, refactorized when the iterations grow or a cut changes the "
       "pattern; in the FMU without a worker thread (integrator.pcgTolerance, integrator.pcgMaxIterations)"},
      {"pcgTwoLevel",
       "CG preconditioned by Jacobi plus an exact solve on the rigid motions of small aggregates of vertices (a "
       "two-level method: the slow motions converge in every iteration, no large factorization) "
       "(integrator.pcgTolerance, integrator.pcgMaxIterations)"}}}};

/// Parses "pcg" / "cholmod" / "pcgCholesky" / "pcgTwoLevel" (LINEAR_SOLVER_NAMES); throws ParameterError otherwise.
LinearSolverKind parse_linear_solver_kind(std::string_view name);
[[nodiscard]] std::string_view to_string(LinearSolverKind kind);

/// Backward Euler's linear solver.
struct SolverSettings {
  LinearSolverKind kind = LinearSolverKind::pcg;
  PcgSolver::Settings pcg;  ///< tolerance and iteration cap of pcg, pcgCholesky and pcgTwoLevel
  CholeskyPcgSolver::Refresh refresh;  ///< pcgCholesky: when its lagged factor is rebuilt, and where
  bool warm_start = false;  ///< PCG starts from the previous step's velocity change (see BackwardEuler)
};

/// Throws ParameterError unless tolerance > 0 (finite), max_iterations >= 1, refresh_iterations >= 0
/// and pickup_setups >= 1.
void validate(const SolverSettings& settings);
std::unique_ptr<LinearSolver> make_linear_solver(const SolverSettings& settings);

enum class IntegratorKind { backward_euler, ida };

inline constexpr ItemNames<IntegratorKind, 2> INTEGRATOR_NAMES{
    "integrator",
    {{{"backwardEuler", "Semi-implicit backward Euler, one linear solve per internal step (integrator.linearSolver)"},
      {"ida", "SUNDIALS IDA: variable-order, variable-step BDF with error control (integrator.ida*)"}}}};

/// Parses "backwardEuler" / "ida" (INTEGRATOR_NAMES); throws ParameterError otherwise.
IntegratorKind parse_integrator_kind(std::string_view name);
[[nodiscard]] std::string_view to_string(IntegratorKind kind);

struct IntegratorSettings {
  IntegratorKind kind = IntegratorKind::backward_euler;
  IdaSettings ida;  ///< used when kind is ida
  BackwardEuler::NewtonCorrections newton;  ///< used when kind is backward_euler
  /// Backward Euler: threads per step, 1 or 2 (opt-in; a team made and joined by each step, never
  /// one that outlives it). Changes no result: the assembly is bitwise the same with either.
  int threads = 1;
};

/// Throws ParameterError for an invalid setting (IDA's are checked whatever the kind).
void validate(const IntegratorSettings& settings);

/// The integrator of `settings`; backward Euler gets the linear solver of `solver`.
std::unique_ptr<Integrator> make_integrator(const IntegratorSettings& settings, const SolverSettings& solver);

}  // namespace tissue
