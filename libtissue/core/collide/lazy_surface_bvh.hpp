// LazySurfaceBvh: a SurfaceBvh kept fitted to the positions it reads, refitted when a query needs it
// rather than after every step: a step with no tool near the tissue leaves it stale (the bridge:
// ~0.15 ms of a 2.8 ms step).
#pragma once

#include "core/collide/surface_bvh.hpp"

#include <Eigen/Core>

#include <array>
#include <span>
#include <vector>

namespace tissue {

class LazySurfaceBvh {
 public:
  /// `positions_m` (3 per point the triangles index) outlives the tree; the tree is fitted to it now.
  LazySurfaceBvh(const std::vector<std::array<int, 3>>& triangles, const Eigen::VectorXd& positions_m)
      : m_positions_m(positions_m), m_bvh(triangles, positions_m) {}

  /// The positions moved: the next fitted() refits.
  void positions_moved() { m_stale = true; }
  /// The tree fitted to positions_m().
  [[nodiscard]] const SurfaceBvh& fitted() const {
    if (m_stale) {
      m_bvh.refit(m_positions_m);
      m_stale = false;
    }
    return m_bvh;
  }
  /// The tree's triangles as they are, fitted or not (for its topology: ids, corners, counts).
  [[nodiscard]] const SurfaceBvh& unfitted() const { return m_bvh; }
  [[nodiscard]] const Eigen::VectorXd& positions_m() const { return m_positions_m; }
  /// Appends triangles, fitted to the current positions.
  void add_triangles(std::span<const std::array<int, 3>> triangles) { m_bvh.add_triangles(triangles, m_positions_m); }
  /// Takes triangles out of the tree (SurfaceBvh::remove_triangles); the boxes left stay as fitted.
  void remove_triangles(std::span<const int> ids) { m_bvh.remove_triangles(ids); }

 private:
  const Eigen::VectorXd& m_positions_m;
  mutable SurfaceBvh m_bvh;
  mutable bool m_stale = false;
};

}  // namespace tissue
