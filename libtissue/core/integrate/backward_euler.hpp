// Semi-implicit backward Euler (Baraff and Witkin 1998; dissertation section 4.2.4, with the
// erratum in docs/DESIGN.md, "Equations and errata": the left side of eq. 4.20 holds the tangent K):
//   (M + h D + h^2 K) dv = h (f_ext - f_int(u) - D v - h K v),   v += dv,   u += h v.
// One linear solve per step; with D = alpha M + beta K the matrix is (1 + h alpha) M + (h beta + h^2) K.
// A step that turns some element far (a free piece tumbling, a 0.1 s step) is corrected by Newton
// iterations on the backward-Euler equations: the linearized step moves the nodes along straight
// lines, which the co-rotational energy reads as stretch, and an exact solve then gains energy.
#pragma once

#include "core/integrate/galerkin_start.hpp"
#include "core/integrate/integrator.hpp"
#include "core/solve/linear_solver.hpp"

#include <memory>

namespace tissue {

/// The share of a stiffness k to enter in the tangent so that this step takes it undamped: the
/// matrix holds (h beta + h^2) K and the right side (beta + h) K v, so k h / (h + beta) in K
/// contributes h^2 k and h k v, the undamped step of k (its force, k times the stretch, is entered
/// whole). For the god-object's contact spring, which stands for the rigid tool, not for tissue
/// (point_contact.hpp). Throws ParameterError unless h > 0 and beta >= 0 are finite.
double undamped_tangent_fraction(double step_size_s, double stiffness_damping_s);

class BackwardEuler final : public Integrator {
 public:
  /// Newton corrections of a step that turns elements far.
  struct NewtonCorrections {
    /// Corrected when the linearized step turns some element further than this [rad]
    /// (DynamicsModel::largest_turn_rad); infinity: never (the dissertation's step).
    double trigger_angle_rad = 0.05;
    /// Iterations at most; they stop once a correction turns no element further than 1% of the trigger.
    int max_iterations = 5;
    /// A step that turns some element further than this [rad] is energy-guarded: if its energy
    /// (kinetic + DynamicsModel::potential_energy_j) ends above where it began, the velocity is
    /// scaled down until it does not (energy projection, Dinev et al. 2018). Infinity: never.
    double energy_guard_angle_rad = 0.005;
    /// Take of each correction only as much as lowers the step's incremental potential (halving it
    /// up to LINE_SEARCH_HALVINGS times; none lowers it: the iterations stop). The co-rotational
    /// tangent lacks the rotation's derivative, so a full correction can overshoot a fast-turning
    /// piece and the iterates swing (docs/DESIGN.md, "Newton corrections"). false: full corrections.
    bool line_search = true;
    /// Newton's first iterate: true, the last step's velocity (the step linearized at the predicted
    /// end u0 + h v0, so that a steady turn is not linearized h omega away from where it ends: a chunk
    /// swinging on a thread needs no corrections); false, v1 = 0 (linearized at the start u0: the
    /// dissertation's step). One assembly and one solve a step, as before. The turn that triggers the
    /// corrections is then h (v1 - v0), from the predicted end; the guard acts when that passes its
    /// angle or the step's own turn, h v1, passes the trigger (both turns in one pass), and nothing is
    /// evaluated ahead: the guard's end potential is the next step's start (docs/DESIGN.md, "The step
    /// linearized at its predicted end").
    bool linearize_at_predicted_end = false;
  };
  /// Halvings of a correction before the line search gives up on it.
  static constexpr int LINE_SEARCH_HALVINGS = 6;
  /// The steps' velocity changes a warm start combines (each costs one product with the matrix).
  static constexpr int WARM_START_STEPS = 8;
  struct Settings {
    /// Start each solve from the combination of the last WARM_START_STEPS steps' dv nearest the
    /// solution in the energy norm of the step's matrix, instead of from zero (matters for
    /// iterative solvers; docs/DESIGN.md, "The warm start").
    bool warm_start = false;
    NewtonCorrections newton;
    /// Threads of a step (1 or 2; see IntegratorSettings::threads): a WorkTeam made and joined by each step.
    int threads = 1;
  };
  explicit BackwardEuler(std::unique_ptr<LinearSolver> solver) : BackwardEuler(std::move(solver), Settings{}) {}
  BackwardEuler(std::unique_ptr<LinearSolver> solver, Settings settings);
  StepReport step(DynamicsModel& model, DynamicState& state, double step_size_s) override;
  [[nodiscard]] const Settings& settings() const { return m_settings; }
  [[nodiscard]] std::string_view name() const override { return "backwardEuler"; }
  [[nodiscard]] const LinearSolver& solver() const { return *m_solver; }
  /// The last steps' velocity changes, newest first, one after the other (the next solve's warm
  /// start when enabled; the last one alone without it), then one entry more (1) when the last step's
  /// guard found its end potential by a pass (m_end_potential_by_pass).
  [[nodiscard]] Eigen::VectorXd internal_state() const override;
  /// Takes any vector: a step uses the velocity changes only when their length is a multiple of the
  /// unknowns' count (a multiple of 3; one entry more is the flag above).
  void restore_internal_state(const Eigen::VectorXd& internal_state) override;
  /// One step depends on the state alone (a grown system drops the warm start); a save or a restore
  /// makes the solver forget its lagged factor (LinearSolver::forget_earlier_setups). A step's start
  /// evaluated ahead by the last step's energy guard is what the step would evaluate itself, bitwise
  /// (DynamicsModel::evaluate_ahead): a save keeps it, a restore drops it.
  void restart(Restart why) override {
    if (why == Restart::state_saved || why == Restart::state_restored) m_solver->forget_earlier_setups();
    if (why == Restart::state_restored) m_end_evaluated = false;
  }
  /// (1/h^2) times this step's matrix: newton_stiffness_system with c = 1/h.
  [[nodiscard]] ShiftedSystem newton_stiffness(const DynamicsModel& model, double step_size_s,
                                               Eigen::VectorXd& diagonal) const override;
  [[nodiscard]] double undamped_tangent_share(double step_size_s, double stiffness_damping_s) const override {
    return undamped_tangent_fraction(step_size_s, stiffness_damping_s);
  }

