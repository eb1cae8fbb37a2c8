// Tests of the linear tet: shape gradients, volume and the stiffness K_e (eq. 3.12).
#include "core/fem/tet_element.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <algorithm>

namespace tissue {
namespace {

TetPositions skewed_tet() {
  return {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.011, 0.001, -0.002), Eigen::Vector3d(0.002, 0.009, 0.001),
          Eigen::Vector3d(-0.001, 0.002, 0.012)};
}

TEST(TetElement, ShapeGradientsReproduceLinearFields) {
  const TetPositions x = skewed_tet();
  const TetRest rest = precompute_tet(x);
  // The shape functions form a partition of unity and reproduce x exactly, so
  // sum_i g_i = 0 and sum_i x_i g_i^T = I (to round-off).
  EXPECT_LT(rest.shape_gradients_per_m.rowwise().sum().norm(), 1e-10);
  EXPECT_LT((deformation_gradient(rest, x) - Eigen::Matrix3d::Identity()).norm(), 1e-13);
  const double expected_volume = (x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0]) / 6.0;
  EXPECT_NEAR(rest.volume_m3, expected_volume, 1e-18);
  EXPECT_GT(rest.volume_m3, 0.0);
}

TEST(TetElement, StiffnessIsSymmetricWithExactlySixZeroEigenvalues) {
  const LameParameters lame = lame_parameters(Material{1.0e5, 0.4, 1000.0});
  const Matrix12d k = linear_stiffness_matrix(precompute_tet(skewed_tet()), lame);
  EXPECT_LT((k - k.transpose()).norm(), 1e-12 * k.norm());
  Eigen::SelfAdjointEigenSolver<Matrix12d> eigen(k);
  const auto values = eigen.eigenvalues();  // ascending
  const double largest = values(11);
  // Six rigid modes (3 translations, 3 infinitesimal rotations) have zero strain: eigenvalue 0
  // to round-off (1e-12 relative). The six deformation modes are strictly positive; for this
  // well-shaped tet the smallest is ~1% of the largest, so 1e-4 separates them safely.
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(values(i)), 1e-12 * largest) << "eigenvalue " << i;
  for (int i = 6; i < 12; ++i) EXPECT_GT(values(i), 1e-4 * largest) << "eigenvalue " << i;
}

TEST(TetElement, UniaxialStretchGivesHookesLaw) {
  // A homogeneous strain eps_xx with nu = 0: the nodal forces on the x-faces add up to E eps A,
  // which for a tet is checked through the energy: 1/2 u^T K u = 1/2 E eps^2 V.
  const double young = 2.0e5;
  const LameParameters lame = lame_parameters(Material{young, 0.0, 1000.0});
  const TetPositions x = skewed_tet();
  const TetRest rest = precompute_tet(x);
  const double strain = 1e-3;
  Vector12d u;
  for (int i = 0; i < 4; ++i) u.segment<3>(3 * i) = Eigen::Vector3d(strain * x[static_cast<size_t>(i)].x(), 0.0, 0.0);
  const double energy = 0.5 * u.dot(linear_stiffness_matrix(rest, lame) * u);
  EXPECT_NEAR(energy, 0.5 * young * strain * strain * rest.volume_m3, 1e-12 * energy);
}

}  // namespace
}  // namespace tissue
