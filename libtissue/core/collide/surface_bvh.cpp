// SurfaceBvh on Bullet's btDbvt (see surface_bvh.hpp). Bullet builds the tree and inserts cut faces;
// the refit (van den Bergen, dissertation 4.3.1) and the queries walk the btDbvtNode tree here, so
// that neither allocates nor changes the tree. The exact tests are those of geometry.hpp.
#include "core/collide/surface_bvh.hpp"

#include "core/collide/geometry.hpp"

#ifndef BT_USE_DOUBLE_PRECISION
#error "surface_bvh.cpp must see Bullet's double-precision build (link tissue::bullet)"
#endif
#include <BulletCollision/BroadphaseCollision/btDbvt.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace tissue {

struct SurfaceBvh::Tree {
  btDbvt dbvt;
  std::vector<btDbvtNode*> leaves;           ///< leaf of each triangle, by id
  std::vector<btDbvtNode*> refit_order;      ///< internal nodes, every child before its parent
  Eigen::Index required_position_count = 0;  ///< 3 (largest vertex id + 1)
};

namespace {

/// Boxes grow by this fraction of the largest absolute coordinate, so that rounding in the box
/// tests (about 1e-16 of the coordinates) never prunes a triangle the exact test would accept.
constexpr double RELATIVE_BOX_MARGIN = 1e-9;

/// The triangle's axis-aligned box, grown by margin_m on every side.
btDbvtVolume triangle_box(const std::array<int, 3>& triangle, const Eigen::VectorXd& positions_m, double margin_m) {
  const Eigen::Vector3d x0 = vertex_position(positions_m, triangle[0]);
  const Eigen::Vector3d x1 = vertex_position(positions_m, triangle[1]);
  const Eigen::Vector3d x2 = vertex_position(positions_m, triangle[2]);
  const Eigen::Vector3d lower = x0.cwiseMin(x1).cwiseMin(x2).array() - margin_m;
  const Eigen::Vector3d upper = x0.cwiseMax(x1).cwiseMax(x2).array() + margin_m;
  return btDbvtVolume::FromMM(btVector3(lower.x(), lower.y(), lower.z()), btVector3(upper.x(), upper.y(), upper.z()));
}

double box_margin(const Eigen::VectorXd& positions_m) {
  return positions_m.size() == 0 ? 0.0 : RELATIVE_BOX_MARGIN * positions_m.cwiseAbs().maxCoeff();
}

/// Does the closed segment a + t d, t in [0, 1], touch the box? Slab test; a zero direction
/// component only asks whether a lies within that slab (no 0/0).
bool segment_touches_box(const Eigen::Vector3d& a, const Eigen::Vector3d& d, const btDbvtVolume& box) {
  double t_enter = 0.0;
  double t_exit = 1.0;
  for (int k = 0; k < 3; ++k) {
    const double lower = box.Mins()[k];
    const double upper = box.Maxs()[k];
    if (d[k] == 0.0) {
      if (a[k] < lower || a[k] > upper) return false;
      continue;
    }
    double t_lower = (lower - a[k]) / d[k];
    double t_upper = (upper - a[k]) / d[k];
    if (t_lower > t_upper) std::swap(t_lower, t_upper);
    t_enter = std::max(t_enter, t_lower);
    t_exit = std::min(t_exit, t_upper);
    if (t_enter > t_exit) return false;
  }
  return true;
}

bool sphere_touches_box(const Eigen::Vector3d& centre, double radius_m, const btDbvtVolume& box) {
  double squared_distance = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double outside = std::max({box.Mins()[k] - centre[k], 0.0, centre[k] - box.Maxs()[k]});
    squared_distance += outside * outside;
  }
  return squared_distance <= radius_m * radius_m;
}

bool boxes_overlap(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, const btDbvtVolume& box) {
  for (int k = 0; k < 3; ++k) {
    if (upper[k] < box.Mins()[k] || lower[k] > box.Maxs()[k]) return false;
  }
  return true;
}

/// Depth-first walk of the subtrees whose boxes pass `touches`, calling `visit(triangle id)` at each
/// leaf that passes. Stackless (it climbs back through the parent pointers), so it neither allocates
/// nor depends on the tree's depth, and concurrent queries share nothing.
template <typename Touches, typename Visit>
void for_each_touched_leaf(const btDbvtNode* root, const Touches& touches, const Visit& visit) {
  if (root == nullptr) return;
  const btDbvtNode* node = root;
  while (true) {
    if (touches(node->volume)) {
      if (node->isinternal()) {
        node = node->childs[0];
        continue;
      }
      visit(node->dataAsInt);
    }
    while (node != root && node == node->parent->childs[1]) node = node->parent;
    if (node == root) return;
    node = node->parent->childs[1];
  }
}

