// Integrator: advances a DynamicState of a DynamicsModel by one step. Backward Euler and SUNDIALS
// IDA implement it; make_integrator() (integrator_factory.hpp) picks one from the settings.
//
// The contract, beyond step():
// * restart(why): the system grew (a cut), a state was saved or a saved state restored, or a
//   contact began or ended. A multistep method (IDA) drops its history and starts afresh (order 1,
//   a new step size, new memory when the size changed) from the state it is given at the next
//   step() (not for a save). A one-step method has no history; where a state is saved or restored
//   it lets its linear solver forget what earlier setups left (a lagged factor), so that the run
//   after a save and the run after its restore continue alike, bitwise.
// * internal_state(): what carries over between steps and can be saved with an FMU state (backward
//   Euler's warm start). A multistep history cannot be exported: internal_state() is empty, and a
//   restored state continues exactly as a restart at the restored point would (tests/unit/integrate).
// * newton_stiffness(): the matrix of the step's Newton iteration in the unknowns u, scaled to a
//   stiffness [N/m]: the stiffness a point of the body meets within one step (inertia and damping
//   hold the rest). The contact's K_c of a body that nothing holds is condensed from it
//   (docs/DESIGN.md, "Contact"), so the contact asks the integrator instead of re-deriving its matrix.
#pragma once

#include "core/parameter_error.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/system/dynamics_model.hpp"

#include <stdexcept>
#include <string_view>

namespace tissue {

/// A step that could not be completed; the state is left as it was before the step.
class IntegrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct StepReport {
  double assembly_s = 0.0;      ///< forces and tangent (wall time)
  double solve_s = 0.0;         ///< linear solve(s) (wall time)
  SolveReport solve;            ///< of the (last) linear solve
  int internal_steps = 1;       ///< steps the integrator took inside this one (IDA: error control)
  int newton_iterations = 0;    ///< nonlinear iterations (0 for the linearized backward Euler)
  long linear_iterations = 0;   ///< Krylov iterations of all solves (PCG, GMRES); 0 for direct solves
  bool energy_guarded = false;  ///< backward Euler scaled the velocity down so the energy did not rise
  double guard_s = 0.0;         ///< backward Euler's energy guard: its two energy passes (wall time)
};

/// Why an integrator must start afresh at its next step.
enum class Restart { system_grown, state_saved, state_restored, contact_changed };

class Integrator {
 public:
  virtual ~Integrator() = default;
  /// Advances `state` by `step_size_s` (> 0). Throws IntegrationError (state unchanged) when the
  /// step cannot be taken, e.g. the linear solver fails or the result is not finite.
  virtual StepReport step(DynamicsModel& model, DynamicState& state, double step_size_s) = 0;
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// What the integrator carries from one step to the next beyond the DynamicState (a warm start),
  /// packed in one vector, so that a saved state continues bitwise; empty if nothing (or nothing
  /// that can be exported: a multistep history, see restart()).
  [[nodiscard]] virtual Eigen::VectorXd internal_state() const = 0;
  /// Restores internal_state(); throws std::invalid_argument (nothing changed) for a wrong size.
  virtual void restore_internal_state(const Eigen::VectorXd& internal_state) = 0;
  /// The next step starts afresh (see the contract above).
  virtual void restart(Restart why) = 0;
  /// The Newton matrix of a step of `step_size_s` as a stiffness (see above); `diagonal` is the
  /// shift it points to (resized here; keep it alive with the result). Throws ParameterError for
  /// a step size that is not finite and > 0.
  [[nodiscard]] virtual ShiftedSystem newton_stiffness(const DynamicsModel& model, double step_size_s,
                                                       Eigen::VectorXd& diagonal) const = 0;
  /// The share of its stiffness a force term that stands for something rigid, not tissue (the
  /// contact's spring: system/force_term.hpp), puts in the tangent so that the step does not damp
  /// it (backward Euler: h / (h + beta)); 1 where it cannot be kept undamped that way.
  [[nodiscard]] virtual double undamped_tangent_share(double step_size_s, double stiffness_damping_s) const = 0;
};

/// The Newton matrix of the residual M a + D v + f_int(u) - f_ext in u, when the method ties
/// v = c u + ... and a = c v + ... (c the leading coefficient [1/s]: 1/h for backward Euler, IDA's
/// c_j for a BDF step), as a stiffness:
///   A = (c^2 + c alpha) M + (1 + c beta) K,   K the model's tangent.
/// Throws ParameterError unless c is finite and > 0.
ShiftedSystem newton_stiffness_system(const DynamicsModel& model, double leading_coefficient_per_s,
                                      Eigen::VectorXd& diagonal);

}  // namespace tissue
