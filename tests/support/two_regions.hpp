// A mesh split into two regions by a plane across x (issue 25's tests): the one place the tests
// build their two-material bodies.
#pragma once

#include "core/mesh/tet_mesh.hpp"

#include <utility>

namespace tissue::test {

/// `mesh` with two regions: `below` holds the tets whose centroid lies at x < split_x_m, `above` the
/// rest (a plane through no centroid: between two layers of cells).
inline TetMesh split_at_x(TetMesh mesh, double split_x_m, MeshRegion below, MeshRegion above) {
  mesh.regions = {std::move(below), std::move(above)};
  mesh.tet_regions.clear();
  for (int t = 0; t < mesh.tet_count(); ++t) {
    double x = 0.0;
    for (const Eigen::Vector3d& corner : mesh.rest_corners(t)) x += 0.25 * corner.x();
    mesh.tet_regions.push_back(x < split_x_m ? 0 : 1);
  }
  return mesh;
}

}  // namespace tissue::test
