// Choosing fixed vertices by region: an axis-aligned box, or the slab at the minimum of one axis.
#pragma once

#include "core/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <vector>

namespace tissue {

/// Vertices whose rest position lies in [min_m, max_m] (inclusive), sorted.
std::vector<int> vertices_in_box(const TetMesh& mesh, const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m);

/// The slab of a mesh within `fraction` of its bounding-box extent from the minimum along `axis`.
struct MinimumSlab {
  int axis = 2;            ///< 0 = x, 1 = y, 2 = z
  double fraction = 0.25;  ///< in [0, 1]
};

/// Throws ParameterError unless axis is 0, 1 or 2 and fraction is in [0, 1].
void validate(const MinimumSlab& slab);

/// Vertices within `fraction` of the bounding-box extent of the minimum along `axis` (0 = x, 1 = y, 2 = z), sorted.
/// tissue-bench's default: axis 0, fraction 0.01 ("the vertices at the minimum x").
std::vector<int> vertices_at_minimum(const TetMesh& mesh, int axis, double fraction);

}  // namespace tissue
