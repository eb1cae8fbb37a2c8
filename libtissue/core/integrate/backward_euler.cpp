// Semi-implicit backward Euler step (see backward_euler.hpp).
#include "core/integrate/backward_euler.hpp"
#include "core/system/rows_left.hpp"

#include "core/wall_clock.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace tissue {
namespace {

// Lends a step's team to the model and the solver and takes it back when the step ends, however
// it ends.
class TeamLoan {
 public:
  TeamLoan(DynamicsModel& model, LinearSolver& solver, WorkTeam* team) : m_model(model), m_solver(solver) {
    m_model.lend_work_team(team);
    m_solver.lend_work_team(team);
  }
  ~TeamLoan() {
    m_model.lend_work_team(nullptr);
    m_solver.lend_work_team(nullptr);
  }
  TeamLoan(const TeamLoan&) = delete;
  TeamLoan& operator=(const TeamLoan&) = delete;

 private:
  DynamicsModel& m_model;
  LinearSolver& m_solver;
};

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

void validate(const BackwardEuler::NewtonCorrections& newton) {
  if (!(newton.trigger_angle_rad > 0.0)) {  // infinity allowed: never corrected
    throw ParameterError("backward Euler: the Newton trigger angle must be > 0 rad (infinity: off), got " +
                         std::to_string(newton.trigger_angle_rad));
  }
  if (!(newton.energy_guard_angle_rad > 0.0)) {
    throw ParameterError("backward Euler: the energy guard angle must be > 0 rad (infinity: off), got " +
                         std::to_string(newton.energy_guard_angle_rad));
  }
  if (newton.max_iterations < 1 || newton.max_iterations > 100) {
    throw ParameterError("backward Euler: Newton corrections must be 1 to 100 iterations, got " +
                         std::to_string(newton.max_iterations));
  }
}

BackwardEuler::BackwardEuler(std::unique_ptr<LinearSolver> solver, Settings settings)
    : m_solver(std::move(solver)), m_settings(settings) {
  if (!m_solver) throw std::invalid_argument("BackwardEuler needs a linear solver");
  validate(m_settings.newton);
  validate_step_threads(m_settings.threads);
}

// (1 + h alpha) M + (h beta + h^2) K at the model's current tangent: the matrix of the step and of
// its Newton corrections.
ShiftedSystem BackwardEuler::step_system(const DynamicsModel& model, double h, const Eigen::VectorXd& displacement_m) {
  m_system_diagonal.resize(model.dof_count());
  m_system_diagonal.noalias() = model.mass_kg() + h * model.mass_damping_kg_per_s();
  return ShiftedSystem{&model.tangent(),
                       h * model.stiffness_damping_s() + h * h,
                       &m_system_diagonal,
                       m_solver->follows_block_frames() ? model.block_frames() : nullptr,
                       m_solver->uses_block_positions() ? model.block_positions(displacement_m) : nullptr,
                       model.rows_left()};
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
  reserve_guard_lists(n / 3);
  // The opt-in team lives for this step only: joined (and taken back from the model) on every exit.
  std::optional<WorkTeam> team;
  if (m_settings.threads > 1) team.emplace(m_settings.threads);
  const TeamLoan loan(model, *m_solver, team ? &*team : nullptr);
  const auto assembly_start = std::chrono::steady_clock::now();
  const bool predicted = m_settings.newton.linearize_at_predicted_end;
  linearize(model, state, h, team ? &*team : nullptr);
  m_end_potential_by_pass = false;
  const ShiftedSystem system = step_system(model, h, predicted ? m_end_displacement : state.displacement_m);
  report.assembly_s = seconds_since(assembly_start);

  const auto solve_start = std::chrono::steady_clock::now();
  try {
    m_solver->setup(system);
    start_velocity_change(system);  // after the setup: its products are the solver's
    report.solve = m_solver->solve(m_rhs, m_velocity_change);
  } catch (const SolverError& error) {
    m_velocity_change.setZero();
    m_past_velocity_changes.resize(0);
    throw IntegrationError(std::string("backward Euler: linear solve failed: ") + error.what());
  }
  report.solve_s = seconds_since(solve_start);
  report.linear_iterations = report.solve.iterations;
  if (!m_velocity_change.allFinite()) {
    m_velocity_change.setZero();
    m_past_velocity_changes.resize(0);
    throw IntegrationError("backward Euler: the velocity update is not finite; state kept");
  }
  m_end_velocity.noalias() = state.velocity_m_per_s + m_velocity_change;
  // The corrections follow the turn from where the step was linearized. Linearized at the start, so
  // does the guard, and one pass answers both thresholds (a corrected step is measured again).
  // Linearized at the predicted end, the guard acts on a step whose change of turn, h (v1 - v0), passes
  // its angle, or whose own turn, h v1, passes the corrections' trigger: a steady swing linearized at its
  // predicted end still gains energy when it turns far (the co-rotational tangent lacks the rotation's
  // derivative: the hinged cube at ~0.1 rad a step), and a sagging organ turning 0.005-0.05 rad a step
  // does not need the guard's energy passes (nothing is evaluated ahead in this mode: the next step
  // takes the end's pass as its start, linearize()). Both turns are measured in one pass.
  const NewtonCorrections& newton = m_settings.newton;
  const bool step_turn_guards = predicted && std::isfinite(newton.energy_guard_angle_rad);
  double turn_rad = 0.0;       // of h (v1 - where the step was linearized)
  double step_turn_rad = 0.0;  // of h v1, where step_turn_guards
  const auto measure_turns = [&](double angle_rad) {
    m_end_displacement.noalias() = h * (predicted ? m_velocity_change : m_end_velocity);
    if (!step_turn_guards) {
      turn_rad = model.largest_turn_rad(m_end_displacement, angle_rad);
      return;
    }
    m_step_increment_m.noalias() = h * m_end_velocity;
    const std::array<double, 2> turns =
        model.largest_turns_rad(m_end_displacement, m_step_increment_m, {angle_rad, newton.trigger_angle_rad});
    turn_rad = turns[0];
    step_turn_rad = turns[1];
  };
  measure_turns(std::min(newton.trigger_angle_rad, newton.energy_guard_angle_rad));
  if (turn_rad > newton.trigger_angle_rad) {
    correct(model, state, h, report, team ? &*team : nullptr);
    m_velocity_change.noalias() = m_end_velocity - state.velocity_m_per_s;
    measure_turns(newton.energy_guard_angle_rad);
  }
  const bool guard = turn_rad > newton.energy_guard_angle_rad || step_turn_rad > newton.trigger_angle_rad;
  remember_velocity_change();
  state.displacement_m += h * m_end_velocity;
  if (guard) {
    const auto guard_start = std::chrono::steady_clock::now();
    report.energy_guarded = guard_energy(model, state, h);
    report.guard_s = seconds_since(guard_start);
  }
  state.velocity_m_per_s = m_end_velocity;
  state.time_s += h;
  return report;
}

// Evaluates the model where the step is linearized (u0, or the predicted end u0 + h v0, left in
// m_end_displacement) and sets m_rhs, the right side of the step's solve.
void BackwardEuler::linearize(DynamicsModel& model, const DynamicState& state, double h, WorkTeam* team) {
  const bool predicted = m_settings.newton.linearize_at_predicted_end;
  const Eigen::Index n = state.displacement_m.size();
  m_end_potential_j = std::numeric_limits<double>::quiet_NaN();
  // The start as the last step's energy guard evaluated it ahead, when the model takes that (nothing
  // changed it since); else the energy guard's start found in the same pass when the guard may act.
  // Linearized at the predicted end, the start's potential is found by the guard when it acts.
  const bool taken = m_end_evaluated && model.take_evaluation_ahead(state.displacement_m);
  m_end_evaluated = false;
  m_start_potential_j = std::numeric_limits<double>::quiet_NaN();
  if (predicted) {
    // The guard's start: the last guard's pass at this u kept by the model, else (when the last step
    // made that pass) the same pass now, before this step's evaluation moves the rotations' warm
    // starts, so that a step restored here finds the same energy, bitwise.
    if (std::isfinite(m_settings.newton.energy_guard_angle_rad)) {
      m_start_potential_j = model.kept_potential_energy_j(state.displacement_m);
      if (!std::isfinite(m_start_potential_j) && m_end_potential_by_pass) {
        m_start_potential_j = model.potential_energy_j(state.displacement_m);
      }
    }
    m_end_velocity = state.velocity_m_per_s;
    m_end_displacement.noalias() = state.displacement_m + h * m_end_velocity;
    model.evaluate(m_end_displacement, m_internal_force_n, /*update_tangent=*/true);
  } else if (taken) {
    m_start_potential_j = model.potential_energy_at_last_evaluate_j();  // m_internal_force_n its force
  } else if (std::isfinite(m_settings.newton.energy_guard_angle_rad)) {
    model.evaluate_with_potential(state.displacement_m, m_internal_force_n, /*update_tangent=*/true);
    m_start_potential_j = model.potential_energy_at_last_evaluate_j();
  } else {
    model.evaluate(state.displacement_m, m_internal_force_n, /*update_tangent=*/true);
  }

  // rhs = h (f_ext - f_int(u) - alpha M v0 - (beta + h) K v0) at u = u0; at the predicted end
  // u = u0 + h v0 (Newton's residual at v1 = v0), h (f_ext - f_int(u) - alpha M v0 - beta K v0).
  // (At the predicted end the product is the damping's alone: the tool's spring enters it undamped.)
  const double stiffness_times_velocity_s = model.stiffness_damping_s() + (predicted ? 0.0 : h);
  m_stiffness_times_velocity.resize(n);
  if (stiffness_times_velocity_s == 0.0) {
    m_stiffness_times_velocity.setZero();
  } else if (predicted) {
    damped_stiffness_product(model, state.velocity_m_per_s, m_stiffness_times_velocity, team);
  } else {
    model.tangent().multiply(state.velocity_m_per_s, m_stiffness_times_velocity, team);
  }
  m_rhs.resize(n);
  m_rhs.noalias() = h * (model.external_force_n() - m_internal_force_n -
                         model.mass_damping_kg_per_s().cwiseProduct(state.velocity_m_per_s) -
                         stiffness_times_velocity_s * m_stiffness_times_velocity);
}

// At most one part per row: reserved as the system grows (a cut, which allocates anyway), so that the
// first step the guard scales after it does not allocate.
void BackwardEuler::reserve_guard_lists(Eigen::Index blocks) {
  const auto rows = static_cast<size_t>(blocks);
  if (m_part_mass.capacity() >= rows) return;
  m_part_momentum.reserve(rows);
  m_part_mass.reserve(rows);
  m_turning_rows.reserve(rows);
}

void BackwardEuler::damped_stiffness_product(const DynamicsModel& model, const Eigen::VectorXd& v,
                                             Eigen::VectorXd& product, WorkTeam* team) {
  model.tangent().multiply(v, product, team);
  m_terms_product.setZero(v.size());
  model.add_force_terms_tangent_product(v, m_terms_product);
  product -= m_terms_product;
}

// The initial guess: zero (as Vega and the dissertation), or galerkin_start over the last steps'
// velocity changes (a grown system drops them: their length no longer divides). Off by default: it
// pays at strict tolerances; under the real-time iteration cap its products cost 40% of the solve,
// and a start from earlier steps leaves their error in the slow modes that the cap does not remove
// (the raw last dv pumped energy in: docs/BENCHMARKS.md).
Eigen::Index BackwardEuler::past_velocity_changes(Eigen::Index n) const {
  return n > 0 && m_past_velocity_changes.size() % n == 0 ? m_past_velocity_changes.size() / n : 0;
}

void BackwardEuler::start_velocity_change(const ShiftedSystem& system) {
  const Eigen::Index n = system.rows();
  m_velocity_change.setZero(n);
  const Eigen::Index past = std::min<Eigen::Index>(past_velocity_changes(n), WARM_START_STEPS);
  if (!m_settings.warm_start || past == 0) return;
  galerkin_start(system, m_rhs, Eigen::Map<const Eigen::MatrixXd>(m_past_velocity_changes.data(), n, past),
                 m_velocity_change, m_warm_start, m_solver.get());
}

Eigen::VectorXd BackwardEuler::internal_state() const {
  if (!m_end_potential_by_pass) return m_past_velocity_changes;
  Eigen::VectorXd state(m_past_velocity_changes.size() + 1);
  state << m_past_velocity_changes, 1.0;
  return state;
}

void BackwardEuler::restore_internal_state(const Eigen::VectorXd& internal_state) {
  m_end_potential_by_pass = internal_state.size() % 3 == 1 && internal_state[internal_state.size() - 1] == 1.0;
  m_past_velocity_changes =
      m_end_potential_by_pass ? Eigen::VectorXd(internal_state.head(internal_state.size() - 1)) : internal_state;
}

void BackwardEuler::remember_velocity_change() {
  const Eigen::Index n = m_velocity_change.size();
  const Eigen::Index kept =
      m_settings.warm_start ? std::min<Eigen::Index>(past_velocity_changes(n), WARM_START_STEPS - 1) : 0;
  // In place, oldest kept first; allocates only while the history fills.
  m_past_velocity_changes.conservativeResize(n * (kept + 1));
  for (Eigen::Index k = kept; k > 0; --k) {
    m_past_velocity_changes.segment(n * k, n) = m_past_velocity_changes.segment(n * (k - 1), n);
  }
  m_past_velocity_changes.head(n) = m_velocity_change;
}

// Newton on the backward-Euler equations in v1 (u1 = u0 + h v1):
//   r(v1) = h (f_ext - f_int(u1) - alpha M v1 - beta K(u1) v1) - M (v1 - v0) = 0,
// with the matrix of the step, (1 + h alpha) M + (h beta + h^2) K(u1), taken at each iterate.
// A correction that will be followed by another has its full trial evaluated with the tangent by
// the line search; when the search takes it whole, that evaluation is the next iterate's.
void BackwardEuler::correct(DynamicsModel& model, const DynamicState& state, double h, StepReport& report,
                            WorkTeam* team) {
  const int n = model.dof_count();
  const Eigen::VectorXd& mass = model.mass_kg();
  const double beta_s = model.stiffness_damping_s();
  const double converged_rad = 0.01 * m_settings.newton.trigger_angle_rad;
  bool evaluated = false;  // the model's forces and tangent are at the iterate already
  for (int iteration = 0; iteration < m_settings.newton.max_iterations; ++iteration) {
    const auto assembly_start = std::chrono::steady_clock::now();
    m_end_displacement.noalias() = state.displacement_m + h * m_end_velocity;
    if (!evaluated && m_settings.newton.line_search && !std::isfinite(m_end_potential_j)) {
      // The line search starts from the iterate's potential energy: found in the same pass.
      model.evaluate_with_potential(m_end_displacement, m_internal_force_n, /*update_tangent=*/true);
      m_end_potential_j = model.potential_energy_at_last_evaluate_j();
    } else if (!evaluated) {
      model.evaluate(m_end_displacement, m_internal_force_n, /*update_tangent=*/true);
    }
    m_rhs.noalias() = h * (model.external_force_n() - m_internal_force_n -
                           model.mass_damping_kg_per_s().cwiseProduct(m_end_velocity)) -
                      mass.cwiseProduct(m_end_velocity - state.velocity_m_per_s);
    if (beta_s != 0.0) {
      damped_stiffness_product(model, m_end_velocity, m_stiffness_times_velocity, team);
      m_rhs.noalias() -= (h * beta_s) * m_stiffness_times_velocity;
    }
    const ShiftedSystem system = step_system(model, h, m_end_displacement);
    report.assembly_s += seconds_since(assembly_start);

    // Each correction is solved roughly (a forcing term: while the iterations go on, the linear
    // error stays far below what the next correction redoes; at the cap, below the error of the
    // iterate itself), and carried on to the step's own accuracy when it turns out converged: it
    // turns no element further than converged_rad. The turn is linear in the correction, so a
    // share t of it turns t times as far.
    const bool last = iteration + 1 == m_settings.newton.max_iterations;
    const auto solve_start = std::chrono::steady_clock::now();
    m_correction.setZero(n);
    double turn_rad = 0.0;
    try {
      m_solver->setup_nearby(system);  // the step's matrix moved a little
      report.solve = m_solver->solve_roughly(m_rhs, m_correction);
      report.linear_iterations += report.solve.iterations;
      if ((!last || m_solver->solves_roughly()) && m_correction.allFinite()) {
        m_end_displacement.noalias() = h * m_correction;
        turn_rad = model.largest_turn_rad(m_end_displacement, converged_rad);
        if (turn_rad <= converged_rad) {
          const SolveReport refined = m_solver->refine(m_rhs, m_correction);
          report.linear_iterations += refined.iterations;
          if (refined.iterations > 0) report.solve = refined;
        }
      }
    } catch (const SolverError& error) {
      throw IntegrationError(std::string("backward Euler: a Newton correction's solve failed: ") + error.what());
    }
    report.solve_s += seconds_since(solve_start);
    if (!m_correction.allFinite()) throw IntegrationError("backward Euler: a Newton correction is not finite; state kept");
    ++report.newton_iterations;
    const bool another = !last && turn_rad > converged_rad;
    double share = 1.0;
    if (m_settings.newton.line_search) {
      share = line_search(model, state, h, team, another);
      if (share == 0.0) break;
      m_end_velocity = m_trial_velocity;  // v1 + share correction, as the search measured it
      m_end_potential_j = m_trial_potential_j;
      evaluated = m_trial_evaluated;
    } else {
      m_end_velocity += m_correction;
      m_end_potential_j = std::numeric_limits<double>::quiet_NaN();
    }
    if (!another || share * turn_rad <= converged_rad) break;
  }
}

// Backward Euler's step minimizes, over the end velocity v1 (u1 = u0 + h v1),
//   Phi(v1) = 1/2 |v1 - v0|^2_M + h alpha/2 |v1|^2_M + h beta/2 v1^T K v1 + E(u1),
// E the potential (elastic, the loads', the force terms'), K frozen at the iterate the correction
// was solved at: grad Phi = -r(v1) of correct() there. The matrix is positive definite, so a
// correction descends Phi; the line search keeps the iterates from overshooting it. Along v1 + t c
// the stiffness damping's term is the quadratic v^T K v + 2 t c^T K v + t^2 c^T K c, its three
// products taken before a trial's evaluation replaces the tangent.
double BackwardEuler::incremental_potential_j(const DynamicsModel& model, const DynamicState& state, double h,
                                              const Eigen::VectorXd& v1, double stiffness_damping_j,
                                              double potential_j) const {
  const Eigen::VectorXd& mass = model.mass_kg();
  double kinetic_j = 0.0;
  double damping_j = 0.0;
  for (Eigen::Index i = 0; i < v1.size(); ++i) {
    const double change = v1[i] - state.velocity_m_per_s[i];
    kinetic_j += mass[i] * change * change;
    damping_j += model.mass_damping_kg_per_s()[i] * v1[i] * v1[i];
  }
  return 0.5 * kinetic_j + 0.5 * h * (damping_j + stiffness_damping_j) + potential_j;
}

double BackwardEuler::trial_potential_j(DynamicsModel& model, const DynamicState& state, double h, TrialPass pass) {
  m_trial_displacement.noalias() = state.displacement_m + h * m_trial_velocity;
  m_end_evaluated = false;
  if (pass == TrialPass::with_tangent) {
    model.evaluate_with_potential(m_trial_displacement, m_internal_force_n, /*update_tangent=*/true);
    const double potential_j = model.potential_energy_at_last_evaluate_j();
    if (std::isfinite(potential_j)) return potential_j;
  } else if (pass == TrialPass::ahead && model.evaluate_ahead(m_trial_displacement, m_internal_force_n)) {
    const double potential_j = model.potential_energy_at_last_evaluate_j();
    m_end_evaluated = std::isfinite(potential_j);
    if (m_end_evaluated) return potential_j;
  }
  return model.potential_energy_j(m_trial_displacement);
}

double BackwardEuler::line_search(DynamicsModel& model, const DynamicState& state, double h, WorkTeam* team,
                                  bool evaluate_whole) {
  m_trial_evaluated = false;
  const double beta_s = model.stiffness_damping_s();
  std::array<double, 3> quadratic{0.0, 0.0, 0.0};  // v^T K v, c^T K v, c^T K c
  if (beta_s != 0.0) {
    // K v1 is the right side's (the same K, the same v1): one product, not two (a full K's product
    // per correction, a tenth of a hatched run's late steps).
    quadratic = {m_end_velocity.dot(m_stiffness_times_velocity), m_correction.dot(m_stiffness_times_velocity), 0.0};
    m_trial_product.resize(m_correction.size());
    damped_stiffness_product(model, m_correction, m_trial_product, team);
    quadratic[2] = m_correction.dot(m_trial_product);
  }
  const auto stiffness_damping_j = [&](double share) {
    return beta_s * (quadratic[0] + 2.0 * share * quadratic[1] + share * share * quadratic[2]);
  };
  double start_potential_j = m_end_potential_j;
  if (!std::isfinite(start_potential_j)) {
    m_trial_displacement.noalias() = state.displacement_m + h * m_end_velocity;
    start_potential_j = model.potential_energy_j(m_trial_displacement);
  }
  const double start_j =
      incremental_potential_j(model, state, h, m_end_velocity, stiffness_damping_j(0.0), start_potential_j);
  if (!std::isfinite(start_j)) {  // the model cannot say: the full correction, as without the search
    m_trial_velocity.noalias() = m_end_velocity + m_correction;
    m_trial_potential_j = std::numeric_limits<double>::quiet_NaN();
    return 1.0;
  }
  double share = 1.0;
  for (int halving = 0; halving <= LINE_SEARCH_HALVINGS; ++halving, share *= 0.5) {
    m_trial_velocity.noalias() = m_end_velocity + share * m_correction;
    // The first trial of the last correction is likely the step's end: evaluated ahead of the next
    // step, which takes it as its start if the search does (else the next one is not at that u).
    const bool whole = halving == 0 && evaluate_whole;
    const bool ahead = halving == 0 && evaluates_ahead();
    const TrialPass pass = whole ? TrialPass::with_tangent : ahead ? TrialPass::ahead : TrialPass::potential;
    m_trial_potential_j = trial_potential_j(model, state, h, pass);
    if (incremental_potential_j(model, state, h, m_trial_velocity, stiffness_damping_j(share), m_trial_potential_j) <=
        start_j) {
      m_trial_evaluated = whole;
      return share;
    }
  }
  return 0.0;
}

}  // namespace tissue
