// Rotation extraction for co-rotational FEM (see rotation.hpp for the method and references).
#include "core/fem/rotation.hpp"

#include "core/parameter_error.hpp"
#include "core/system/hot_kernel.hpp"

#include <Eigen/SVD>

#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

// The maximiser R of tr(R^T F) over SO(3) is found by Newton's method on the rotation manifold:
// with S = R^T F and R' = R exp([theta]x),
//   tr(R'^T F) = tr(S) + theta . g - 1/2 theta^T H theta + O(theta^3),
//   g = (S21 - S12, S02 - S20, S10 - S01),   H = tr(S) I - sym(S),
// so the step is theta = H^-1 g, and R is the maximum exactly when g = 0 and H is positive
// definite. Where H is not (far from the maximum, or at a saddle such as a half turn), the step
// falls back to theta = g / |tr S|, the step of Mueller et al. 2016 written in the body frame.
// The step as theta = numerator / denominator (denominator > 0): the division is left to the caller,
// which limits the step and divides once (see extract_rotation).
struct NewtonStep {
  Eigen::Vector3d numerator;
  double denominator = 1.0;
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
    return {adjugate * g, det, true};
  }
  return {g, std::abs(trace) + 1e-9 * scale, false};
}

}  // namespace

void validate(const RotationSettings& settings) {
  if (settings.max_iterations < 1 || settings.max_iterations > 100) {
    throw ParameterError("rotation extraction: 1 to 100 iterations, got " + std::to_string(settings.max_iterations));
  }
  if (!(settings.max_error_rad > 0.0) || !std::isfinite(settings.max_error_rad)) {
    throw ParameterError("rotation extraction: the accepted error must be finite and > 0 rad, got " +
                         std::to_string(settings.max_error_rad));
  }
}

Eigen::Matrix3d rotation_by_svd(const Eigen::Matrix3d& deformation_gradient) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(deformation_gradient, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  // Singular values are sorted in decreasing order: flipping the last column of U negates the
  // smallest one, which is the proper rotation closest to F (invertible FEM).
  if ((u * v.transpose()).determinant() < 0.0) u.col(2) = -u.col(2);
  return u * v.transpose();
}

