// Integrator: advances a DynamicState of a DynamicsModel by one step. Backward Euler is one
// implementation; SUNDIALS IDA (issue 5) is another, behind the same contract.
#pragma once

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
  double assembly_s = 0.0;  ///< forces and tangent (wall time)
  double solve_s = 0.0;     ///< linear solve(s) (wall time)
  SolveReport solve;        ///< of the (last) linear solve
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  /// Advances `state` by `step_size_s` (> 0). Throws IntegrationError (state unchanged) when the
  /// step cannot be taken, e.g. the linear solver fails or the result is not finite.
  virtual StepReport step(DynamicsModel& model, DynamicState& state, double step_size_s) = 0;
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// What the integrator carries from one step to the next beyond the DynamicState (a warm start,
  /// a history), packed in one vector, so that a saved state continues bitwise; empty if nothing.
  [[nodiscard]] virtual Eigen::VectorXd internal_state() const = 0;
  /// Restores internal_state(); throws std::invalid_argument (nothing changed) for a wrong size.
  virtual void restore_internal_state(const Eigen::VectorXd& internal_state) = 0;
};

}  // namespace tissue
