// TetMesh helpers: the signed volume that fixes the orientation convention of the whole core.
#include "core/mesh/tet_mesh.hpp"

#include <Eigen/Geometry>

namespace tissue {

double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

}  // namespace tissue
