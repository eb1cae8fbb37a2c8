// Integrator settings and factory (see integrator_factory.hpp).
#include "core/integrate/integrator_factory.hpp"

#include "core/integrate/backward_euler.hpp"

#include <cmath>
#include <string>

namespace tissue {

LinearSolverKind parse_linear_solver_kind(std::string_view name) {
  if (name == "pcg") return LinearSolverKind::pcg;
  if (name == "cholmod") return LinearSolverKind::cholmod;
  throw ParameterError("unknown linear solver '" + std::string(name) + "' (expected pcg or cholmod)");
}

std::string_view to_string(LinearSolverKind kind) { return kind == LinearSolverKind::pcg ? "pcg" : "cholmod"; }

void validate(const SolverSettings& settings) {
  if (!(settings.pcg.tolerance > 0.0) || !std::isfinite(settings.pcg.tolerance)) {
    throw ParameterError("PCG tolerance must be finite and > 0, got " + std::to_string(settings.pcg.tolerance));
  }
  if (settings.pcg.max_iterations < 1) {
    throw ParameterError("PCG max iterations must be >= 1, got " + std::to_string(settings.pcg.max_iterations));
  }
}

std::unique_ptr<LinearSolver> make_linear_solver(const SolverSettings& settings) {
  validate(settings);
  switch (settings.kind) {
    case LinearSolverKind::pcg:
      return std::make_unique<PcgSolver>(settings.pcg);
    case LinearSolverKind::cholmod:
      return std::make_unique<CholmodSolver>();
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
}

std::unique_ptr<Integrator> make_integrator(const IntegratorSettings& settings, const SolverSettings& solver) {
  validate(settings);
  if (settings.kind == IntegratorKind::ida) return std::make_unique<IdaIntegrator>(settings.ida);
  return std::make_unique<BackwardEuler>(make_linear_solver(solver), BackwardEuler::Settings{solver.warm_start, settings.newton});
}

}  // namespace tissue