 private:
  void correct(DynamicsModel& model, const DynamicState& state, double h, StepReport& report, WorkTeam* team);
  // The model evaluated where the step is linearized (at u0, or at the predicted end u0 + h v0, left in
  // m_end_displacement) and m_rhs, the step's right side.
  void linearize(DynamicsModel& model, const DynamicState& state, double h, WorkTeam* team);
  // Reserves the guard's lists per part and per row for `blocks` rows.
  void reserve_guard_lists(Eigen::Index blocks);
  // product = K v without the force terms' share (DynamicsModel::add_force_terms_tangent_product):
  // the stiffness damping's product, beta K v, damps the tissue and not the tool's spring, whose share
  // of the tangent takes the step's (h beta + h^2) to h^2 (undamped_tangent_fraction).
  void damped_stiffness_product(const DynamicsModel& model, const Eigen::VectorXd& v, Eigen::VectorXd& product,
                                WorkTeam* team);
  // Whether a step may evaluate the next step's start ahead (its start is u1, not u1 + h v1).
  [[nodiscard]] bool evaluates_ahead() const { return !m_settings.newton.linearize_at_predicted_end; }
  ShiftedSystem step_system(const DynamicsModel& model, double h, const Eigen::VectorXd& displacement_m);
  // How many whole velocity changes of `n` unknowns the history holds (0 when its length does not
  // divide by n: the system grew since).
  [[nodiscard]] Eigen::Index past_velocity_changes(Eigen::Index n) const;
  // m_velocity_change = the warm start of the solve of `system` x = m_rhs (zero without one), by the
  // solver's products: after its setup.
  void start_velocity_change(const ShiftedSystem& system);
  // Puts m_velocity_change first among the past velocity changes.
  void remember_velocity_change();
  // Scales v1 (m_end_velocity) so that the step's energy does not rise; true if it did. The
  // potential energy at the start is m_start_potential_j when the step's evaluate found it.
  bool guard_energy(DynamicsModel& model, const DynamicState& state, double h);
  // Each part's (DynamicsModel::row_parts) mass-weighted mean velocity of v1 over the rows not left
  // into m_part_momentum (its mass into m_part_mass); returns the kinetic energy of those means, a
  // row no element uses counting as its own mean.
  double part_means(const DynamicsModel& model);
  // The guard where no velocity takes the gain back: the rows of the elements v1 turns past the
  // guard's angle (not left) get the mass-weighted mean velocity of their part's such rows; true if
  // there were any.
  bool brake_turning_rows(const DynamicsModel& model, double h);
  // The step's incremental potential at v1 (backward_euler.cpp), given beta v1^T K v1 and the
  // model's potential energy at u0 + h v1.
  double incremental_potential_j(const DynamicsModel& model, const DynamicState& state, double h,
                                 const Eigen::VectorXd& v1, double stiffness_damping_j, double potential_j) const;
  // How a trial's potential is found: an energy pass, an evaluate with the tangent (m_internal_force_n
  // and the model's tangent then are the trial's), or an evaluation ahead of the next step (the
  // model's, DynamicsModel::evaluate_ahead; m_end_evaluated tells whether it made one).
  enum class TrialPass { potential, with_tangent, ahead };
  // The model's potential energy at u0 + h m_trial_velocity, by `pass`.
  double trial_potential_j(DynamicsModel& model, const DynamicState& state, double h, TrialPass pass);
  // The share t of m_correction to take (0: none lowers the incremental potential); the trial taken
  // is left in m_trial_velocity, its potential energy in m_trial_potential_j. The iterate's
  // potential energy is m_end_potential_j when known. `evaluate_whole`: the whole correction's trial
  // is evaluated with the tangent (m_trial_evaluated tells whether the search took it). With
  // stiffness damping, m_stiffness_times_velocity must hold K m_end_velocity (correct()'s right side).
  double line_search(DynamicsModel& model, const DynamicState& state, double h, WorkTeam* team, bool evaluate_whole);

