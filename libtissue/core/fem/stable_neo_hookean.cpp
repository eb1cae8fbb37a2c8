// Stable Neo-Hookean: energy, stress, stress derivative and the per-tet forces and tangent.
#include "core/fem/stable_neo_hookean.hpp"
#include "core/system/cross_matrix.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <array>
#include <cmath>

namespace tissue {
namespace {

// dJ/dF: the cofactor matrix, columns f1 x f2, f2 x f0, f0 x f1.
Eigen::Matrix3d cofactor(const Eigen::Matrix3d& f) {
  Eigen::Matrix3d c;
  c.col(0) = f.col(1).cross(f.col(2));
  c.col(1) = f.col(2).cross(f.col(0));
  c.col(2) = f.col(0).cross(f.col(1));
  return c;
}

Vector9d vec(const Eigen::Matrix3d& m) { return Eigen::Map<const Vector9d>(m.data()); }

// F = U diag(sigma) V^T with U and V rotations, the sign of det F on sigma_2 (the rotation-variant
// SVD). V from the closed-form eigenvectors of F^T F (largest first); U's first two columns by
// Gram-Schmidt on F v_0, F v_1 (any unit vectors where those vanish), its third their cross product;
// sigma_i = u_i . F v_i, which carries the sign of det F to sigma_2. Several times cheaper than
// Eigen's JacobiSVD, which took a quarter of a Neo-Hookean assembly.
struct RotationVariantSvd {
  Eigen::Matrix3d u, v;
  Eigen::Vector3d sigma;
};

Eigen::Vector3d any_unit_normal_to(const Eigen::Vector3d& a) {
  Eigen::Index smallest = 0;
  a.cwiseAbs().minCoeff(&smallest);
  return a.cross(Eigen::Vector3d::Unit(smallest)).normalized();
}

RotationVariantSvd rotation_variant_svd(const Eigen::Matrix3d& f) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(f.transpose() * f);  // eigenvalues ascending
  RotationVariantSvd svd;
  svd.v.col(0) = eigen.eigenvectors().col(2);
  svd.v.col(1) = eigen.eigenvectors().col(1);
  svd.v.col(2) = svd.v.col(0).cross(svd.v.col(1));
  const Eigen::Vector3d f0 = f * svd.v.col(0);
  const Eigen::Vector3d f1 = f * svd.v.col(1);
  const double scale = f.norm();
  svd.u.col(0) = f0.norm() > 1e-12 * scale && scale > 0.0 ? Eigen::Vector3d(f0.normalized()) : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d f1_normal = f1 - svd.u.col(0).dot(f1) * svd.u.col(0);
  svd.u.col(1) =
      f1_normal.norm() > 1e-12 * scale ? Eigen::Vector3d(f1_normal.normalized()) : any_unit_normal_to(svd.u.col(0));
  svd.u.col(2) = svd.u.col(0).cross(svd.u.col(1));
  for (int i = 0; i < 3; ++i) svd.sigma(i) = svd.u.col(i).dot(f * svd.v.col(i));
  return svd;
}

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

Matrix9d neo_hookean_stress_derivative(const StableNeoHookean& material, const Eigen::Matrix3d& f) {
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
  return h;
}

namespace {

// The quantities of the closed-form eigensystem at F.
struct Eigensystem {
  RotationVariantSvd svd;
  double a = 0.0;                                     // mu' (1 - 1/(I_C + 1)): every mode's share of mu' I
  double scale = 0.0;                                 // lambda' (J - alpha), d^2J/dF^2's factor
  Eigen::Matrix3d scaling = Eigen::Matrix3d::Zero();  // the 3 x 3 block on the scaling modes
};

Eigensystem eigensystem(const StableNeoHookean& material, const Eigen::Matrix3d& f) {
  Eigensystem e;
  e.svd = rotation_variant_svd(f);
  const Eigen::Vector3d& sigma = e.svd.sigma;
  const double i_c = sigma.squaredNorm();
  e.a = material.mu_pa * (1.0 - 1.0 / (i_c + 1.0));
  const double b = 2.0 * material.mu_pa / ((i_c + 1.0) * (i_c + 1.0));
  e.scale = material.lambda_pa * (sigma.prod() - material.alpha);
  // A = a I + b sigma sigma^T + lambda' g g^T (g = dJ/dsigma) + scale d^2J/dsigma^2.
  const Eigen::Vector3d g(sigma(1) * sigma(2), sigma(0) * sigma(2), sigma(0) * sigma(1));
  e.scaling =
      e.a * Eigen::Matrix3d::Identity() + b * sigma * sigma.transpose() + material.lambda_pa * g * g.transpose();
  for (int l = 0; l < 3; ++l) {
    const int i = (l + 1) % 3;
    const int k = (l + 2) % 3;
    e.scaling(i, k) += e.scale * sigma(l);
    e.scaling(k, i) += e.scale * sigma(l);
  }
  return e;
}

// The modes with positive eigenvalues, each m-th one E_m = U Ehat_m V^T scaled by the root of its
// eigenvalue, so that the projected dP/dF is sum_m vec(E_m) vec(E_m)^T. Handed over in the U/V
// frames: a twist (sign -1) or flip (+1) of axes i and k as pair(m, root, i, k, sign), Ehat =
// (e_i e_k^T + sign e_k e_i^T) / sqrt 2; a scaling mode as scaling(m, d), Ehat = diag(d) with the root
// folded into d. The scaling block is factorized by Cholesky where it is positive definite (nearly
// always: lambda' g g^T dominates it), eigensolved otherwise.
template <class Pair, class Scaling>
void for_each_positive_mode(const Eigensystem& e, Pair pair, Scaling scaling) {
  int modes = 0;
  for (int l = 0; l < 3; ++l) {
    const int i = (l + 1) % 3;
    const int k = (l + 2) % 3;
    const double twist_value = e.a + e.scale * e.svd.sigma(l);
    const double flip_value = e.a - e.scale * e.svd.sigma(l);
    if (twist_value > 0.0) pair(modes++, std::sqrt(twist_value), i, k, -1.0);
    if (flip_value > 0.0) pair(modes++, std::sqrt(flip_value), i, k, 1.0);
  }
  const Eigen::LLT<Eigen::Matrix3d> cholesky(e.scaling);
  if (cholesky.info() == Eigen::Success) {
    const Eigen::Matrix3d l = cholesky.matrixL();
    for (int m = 0; m < 3; ++m) scaling(modes++, Eigen::Vector3d(l.col(m)));
    return;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(e.scaling);
  for (int m = 0; m < 3; ++m) {
    const double value = eigen.eigenvalues()(m);
    if (value > 0.0) scaling(modes++, Eigen::Vector3d(std::sqrt(value) * eigen.eigenvectors().col(m)));
  }
}

}  // namespace

void neo_hookean_projected_blocks(const TetRest& rest, const StableNeoHookean& material, const Eigen::Matrix3d& f,
                                  std::array<Eigen::Matrix3d, 16>& out) {
  // K_ij = V sum_m (E_m g_i)(E_m g_j)^T: the modes applied to the shape gradients, with g in V's frame
  // (E_m g = U Ehat_m V^T g), the volume's root folded into each mode's.
  const Eigensystem e = eigensystem(material, f);
  const Eigen::Matrix3d& u = e.svd.u;
  const Eigen::Matrix<double, 3, 4> g_hat = e.svd.v.transpose() * rest.shape_gradients_per_m;
  const double root_volume = std::sqrt(rest.volume_m3);
  const double root_half_volume = std::sqrt(0.5 * rest.volume_m3);
  Eigen::Matrix<double, 12, 9> w = Eigen::Matrix<double, 12, 9>::Zero();
  for_each_positive_mode(
      e,
      [&](int m, double root, int i, int k, double sign) {
        const double c = root * root_half_volume;
        for (int vertex = 0; vertex < 4; ++vertex) {
          w.block<3, 1>(3 * vertex, m) = c * (g_hat(k, vertex) * u.col(i) + sign * g_hat(i, vertex) * u.col(k));
        }
      },
      [&](int m, const Eigen::Vector3d& d) {
        for (int vertex = 0; vertex < 4; ++vertex) {
          w.block<3, 1>(3 * vertex, m) = root_volume * (u * d.cwiseProduct(g_hat.col(vertex)));
        }
      });
  for (int i = 0; i < 4; ++i) {
    for (int j = i; j < 4; ++j) {
      out[static_cast<size_t>(4 * i + j)].noalias() =
          w.block<3, 9>(3 * i, 0).lazyProduct(w.block<3, 9>(3 * j, 0).transpose());
    }
  }
}

Eigen::Matrix<double, 3, 4> neo_hookean_forces(const TetRest& rest, const StableNeoHookean& material,
                                               const Eigen::Matrix3d& f) {
  return rest.volume_m3 * neo_hookean_stress(material, f) * rest.shape_gradients_per_m;
}

Matrix12d neo_hookean_stiffness(const TetRest& rest, const StableNeoHookean& material, const Eigen::Matrix3d& f,
                                bool project) {
  if (project) {
    std::array<Eigen::Matrix3d, 16> blocks;
    neo_hookean_projected_blocks(rest, material, f, blocks);
    Matrix12d k;
    for (int i = 0; i < 4; ++i) {
      for (int j = i; j < 4; ++j) {
        k.block<3, 3>(3 * i, 3 * j) = blocks[static_cast<size_t>(4 * i + j)];
        if (i != j) k.block<3, 3>(3 * j, 3 * i) = blocks[static_cast<size_t>(4 * i + j)].transpose();
      }
    }
    return k;
  }
  const Matrix9d h = neo_hookean_stress_derivative(material, f);
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
