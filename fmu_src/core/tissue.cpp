// The Tissue facade.
#include "core/tissue.hpp"

#include "core/integrate/backward_euler.hpp"

#include <cmath>
#include <string>

namespace tissue {

LinearSolverKind parse_linear_solver_kind(std::string_view name) {
  if (name == "pcg") return LinearSolverKind::pcg;
  if (name == "cholmod") return LinearSolverKind::cholmod;
  throw ParameterError("unknown linear solver '" + std::string(name) + "' (expected pcg or cholmod)");
}

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

namespace {

TissueSettings checked(TissueSettings settings) {
  if (!(settings.step_size_s > 0.0) || !std::isfinite(settings.step_size_s)) {
    throw ParameterError("step size must be finite and > 0 s, got " + std::to_string(settings.step_size_s));
  }
  validate(settings.solver);
  return settings;
}

}  // namespace

Tissue::Tissue(TetMesh mesh, TissueSettings settings)
    : m_settings(checked(std::move(settings))),
      m_body(std::move(mesh), m_settings.body),
      m_integrator(std::make_unique<BackwardEuler>(make_linear_solver(m_settings.solver),
                                                   BackwardEuler::Settings{m_settings.solver.warm_start})) {
  m_state.displacement_m.setZero(m_body.dof_count());
  m_state.velocity_m_per_s.setZero(m_body.dof_count());
}

StepReport Tissue::step() { return m_integrator->step(m_body, m_state, m_settings.step_size_s); }

}  // namespace tissue
