// The co-rotational kernel of one tet (or one part of a cut tet), shared by the uncut model
// (corotational.cpp) and the XFEM parts (xfem_elasticity.cpp): strain, stress, nodal forces,
// energy and the rotated stiffness blocks, all in the rotated-gradient form (docs/DESIGN.md, "Elasticity"):
//   f_i = V R sigma(sym(R^T F) - I) g_i = [R K_e (R^T x - X)]_i,
//   R K_ij R^T = V [lambda c_i c_j^T + mu c_j c_i^T + mu (g_i . g_j) I],   c = R g.
// Inline: these are the innermost loop of every step.
#pragma once

#include "core/material/material.hpp"
#include "core/fem/tet_element.hpp"

#include <Eigen/Core>

namespace tissue {

/// The co-rotated (rotated-back) strain eps = sym(R^T F) - I.
inline Eigen::Matrix3d corotated_strain(const Eigen::Matrix3d& rotation, const Eigen::Matrix3d& f) {
  const Eigen::Matrix3d s = rotation.transpose() * f;
  Eigen::Matrix3d strain = 0.5 * (s + s.transpose());
  strain.diagonal().array() -= 1.0;
  return strain;
}

/// Linear stress of the co-rotated strain: sigma = 2 mu eps + lambda tr(eps) I. [Pa]
inline Eigen::Matrix3d corotated_stress(const Eigen::Matrix3d& rotation, const Eigen::Matrix3d& f,
                                        const LameParameters& lame) {
  const Eigen::Matrix3d strain = corotated_strain(rotation, f);
  Eigen::Matrix3d stress = 2.0 * lame.mu_pa * strain;
  stress.diagonal().array() += lame.lambda_pa * strain.trace();
  return stress;
}

/// Internal forces (3x4, column i acts on vertex i) f_i = V R sigma g_i, equal to R K_e (R^T x - X). [N]
inline Eigen::Matrix<double, 3, 4> corotated_forces(const TetRest& rest, const Eigen::Matrix3d& rotation,
                                                    const Eigen::Matrix3d& f, const LameParameters& lame) {
  const Eigen::Matrix3d r_stress_v = rest.volume_m3 * (rotation * corotated_stress(rotation, f, lame));
  return r_stress_v * rest.shape_gradients_per_m;
}

/// Elastic energy V (mu eps:eps + lambda/2 tr(eps)^2) of one tet. [J]
inline double corotated_energy_j(const TetRest& rest, const Eigen::Matrix3d& rotation, const Eigen::Matrix3d& f,
                                 const LameParameters& lame) {
  const Eigen::Matrix3d strain = corotated_strain(rotation, f);
  return rest.volume_m3 * (lame.mu_pa * strain.squaredNorm() + 0.5 * lame.lambda_pa * strain.trace() * strain.trace());
}

/// Block (i, j) of R K_e R^T from the rotated shape gradients c = R g (3x4). [N/m]
inline Eigen::Matrix3d rotated_stiffness_block(const TetRest& rest, const LameParameters& lame,
                                               const Eigen::Matrix<double, 3, 4>& rotated_gradients, int i, int j) {
  const double lambda_v = lame.lambda_pa * rest.volume_m3;
  const double mu_v = lame.mu_pa * rest.volume_m3;
  const auto ci = rotated_gradients.col(i);
  const auto cj = rotated_gradients.col(j);
  Eigen::Matrix3d block = lambda_v * ci * cj.transpose() + mu_v * cj * ci.transpose();
  block.diagonal().array() += mu_v * rest.shape_gradients_per_m.col(i).dot(rest.shape_gradients_per_m.col(j));
  return block;
}

}  // namespace tissue
