// Fixed-vertex selection by region.
#include "core/fixed_region.hpp"

#include "core/material/material.hpp"

#include <limits>
#include <string>

namespace tissue {

std::vector<int> vertices_in_box(const TetMesh& mesh, const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m) {
  if (!min_m.allFinite() || !max_m.allFinite() || (min_m.array() > max_m.array()).any()) {
    throw ParameterError("fixed region: the box needs finite corners with min <= max");
  }
  std::vector<int> vertices;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Vector3d& p = mesh.rest_positions_m[static_cast<size_t>(v)];
    if ((p.array() >= min_m.array()).all() && (p.array() <= max_m.array()).all()) vertices.push_back(v);
  }
  return vertices;
}

void validate(const MinimumSlab& slab) {
  if (slab.axis < 0 || slab.axis > 2) {
    throw ParameterError("fixed region: axis must be 0, 1 or 2, got " + std::to_string(slab.axis));
  }
  if (!(slab.fraction >= 0.0 && slab.fraction <= 1.0)) {
    throw ParameterError("fixed region: fraction must be in [0, 1], got " + std::to_string(slab.fraction));
  }
}

std::vector<int> vertices_at_minimum(const TetMesh& mesh, int axis, double fraction) {
  validate(MinimumSlab{axis, fraction});
  double lowest = std::numeric_limits<double>::infinity();
  double highest = -lowest;
  for (const Eigen::Vector3d& p : mesh.rest_positions_m) {
    lowest = std::min(lowest, p[axis]);
    highest = std::max(highest, p[axis]);
  }
  const double limit = lowest + fraction * (highest - lowest);
  std::vector<int> vertices;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.rest_positions_m[static_cast<size_t>(v)][axis] <= limit) vertices.push_back(v);
  }
  return vertices;
}

}  // namespace tissue
