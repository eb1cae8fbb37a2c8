// DynamicsModel: the semi-discrete equations of motion M a + D v + f_int(u) = f_ext on the
// unknowns of a body (3 per free vertex, then 3 per enriched XFEM unknown), as the integrators see them.
// Integrators call this interface; the FEM implements it (fem/deformable_body.hpp).
#pragma once

#include "core/system/block_sparse_matrix.hpp"
#include "core/system/work_team.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace tissue {

class DynamicsModel {
 public:
  virtual ~DynamicsModel() = default;

  /// Number of unknowns.
  [[nodiscard]] virtual int dof_count() const = 0;
  /// Lumped (diagonal) mass per unknown [kg].
  [[nodiscard]] virtual const Eigen::VectorXd& mass_kg() const = 0;
  /// Rayleigh damping D = diag(mass_damping_kg_per_s()) + beta K (eq. 4.21): its mass part per
  /// unknown [kg/s], alpha m lumped like the mass with each material's alpha (a body of one
  /// material: alpha M), ...
  [[nodiscard]] virtual const Eigen::VectorXd& mass_damping_kg_per_s() const = 0;
  /// ... and beta [s], one for the whole model.
  [[nodiscard]] virtual double stiffness_damping_s() const = 0;
  /// External force per unknown [N] (gravity; contact later).
  [[nodiscard]] virtual const Eigen::VectorXd& external_force_n() const = 0;

