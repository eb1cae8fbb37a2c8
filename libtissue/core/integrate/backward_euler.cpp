// Semi-implicit backward Euler step (see backward_euler.hpp).
#include "core/integrate/backward_euler.hpp"

#include <chrono>
#include <cmath>
#include <string>

namespace tissue {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

double undamped_tangent_fraction(double step_size_s, double stiffness_damping_s) {
  if (!(step_size_s > 0.0) || !std::isfinite(step_size_s)) {
    throw ParameterError("undamped tangent fraction: step size must be finite and > 0 s, got " +
                         std::to_string(step_size_s));
  }
  if (!(stiffness_damping_s >= 0.0) || !std::isfinite(stiffness_damping_s)) {
    throw ParameterError("undamped tangent fraction: beta must be finite and >= 0 s, got " +
                         std::to_string(stiffness_damping_s));
  }
  return step_size_s / (step_size_s + stiffness_damping_s);
}

ShiftedSystem BackwardEuler::newton_stiffness(const DynamicsModel& model, double step_size_s,
                                             Eigen::VectorXd& diagonal) const {
  if (!(step_size_s > 0.0) || !std::isfinite(step_size_s)) {
    throw ParameterError("Newton matrix: step size must be finite and > 0 s, got " + std::to_string(step_size_s));
  }
  return newton_stiffness_system(model, 1.0 / step_size_s, diagonal);
}

BackwardEuler::BackwardEuler(std::unique_ptr<LinearSolver> solver, Settings settings)
    : m_solver(std::move(solver)), m_settings(settings) {
  if (!m_solver) throw std::invalid_argument("BackwardEuler needs a linear solver");
}

StepReport BackwardEuler::step(DynamicsModel& model, DynamicState& state, double step_size_s) {
  if (!(step_size_s > 0.0) || !std::isfinite(step_size_s)) {
    throw IntegrationError("step size must be finite and > 0 s, got " + std::to_string(step_size_s));
  }
  const double h = step_size_s;
  const int n = model.dof_count();
  if (state.displacement_m.size() != n || state.velocity_m_per_s.size() != n) {
    throw IntegrationError("state has " + std::to_string(state.displacement_m.size()) + " unknowns, model has " +
                           std::to_string(n));
  }
  StepReport report;
  const auto assembly_start = std::chrono::steady_clock::now();
  model.evaluate(state.displacement_m, m_internal_force_n, /*update_tangent=*/true);
  const BlockSparseMatrix& stiffness = model.tangent();
  const RayleighDamping& damping = model.damping();
  const Eigen::VectorXd& mass = model.mass_kg();

  // rhs = h (f_ext - f_int - alpha M v - (beta + h) K v)
  m_stiffness_times_velocity.resize(n);
  stiffness.multiply(state.velocity_m_per_s, m_stiffness_times_velocity);
  m_rhs.resize(n);
  m_rhs.noalias() = h * (model.external_force_n() - m_internal_force_n -
                         damping.mass_damping_per_s * mass.cwiseProduct(state.velocity_m_per_s) -
                         (damping.stiffness_damping_s + h) * m_stiffness_times_velocity);
  m_system_diagonal.resize(n);
  m_system_diagonal.noalias() = (1.0 + h * damping.mass_damping_per_s) * mass;
  const ShiftedSystem system{&stiffness, h * damping.stiffness_damping_s + h * h, &m_system_diagonal};
  report.assembly_s = seconds_since(assembly_start);

  const auto solve_start = std::chrono::steady_clock::now();
  // The initial guess: zero (as Vega and the dissertation), or the previous step's dv. The warm
  // start saves iterations at a strict tolerance, but under an iteration cap the error it leaves in
  // the slow modes repeats last step's acceleration and can pump energy in (docs/BENCHMARKS.md).
  if (!m_settings.warm_start || m_velocity_change.size() != n) m_velocity_change.setZero(n);
  try {
    report.solve = m_solver->solve(system, m_rhs, m_velocity_change);
  } catch (const SolverError& error) {
    m_velocity_change.setZero();
    throw IntegrationError(std::string("backward Euler: linear solve failed: ") + error.what());
  }
  report.solve_s = seconds_since(solve_start);
  report.linear_iterations = report.solve.iterations;
  if (!m_velocity_change.allFinite()) {
    m_velocity_change.setZero();
    throw IntegrationError("backward Euler: the velocity update is not finite; state kept");
  }
  state.velocity_m_per_s += m_velocity_change;
  state.displacement_m += h * state.velocity_m_per_s;
  state.time_s += h;
  return report;
}

}  // namespace tissue
