// The scene the contact tests share: the project's frog (meshes/frog.veg; x tail to head, z up),
// pinned by its belly or hanging by its hind feet, gravity off unless a test turns it on, and a few
// contact points on its back chosen by position.
#pragma once

#include "core/contact/surface_point.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace tissue::contact_test {

inline TetMesh frog_mesh() { return read_veg(std::string(TISSUE_MESH_DIR) + "/frog.veg"); }

/// How the frog is held: pinned by its belly to the tray (for pokes: a local indentation), or
/// hanging by its hind feet (the vertices within 5% of the x extent from the tail; it swings).
enum class Hold { belly, hind_feet };

inline BodySettings frog_settings(const TetMesh& mesh, Hold hold = Hold::belly) {
  BodySettings settings;
  settings.material = Material{1.0e5, 0.4, 1000.0};
  settings.gravity_m_per_s2.setZero();
  // The body ellipsoid spans z in [0.004, 0.036] m (meshes/make_frog.py): its lowest 4 mm.
  settings.fixed_vertices = hold == Hold::belly ? vertices_in_box(mesh, Eigen::Vector3d(-0.035, -0.024, -1.0),
                                                                  Eigen::Vector3d(0.035, 0.024, 0.008))
                                                : vertices_at_minimum(mesh, 0, 0.05);
  return settings;
}

inline Eigen::VectorXd rest_positions(const TetMesh& mesh) {
  Eigen::VectorXd x(3 * mesh.vertex_count());
  for (int v = 0; v < mesh.vertex_count(); ++v) x.segment<3>(3 * v) = mesh.rest_positions_m[static_cast<size_t>(v)];
  return x;
}

/// Unit outward normal of a surface triangle at `positions_m`.
inline Eigen::Vector3d unit_normal(const std::array<int, 3>& triangle, const Eigen::VectorXd& positions_m) {
  return triangle_area_normal(triangle, positions_m).normalized();
}

/// The centroid of the upward-facing (normal z > 0.8) surface triangle whose centroid is nearest to
/// (x, y) in the horizontal plane: a point on the frog's back (or head) to press on.
inline SurfacePoint back_point(const SurfaceMesh& surface, const Eigen::VectorXd& positions_m, double x_m, double y_m) {
  SurfacePoint best;
  double best_distance = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const std::array<int, 3>& triangle = surface.triangles[t];
    if (unit_normal(triangle, positions_m).z() < 0.8) continue;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int v : triangle) centroid += positions_m.segment<3>(3 * v) / 3.0;
    const double distance = std::hypot(centroid.x() - x_m, centroid.y() - y_m);
    if (distance < best_distance) {
      best_distance = distance;
      best = SurfacePoint{static_cast<int>(t), Eigen::Vector3d::Constant(1.0 / 3.0)};
    }
  }
  return best;
}

/// Contact points the tests press on: the middle of the back, towards the head, off to one side.
inline std::vector<SurfacePoint> back_points(const SurfaceMesh& surface, const Eigen::VectorXd& positions_m) {
  return {back_point(surface, positions_m, 0.0, 0.0), back_point(surface, positions_m, 0.03, 0.005),
          back_point(surface, positions_m, -0.015, 0.015)};
}

}  // namespace tissue::contact_test
