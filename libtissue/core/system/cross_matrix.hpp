// [v]x, the cross-product matrix ([v]x w = v x w): the rigid rotations' columns of the two-level
// coarse spaces and the Neo-Hookean cofactor's derivative.
#pragma once

#include <Eigen/Core>

namespace tissue {

inline Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace tissue
