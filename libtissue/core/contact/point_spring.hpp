// The god-object contact's spring as a force term of the body: from a material point of the body
// (a point of a surface triangle) to the tool's interaction point (point_contact.hpp says why a
// spring, and why its tangent share is below 1); for a pad probe, the pad's springs beside it, one per
// sample of the pad (point_contact.hpp, "A pad").
#pragma once

#include "core/system/force_term.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <vector>

namespace tissue {

/// A spring of stiffness k from a material point x_p = sum_i w_i x_i of the body (a point of a
/// surface triangle) to a target: the body feels k D (target - x_p) + F, shared out with the
/// weights, D = I (the spring pulls along every axis) or d d^T (along a unit direction d alone: the
/// point slides freely across d, a frictionless contact), F a constant force (a slipping contact's
/// friction; point_contact.hpp).
struct PointSpring {
  std::array<int, 3> vertices{};  ///< mesh vertices (the 3 vertices of a surface triangle)
  Eigen::Vector3d weights = Eigen::Vector3d::Constant(1.0 / 3.0);  ///< w_i, summing to 1
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
  double stiffness_n_per_m = 0.0;
  /// The share of k entered in the tangent, in (0, 1]. 1 makes the tangent d f_int / du; but the
  /// integrators damp the tangent (D = alpha M + beta K), which damps the spring like tissue,
  /// beta k against a fixed frame. Integrator::undamped_tangent_share() takes the damping out of
  /// the step. The force is k (x_p - target) whatever the share.
  double tangent_fraction = 1.0;
  /// Zero: D = I. A unit vector d: D = d d^T.
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  /// F, a constant force on the body at x_p [N] (in no tangent).
  Eigen::Vector3d constant_force_on_body_n = Eigen::Vector3d::Zero();
};

/// D (see PointSpring): the identity, or d d^T for a spring with a direction.
Eigen::Matrix3d spring_projector(const PointSpring& spring);
/// The spring's material point sum_i w_i x_i with the vertices at `positions_m` (3 per vertex) [m].
Eigen::Vector3d spring_material_point_m(const PointSpring& spring, const Eigen::VectorXd& positions_m);
/// The force the springs apply to the body with its vertices at `positions_m` (3 per vertex) [N].
Eigen::Vector3d springs_force_on_body_n(const std::vector<PointSpring>& springs, const Eigen::VectorXd& positions_m);
/// The force the spring applies to the body with its material point at `material_point_m`:
/// k D (target - x_p) + F [N] (the force on the tool is its opposite).
Eigen::Vector3d spring_force_on_body_n(const PointSpring& spring, const Eigen::Vector3d& material_point_m);

/// The body's point spring and a pad's springs, or none. Attach it to the body (DeformableBody::attach)
/// once; set() it as the contact starts, moves and ends.
class PointSpringTerm final : public ForceTerm {
 public:
  /// Sets (or clears) the spring and the pad's (none unless `spring` is set): each gives f_int
  /// w_i (k D (x_p - target) - F) on each of its vertices i, the tangent c k w_i w_j D between free
  /// vertices (c its tangent_fraction). Throws ParameterError (springs unchanged) unless, for each,
  /// the vertices are in range, every pair of free ones shares a tet, weights, target and F are
  /// finite with |sum w - 1| <= 1e-6, 0 <= k < inf, 0 < c <= 1 and the direction zero or of length 1
  /// within 1e-6, or for a pad without a spring. `layout` is the body's (DeformableBody::term_layout).
  void set(std::optional<PointSpring> spring, const TermLayout& layout, std::vector<PointSpring> pad = {});
  [[nodiscard]] const std::optional<PointSpring>& spring() const { return m_spring; }
  /// The pad's springs (empty for a point probe).
  [[nodiscard]] const std::vector<PointSpring>& pad() const { return m_pad; }
  /// k D (target - x_p) + F at the last add_force(): the force the spring and the pad's apply to the
  /// body (zero without a spring) [N].
  [[nodiscard]] const Eigen::Vector3d& force_on_body_n() const { return m_force_on_body_n; }

  void add_force(const Eigen::VectorXd& positions_m, Eigen::VectorXd& vertex_forces_n) override;
  void add_tangent(BlockSparseMatrix& tangent) const override;
  void add_tangent_product(const Eigen::VectorXd& vector, Eigen::VectorXd& product) const override;
  [[nodiscard]] double energy_j(const Eigen::VectorXd& positions_m) const override;
  void locate(const TermLayout& layout) override;
  /// No spring set (then no pad either).
  [[nodiscard]] bool idle() const override { return !m_spring; }

 private:
  using Slots = std::array<int, 9>;  // [3 i + j]: block (row of vertex i, row of vertex j), -1 if fixed

  std::optional<PointSpring> m_spring;
  Slots m_slots{};
  std::vector<PointSpring> m_pad;
  std::vector<Slots> m_pad_slots;
  std::vector<std::array<int, 3>> m_rows;  // per spring (the point's, then the pad's): its vertices' rows, -1 fixed
  Eigen::Vector3d m_force_on_body_n = Eigen::Vector3d::Zero();
};

}  // namespace tissue
