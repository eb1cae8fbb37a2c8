// Rest-state precompute and the linear stiffness of one tet.
#include "core/fem/tet_element.hpp"

#include <Eigen/LU>

namespace tissue {

TetRest precompute_tet(const TetPositions& rest_positions_m) {
  // Edge matrix Dm = [X1-X0, X2-X0, X3-X0]; grad(phi_k) for k=1..3 are the rows of Dm^-1,
  // and grad(phi_0) = -(sum of the others), so that the shape functions sum to one.
  Eigen::Matrix3d edges;
  for (int k = 0; k < 3; ++k) edges.col(k) = rest_positions_m[static_cast<size_t>(k + 1)] - rest_positions_m[0];
  const Eigen::Matrix3d inverse = edges.inverse();
  TetRest rest;
  rest.shape_gradients_per_m.rightCols<3>() = inverse.transpose();
  rest.shape_gradients_per_m.col(0) = -inverse.transpose().rowwise().sum();
  rest.volume_m3 = edges.determinant() / 6.0;
  return rest;
}

Eigen::Matrix3d linear_stiffness_block(const TetRest& rest, const LameParameters& lame, int i, int j) {
  const auto gi = rest.shape_gradients_per_m.col(i);
  const auto gj = rest.shape_gradients_per_m.col(j);
  Eigen::Matrix3d block = lame.lambda_pa * gi * gj.transpose() + lame.mu_pa * gj * gi.transpose();
  block.diagonal().array() += lame.mu_pa * gi.dot(gj);
  return rest.volume_m3 * block;
}

Matrix12d linear_stiffness_matrix(const TetRest& rest, const LameParameters& lame) {
  Matrix12d k;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) k.block<3, 3>(3 * i, 3 * j) = linear_stiffness_block(rest, lame, i, j);
  }
  return k;
}

}  // namespace tissue
