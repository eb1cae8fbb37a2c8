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

/// Four doubles in one AVX2 register (two SSE registers in the baseline clone): a column of three
/// and a zero, for the kernels written column by column (here and element_blocks.hpp).
using ColumnLanes = double __attribute__((vector_size(32)));

/// Internal forces (3x4, column i acts on vertex i) f_i = V R sigma g_i, equal to R K_e (R^T x - X). [N]
/// Column by column in lanes (Eigen's fixed-size 3 x 3 products stayed scalar here; the frog's step
/// 0.973x with lanes, docs/BENCHMARKS.md): S = R^T F by R's rows, V sigma's columns from S's and its
/// transpose's, P = R (V sigma) by R's columns, f_i = P g_i.
[[gnu::always_inline]] inline Eigen::Matrix<double, 3, 4> corotated_forces(const TetRest& rest,
                                                                           const Eigen::Matrix3d& rotation,
                                                                           const Eigen::Matrix3d& f,
                                                                           const LameParameters& lame) {
  using Lanes = ColumnLanes;
  const Eigen::Matrix3d& r = rotation;
  const Eigen::Matrix<double, 3, 4>& g = rest.shape_gradients_per_m;
  const Lanes row0{r(0, 0), r(0, 1), r(0, 2), 0.0};
  const Lanes row1{r(1, 0), r(1, 1), r(1, 2), 0.0};
  const Lanes row2{r(2, 0), r(2, 1), r(2, 2), 0.0};
  // S's columns: S e_j = R^T f_j = sum_k (row k of R)^T F(k, j).
  const Lanes s0 = row0 * f(0, 0) + row1 * f(1, 0) + row2 * f(2, 0);
  const Lanes s1 = row0 * f(0, 1) + row1 * f(1, 1) + row2 * f(2, 1);
  const Lanes s2 = row0 * f(0, 2) + row1 * f(1, 2) + row2 * f(2, 2);
  // S^T's columns (S's rows).
  const Lanes t0{s0[0], s1[0], s2[0], 0.0};
  const Lanes t1{s0[1], s1[1], s2[1], 0.0};
  const Lanes t2{s0[2], s1[2], s2[2], 0.0};
  // V sigma = V mu (S + S^T) + V (lambda tr(eps) - 2 mu) I, tr(eps) = tr S - 3.
  const double mu_v = lame.mu_pa * rest.volume_m3;
  const double diagonal = rest.volume_m3 * (lame.lambda_pa * (s0[0] + s1[1] + s2[2] - 3.0) - 2.0 * lame.mu_pa);
  const Lanes sigma0 = mu_v * (s0 + t0) + Lanes{diagonal, 0.0, 0.0, 0.0};
  const Lanes sigma1 = mu_v * (s1 + t1) + Lanes{0.0, diagonal, 0.0, 0.0};
  const Lanes sigma2 = mu_v * (s2 + t2) + Lanes{0.0, 0.0, diagonal, 0.0};
  // P = R (V sigma): column j = sum_k (column k of R) (V sigma)(k, j).
  const Lanes c0{r(0, 0), r(1, 0), r(2, 0), 0.0};
  const Lanes c1{r(0, 1), r(1, 1), r(2, 1), 0.0};
  const Lanes c2{r(0, 2), r(1, 2), r(2, 2), 0.0};
  const Lanes p0 = c0 * sigma0[0] + c1 * sigma0[1] + c2 * sigma0[2];
  const Lanes p1 = c0 * sigma1[0] + c1 * sigma1[1] + c2 * sigma1[2];
  const Lanes p2 = c0 * sigma2[0] + c1 * sigma2[1] + c2 * sigma2[2];
  Eigen::Matrix<double, 3, 4> forces;
  for (int i = 0; i < 4; ++i) {
    const Lanes force = p0 * g(0, i) + p1 * g(1, i) + p2 * g(2, i);
    forces(0, i) = force[0];
    forces(1, i) = force[1];
    forces(2, i) = force[2];
  }
  return forces;
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
