// Integrator settings and factory (see integrator_factory.hpp).
#include "core/integrate/integrator_factory.hpp"

#include "core/integrate/backward_euler.hpp"

#include <array>
#include <cmath>
#include <string>

namespace tissue {

namespace {

constexpr std::array LINEAR_SOLVER_KINDS{LinearSolverKind::pcg, LinearSolverKind::cholmod,
                                         LinearSolverKind::pcg_cholesky};

}  // namespace

LinearSolverKind parse_linear_solver_kind(std::string_view name) {
  for (const LinearSolverKind kind : LINEAR_SOLVER_KINDS) {
    if (name == to_string(kind)) return kind;
  }
  throw ParameterError("unknown linear solver '" + std::string(name) + "' (expected " +
                       std::string(linear_solver_names()) + ")");
}

std::string_view to_string(LinearSolverKind kind) {
  switch (kind) {
    case LinearSolverKind::pcg:
      return "pcg";
    case LinearSolverKind::cholmod:
      return "cholmod";
    case LinearSolverKind::pcg_cholesky:
      return "pcg-cholesky";
  }
  return "unknown";
}

std::string_view linear_solver_names() {
  // "a, b or c", from the list above.
  static const std::string names = [] {
    std::string text;
    for (size_t k = 0; k < LINEAR_SOLVER_KINDS.size(); ++k) {
      if (k > 0) text += k + 1 == LINEAR_SOLVER_KINDS.size() ? " or " : ", ";
      text += to_string(LINEAR_SOLVER_KINDS[k]);
    }
    return text;
  }();
  return names;
}

void validate(const SolverSettings& settings) {
  if (!(settings.pcg.tolerance > 0.0) || !std::isfinite(settings.pcg.tolerance)) {
    throw ParameterError("PCG tolerance must be finite and > 0, got " + std::to_string(settings.pcg.tolerance));
  }
  if (settings.pcg.max_iterations < 1) {
    throw ParameterError("PCG max iterations must be >= 1, got " + std::to_string(settings.pcg.max_iterations));
  }
  if (const std::string problem = settings.refresh.problem(); !problem.empty()) throw ParameterError(problem);
}

std::unique_ptr<LinearSolver> make_linear_solver(const SolverSettings& settings) {
  validate(settings);
  switch (settings.kind) {
    case LinearSolverKind::pcg:
      return std::make_unique<PcgSolver>(settings.pcg);
    case LinearSolverKind::cholmod:
      return std::make_unique<CholmodSolver>();
    case LinearSolverKind::pcg_cholesky:
      return std::make_unique<CholeskyPcgSolver>(settings.pcg, settings.refresh);
  }
  throw ParameterError("unknown linear solver kind");
}

IntegratorKind parse_integrator_kind(std::string_view name) {
  if (name == "backward-euler") return IntegratorKind::backward_euler;
  if (name == "ida") return IntegratorKind::ida;
  throw ParameterError("unknown integrator '" + std::string(name) + "' (expected backward-euler or ida)");
}

std::string_view to_string(IntegratorKind kind) {
  return kind == IntegratorKind::backward_euler ? "backward-euler" : "ida";
}

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