bool is_rotation(const Eigen::Matrix3d& r) {
  return r.allFinite() && (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() <= ROTATION_TOLERANCE &&
         r.determinant() > 0.0;
}

bool is_unit_quaternion(const Eigen::Quaterniond& q) {
  return q.coeffs().allFinite() && std::abs(q.norm() - 1.0) <= ROTATION_TOLERANCE;
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
    const double numerator_norm = step.numerator.norm();
    const double angle = numerator_norm / step.denominator;  // |theta|
    if (angle > 0.0) {
      // A step is limited to |theta| <= 1 rad: far from the maximum the model is not to be trusted;
      // theta min(1, 1/|theta|) = numerator / max(denominator, |numerator|), one division.
      // The retraction exp([theta]x) is replaced by the unit quaternion (1, theta/2) normalised,
      // which agrees with it to second order (Newton stays quadratic) and needs no sin/cos; its
      // norm is |q| |(1, theta/2)|, known before the product (a shorter chain of dependent steps).
      const Eigen::Vector3d half = (0.5 / std::max(step.denominator, numerator_norm)) * step.numerator;
      const double inverse_norm = 1.0 / std::sqrt(q.squaredNorm() * (1.0 + half.squaredNorm()));
      q = q * Eigen::Quaterniond(1.0, half.x(), half.y(), half.z());
      q.coeffs() *= inverse_norm;
      r = q.toRotationMatrix();
    }
    if (step.newton && RotationSettings::NEWTON_ERROR_BOUND * angle * angle * angle <= settings.max_error_rad) {
      converged = true;  // Newton: the remaining error is below ~0.55 angle^3 (rotation.hpp)
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


// --- The batched version: the same Newton iteration in SIMD lanes (GCC vector extensions; four
// lanes, two SSE2 registers each on a baseline x86-64). Every step below is extract_rotation()'s,
// written lane-wise; a lane that has converged is frozen by selects while the others go on.
// The lane helpers below pass vectors by value between functions of this file only (internal
// linkage, inlined), so GCC's note that such an ABI differs with AVX does not concern them.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace {

using Lanes = double __attribute__((vector_size(8 * ROTATION_BATCH)));
using LaneMask = long long __attribute__((vector_size(8 * ROTATION_BATCH)));

struct LaneQuaternion {
  Lanes w, x, y, z;
};

// The quaternions *from[0] .. *from[count - 1] in lanes; lanes beyond count repeat the first. Each
// vector made whole from four values in memory (see extract_rotations: no stores lane by lane).
LaneQuaternion load_lanes(Eigen::Quaterniond* const* from, int count) {
  const Eigen::Quaterniond &q0 = *from[0], &q1 = *from[count > 1 ? 1 : 0], &q2 = *from[count > 2 ? 2 : 0],
                           &q3 = *from[count > 3 ? 3 : 0];
  return {Lanes{q0.w(), q1.w(), q2.w(), q3.w()}, Lanes{q0.x(), q1.x(), q2.x(), q3.x()},
          Lanes{q0.y(), q1.y(), q2.y(), q3.y()}, Lanes{q0.z(), q1.z(), q2.z(), q3.z()}};
}


// R(q) for a unit quaternion, as Eigen's toRotationMatrix (r[i + 3 j] = R(i, j)).
void lane_rotation_matrix(const LaneQuaternion& q, Lanes* r) {
  const Lanes tx = 2.0 * q.x, ty = 2.0 * q.y, tz = 2.0 * q.z;
  const Lanes twx = tx * q.w, twy = ty * q.w, twz = tz * q.w;
  const Lanes txx = tx * q.x, txy = ty * q.x, txz = tz * q.x;
  const Lanes tyy = ty * q.y, tyz = tz * q.y, tzz = tz * q.z;
  r[0] = 1.0 - (tyy + tzz);
  r[3] = txy - twz;
  r[6] = txz + twy;
  r[1] = txy + twz;
  r[4] = 1.0 - (txx + tzz);
  r[7] = tyz - twx;
  r[2] = txz - twy;
  r[5] = tyz + twx;
  r[8] = 1.0 - (txx + tyy);
}

Lanes lane_select(LaneMask mask, Lanes yes, Lanes no) { return mask ? yes : no; }

Lanes lane_sqrt(Lanes v) {
  Lanes out;
  // One sqrtpd at -O2 and up, given -fno-math-errno (libtissue/core/CMakeLists.txt): with errno
  // GCC made a scalar root a lane, each tested for a negative argument.
  for (int l = 0; l < ROTATION_BATCH; ++l) out[l] = std::sqrt(v[l]);
  return out;
}

// p / |p| per lane.
LaneQuaternion normalized(const LaneQuaternion& p) {
  const Lanes inverse_norm = 1.0 / lane_sqrt(p.w * p.w + p.x * p.x + p.y * p.y + p.z * p.z);
  return {p.w * inverse_norm, p.x * inverse_norm, p.y * inverse_norm, p.z * inverse_norm};
}

// q (b^-1 q), normalised, per lane (extrapolated_turn), from the lanes' warm starts q and the turns
// before b; with `keep`, q goes into the turns before.
void start_extrapolated(int count, const TurnsBefore& turns, LaneQuaternion& q) {
  // c = b^-1 q = conj(b) q (b a unit quaternion)
  const LaneQuaternion b = load_lanes(turns.before, count);
  const Lanes cw = b.w * q.w + b.x * q.x + b.y * q.y + b.z * q.z;
  const Lanes cx = b.w * q.x - b.x * q.w - b.y * q.z + b.z * q.y;
  const Lanes cy = b.w * q.y + b.x * q.z - b.y * q.w - b.z * q.x;
  const Lanes cz = b.w * q.z - b.x * q.y + b.y * q.x - b.z * q.w;
  if (turns.keep) {
    for (int l = 0; l < count; ++l) *turns.before[l] = Eigen::Quaterniond(q.w[l], q.x[l], q.y[l], q.z[l]);
  }
  // p = q c
  LaneQuaternion p;
  p.w = q.w * cw - q.x * cx - q.y * cy - q.z * cz;
  p.x = q.w * cx + q.x * cw + q.y * cz - q.z * cy;
  p.y = q.w * cy - q.x * cz + q.y * cw + q.z * cx;
  p.z = q.w * cz + q.x * cy - q.y * cx + q.z * cw;
  q = normalized(p);
}

bool any(LaneMask mask) {
  for (int l = 0; l < ROTATION_BATCH; ++l) {
    if (mask[l] != 0) return true;
  }
  return false;
}

}  // namespace

TISSUE_HOT_KERNEL void extract_rotations(int count, const Eigen::Matrix3d* f_in, Eigen::Quaterniond* const* warm_starts,
                                         Eigen::Matrix3d* const* rotations, const RotationSettings& settings,
                                         TurnsBefore turns) {
  if (count <= 0) return;
  if (count > ROTATION_BATCH) {
    throw std::invalid_argument("extract_rotations: at most " + std::to_string(ROTATION_BATCH) + " at once");
  }
  // Lanes beyond count repeat the first gradient (their results are dropped). Each vector is made
  // whole from the four values in memory: set lane by lane it went through the stack as four
  // stores that its load then waited for (a store-forwarding stall on every input).
  static_assert(ROTATION_BATCH == 4, "the lanes below are written out");
  const int k1 = count > 1 ? 1 : 0, k2 = count > 2 ? 2 : 0, k3 = count > 3 ? 3 : 0;
  const Eigen::Matrix3d &f0 = f_in[0], &f1 = f_in[k1], &f2 = f_in[k2], &f3 = f_in[k3];
  Lanes f[9];
  for (int e = 0; e < 9; ++e) f[e] = Lanes{f0(e), f1(e), f2(e), f3(e)};
  LaneQuaternion q = load_lanes(warm_starts, count);
  if (turns.before != nullptr) start_extrapolated(count, turns, q);
  const Lanes scale{f0.cwiseAbs().maxCoeff(), f1.cwiseAbs().maxCoeff(), f2.cwiseAbs().maxCoeff(),
                    f3.cwiseAbs().maxCoeff()};
  Lanes r[9];
  lane_rotation_matrix(q, r);
  // Lanes with F = 0 or not finite keep the warm start, as extract_rotation() does.
  LaneMask usable = {};
  for (int l = 0; l < ROTATION_BATCH; ++l) usable[l] = (scale[l] > 0.0 && std::isfinite(scale[l])) ? -1 : 0;
  LaneMask active = usable;
  LaneMask converged = {};
  const Lanes tol = 1e-10 * scale;
  for (int iteration = 0; iteration < settings.max_iterations && any(active); ++iteration) {
    Lanes s[9];  // S = R^T F
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) s[i + 3 * j] = r[3 * i] * f[3 * j] + r[3 * i + 1] * f[3 * j + 1] + r[3 * i + 2] * f[3 * j + 2];
    }
    const Lanes g0 = s[5] - s[7], g1 = s[6] - s[2], g2 = s[1] - s[3];  // (S21 - S12, S02 - S20, S10 - S01)
    const Lanes trace = s[0] + s[4] + s[8];
    // H = tr(S) I - sym(S)
    const Lanes h00 = trace - s[0], h11 = trace - s[4], h22 = trace - s[8];
    const Lanes h01 = -0.5 * (s[3] + s[1]), h02 = -0.5 * (s[6] + s[2]), h12 = -0.5 * (s[7] + s[5]);
    const Lanes minor2 = h00 * h11 - h01 * h01;
    const Lanes a00 = h11 * h22 - h12 * h12, a01 = h02 * h12 - h01 * h22, a02 = h01 * h12 - h02 * h11;
    const Lanes a11 = h00 * h22 - h02 * h02, a12 = h02 * h01 - h00 * h12;
    const Lanes det = h00 * a00 + h01 * a01 + h02 * a02;
    const LaneMask newton = (h00 > tol) & (minor2 > tol * scale) & (det > tol * scale * scale);
    // theta = n / d (rotation_step), limited to 1 rad: h = theta/2 min(1, 1/|theta|) = n / (2 max(d, |n|)).
    const Lanes abs_trace = lane_select(trace < 0.0, -trace, trace);
    const Lanes d = lane_select(newton, det, abs_trace + 1e-9 * scale);
    const Lanes n0 = lane_select(newton, a00 * g0 + a01 * g1 + a02 * g2, g0);
    const Lanes n1 = lane_select(newton, a01 * g0 + a11 * g1 + a12 * g2, g1);
    const Lanes n2 = lane_select(newton, a02 * g0 + a12 * g1 + minor2 * g2, g2);
    const Lanes n_norm = lane_sqrt(n0 * n0 + n1 * n1 + n2 * n2);
    const Lanes angle = n_norm / d;
    const Lanes half_over = 0.5 / lane_select(d < n_norm, n_norm, d);
    const Lanes hx = half_over * n0, hy = half_over * n1, hz = half_over * n2;
    // q (1, h), normalised by |q| |(1, h)| (the quaternion (1, theta/2) stands in for exp([theta]x)).
    const Lanes inverse_norm =
        1.0 / lane_sqrt((q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z) * (1.0 + (hx * hx + hy * hy + hz * hz)));
    LaneQuaternion unit;
    unit.w = (q.w - q.x * hx - q.y * hy - q.z * hz) * inverse_norm;
    unit.x = (q.w * hx + q.x + q.y * hz - q.z * hy) * inverse_norm;
    unit.y = (q.w * hy - q.x * hz + q.y + q.z * hx) * inverse_norm;
    unit.z = (q.w * hz + q.x * hy - q.y * hx + q.z) * inverse_norm;
    const LaneMask update = active & (angle > 0.0);
    q.w = lane_select(update, unit.w, q.w);
    q.x = lane_select(update, unit.x, q.x);
    q.y = lane_select(update, unit.y, q.y);
    q.z = lane_select(update, unit.z, q.z);
    lane_rotation_matrix(q, r);
    const LaneMask done = active & newton & (RotationSettings::NEWTON_ERROR_BOUND * angle * angle * angle <=
                                            settings.max_error_rad);
    converged |= done;
    active &= ~done;
  }
  for (int l = 0; l < count; ++l) {
    Eigen::Matrix3d& rotation = *rotations[l];
    if (usable[l] == 0) {  // F = 0 or not finite: the start's rotation, kept as the warm start
      *warm_starts[l] = Eigen::Quaterniond(q.w[l], q.x[l], q.y[l], q.z[l]);
      rotation = warm_starts[l]->toRotationMatrix();
      continue;
    }
    if (converged[l] == 0) {  // no convergence: the SVD decides, as in extract_rotation()
      rotation = rotation_by_svd(f_in[l]);
      *warm_starts[l] = Eigen::Quaterniond(rotation);
      continue;
    }
    for (int e = 0; e < 9; ++e) rotation(e) = r[e][l];
    *warm_starts[l] = Eigen::Quaterniond(q.w[l], q.x[l], q.y[l], q.z[l]);
  }
}

}  // namespace tissue