  std::unique_ptr<LinearSolver> m_solver;
  Settings m_settings;
  Eigen::VectorXd m_internal_force_n;
  Eigen::VectorXd m_stiffness_times_velocity;
  Eigen::VectorXd m_rhs;
  Eigen::VectorXd m_system_diagonal;
  Eigen::VectorXd m_velocity_change;        // the step's solve's
  Eigen::VectorXd m_past_velocity_changes;  // kept: the last steps', newest first (internal_state)
  GalerkinStartWork m_warm_start;
  Eigen::VectorXd m_end_displacement;  // the Newton iterate u0 + h v1
  Eigen::VectorXd m_step_increment_m;  // h v1, whose turn the guard reads at the predicted end
  std::vector<std::uint8_t> m_turning_rows;  // brake_turning_rows()
  std::vector<Eigen::Vector3d> m_part_momentum, m_part_mass;  // per part of the model: part_means(), the brake
  Eigen::VectorXd m_end_velocity;      // v1
  Eigen::VectorXd m_correction;        // a Newton correction of v1
  Eigen::VectorXd m_trial_velocity;    // v1 + t correction, in the line search
  Eigen::VectorXd m_trial_displacement;
  Eigen::VectorXd m_trial_product;     // K v of a trial
  Eigen::VectorXd m_terms_product;     // the force terms' share of K v (damped_stiffness_product)
  double m_trial_potential_j = 0.0;    // the model's potential energy at the last trial's u1
  double m_start_potential_j = 0.0;    // at u0, from the step's evaluate (NaN: the model keeps none)
  double m_end_potential_j = 0.0;      // at u0 + h v1 when the corrections' line search found it, else NaN
  bool m_trial_evaluated = false;      // the line search took a trial evaluated with the tangent
  // The energy guard evaluated the step's end ahead (DynamicsModel::evaluate_ahead): m_internal_force_n
  // is its force, for the next step's start if the model lets it take the evaluation.
  bool m_end_evaluated = false;
  // The last step's guard found its end potential by a pass (DynamicsModel::potential_energy_j at u1):
  // linearized at the predicted end, the next step takes its start potential from that pass, or makes
  // the same pass before its own evaluation. Carried in internal_state(), so a restored step does
  // what the step it continues did, bitwise.
  bool m_end_potential_by_pass = false;
};

/// Throws ParameterError unless the trigger angle is > 0 (infinity: off) and 1 to 100 iterations.
void validate(const BackwardEuler::NewtonCorrections& newton);

}  // namespace tissue
