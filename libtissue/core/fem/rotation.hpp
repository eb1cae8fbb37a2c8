// The rotation of a deformation gradient for co-rotational FEM: a proper rotation (det +1)
// for every F, inverted (det F < 0) and flat (rank-deficient) ones included.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tissue {

struct RotationSettings {
  int max_iterations = 16;            ///< iterations of the fast method before falling back to the SVD
  double angle_tolerance_rad = 1e-6;  ///< stop after a Newton step smaller than this (error ~ its square)
};

/// Returns the rotation R in SO(3) that maximises tr(R^T F): the rotation of the polar
/// decomposition when det F > 0, and the "invertible FEM" rotation U diag(1,1,-1) V^T when
/// det F <= 0 (Irving, Teran, Fedkiw 2004), so an inverted tet is pushed back, not mirrored.
///
/// Fast path: Newton's method on SO(3) for the maximum of tr(R^T F) (gradient and Hessian in
/// rotation.cpp), warm-started from `warm_start` (the tet's rotation of the previous step); a step
/// costs ~150 flops and a warm start needs one or two. It updates a unit quaternion, so R is always
/// a proper rotation. Where the Hessian is not positive definite it takes the step of Mueller,
/// Bender, Chentanez, Macklin, "A robust method to extract the rotational part of deformations"
/// (MIG 2016); without convergence in max_iterations the SVD decides. `warm_start` (a unit
/// quaternion) is updated.
Eigen::Matrix3d extract_rotation(const Eigen::Matrix3d& deformation_gradient, Eigen::Quaterniond& warm_start,
                                 const RotationSettings& settings = {});

/// The reference: R = U diag(1, 1, det(U V^T)) V^T from a full SVD. Slow; used as the fallback and in tests.
Eigen::Matrix3d rotation_by_svd(const Eigen::Matrix3d& deformation_gradient);

}  // namespace tissue
