// Stable Neo-Hookean: energy, stress, stress derivative and the per-tet forces and tangent.
#include "core/fem/stable_neo_hookean.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <array>
#include <cmath>

namespace tissue {
namespace {

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

// dJ/dF: the cofactor matrix, columns f1 x f2, f2 x f0, f0 x f1.
Eigen::Matrix3d cofactor(const Eigen::Matrix3d& f) {
  Eigen::Matrix3d c;
  c.col(0) = f.col(1).cross(f.col(2));
  c.col(1) = f.col(2).cross(f.col(0));
  c.col(2) = f.col(0).cross(f.col(1));
  return c;
}

Vector9d vec(const Eigen::Matrix3d& m) { return Eigen::Map<const Vector9d>(m.data()); }

}  // namespace

StableNeoHookean stable_neo_hookean(const LameParameters& lame) {
  StableNeoHookean m;
  m.mu_pa = 4.0 / 3.0 * lame.mu_pa;
  m.lambda_pa = lame.lambda_pa + 5.0 / 6.0 * lame.mu_pa;
  m.alpha = 1.0 + 0.75 * m.mu_pa / m.lambda_pa;
  return m;
}

double neo_hookean_energy_density(const StableNeoHookean& material, const Eigen::Matrix3d& f) {
  const double i_c = f.squaredNorm();
  const double j = f.determinant();
  const double rest_j_term = 0.5 * material.lambda_pa * (1.0 - material.alpha) * (1.0 - material.alpha);
  return 0.5 * material.mu_pa * (i_c - 3.0) + 0.5 * material.lambda_pa * (j - material.alpha) * (j - material.alpha) -
         rest_j_term - 0.5 * material.mu_pa * (std::log(i_c + 1.0) - std::log(4.0));
}

Eigen::Matrix3d neo_hookean_stress(const StableNeoHookean& material, const Eigen::Matrix3d& f) {
  const double i_c = f.squaredNorm();
  const double j = f.determinant();
  return material.mu_pa * (1.0 - 1.0 / (i_c + 1.0)) * f + material.lambda_pa * (j - material.alpha) * cofactor(f);
}

Matrix9d neo_hookean_stress_derivative(const StableNeoHookean& material, const Eigen::Matrix3d& f, bool project) {
  const double i_c = f.squaredNorm();
  const double j = f.determinant();
  const Vector9d f_vec = vec(f);
  const Vector9d g = vec(cofactor(f));
  Matrix9d h = material.mu_pa * (1.0 - 1.0 / (i_c + 1.0)) * Matrix9d::Identity();
  h.noalias() += 2.0 * material.mu_pa / ((i_c + 1.0) * (i_c + 1.0)) * f_vec * f_vec.transpose();
  h.noalias() += material.lambda_pa * g * g.transpose();
  // d^2 J / dF^2: block (a, b) is d(cofactor column a) / d(column b of F).
  const double scale = material.lambda_pa * (j - material.alpha);
  const Eigen::Matrix3d c0 = scale * cross_matrix(f.col(0));
  const Eigen::Matrix3d c1 = scale * cross_matrix(f.col(1));
  const Eigen::Matrix3d c2 = scale * cross_matrix(f.col(2));
  h.block<3, 3>(0, 3) -= c2;
  h.block<3, 3>(0, 6) += c1;
  h.block<3, 3>(3, 0) += c2;
  h.block<3, 3>(3, 6) -= c0;
  h.block<3, 3>(6, 0) -= c1;
  h.block<3, 3>(6, 3) += c0;
  if (!project) return h;
  // Most elements of a body near rest have a positive definite dP/dF: a Cholesky factorization (~10x
  // cheaper than the eigendecomposition) says so, and then there is nothing to project.
  if (Eigen::LLT<Matrix9d>(h).info() == Eigen::Success) return h;
  Eigen::SelfAdjointEigenSolver<Matrix9d> eigen(h);
  const Vector9d clamped = eigen.eigenvalues().cwiseMax(0.0);
  return eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
}

Eigen::Matrix<double, 3, 4> neo_hookean_forces(const TetRest& rest, const StableNeoHookean& material,
                                               const Eigen::Matrix3d& f) {
  return rest.volume_m3 * neo_hookean_stress(material, f) * rest.shape_gradients_per_m;
}

Matrix12d neo_hookean_stiffness(const TetRest& rest, const StableNeoHookean& material, const Eigen::Matrix3d& f,
                                bool project) {
  const Matrix9d h = neo_hookean_stress_derivative(material, f, project);
  // K_ij = V sum_{c,d} g_i[c] g_j[d] H_cd (H_cd the 3 x 3 block of dP/dF at columns c, d of F):
  // first T_j = sum_d g_j[d] H_(:,d) (9 x 3), then K_ij = sum_c g_i[c] T_j(c), ~600 products
  // where the dense B^T H B (B 9 x 12, mostly zeros) took ~2300.
  const Eigen::Matrix<double, 3, 4>& g = rest.shape_gradients_per_m;
  std::array<Eigen::Matrix<double, 9, 3>, 4> t;
  for (int j = 0; j < 4; ++j) {
    t[static_cast<size_t>(j)] =
        g(0, j) * h.block<9, 3>(0, 0) + g(1, j) * h.block<9, 3>(0, 3) + g(2, j) * h.block<9, 3>(0, 6);
  }
  Matrix12d k;
  for (int i = 0; i < 4; ++i) {
    for (int j = i; j < 4; ++j) {
      const Eigen::Matrix<double, 9, 3>& tj = t[static_cast<size_t>(j)];
      const Eigen::Matrix3d block = rest.volume_m3 * (g(0, i) * tj.block<3, 3>(0, 0) + g(1, i) * tj.block<3, 3>(3, 0) +
                                                      g(2, i) * tj.block<3, 3>(6, 0));
      k.block<3, 3>(3 * i, 3 * j) = block;
      if (i != j) k.block<3, 3>(3 * j, 3 * i) = block.transpose();
    }
  }
  return k;
}

}  // namespace tissue
