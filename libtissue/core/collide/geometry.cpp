// Geometric predicates (see geometry.hpp).
#include "core/collide/geometry.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace tissue {

std::optional<SegmentTriangleHit> intersect_segment_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                             const Eigen::Vector3d& t0, const Eigen::Vector3d& t1,
                                                             const Eigen::Vector3d& t2) {
  const Eigen::Vector3d e1 = t1 - t0;
  const Eigen::Vector3d e2 = t2 - t0;
  const Eigen::Vector3d direction = b - a;
  const Eigen::Vector3d normal = e1.cross(e2);
  const double edge_scale = std::max(e1.squaredNorm(), e2.squaredNorm());
  if (normal.squaredNorm() <= 1e-30 * edge_scale * edge_scale) return std::nullopt;  // degenerate triangle
  const double denominator = -direction.dot(normal);
  // Parallel (or coplanar) segment: relative test against |d| |n|.
  if (std::abs(denominator) <= 1e-14 * direction.norm() * normal.norm()) return std::nullopt;
  const Eigen::Vector3d from_t0 = a - t0;
  const double s = from_t0.dot(normal) / denominator;
  if (s < 0.0 || s > 1.0) return std::nullopt;
  // Barycentric via Cramer's rule on a - t0 = -s d + u e1 + v e2.
  const Eigen::Vector3d q = from_t0.cross(direction);
  const double u = q.dot(e2) / denominator;
  const double v = -q.dot(e1) / denominator;
  if (u < 0.0 || v < 0.0 || u + v > 1.0) return std::nullopt;
  SegmentTriangleHit hit;
  hit.segment_parameter = s;
  hit.barycentric = Eigen::Vector3d(1.0 - u - v, u, v);
  return hit;
}

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                                          const Eigen::Vector3d& t1, const Eigen::Vector3d& t2) {
  const Eigen::Vector3d ab = t1 - t0;
  const Eigen::Vector3d ac = t2 - t0;
  const Eigen::Vector3d ap = p - t0;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {1.0, 0.0, 0.0};  // vertex region t0
  const Eigen::Vector3d bp = p - t1;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {0.0, 1.0, 0.0};  // vertex region t1
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {  // edge region t0-t1
    const double denominator = d1 - d3;
    const double v = denominator > 0.0 ? d1 / denominator : 0.0;
    return {1.0 - v, v, 0.0};
  }
  const Eigen::Vector3d cp = p - t2;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {0.0, 0.0, 1.0};  // vertex region t2
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {  // edge region t0-t2
    const double denominator = d2 - d6;
    const double w = denominator > 0.0 ? d2 / denominator : 0.0;
    return {1.0 - w, 0.0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {  // edge region t1-t2
    const double denominator = (d4 - d3) + (d5 - d6);
    const double w = denominator > 0.0 ? (d4 - d3) / denominator : 0.0;
    return {0.0, 1.0 - w, w};
  }
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) return {1.0, 0.0, 0.0};  // degenerate triangle: any vertex is as close as the regions say
  const double v = vb / sum;
  const double w = vc / sum;
  return {1.0 - v - w, v, w};
}

std::optional<Eigen::Vector4d> tet_barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& x0,
                                               const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                                               const Eigen::Vector3d& x3) {
  Eigen::Matrix3d edges;
  edges << x1 - x0, x2 - x0, x3 - x0;
  const double det = edges.determinant();
  const double scale = std::max({edges.col(0).norm(), edges.col(1).norm(), edges.col(2).norm()});
  if (std::abs(det) <= 1e-30 * scale * scale * scale) return std::nullopt;
  const Eigen::Vector3d local = edges.inverse() * (p - x0);
  return Eigen::Vector4d(1.0 - local.sum(), local.x(), local.y(), local.z());
}

}  // namespace tissue
