// Material points of a deforming triangle surface and the god-object's sliding step: a point is
// stored as (triangle, barycentric), so it moves with the surface; `slide_to_closest_point` moves
// it over the surface, triangle to adjacent triangle, to the point closest to a query (the HIP).
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

namespace tissue {

/// A material point of the surface: sum_k barycentric[k] x(triangle[k]) at any configuration.
struct SurfacePoint {
  int triangle = -1;
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();  ///< in [0, 1], summing to 1
};

using SurfaceTriangles = std::vector<std::array<int, 3>>;

/// The point's position in the configuration `positions_m` (3 doubles per vertex). [m]
Eigen::Vector3d surface_point_position_m(const SurfacePoint& point, const SurfaceTriangles& triangles,
                                         const Eigen::VectorXd& positions_m);

/// (x1 - x0) x (x2 - x0) at `positions_m`: outward for the outward-wound surface, |.| = 2 area. [m^2]
Eigen::Vector3d triangle_area_normal(const std::array<int, 3>& triangle, const Eigen::VectorXd& positions_m);

/// The material point straight below (or above) `point_m` along z in the configuration `positions_m`:
/// on the highest upward-facing triangle the vertical line through it meets (the point a probe pressed
/// straight down holds); triangle -1 when the line meets none.
SurfacePoint surface_point_below(const Eigen::Vector3d& point_m, const SurfaceTriangles& triangles,
                                 const Eigen::VectorXd& positions_m);

/// Vertex -> incident triangles (compressed rows), the adjacency the sliding step walks over.
struct VertexTriangles {
  std::vector<int> begin;      ///< triangles of vertex v: triangles[begin[v] .. begin[v + 1])
  std::vector<int> triangles;  ///< in increasing order per vertex
  int triangle_count = 0;      ///< of the surface this was built from
  /// Rebuilds for `surface` with vertex ids below `vertex_count` (allocates).
  void build(const SurfaceTriangles& surface, int vertex_count);
};

/// The surface's smooth normal at a material point: the area-weighted vertex normals of its
/// triangle's corners (each the sum of its incident triangles' area normals) interpolated with the
/// point's barycentric coordinates, normalized (Phong 1975). Continuous over edges and vertices,
/// where the face normal jumps. Falls back to the face normal where the sum vanishes.
Eigen::Vector3d smooth_normal(const SurfacePoint& point, const SurfaceTriangles& triangles,
                              const VertexTriangles& adjacency, const Eigen::VectorXd& positions_m);

/// Where the sliding step ended.
struct SurfaceProjection {
  SurfacePoint point;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  /// Unit outward pseudo-normal of the feature the point lies on (Baerentzen and Aanaes 2005): the
  /// face normal inside a triangle, the sum of the two face normals on an edge, the angle-weighted
  /// sum at a vertex. The query is inside the body iff (query - position) . normal < 0.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double distance_m = 0.0;  ///< |query - position|
  int steps = 0;            ///< triangles moved across
};

/// The frictionless god-object's motion (Zilles and Salisbury 1995) on a triangle mesh: from
/// `start`, repeatedly moves to the incident triangle (across the closest point's edge or vertex)
/// whose closest point to `query` is strictly nearer, until none is: a local minimum of the
/// distance reached by sliding over the surface. It never jumps through the body to a nearer but
/// unconnected part of the surface (a HIP pushed through a thin leg stays held by the near side).
/// `adjacency` must be built from `triangles`; no allocation. Throws std::invalid_argument for a
/// start triangle out of range.
SurfaceProjection slide_to_closest_point(const Eigen::Vector3d& query, const SurfacePoint& start,
                                         const SurfaceTriangles& triangles, const VertexTriangles& adjacency,
                                         const Eigen::VectorXd& positions_m);

}  // namespace tissue
