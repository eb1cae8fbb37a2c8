// The quasi-static reference for point contact: static equilibrium of the full co-rotational
// model with a material point of the surface pushed to a prescribed position (the probe's tip),
// and the reaction force there. What the contact force of the dynamic simulation and the contact
// stiffness models are measured against (tests/unit/contact; later the `compare` tool).
//
// Equilibrium f_int(u) = f_ext + P lambda with the constraint P^T u = target - x_s(0) (lambda the
// force of the tool on the body, P interpolating the material point s), by Newton's method with a
// Lagrange multiplier, each iteration one CHOLMOD factorization of the tangent K and four solves:
//   du = Z dlambda - K^-1 r,   dlambda = (P^T Z)^-1 (g + P^T K^-1 r),   Z = K^-1 P,
// r the force residual and g the gap. The co-rotational tangent R K R^T omits dR/du, so the
// convergence is linear with a rate of the order of the strain; the tolerance is checked on the
// true residual, so it is met all the same.
//
// Two kinds of contact:
// * bonded: the material point s stays the one held (the reaction may have a tangential part);
//   as d -> 0 the reaction tends to K_c d with the effectiveStatic K_c;
// * frictionless: the point held slides until the reaction is along the deformed surface's smooth
//   normal (smooth_normal, at the surface point closest to the target), which is the equilibrium the
//   god-object contact (PointContact) settles to as its spring stiffness grows. Outer iterations: the bonded solution at s, then s moves to the material
//   point now at target + T (T^T K_c T)^-1 T^T lambda (T the tangent plane): the shift that
//   cancels the tangential reaction to first order.
#pragma once

#include "core/contact/surface_point.hpp"
#include "core/fem/deformable_body.hpp"

#include <Eigen/Core>

namespace tissue {

enum class PokeFriction { bonded, frictionless };

struct QuasiStaticPokeSettings {
  PokeFriction friction = PokeFriction::frictionless;
  /// Newton stops when ||f_int - f_ext - P lambda|| <= tolerance (|lambda| + ||f_ext||), or is at
  /// the rounding level of f_int (1e-15 sqrt(n) max K_ii max |x|: forces come from positions, so a
  /// poke of a few nm cannot do better), and the gap |target - x_s| <= tolerance |target - x_s(rest)|
  /// (+ 1e-15 m).
  double force_tolerance = 1e-11;
  /// Frictionless: the slide stops when |tangential part of lambda| <= tolerance |lambda|.
  double tangential_tolerance = 1e-9;
  int max_newton_iterations = 100;  ///< per bonded solve
  int max_slide_iterations = 60;
};

struct QuasiStaticPoke {
  bool converged = false;
  Eigen::Vector3d force_on_tool_n = Eigen::Vector3d::Zero();  ///< -lambda [N]
  SurfacePoint contact;                                       ///< the material point held at the target
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();           ///< unit outward smooth normal there, deformed
  Eigen::VectorXd displacement_m;                             ///< the equilibrium u (free unknowns)
  /// Effective-static K_c = (P^T K^-1 P)^-1 with the tangent at the equilibrium [N/m].
  Eigen::Matrix3d contact_stiffness_n_per_m = Eigen::Matrix3d::Zero();
  double force_residual = 0.0;       ///< final relative equilibrium residual
  double tangential_residual = 0.0;  ///< final |lambda_t| / |lambda| (also reported for bonded)
  int newton_iterations = 0;         ///< in all bonded solves together
  int slide_iterations = 0;          ///< frictionless outer iterations
};

/// Pushes the material point `start` (a triangle of `triangles`, the body's outward surface) to
/// `target_m` and solves for static equilibrium from `initial_displacement_m` (zero if empty).
/// Uses body.evaluate(), so it changes the body's rotation warm starts; the body's force terms (the
/// contact spring) are detached for the solve and attached again. Throws std::invalid_argument for a body with nothing fixed
/// (no static equilibrium), a non-finite target or a start off the surface; returns converged =
/// false when Newton or the slide runs out of iterations (or the tangent stops being positive definite).
QuasiStaticPoke quasi_static_poke(DeformableBody& body, const SurfaceTriangles& triangles, const SurfacePoint& start,
                                  const Eigen::Vector3d& target_m, const QuasiStaticPokeSettings& settings = {},
                                  const Eigen::VectorXd& initial_displacement_m = Eigen::VectorXd());

}  // namespace tissue