/// Internal nodes in reverse breadth-first order: iterating it visits children before parents.
void compute_refit_order(const btDbvt& dbvt, std::vector<btDbvtNode*>& order) {
  order.clear();
  if (dbvt.m_root == nullptr || dbvt.m_root->isleaf()) return;
  order.push_back(dbvt.m_root);
  for (size_t next = 0; next < order.size(); ++next) {
    for (btDbvtNode* child : order[next]->childs) {
      if (child->isinternal()) order.push_back(child);
    }
  }
  std::reverse(order.begin(), order.end());
}

/// Throws std::invalid_argument unless every vertex of `triangle` lies within `positions_m`.
void check_triangle(const std::array<int, 3>& triangle, int id, const Eigen::VectorXd& positions_m) {
  const Eigen::Index vertex_count = positions_m.size() / 3;
  for (const int vertex : triangle) {
    if (vertex < 0 || vertex >= vertex_count) {
      throw std::invalid_argument("SurfaceBvh: triangle " + std::to_string(id) + " has vertex id " +
                                  std::to_string(vertex) + ", outside the " + std::to_string(vertex_count) +
                                  " vertices of the positions");
    }
  }
}

Eigen::Index required_position_count(const std::array<int, 3>& triangle) {
  return 3 * (static_cast<Eigen::Index>(*std::max_element(triangle.begin(), triangle.end())) + 1);
}

void check_positions(const Eigen::VectorXd& positions_m, Eigen::Index required) {
  if (positions_m.size() < required) {
    throw std::invalid_argument("SurfaceBvh: positions hold " + std::to_string(positions_m.size()) +
                                " values; the triangles need at least " + std::to_string(required));
  }
}

}  // namespace

SurfaceBvh::SurfaceBvh(std::vector<std::array<int, 3>> triangles, const Eigen::VectorXd& positions_m)
    : m_triangles(std::move(triangles)), m_tree(std::make_unique<Tree>()) {
  for (size_t i = 0; i < m_triangles.size(); ++i) check_triangle(m_triangles[i], static_cast<int>(i), positions_m);
  const double margin_m = box_margin(positions_m);
  m_tree->leaves.reserve(m_triangles.size());
  for (size_t i = 0; i < m_triangles.size(); ++i) {
    btDbvtNode* leaf = m_tree->dbvt.insert(triangle_box(m_triangles[i], positions_m, margin_m), nullptr);
    leaf->dataAsInt = static_cast<int>(i);
    m_tree->leaves.push_back(leaf);
    m_tree->required_position_count =
        std::max(m_tree->required_position_count, required_position_count(m_triangles[i]));
  }
  // Incremental insertion gives a poor tree; rebuild it top-down once. The leaves stay the same nodes.
  m_tree->dbvt.optimizeTopDown();
  compute_refit_order(m_tree->dbvt, m_tree->refit_order);
}

SurfaceBvh::~SurfaceBvh() = default;
SurfaceBvh::SurfaceBvh(SurfaceBvh&&) noexcept = default;
SurfaceBvh& SurfaceBvh::operator=(SurfaceBvh&&) noexcept = default;

void SurfaceBvh::refit(const Eigen::VectorXd& positions_m) {
  if (!m_tree) return;
  check_positions(positions_m, m_tree->required_position_count);
  const double margin_m = box_margin(positions_m);
  for (size_t i = 0; i < m_triangles.size(); ++i) {
    btDbvtNode* leaf = m_tree->leaves[i];
    if (leaf != nullptr) leaf->volume = triangle_box(m_triangles[i], positions_m, margin_m);
  }
  for (btDbvtNode* node : m_tree->refit_order) Merge(node->childs[0]->volume, node->childs[1]->volume, node->volume);
}

void SurfaceBvh::remove_triangles(std::span<const int> ids) {
  for (const int id : ids) {
    if (id < 0 || id >= triangle_count()) {
      throw std::invalid_argument("SurfaceBvh: no triangle " + std::to_string(id) + " to remove (" +
                                  std::to_string(triangle_count()) + " triangles)");
    }
  }
  bool removed = false;
  for (const int id : ids) {
    btDbvtNode*& leaf = m_tree->leaves[static_cast<size_t>(id)];
    if (leaf == nullptr) continue;
    m_tree->dbvt.remove(leaf);
    leaf = nullptr;
    removed = true;
  }
  if (removed) compute_refit_order(m_tree->dbvt, m_tree->refit_order);
}

bool SurfaceBvh::in_tree(int id) const {
  return id >= 0 && id < triangle_count() && m_tree->leaves[static_cast<size_t>(id)] != nullptr;
}

int SurfaceBvh::add_triangle(const std::array<int, 3>& triangle, const Eigen::VectorXd& positions_m) {
  return add_triangles(std::span(&triangle, 1), positions_m);
}

