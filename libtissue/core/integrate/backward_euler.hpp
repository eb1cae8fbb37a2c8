// Semi-implicit backward Euler (Baraff and Witkin 1998; dissertation section 4.2.4, with the
// erratum of DESIGN section 4: the left side of eq. 4.20 holds the tangent K):
//   (M + h D + h^2 K) dv = h (f_ext - f_int(u) - D v - h K v),   v += dv,   u += h v.
// One linear solve per step; with D = alpha M + beta K the matrix is (1 + h alpha) M + (h beta + h^2) K.
#pragma once

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
  struct Settings {
    /// Start each solve from the previous step's dv instead of zero (matters for iterative solvers).
    bool warm_start = false;
  };
  explicit BackwardEuler(std::unique_ptr<LinearSolver> solver) : BackwardEuler(std::move(solver), Settings{}) {}
  BackwardEuler(std::unique_ptr<LinearSolver> solver, Settings settings);
  StepReport step(DynamicsModel& model, DynamicState& state, double step_size_s) override;
  [[nodiscard]] std::string_view name() const override { return "backward-euler"; }
  [[nodiscard]] const LinearSolver& solver() const { return *m_solver; }
  /// The last velocity change (the next solve's warm start when enabled).
  [[nodiscard]] Eigen::VectorXd internal_state() const override { return m_velocity_change; }
  void restore_internal_state(const Eigen::VectorXd& internal_state) override {
    m_velocity_change = internal_state;
  }
  /// One step depends on the state alone: nothing to forget (a grown system drops the warm start).
  void restart(Restart /*why*/) override {}
  /// (1/h^2) times this step's matrix: newton_stiffness_system with c = 1/h.
  [[nodiscard]] ShiftedSystem newton_stiffness(const DynamicsModel& model, double step_size_s,
                                               Eigen::VectorXd& diagonal) const override;
  [[nodiscard]] double undamped_spring_fraction(double step_size_s, double stiffness_damping_s) const override {
    return undamped_tangent_fraction(step_size_s, stiffness_damping_s);
  }

 private:
  std::unique_ptr<LinearSolver> m_solver;
  Settings m_settings;
  Eigen::VectorXd m_internal_force_n;
  Eigen::VectorXd m_stiffness_times_velocity;
  Eigen::VectorXd m_rhs;
  Eigen::VectorXd m_system_diagonal;
  Eigen::VectorXd m_velocity_change;  // kept: the warm start of the next solve
};

}  // namespace tissue
