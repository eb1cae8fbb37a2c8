// SurfaceBvh: an AABB tree (Bullet's btDbvt) over the surface triangles of a deforming body.
// Built once; each step it is refitted bottom-up (leaf boxes from the current positions, then
// every parent from its children, in an order computed once) without changing its structure,
// as in van den Bergen (dissertation 4.3.1). Triangles added later (cut faces) are inserted.
// Queries are exact in double precision; the boxes only prune.
#pragma once

#include "core/collide/geometry.hpp"

#include <Eigen/Core>

#include <array>
#include <memory>
#include <span>
#include <vector>

namespace tissue {

class SurfaceBvh {
 public:
  /// `triangles` hold vertex ids into `positions_m` (3 doubles per vertex). Throws
  /// std::invalid_argument for an id outside the positions.
  SurfaceBvh(std::vector<std::array<int, 3>> triangles, const Eigen::VectorXd& positions_m);
  ~SurfaceBvh();
  SurfaceBvh(SurfaceBvh&&) noexcept;
  SurfaceBvh& operator=(SurfaceBvh&&) noexcept;
  SurfaceBvh(const SurfaceBvh&) = delete;
  SurfaceBvh& operator=(const SurfaceBvh&) = delete;

  [[nodiscard]] int triangle_count() const { return static_cast<int>(m_triangles.size()); }
  [[nodiscard]] const std::array<int, 3>& triangle(int id) const { return m_triangles[static_cast<size_t>(id)]; }
  [[nodiscard]] const std::vector<std::array<int, 3>>& triangles() const { return m_triangles; }

  /// Recomputes every box for the current positions, bottom-up; the tree keeps its structure.
  /// No allocation. Positions must have the length given at construction (or at the last add).
  void refit(const Eigen::VectorXd& positions_m);

  /// Inserts a triangle (a cut face) and returns its id (= the previous triangle_count()).
  int add_triangle(const std::array<int, 3>& triangle, const Eigen::VectorXd& positions_m);
  /// Inserts several triangles (the faces of one step's cuts) with one refit-order update and one
  /// refit. Returns the id of the first. Throws std::invalid_argument (nothing added) for a bad id.
  int add_triangles(std::span<const std::array<int, 3>> triangles, const Eigen::VectorXd& positions_m);

  /// Takes triangles out of the tree (the faces of cut tets a later cut replaced, of parts out of the
  /// field): no query returns them and refit() no longer fits them; their ids and corners stay
  /// (triangle(id)), so ids never change. An id already out is skipped. Throws std::invalid_argument
  /// (nothing removed) for an id that is not a triangle's.
  void remove_triangles(std::span<const int> ids);
  /// Whether triangle `id` is in the tree (not removed).
  [[nodiscard]] bool in_tree(int id) const;

  struct SegmentHit {
    int triangle = -1;
    double segment_parameter = 0.0;  ///< point = a + s (b - a)
    Eigen::Vector3d barycentric;     ///< point = sum_k barycentric[k] x(triangle[k])
  };
  /// Every triangle the closed segment a-b crosses, sorted by segment_parameter. `hits` is cleared first.
  void intersect_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::VectorXd& positions_m,
                         std::vector<SegmentHit>& hits) const;

  struct SphereHit {
    int triangle = -1;
    double distance_m = 0.0;      ///< from the centre to the closest point of the triangle
    Eigen::Vector3d barycentric;  ///< of that closest point
  };
  /// Every triangle within `radius_m` of `centre` (exact distance), sorted by distance. `hits` is cleared first.
  void intersect_sphere(const Eigen::Vector3d& centre, double radius_m, const Eigen::VectorXd& positions_m,
                        std::vector<SphereHit>& hits) const;

  /// Ids of the triangles whose (refitted) boxes overlap the box [lower, upper]: candidates only,
  /// in ascending id order (independent of the tree shape). `triangles` is cleared first.
  void overlap_box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, std::vector<int>& triangles) const;

  /// One node of the tree, for tests and diagnostics.
  struct NodeShape {
    int parent = -1;    ///< index of the parent in shape() (-1 for the root)
    int triangle = -1;  ///< the leaf's triangle id (-1 for an internal node)
    bool operator==(const NodeShape&) const = default;
  };
  /// The tree's structure, breadth-first from the root: refit leaves it unchanged, add_triangle grows it.
  [[nodiscard]] std::vector<NodeShape> shape() const;

 private:
  struct Tree;  // btDbvt and the refit order; Bullet stays out of this header
  std::vector<std::array<int, 3>> m_triangles;
  std::unique_ptr<Tree> m_tree;
};

}  // namespace tissue
