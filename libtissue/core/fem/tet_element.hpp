// One linear tetrahedron: rest-state precompute (shape gradients, volume), the linear stiffness
// K_e = V B^T E B (eq. 3.12) and the deformation gradient. Shared by the co-rotational model and tests.
#pragma once

#include "core/material/material.hpp"

#include <Eigen/Core>

#include <array>

namespace tissue {

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Vector12d = Eigen::Matrix<double, 12, 1>;
using TetPositions = std::array<Eigen::Vector3d, 4>;

/// Rest-state quantities of one tet.
struct TetRest {
  /// Column i is grad(phi_i) [1/m], the gradient of the barycentric shape function of vertex i.
  /// The columns sum to zero, and sum_i X_i grad(phi_i)^T = I for the rest positions X_i.
  Eigen::Matrix<double, 3, 4> shape_gradients_per_m;
  double volume_m3 = 0.0;
  /// The tet's material: an index into the body's materials, one per mesh region (TetMesh::regions).
  /// Cut pieces copy their tet's TetRest, so they keep it.
  int material = 0;
};
// The index sits in what was padding: the per-tet data a step streams did not grow.
static_assert(sizeof(TetRest) == 112, "TetRest grew: the co-rotational step streams it per tet");

/// Requires a positively oriented tet (volume > 0); the mesh readers guarantee it.
TetRest precompute_tet(const TetPositions& rest_positions_m);

/// F = sum_i x_i grad(phi_i)^T (3x3), the deformation gradient for current positions x.
/// Inline: it is in the innermost loop of every step.
inline Eigen::Matrix3d deformation_gradient(const TetRest& rest, const TetPositions& positions_m) {
  Eigen::Matrix3d f = positions_m[0] * rest.shape_gradients_per_m.col(0).transpose();
  for (size_t i = 1; i < 4; ++i) {
    f.noalias() += positions_m[i] * rest.shape_gradients_per_m.col(static_cast<Eigen::Index>(i)).transpose();
  }
  return f;
}

/// 3x3 block (i, j) of the linear stiffness: V [lambda g_i g_j^T + mu g_j g_i^T + mu (g_i . g_j) I].
Eigen::Matrix3d linear_stiffness_block(const TetRest& rest, const LameParameters& lame, int i, int j);

/// The full 12x12 K_e, vertex-major (3 rows per vertex). [N/m]
Matrix12d linear_stiffness_matrix(const TetRest& rest, const LameParameters& lame);

}  // namespace tissue
