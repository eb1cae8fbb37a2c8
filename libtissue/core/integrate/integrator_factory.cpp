// Integrator settings and factory (see integrator_factory.hpp).
#include "core/integrate/integrator_factory.hpp"

#include "core/integrate/backward_euler.hpp"
#include "core/solve/compact_rows_solver.hpp"

#include <cmath>
#include <string>

namespace tissue {

LinearSolverKind parse_linear_solver_kind(std::string_view name) { return LINEAR_SOLVER_NAMES.parse(name); }

std::string_view to_string(LinearSolverKind kind) { return LINEAR_SOLVER_NAMES.name(kind); }

void validate(const SolverSettings& settings) {
  if (!(settings.pcg.tolerance > 0.0) || !std::isfinite(settings.pcg.tolerance)) {
    throw ParameterError("PCG tolerance must be finite and > 0, got " + std::to_string(settings.pcg.tolerance));
  }
  if (settings.pcg.max_iterations < 1) {
    throw ParameterError("PCG max iterations must be >= 1, got " + std::to_string(settings.pcg.max_iterations));
  }
  if (const std::string problem = settings.refresh.problem(); !problem.empty()) throw ParameterError(problem);
}

namespace {

std::unique_ptr<LinearSolver> make_solver_of_kind(const SolverSettings& settings) {
  switch (settings.kind) {
    case LinearSolverKind::pcg:
      return std::make_unique<PcgSolver>(settings.pcg);
    case LinearSolverKind::cholmod:
      return std::make_unique<CholmodSolver>();
    case LinearSolverKind::pcg_cholesky:
      return std::make_unique<CholeskyPcgSolver>(settings.pcg, settings.refresh);
    case LinearSolverKind::pcg_two_level:
      return std::make_unique<TwoLevelPcgSolver>(settings.pcg);
  }
  throw ParameterError("unknown linear solver kind");
}

}  // namespace

// Every kind behind CompactRowsSolver: the rows a cut body leaves uncoupled are solved apart.
std::unique_ptr<LinearSolver> make_linear_solver(const SolverSettings& settings) {
  validate(settings);
  return std::make_unique<CompactRowsSolver>(make_solver_of_kind(settings));
}

IntegratorKind parse_integrator_kind(std::string_view name) { return INTEGRATOR_NAMES.parse(name); }

std::string_view to_string(IntegratorKind kind) { return INTEGRATOR_NAMES.name(kind); }

void validate(const IntegratorSettings& settings) {
  if (settings.kind != IntegratorKind::backward_euler && settings.kind != IntegratorKind::ida) {
    throw ParameterError("unknown integrator kind");
  }
  validate(settings.ida);
  validate(settings.newton);
  validate_step_threads(settings.threads);
}

std::unique_ptr<Integrator> make_integrator(const IntegratorSettings& settings, const SolverSettings& solver) {
  validate(settings);
  if (settings.kind == IntegratorKind::ida) return std::make_unique<IdaIntegrator>(settings.ida);
  return std::make_unique<BackwardEuler>(make_linear_solver(solver),
                                         BackwardEuler::Settings{solver.warm_start, settings.newton, settings.threads});
}

}  // namespace tissue
