// Stable Neo-Hookean elasticity (Smith, de Goes and Kim, "Stable Neo-Hookean Flesh Simulation",
// ACM TOG 37(2), 2018), the hyperelastic option beside co-rotational linear elasticity (issue 25).
// Energy density, with the paper's log term and its Lame reparametrization (section 3.4):
//   Psi(F) = mu'/2 (I_C - 3) + lambda'/2 (J - alpha)^2 - mu'/2 log(I_C + 1),
//   I_C = tr(F^T F), J = det F, mu' = 4/3 mu, lambda' = lambda + 5/6 mu, alpha = 1 + 3/4 mu'/lambda',
// which is stress-free at F = I, agrees with linear elasticity of Lame parameters (lambda, mu) to
// first order in the strain, and is defined for every F, inverted (J <= 0) or flat, so an inverted
// element is pushed back (the J term's gradient dJ/dF never vanishes away from a collapsed F).
// The constants mu'/2 log 4 - lambda'/2 (1 - alpha)^2 are added so that Psi(I) = 0. First Piola-Kirchhoff stress P =
// dPsi/dF and its derivative dP/dF (9 x 9, column-major vec(F)), whose negative eigenvalues are clamped to zero where a
// solver needs a positive semi-definite tangent (in closed form: neo_hookean_projected_blocks). Per linear tet (shape
// gradients g_i, volume V): the internal force on vertex i is V P g_i (the restoring force, as the co-rotational
// kernel's) and the tangent block K_ij = V (g_i^T (x) I) dP/dF (g_j (x) I).
#pragma once

#include "core/fem/tet_element.hpp"
#include "core/material/material.hpp"

#include <Eigen/Core>

#include <array>

namespace tissue {

using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Vector9d = Eigen::Matrix<double, 9, 1>;

/// The paper's reparametrized constants for Lame parameters (lambda, mu).
struct StableNeoHookean {
  double mu_pa = 0.0;      ///< mu' = 4/3 mu
  double lambda_pa = 0.0;  ///< lambda' = lambda + 5/6 mu
  double alpha = 1.0;      ///< 1 + 3/4 mu'/lambda' (the rest state is stress-free)
};

StableNeoHookean stable_neo_hookean(const LameParameters& lame);

/// Psi(F) [J/m^3].
double neo_hookean_energy_density(const StableNeoHookean& material, const Eigen::Matrix3d& f);

/// P(F) = mu' (1 - 1/(I_C + 1)) F + lambda' (J - alpha) dJ/dF [Pa], dJ/dF the cofactor matrix of F.
Eigen::Matrix3d neo_hookean_stress(const StableNeoHookean& material, const Eigen::Matrix3d& f);

/// dP/dF, exact (9 x 9, vec(F) column-major: index 3 * column + row).
Matrix9d neo_hookean_stress_derivative(const StableNeoHookean& material, const Eigen::Matrix3d& f);

/// The element tangent's blocks K_ij = d f_i / d x_j, i <= j, at [4 i + j] (block (j, i) is the
/// transpose), with dP/dF projected onto the positive semi-definite cone from its eigensystem in closed
/// form (Smith, de Goes and Kim 2018, section 4.2; derived in docs/DESIGN.md, "Elasticity"): with the
/// rotation-variant SVD F = U diag(sigma) V^T, six twist and flip modes U (e_i e_k^T -/+ e_k e_i^T)
/// V^T / sqrt 2 with eigenvalues a +/- lambda' (J - alpha) sigma_l (a = mu' (1 - 1/(I_C + 1)), l the
/// third axis), and three scaling modes U diag(d) V^T from a 3 x 3 matrix; negative ones dropped. The
/// modes are applied to the shape gradients straight away, without the 9 x 9 dP/dF: what the body's
/// assembly takes. [N/m]
void neo_hookean_projected_blocks(const TetRest& rest, const StableNeoHookean& material, const Eigen::Matrix3d& f,
                                  std::array<Eigen::Matrix3d, 16>& out);

/// Internal forces (3 x 4, column i acts on vertex i, the restoring force of M a + f_int = f_ext as
/// the co-rotational kernel's): V P g_i. [N]
Eigen::Matrix<double, 3, 4> neo_hookean_forces(const TetRest& rest, const StableNeoHookean& material,
                                               const Eigen::Matrix3d& f);

/// The element tangent d f_int / d x (12 x 12, vertex-major), from dP/dF (projected if asked). [N/m]
Matrix12d neo_hookean_stiffness(const TetRest& rest, const StableNeoHookean& material, const Eigen::Matrix3d& f,
                                bool project);

}  // namespace tissue
