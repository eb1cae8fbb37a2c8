// The rotation of a deformation gradient for co-rotational FEM: a proper rotation (det +1)
// for every F, inverted (det F < 0) and flat (rank-deficient) ones included.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tissue {

/// When the fast method stops. Newton's method here converges cubically near the maximum: after a
/// Newton step of angle a the rotation is off by at most ~0.55 a^3 (measured over stretches with
/// principal values from 0.2 to 2; tests/unit/fem/test_rotation.cpp), so the iteration stops after
/// a Newton step with NEWTON_ERROR_BOUND * a^3 <= max_error_rad (the bound has a margin of ~7).
/// A warm start moved by up to ~6e-3 rad since the last call then needs one step at the default.
/// The rotation error e changes the element force by a relative ~e (the co-rotated strain only by
/// e times the strain), far below the 1e-3 of a real-time linear solve.
struct RotationSettings {
  static constexpr double NEWTON_ERROR_BOUND = 4.0;  ///< error after a Newton step of a: <= this * a^3
  int max_iterations = 16;      ///< iterations of the fast method before falling back to the SVD
  double max_error_rad = 1e-6;  ///< accepted rotation error (4e-18: the pre-issue-12 rule, steps < 1e-6 rad)
};

/// Where an elasticity's evaluate puts the rotations and warm starts it extracts: into the elements'
/// own (a step), or into a second set beside them, from the own warm starts (an evaluation ahead of
/// the next step, DeformableBody::evaluate_ahead), which take_ahead() makes the own.
enum class ExtractInto { own, ahead };

/// Throws ParameterError unless 1 <= max_iterations <= 100 and max_error_rad is finite and > 0.
void validate(const RotationSettings& settings);

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

/// The warm start of a rotation's next extraction: the turn it made since the extraction `before`
/// made once more, now (before^-1 now), normalised. For an element turning steadily that is its next
/// rotation (exactly, for a constant turn per step); the rotation itself is still found by the
/// iteration, to the same tolerance, so only the iteration's steps change: a warm start off by a
/// step's turn a needs a Newton step while 0.55 a^3 > max_error_rad, one off by the change of the turn
/// (a^2-ish) none more often. Both unit quaternions; the result is one too. The scalar form of what
/// extract_rotations() computes in its lanes (TurnsBefore); tests compare the two.
[[nodiscard]] inline Eigen::Quaterniond extrapolated_turn(const Eigen::Quaterniond& now,
                                                          const Eigen::Quaterniond& before) {
  return (now * (before.conjugate() * now)).normalized();
}

/// How many deformation gradients extract_rotations() takes at once (its SIMD lanes).
inline constexpr int ROTATION_BATCH = 4;

/// Where extract_rotations() starts: from each warm start as it is, or from extrapolated_turn(warm
/// start, turns_before[k]) (computed in the lanes), the warm start as it was then kept in
/// turns_before[k] when `keep` is set (a step's own extraction: what it starts from becomes the turn
/// before of the next).
struct TurnsBefore {
  Eigen::Quaterniond* const* before = nullptr;  ///< one per lane; nullptr: no extrapolation
  bool keep = false;
};

/// extract_rotation() of up to ROTATION_BATCH deformation gradients at once, in SIMD lanes (the same
/// iteration, stopping rule and fallback per lane, so each result equals extract_rotation()'s to
/// rounding): `count` gradients `f[k]`, warm starts `*warm_starts[k]` (updated) and results
/// `*rotations[k]`. Iterating lanes side by side hides the latency of each lane's dependent chain
/// (divisions, square roots), which is what bounds the one-at-a-time version.
void extract_rotations(int count, const Eigen::Matrix3d* f, Eigen::Quaterniond* const* warm_starts,
                       Eigen::Matrix3d* const* rotations, const RotationSettings& settings = {},
                       TurnsBefore turns = {});

/// How far from orthonormal (Frobenius norm of R^T R - I) or from unit length a rotation or a warm
/// start may be and still count as one: far above the rounding of the ones the engine makes.
inline constexpr double ROTATION_TOLERANCE = 1e-6;
/// Whether `r` is a proper rotation to ROTATION_TOLERANCE: finite, R^T R = I, det R > 0.
[[nodiscard]] bool is_rotation(const Eigen::Matrix3d& r);
/// Whether `q` is a unit quaternion to ROTATION_TOLERANCE (finite): a warm start extract_rotation takes.
[[nodiscard]] bool is_unit_quaternion(const Eigen::Quaterniond& q);

/// The reference: R = U diag(1, 1, det(U V^T)) V^T from a full SVD. Slow; used as the fallback and in tests.
Eigen::Matrix3d rotation_by_svd(const Eigen::Matrix3d& deformation_gradient);

}  // namespace tissue
