// LazySurfaceBvh: a SurfaceBvh kept fitted to the positions it reads, refitted when a query needs it
// rather than after every step: a step with no tool near the tissue leaves it stale (the bridge:
// ~0.15 ms of a 2.8 ms step). The positions themselves may be brought up to date when first read,
// by the owner's hook (SurfaceViews: the cut faces' corners, 20% of a diced frog's step).
#pragma once

#include "core/collide/surface_bvh.hpp"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace tissue {

class LazySurfaceBvh {
 public:
  /// `positions_m` (3 per point the triangles index) outlives the tree; the tree is fitted to it now.
  /// `bring_positions_up_to_date`, when given, is called before every read of the positions (a query,
  /// a refit, triangles added): the owner writes them there when they are stale.
  LazySurfaceBvh(const std::vector<std::array<int, 3>>& triangles, const Eigen::VectorXd& positions_m,
                 std::function<void()> bring_positions_up_to_date = {})
      : m_positions_m(positions_m),
        m_bvh(triangles, positions_m),
        m_bring_positions_up_to_date(std::move(bring_positions_up_to_date)) {}

  /// The positions moved: the next fitted() refits.
  void positions_moved() { m_stale = true; }
  /// The tree fitted to positions_m().
  [[nodiscard]] const SurfaceBvh& fitted() const {
    bring_positions_up_to_date();
    if (m_stale) {
      m_bvh.refit(m_positions_m);
      m_stale = false;
    }
    return m_bvh;
  }
  /// The tree's triangles as they are, fitted or not (for its topology: ids, corners, counts).
  [[nodiscard]] const SurfaceBvh& unfitted() const { return m_bvh; }
  [[nodiscard]] const Eigen::VectorXd& positions_m() const {
    bring_positions_up_to_date();
    return m_positions_m;
  }
  /// Appends triangles, fitted to the current positions.
  void add_triangles(std::span<const std::array<int, 3>> triangles) {
    bring_positions_up_to_date();
    m_bvh.add_triangles(triangles, m_positions_m);
  }
  /// Takes triangles out of the tree (SurfaceBvh::remove_triangles); the boxes left stay as fitted.
  void remove_triangles(std::span<const int> ids) { m_bvh.remove_triangles(ids); }

 private:
  void bring_positions_up_to_date() const {
    if (m_bring_positions_up_to_date) m_bring_positions_up_to_date();
  }

  const Eigen::VectorXd& m_positions_m;
  mutable SurfaceBvh m_bvh;
  mutable bool m_stale = false;
  std::function<void()> m_bring_positions_up_to_date;
};

}  // namespace tissue
