// IdaIntegrator: SUNDIALS IDA (variable-order, variable-step BDF with error control) on the
// equations of motion written as the DAE residual in y = [u; v]:
//   F(t, y, y') = [u' - v;  M v' + D v + f_int(u) - f_ext] = 0,   D = alpha M + beta K(u),
// with the analytic Newton matrix dF/dy + c_j dF/dy' = [c_j I, -I; K, (alpha + c_j) M + beta K]
// (K the co-rotational tangent; its change with u inside D v is left out of the Jacobian only).
// Linear solvers: KLU (SuiteSparse, direct, on the 2n x 2n matrix in compressed columns) or GMRES
// preconditioned by eliminating v exactly and taking the Schur complement
//   S = (1 + c_j beta) K + (c_j^2 + c_j alpha) M   (newton_stiffness_system with c = c_j)
// by its diagonal (Jacobi). One step() integrates to t + h through as many internal steps as the
// tolerances need, ending exactly at t + h (IDA's stop time).
//
// Restarts (Integrator's contract): a grown system gets new IDA memory; a restored state or a
// contact that begins or ends re-initializes IDA at the current state (order 1, history dropped),
// with the consistent y' = [v; M^-1 (f_ext - f_int - D v)]. Nothing of the history is exported:
// a restored FMU state continues as this restart does.
#pragma once

#include "core/integrate/integrator.hpp"
#include "core/named_items.hpp"

#include <memory>
#include <string_view>

namespace tissue {

enum class IdaLinearSolverKind { klu, krylov };

inline constexpr ItemNames<IdaLinearSolverKind, 2> IDA_LINEAR_SOLVER_NAMES{
    "IDA linear solver",
    {{{"klu", "Sparse LU factorization of the Newton matrix (KLU, direct)"},
      {"krylov", "GMRES, preconditioned by eliminating the velocities and the diagonal of the rest (iterative)"}}}};

/// Parses "klu" / "krylov" (IDA_LINEAR_SOLVER_NAMES); throws ParameterError otherwise.
IdaLinearSolverKind parse_ida_linear_solver_kind(std::string_view name);
[[nodiscard]] std::string_view to_string(IdaLinearSolverKind kind);

struct IdaSettings {
  double relative_tolerance = 1e-4;
  /// On displacements [m] and velocities [m/s] alike.
  double absolute_tolerance = 1e-8;
  int max_order = 5;        ///< BDF order cap, 1..5
  double max_step_s = 0.0;  ///< cap on IDA's internal step [s]; 0: none (up to the whole step)
  IdaLinearSolverKind linear_solver = IdaLinearSolverKind::klu;
  /// Internal steps allowed in one step() before it refuses (a runaway guard, not a tolerance): a
  /// crawl of microsecond steps (inverted tets, GMRES on stiff modes) is refused in ~0.3-2 s on
  /// bodies of a few thousand unknowns instead of 3-8 s at 20000 (tests/extremes).
  int max_internal_steps = 2000;
};

/// Throws ParameterError unless the tolerances are finite and > 0, 1 <= max_order <= 5,
/// max_step_s is finite and >= 0 and max_internal_steps >= 1.
void validate(const IdaSettings& settings);

class IdaIntegrator final : public Integrator {
 public:
  /// Throws ParameterError for invalid settings.
  explicit IdaIntegrator(IdaSettings settings);
  ~IdaIntegrator() override;
  IdaIntegrator(const IdaIntegrator&) = delete;
  IdaIntegrator& operator=(const IdaIntegrator&) = delete;

  StepReport step(DynamicsModel& model, DynamicState& state, double step_size_s) override;
  [[nodiscard]] std::string_view name() const override { return "ida"; }
  /// Empty: a BDF history cannot be exported (see restart()).
  [[nodiscard]] Eigen::VectorXd internal_state() const override { return {}; }
  /// Accepts only the empty vector of internal_state(); a restart follows (restart(state_restored)).
  void restore_internal_state(const Eigen::VectorXd& internal_state) override;
  void restart(Restart why) override;
  /// With IDA's c_j of its last internal step (1/h before the first).
  [[nodiscard]] ShiftedSystem newton_stiffness(const DynamicsModel& model, double step_size_s,
                                               Eigen::VectorXd& diagonal) const override;
  /// 1: the spring enters the tangent whole (IDA's residual damps it by beta k; docs/DESIGN.md, "Integrators").
  [[nodiscard]] double undamped_tangent_share(double /*step_size_s*/, double /*stiffness_damping_s*/) const override {
    return 1.0;
  }
  [[nodiscard]] const IdaSettings& settings() const { return m_settings; }
  /// How many times IDA memory was created and re-initialized so far (tests check the restarts).
  [[nodiscard]] int creations() const;
  [[nodiscard]] int reinitializations() const;

 private:
  struct Impl;
  IdaSettings m_settings;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace tissue
