// Rotation extraction for co-rotational FEM (see rotation.hpp for the method and references).
#include "core/fem/rotation.hpp"

#include <Eigen/SVD>

#include <cmath>

namespace tissue {
namespace {

// The maximiser R of tr(R^T F) over SO(3) is found by Newton's method on the rotation manifold:
// with S = R^T F and R' = R exp([theta]x),
//   tr(R'^T F) = tr(S) + theta . g - 1/2 theta^T H theta + O(theta^3),
//   g = (S21 - S12, S02 - S20, S10 - S01),   H = tr(S) I - sym(S),
// so the step is theta = H^-1 g, and R is the maximum exactly when g = 0 and H is positive
// definite. Where H is not (far from the maximum, or at a saddle such as a half turn), the step
// falls back to theta = g / |tr S|, the step of Mueller et al. 2016 written in the body frame.
struct NewtonStep {
  Eigen::Vector3d theta;
  bool newton = false;  // H was positive definite, so the iterate is near a true maximum
};

NewtonStep rotation_step(const Eigen::Matrix3d& s, double scale) {
  const Eigen::Vector3d g(s(2, 1) - s(1, 2), s(0, 2) - s(2, 0), s(1, 0) - s(0, 1));
  const double trace = s.trace();
  Eigen::Matrix3d h = -0.5 * (s + s.transpose());
  h.diagonal().array() += trace;
  // Positive definiteness by the leading minors, relative to the size of F.
  const double tol = 1e-10 * scale;
  const double minor2 = h(0, 0) * h(1, 1) - h(0, 1) * h(1, 0);
  const double det = h.determinant();
  if (h(0, 0) > tol && minor2 > tol * scale && det > tol * scale * scale) {
    // H^-1 g by the adjugate (H is symmetric).
    Eigen::Matrix3d adjugate;
    adjugate(0, 0) = h(1, 1) * h(2, 2) - h(1, 2) * h(2, 1);
    adjugate(0, 1) = h(0, 2) * h(2, 1) - h(0, 1) * h(2, 2);
    adjugate(0, 2) = h(0, 1) * h(1, 2) - h(0, 2) * h(1, 1);
    adjugate(1, 1) = h(0, 0) * h(2, 2) - h(0, 2) * h(2, 0);
    adjugate(1, 2) = h(0, 2) * h(1, 0) - h(0, 0) * h(1, 2);
    adjugate(2, 2) = minor2;
    adjugate(1, 0) = adjugate(0, 1);
    adjugate(2, 0) = adjugate(0, 2);
    adjugate(2, 1) = adjugate(1, 2);
    return {adjugate * g / det, true};
  }
  return {g / (std::abs(trace) + 1e-9 * scale), false};
}

}  // namespace

Eigen::Matrix3d rotation_by_svd(const Eigen::Matrix3d& deformation_gradient) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(deformation_gradient, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  // Singular values are sorted in decreasing order: flipping the last column of U negates the
  // smallest one, which is the proper rotation closest to F (invertible FEM).
  if ((u * v.transpose()).determinant() < 0.0) u.col(2) = -u.col(2);
  return u * v.transpose();
}

Eigen::Matrix3d extract_rotation(const Eigen::Matrix3d& f, Eigen::Quaterniond& warm_start,
                                 const RotationSettings& settings) {
  const double scale = f.cwiseAbs().maxCoeff();
  Eigen::Quaterniond q = warm_start;  // kept unit by every update below
  Eigen::Matrix3d r = q.toRotationMatrix();
  if (!(scale > 0.0) || !std::isfinite(scale)) return r;  // F = 0 or not finite: nothing to extract
  bool converged = false;
  for (int iteration = 0; iteration < settings.max_iterations; ++iteration) {
    const NewtonStep step = rotation_step(r.transpose() * f, scale);
    const double angle = step.theta.norm();
    if (angle > 0.0) {
      // A step is limited to |theta| <= 1 rad: far from the maximum the model is not to be trusted.
      // The retraction exp([theta]x) is replaced by the unit quaternion (1, theta/2) normalised,
      // which agrees with it to second order (Newton stays quadratic) and needs no sin/cos.
      const Eigen::Vector3d half = (0.5 * std::min(1.0, 1.0 / angle)) * step.theta;
      q = (q * Eigen::Quaterniond(1.0, half.x(), half.y(), half.z())).normalized();
      r = q.toRotationMatrix();
    }
    if (step.newton && angle < settings.angle_tolerance_rad) {
      converged = true;  // Newton: the remaining error is O(angle^2), ~1e-12 at the default tolerance
      break;
    }
  }
  if (!converged) {
    r = rotation_by_svd(f);
    q = Eigen::Quaterniond(r);
  }
  warm_start = q;
  return r;
}

}  // namespace tissue