int SurfaceBvh::add_triangles(std::span<const std::array<int, 3>> triangles, const Eigen::VectorXd& positions_m) {
  const int first = triangle_count();
  for (size_t k = 0; k < triangles.size(); ++k) check_triangle(triangles[k], first + static_cast<int>(k), positions_m);
  if (triangles.empty()) return first;
  if (!m_tree) m_tree = std::make_unique<Tree>();
  const double margin = box_margin(positions_m);
  for (const std::array<int, 3>& triangle : triangles) {
    const int id = triangle_count();
    m_triangles.push_back(triangle);
    btDbvtNode* leaf = m_tree->dbvt.insert(triangle_box(triangle, positions_m, margin), nullptr);
    leaf->dataAsInt = id;
    m_tree->leaves.push_back(leaf);
    m_tree->required_position_count = std::max(m_tree->required_position_count, required_position_count(triangle));
  }
  compute_refit_order(m_tree->dbvt, m_tree->refit_order);
  // The other boxes were fitted to the positions of the last refit; fit the whole tree to these.
  refit(positions_m);
  return first;
}

void SurfaceBvh::intersect_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::VectorXd& positions_m, std::vector<SegmentHit>& hits) const {
  hits.clear();
  if (!m_tree) return;
  check_positions(positions_m, m_tree->required_position_count);
  const Eigen::Vector3d direction = b - a;
  const auto touches = [&](const btDbvtVolume& box) { return segment_touches_box(a, direction, box); };
  const auto visit = [&](int id) {
    const std::array<int, 3>& t = m_triangles[static_cast<size_t>(id)];
    const std::optional<SegmentTriangleHit> hit =
        intersect_segment_triangle(a, b, vertex_position(positions_m, t[0]), vertex_position(positions_m, t[1]),
                                   vertex_position(positions_m, t[2]));
    if (hit) hits.push_back({id, hit->segment_parameter, hit->barycentric});
  };
  for_each_touched_leaf(m_tree->dbvt.m_root, touches, visit);
  std::sort(hits.begin(), hits.end(), [](const SegmentHit& x, const SegmentHit& y) {
    return std::pair(x.segment_parameter, x.triangle) < std::pair(y.segment_parameter, y.triangle);
  });
}

void SurfaceBvh::intersect_sphere(const Eigen::Vector3d& centre, double radius_m, const Eigen::VectorXd& positions_m,
                                  std::vector<SphereHit>& hits) const {
  hits.clear();
  if (!(radius_m >= 0.0)) throw std::invalid_argument("SurfaceBvh: sphere radius must be >= 0 (and not NaN)");
  if (!m_tree) return;
  check_positions(positions_m, m_tree->required_position_count);
  const auto touches = [&](const btDbvtVolume& box) { return sphere_touches_box(centre, radius_m, box); };
  const auto visit = [&](int id) {
    const std::array<int, 3>& t = m_triangles[static_cast<size_t>(id)];
    const Eigen::Vector3d x0 = vertex_position(positions_m, t[0]);
    const Eigen::Vector3d x1 = vertex_position(positions_m, t[1]);
    const Eigen::Vector3d x2 = vertex_position(positions_m, t[2]);
    const Eigen::Vector3d barycentric = closest_point_on_triangle(centre, x0, x1, x2);
    const Eigen::Vector3d closest = barycentric[0] * x0 + barycentric[1] * x1 + barycentric[2] * x2;
    const double distance_m = (centre - closest).norm();
    if (distance_m <= radius_m) hits.push_back({id, distance_m, barycentric});
  };
  for_each_touched_leaf(m_tree->dbvt.m_root, touches, visit);
  std::sort(hits.begin(), hits.end(), [](const SphereHit& x, const SphereHit& y) {
    return std::pair(x.distance_m, x.triangle) < std::pair(y.distance_m, y.triangle);
  });
}

void SurfaceBvh::overlap_box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                             std::vector<int>& triangles) const {
  triangles.clear();
  if (!m_tree) return;
  const auto touches = [&](const btDbvtVolume& box) { return boxes_overlap(lower, upper, box); };
  for_each_touched_leaf(m_tree->dbvt.m_root, touches, [&](int id) { triangles.push_back(id); });
  // In id order, not tree order: the tree's shape depends on the insertion history, and a restored
  // state (rebuilt tree) must see the same order as the instance it was saved from.
  std::sort(triangles.begin(), triangles.end());
}

std::vector<SurfaceBvh::NodeShape> SurfaceBvh::shape() const {
  std::vector<NodeShape> shape;
  if (!m_tree || m_tree->dbvt.m_root == nullptr) return shape;
  std::vector<const btDbvtNode*> nodes{m_tree->dbvt.m_root};
  shape.push_back({});
  for (size_t next = 0; next < nodes.size(); ++next) {
    const btDbvtNode* node = nodes[next];
    if (node->isleaf()) {
      shape[next].triangle = node->dataAsInt;
      continue;
    }
    for (const btDbvtNode* child : node->childs) {
      nodes.push_back(child);
      shape.push_back({static_cast<int>(next), -1});
    }
  }
  return shape;
}

}  // namespace tissue
