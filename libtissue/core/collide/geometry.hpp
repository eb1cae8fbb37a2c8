// Exact (double precision) geometric predicates shared by the surface BVH, the volume cutter and
// point contact: segment/triangle intersection, closest point on a triangle, point in tet.
#pragma once

#include <Eigen/Core>

#include <optional>

namespace tissue {

/// Vertex `vertex`'s point in a flat array of positions (x, y, z per vertex) [m].
inline Eigen::Vector3d vertex_position(const Eigen::VectorXd& positions_m, int vertex) {
  return positions_m.segment<3>(3 * static_cast<Eigen::Index>(vertex));
}

/// Where a segment a->b meets a triangle (t0, t1, t2).
struct SegmentTriangleHit {
  double segment_parameter = 0.0;  ///< hit point = a + s (b - a), s in [0, 1]
  Eigen::Vector3d barycentric;     ///< hit point = sum_k barycentric[k] t_k, all in [0, 1]
};

/// The intersection of the closed segment a-b with the closed triangle, or nothing when they miss,
/// when the triangle is degenerate (area^2 below `1e-30 * |edge|^4`) or when the segment lies in
/// the triangle's plane (a coplanar touch is not a crossing). Moeller-Trumbore in double precision.
std::optional<SegmentTriangleHit> intersect_segment_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                             const Eigen::Vector3d& t0, const Eigen::Vector3d& t1,
                                                             const Eigen::Vector3d& t2);

/// Barycentric coordinates of the point of triangle (t0, t1, t2) closest to p (Ericson, Real-Time
/// Collision Detection, 5.1.5). Always valid: non-negative, summing to 1, also for degenerate triangles.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                                          const Eigen::Vector3d& t1, const Eigen::Vector3d& t2);

/// Barycentric coordinates (4) of p in tet (x0..x3); all >= -tolerance means inside.
/// Returns nothing for a degenerate tet (|6V| below 1e-30 * edge^3).
std::optional<Eigen::Vector4d> tet_barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& x0,
                                               const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                                               const Eigen::Vector3d& x3);

}  // namespace tissue