  /// Computes f_int(u) into `internal_force_n` (overwritten, length dof_count()) and, when
  /// `update_tangent`, refreshes tangent() = d f_int / d u (the co-rotational R K R^T).
  virtual void evaluate(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n,
                        bool update_tangent) = 0;
  /// Lends the model a team of threads for its evaluate() calls, until lent nullptr (an integrator
  /// lends one for the length of a step, see IntegratorSettings::threads). A model may ignore it;
  /// results must not depend on it.
  virtual void lend_work_team(WorkTeam* /*team*/) {}
  /// The tangent stiffness of the last evaluate() with update_tangent [N/m].
  [[nodiscard]] virtual const BlockSparseMatrix& tangent() const = 0;
  /// Per block row of tangent(), the rotation its unknowns have turned through since the rest state
  /// (a vertex's co-rotational frame at the last evaluate()), or nullptr for a model without one.
  /// A lagged preconditioner turns with it (CholeskyPcgSolver). Valid until the next evaluate() or
  /// growth of the model.
  [[nodiscard]] virtual const std::vector<Eigen::Matrix3d>* block_frames() const { return nullptr; }
  /// Per block row of tangent(), the point its unknowns move at displacement `displacement_m` [m]
  /// (a vertex's position; an enriched unknown's, its vertex's rest position moved by it), or
  /// nullptr for a model without points. A two-level preconditioner takes the rigid motions of
  /// groups of them (TwoLevelPcgSolver). Valid until the next call or growth of the model.
  [[nodiscard]] virtual const std::vector<Eigen::Vector3d>* block_positions(
      const Eigen::VectorXd& /*displacement_m*/) const {
    return nullptr;
  }
  /// The largest angle [rad] the displacement increment `increment_m` (from the state of the last
  /// evaluate()) turns an element: a step linearized there strays from the nonlinear model by about
  /// its square. Where a cheap bound shows every element below `resolution_rad`, that bound may be
  /// returned instead (so compare it with thresholds >= resolution_rad). 0 for a model with nothing
  /// to turn.
  [[nodiscard]] virtual double largest_turn_rad(const Eigen::VectorXd& /*increment_m*/,
                                                double /*resolution_rad*/) const {
    return 0.0;
  }
  /// {largest_turn_rad(first_m, resolution_rad[0]), largest_turn_rad(second_m, resolution_rad[1])}, as
  /// those two calls answer; a model may find both in one pass over its elements.
  [[nodiscard]] virtual std::array<double, 2> largest_turns_rad(const Eigen::VectorXd& first_m,
                                                                const Eigen::VectorXd& second_m,
                                                                std::array<double, 2> resolution_rad) const {
    return {largest_turn_rad(first_m, resolution_rad[0]), largest_turn_rad(second_m, resolution_rad[1])};
  }
  /// Sets turning[r] = 1 for every block row r of an element that `increment_m` turns further than
  /// `angle_rad` (as largest_turn_rad() measures it), and 0 for the others; `turning` gets one entry
  /// per block row. The default (a model with no elements to ask) marks every row.
  virtual void mark_turning_rows(const Eigen::VectorXd& increment_m, double /*angle_rad*/,
                                 std::vector<std::uint8_t>& turning) const {
    turning.assign(static_cast<std::size_t>(increment_m.size() / 3), 1);
  }
  /// Per block row, nonzero where the row has left the dynamics (a part parked out of the operating
  /// field): no element joins it to another, it keeps its mass and weight and falls on as a free
  /// particle, whose backward-Euler step is exact and loses energy. The energy guard leaves those rows
  /// out. May be shorter than the rows (the rest are in); nullptr (the default): every row is in. Read
  /// it with row_left() (core/system/rows_left.hpp).
  [[nodiscard]] virtual const std::vector<std::uint8_t>* rows_left() const { return nullptr; }
  /// Per block row, the part of the model it belongs to: rows that elements join, directly or through
  /// others, share a part (numbered from 0); -1 for a row no element uses. No force acts between two
  /// parts, so each keeps its own momentum (the energy guard keeps it). nullptr (the default): the
  /// model is one part. Valid until the model next changes.
  [[nodiscard]] virtual const std::vector<int>* row_parts() const { return nullptr; }
  /// The potential of the model's forces at u: elastic energy plus that of any spring to a fixed
  /// target, minus f_ext . u [J]; NaN for a model that cannot say (its steps are not energy-guarded).
  [[nodiscard]] virtual double potential_energy_j(const Eigen::VectorXd& /*displacement_m*/) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  /// What the last potential_energy_j(u) call answered, when u is bitwise that call's displacement
  /// and nothing changed the model since (no evaluate, cut, park, restore, term attached, detached or
  /// moved): the value a new call would give, bitwise (a call reads the rotations' warm starts and
  /// does not change them). NaN otherwise, and for a model that keeps none.
  [[nodiscard]] virtual double kept_potential_energy_j(const Eigen::VectorXd& /*displacement_m*/) const {
    return std::numeric_limits<double>::quiet_NaN();
  }
  /// evaluate(), and potential_energy_j at u found in the same pass where the model can (then
  /// potential_energy_at_last_evaluate_j() gives it): the energy guard's start without a pass of
  /// its own. A model that cannot: evaluate() alone.
  virtual void evaluate_with_potential(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n,
                                       bool update_tangent) {
    evaluate(displacement_m, internal_force_n, update_tangent);
  }
  /// The potential energy evaluate_with_potential() found; NaN when the last evaluate was not one,
  /// the model keeps none or has changed since.
  [[nodiscard]] virtual double potential_energy_at_last_evaluate_j() const {
    return std::numeric_limits<double>::quiet_NaN();
  }
  /// Adds the force terms' share of tangent() (ForceTerm: the blocks a term such as the tool's spring
  /// enters with Integrator::undamped_tangent_share, which the step must not damp) times `vector` to
  /// `product`. None by default.
  virtual void add_force_terms_tangent_product(const Eigen::VectorXd& /*vector*/, Eigen::VectorXd& /*product*/) const {}
  /// evaluate_with_potential(u, f, true) ahead of the next step, whose start u is: the model keeps
  /// its state from before (what a save records) until the next step takes the evaluation
  /// (take_evaluation_ahead), so that a step from a restored state, evaluating u itself, continues
  /// bitwise as the one that took it. Returns false, with nothing done, where the model cannot or
  /// expects a change before the next step (a force term in use: the tool moves between steps).
  virtual bool evaluate_ahead(const Eigen::VectorXd& /*displacement_m*/, Eigen::VectorXd& /*internal_force_n*/) {
    return false;
  }
  /// Whether the last evaluate_ahead() was at exactly (bitwise) `displacement_m` and nothing changed
  /// the model since (no evaluate, cut, parked part, restore, force term attached, detached or set):
  /// then it is taken (its forces, tangent, potential and rotations are the model's from now on) and
  /// an evaluate there would give the same. Else false, and the model is as before the evaluation
  /// ahead (its rotations; the tangent is that evaluation's until the next evaluate).
  virtual bool take_evaluation_ahead(const Eigen::VectorXd& /*displacement_m*/) { return false; }
};

/// The state an integrator advances: displacement and velocity per unknown, and time.
struct DynamicState {
  Eigen::VectorXd displacement_m;
  Eigen::VectorXd velocity_m_per_s;
  double time_s = 0.0;
};

}  // namespace tissue
