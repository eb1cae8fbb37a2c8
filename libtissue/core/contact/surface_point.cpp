// Surface material points and the god-object's sliding step (see surface_point.hpp).
#include "core/contact/surface_point.hpp"

#include "core/collide/geometry.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace tissue {
namespace {

// The closest point of one triangle to the query.
struct TriangleCandidate {
  int triangle = -1;
  Eigen::Vector3d barycentric;
  Eigen::Vector3d position_m;
  double squared_distance_m2 = 0.0;
};

TriangleCandidate closest_on_triangle(const Eigen::Vector3d& query, int triangle, const SurfaceTriangles& triangles,
                                      const Eigen::VectorXd& positions_m) {
  const std::array<int, 3>& t = triangles[static_cast<size_t>(triangle)];
  const Eigen::Vector3d x0 = vertex_position(positions_m, t[0]);
  const Eigen::Vector3d x1 = vertex_position(positions_m, t[1]);
  const Eigen::Vector3d x2 = vertex_position(positions_m, t[2]);
  TriangleCandidate candidate;
  candidate.triangle = triangle;
  // Clamped and renormalised: rounding may leave a coordinate at -1e-17 in the face region.
  candidate.barycentric = closest_point_on_triangle(query, x0, x1, x2).cwiseMax(0.0);
  candidate.barycentric /= candidate.barycentric.sum();
  candidate.position_m = candidate.barycentric[0] * x0 + candidate.barycentric[1] * x1 + candidate.barycentric[2] * x2;
  candidate.squared_distance_m2 = (query - candidate.position_m).squaredNorm();
  return candidate;
}

bool contains_vertex(const std::array<int, 3>& triangle, int vertex) {
  return triangle[0] == vertex || triangle[1] == vertex || triangle[2] == vertex;
}

// The feature of a triangle a closest point lies on: its vertices with a non-zero barycentric
// coordinate (3: the face, 2: an edge, 1: a vertex). closest_point_on_triangle returns exact zeros
// outside the face region.
int feature_vertices(const std::array<int, 3>& triangle, const Eigen::Vector3d& barycentric,
                     std::array<int, 3>& vertices) {
  int count = 0;
  for (int k = 0; k < 3; ++k) {
    if (barycentric[k] > 0.0) vertices[static_cast<size_t>(count++)] = triangle[static_cast<size_t>(k)];
  }
  return count;
}

// Visits every triangle incident to the feature (all of whose vertices it contains).
template <typename Visit>
void for_each_incident_triangle(const std::array<int, 3>& feature, int feature_size, const SurfaceTriangles& triangles,
                                const VertexTriangles& adjacency, Visit visit) {
  const int pivot = feature[0];
  for (int k = adjacency.begin[static_cast<size_t>(pivot)]; k < adjacency.begin[static_cast<size_t>(pivot) + 1]; ++k) {
    const int candidate = adjacency.triangles[static_cast<size_t>(k)];
    const std::array<int, 3>& t = triangles[static_cast<size_t>(candidate)];
    bool incident = true;
    for (int f = 1; f < feature_size; ++f) incident = incident && contains_vertex(t, feature[static_cast<size_t>(f)]);
    if (incident) visit(candidate);
  }
}

// Interior angle of triangle t at its vertex `vertex`.
double angle_at_vertex(const std::array<int, 3>& t, int vertex, const Eigen::VectorXd& positions_m) {
  int k = 0;
  while (t[static_cast<size_t>(k)] != vertex) ++k;
  const Eigen::Vector3d x = vertex_position(positions_m, vertex);
  const Eigen::Vector3d a = vertex_position(positions_m, t[static_cast<size_t>((k + 1) % 3)]) - x;
  const Eigen::Vector3d b = vertex_position(positions_m, t[static_cast<size_t>((k + 2) % 3)]) - x;
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

Eigen::Vector3d surface_point_position_m(const SurfacePoint& point, const SurfaceTriangles& triangles,
                                         const Eigen::VectorXd& positions_m) {
  const std::array<int, 3>& t = triangles[static_cast<size_t>(point.triangle)];
  return point.barycentric[0] * vertex_position(positions_m, t[0]) +
         point.barycentric[1] * vertex_position(positions_m, t[1]) +
         point.barycentric[2] * vertex_position(positions_m, t[2]);
}

Eigen::Vector3d triangle_area_normal(const std::array<int, 3>& triangle, const Eigen::VectorXd& positions_m) {
  const Eigen::Vector3d x0 = vertex_position(positions_m, triangle[0]);
  return (vertex_position(positions_m, triangle[1]) - x0).cross(vertex_position(positions_m, triangle[2]) - x0);
}

void VertexTriangles::build(const SurfaceTriangles& surface, int vertex_count) {
  // Built aside and swapped in: a surface with a bad vertex id leaves this adjacency as it was.
  std::vector<int> new_begin(static_cast<size_t>(vertex_count) + 1, 0);
  for (const auto& t : surface) {
    for (int v : t) {
      if (v < 0 || v >= vertex_count) {
        throw std::invalid_argument("surface adjacency: vertex " + std::to_string(v) + " outside [0, " +
                                    std::to_string(vertex_count) + ")");
      }
      ++new_begin[static_cast<size_t>(v) + 1];
    }
  }
  for (size_t v = 0; v < static_cast<size_t>(vertex_count); ++v) new_begin[v + 1] += new_begin[v];
  std::vector<int> new_triangles(static_cast<size_t>(new_begin.back()), -1);
  std::vector<int> fill(new_begin.begin(), new_begin.end() - 1);
  for (size_t t = 0; t < surface.size(); ++t) {
    for (int v : surface[t]) new_triangles[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = static_cast<int>(t);
  }
  begin = std::move(new_begin);
  triangles = std::move(new_triangles);
  triangle_count = static_cast<int>(surface.size());
}

Eigen::Vector3d smooth_normal(const SurfacePoint& point, const SurfaceTriangles& triangles,
                              const VertexTriangles& adjacency, const Eigen::VectorXd& positions_m) {
  const std::array<int, 3>& corners = triangles[static_cast<size_t>(point.triangle)];
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < 3; ++k) {
    const int v = corners[k];
    Eigen::Vector3d vertex_normal = Eigen::Vector3d::Zero();
    for (int a = adjacency.begin[static_cast<size_t>(v)]; a < adjacency.begin[static_cast<size_t>(v) + 1]; ++a) {
      vertex_normal += triangle_area_normal(triangles[static_cast<size_t>(adjacency.triangles[static_cast<size_t>(a)])],
                                            positions_m);
    }
    const double length = vertex_normal.norm();
    if (length > 0.0) normal += point.barycentric[static_cast<Eigen::Index>(k)] * vertex_normal / length;
  }
  const double length = normal.norm();
  return length > 0.0 ? Eigen::Vector3d(normal / length)
                      : Eigen::Vector3d(triangle_area_normal(corners, positions_m).normalized());
}

SurfaceProjection slide_to_closest_point(const Eigen::Vector3d& query, const SurfacePoint& start,
                                         const SurfaceTriangles& triangles, const VertexTriangles& adjacency,
                                         const Eigen::VectorXd& positions_m) {
  if (start.triangle < 0 || start.triangle >= static_cast<int>(triangles.size()) ||
      start.triangle >= adjacency.triangle_count) {
    throw std::invalid_argument("slide_to_closest_point: start triangle " + std::to_string(start.triangle) +
                                " is not on the surface (adjacency of " + std::to_string(adjacency.triangle_count) +
                                " triangles)");
  }
  TriangleCandidate current = closest_on_triangle(query, start.triangle, triangles, positions_m);
  std::array<int, 3> feature{};
  int feature_size = 0;
  int steps = 0;
  // Each move strictly lowers the computed distance, and a triangle's computed distance is a fixed
  // number during the slide, so no triangle is visited twice: at most triangle_count moves.
  for (;;) {
    feature_size = feature_vertices(triangles[static_cast<size_t>(current.triangle)], current.barycentric, feature);
    if (feature_size == 3 || steps >= adjacency.triangle_count) break;  // inside a face: a local minimum
    TriangleCandidate best = current;
    // A relative margin keeps rounding-level ties (the same edge point seen from both sides) from moving.
    const double required_m2 = current.squared_distance_m2 * (1.0 - 1e-12);
    for_each_incident_triangle(feature, feature_size, triangles, adjacency, [&](int candidate) {
      if (candidate == current.triangle) return;
      TriangleCandidate c = closest_on_triangle(query, candidate, triangles, positions_m);
      if (c.squared_distance_m2 < required_m2 && c.squared_distance_m2 < best.squared_distance_m2) best = c;
    });
    if (best.triangle == current.triangle) break;
    current = best;
    ++steps;
  }

  // Angle-weighted pseudo-normal of the feature: every incident triangle (all share it).
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  if (feature_size == 3) {
    normal = triangle_area_normal(triangles[static_cast<size_t>(current.triangle)], positions_m);
  } else {
    for_each_incident_triangle(feature, feature_size, triangles, adjacency, [&](int candidate) {
      const std::array<int, 3>& t = triangles[static_cast<size_t>(candidate)];
      const Eigen::Vector3d n = triangle_area_normal(t, positions_m);
      const double length = n.norm();
      if (!(length > 0.0)) return;  // a degenerate triangle has no direction to give
      const double weight = feature_size == 1 ? angle_at_vertex(t, feature[0], positions_m) : 1.0;
      normal += (weight / length) * n;
    });
  }
  const double length = normal.norm();
  if (length > 0.0) normal /= length;

  SurfaceProjection projection;
  projection.point = SurfacePoint{current.triangle, current.barycentric};
  projection.position_m = current.position_m;
  projection.normal = normal;
  projection.distance_m = std::sqrt(current.squared_distance_m2);
  projection.steps = steps;
  return projection;
}

SurfacePoint surface_point_below(const Eigen::Vector3d& point_m, const SurfaceTriangles& triangles,
                                 const Eigen::VectorXd& positions_m) {
  SurfacePoint best;
  double best_height_m = -std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Vector3d a = positions_m.segment<3>(3 * triangles[t][0]);
    const Eigen::Vector3d b = positions_m.segment<3>(3 * triangles[t][1]);
    const Eigen::Vector3d c = positions_m.segment<3>(3 * triangles[t][2]);
    if ((b - a).cross(c - a).z() <= 0.0) continue;  // facing down or vertical
    // Barycentric coordinates of (x, y) in the triangle's projection on the horizontal plane.
    Eigen::Matrix2d edges;
    edges << (b - a).head<2>(), (c - a).head<2>();
    const Eigen::Vector2d beta = edges.inverse() * (point_m - a).head<2>();
    const Eigen::Vector3d barycentric(1.0 - beta.sum(), beta.x(), beta.y());
    if (barycentric.minCoeff() < 0.0) continue;
    const double height_m = barycentric.dot(Eigen::Vector3d(a.z(), b.z(), c.z()));
    if (height_m > best_height_m) {
      best_height_m = height_m;
      best = SurfacePoint{static_cast<int>(t), barycentric};
    }
  }
  return best;
}

}  // namespace tissue
