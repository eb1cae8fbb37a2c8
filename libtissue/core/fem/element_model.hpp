// What one tet (or one piece of a cut tet) adds under the body's material model, written once for
// the uncut model (corotational.cpp) and the XFEM pieces (xfem_elasticity.cpp): its internal forces,
// its tangent blocks and its energy, co-rotational linear or stable Neo-Hookean, with the tet's
// region's material (TetRest::material). The Neo-Hookean tangent is projected to positive
// semi-definite per element (every integrator's linear solver needs an SPD system). Inline: the
// innermost loop of every step.
#pragma once

#include "core/fem/corotational_kernel.hpp"
#include "core/fem/stable_neo_hookean.hpp"
#include "core/material/material.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace tissue {

/// The body's material model and, per material, what it needs.
struct ElementModel {
  /// Stable Neo-Hookean's projected tangent at F = R is exactly the co-rotational one, R K_e R^T with
  /// the same Lame parameters (its twist modes have eigenvalue 0, its flip and scaling modes are
  /// linear elasticity's 2 mu and 2 mu I + lambda 1 1^T: docs/DESIGN.md, "Elasticity"). Where the stretch R^T F is
  /// within this of I (Frobenius), the tangent is taken from there: off by O(strain) relatively, as the
  /// co-rotational tangent omits dR/du, while the forces stay Neo-Hookean's (so do equilibria). It
  /// halves the Neo-Hookean step on a body near rest (docs/BENCHMARKS.md).
  static constexpr double NEAR_REST_STRAIN = 0.01;

  MaterialModel model = MaterialModel::corotational_linear;
  std::vector<LameParameters> lame;           // per material
  std::vector<StableNeoHookean> neo_hookean;  // per material

  ElementModel() = default;
  ElementModel(MaterialModel m, std::vector<LameParameters> lame_per_material)
      : model(m), lame(std::move(lame_per_material)) {
    for (const LameParameters& l : lame) neo_hookean.push_back(stable_neo_hookean(l));
  }
  [[nodiscard]] const LameParameters& lame_of(const TetRest& rest) const {
    return lame[static_cast<size_t>(rest.material)];
  }
  [[nodiscard]] const StableNeoHookean& neo_hookean_of(const TetRest& rest) const {
    return neo_hookean[static_cast<size_t>(rest.material)];
  }

  /// Internal forces (3 x 4, column i on vertex i) at deformation gradient f, `rotation` its
  /// co-rotational rotation (unused by Neo-Hookean). [N]
  [[nodiscard]] Eigen::Matrix<double, 3, 4> forces(const TetRest& rest, const Eigen::Matrix3d& rotation,
                                                   const Eigen::Matrix3d& f) const {
    if (model == MaterialModel::stable_neo_hookean) return neo_hookean_forces(rest, neo_hookean_of(rest), f);
    return corotated_forces(rest, rotation, f, lame_of(rest));
  }

  /// The tangent's blocks (i, j), i <= j, at [4 i + j] (block (j, i) is its transpose); Neo-Hookean's
  /// near rest is the co-rotational one (NEAR_REST_STRAIN). [N/m]
  void blocks(const TetRest& rest, const Eigen::Matrix3d& rotation, const Eigen::Matrix3d& f,
              std::array<Eigen::Matrix3d, 16>& out) const {
    if (model == MaterialModel::stable_neo_hookean &&
        (rotation.transpose() * f - Eigen::Matrix3d::Identity()).norm() > NEAR_REST_STRAIN) {
      neo_hookean_projected_blocks(rest, neo_hookean_of(rest), f, out);
      return;
    }
    const Eigen::Matrix<double, 3, 4> c = rotation * rest.shape_gradients_per_m;  // rotated shape gradients
    for (int i = 0; i < 4; ++i) {
      for (int j = i; j < 4; ++j)
        out[static_cast<size_t>(4 * i + j)] = rotated_stiffness_block(rest, lame_of(rest), c, i, j);
    }
  }

  /// Elastic energy [J].
  [[nodiscard]] double energy_j(const TetRest& rest, const Eigen::Matrix3d& rotation, const Eigen::Matrix3d& f) const {
    if (model == MaterialModel::stable_neo_hookean) {
      return rest.volume_m3 * neo_hookean_energy_density(neo_hookean_of(rest), f);
    }
    return corotated_energy_j(rest, rotation, f, lame_of(rest));
  }
};

}  // namespace tissue
