// Test support for the volume cutter: a body (mesh, surface, adjacency, current positions), the
// brute-force reference cutter (every edge against the sweep, every tet against the blade, every
// surface triangle for entry, at every step), blade paths and checks on emitted TetCuts.
#pragma once

#include "core/collide/geometry.hpp"
#include "core/collide/surface_bvh.hpp"
#include "core/cut/cut_geometry.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/mesh/topology.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

namespace tissue::test_cut {

inline std::size_t at(int index) { return static_cast<std::size_t>(index); }

struct Body {
  TetMesh mesh;
  SurfaceMesh surface;
  TetAdjacency adjacency;
  Eigen::VectorXd positions_m;

  explicit Body(TetMesh tet_mesh)
      : mesh(std::move(tet_mesh)), surface(extract_surface(mesh)), adjacency(build_adjacency(mesh)) {
    positions_m.resize(3 * mesh.vertex_count());
    for (int v = 0; v < mesh.vertex_count(); ++v) positions_m.segment<3>(3 * v) = mesh.rest_positions_m[at(v)];
  }

  [[nodiscard]] Eigen::Vector3d x(int vertex) const { return positions_m.segment<3>(3 * vertex); }
  [[nodiscard]] std::array<Eigen::Vector3d, 4> tet_points(int tet) const {
    const Tet& v = mesh.tets[at(tet)];
    return {x(v[0]), x(v[1]), x(v[2]), x(v[3])};
  }
  [[nodiscard]] Eigen::Vector3d lower() const {
    return positions_m.reshaped(3, mesh.vertex_count()).rowwise().minCoeff();
  }
  [[nodiscard]] Eigen::Vector3d upper() const {
    return positions_m.reshaped(3, mesh.vertex_count()).rowwise().maxCoeff();
  }
  [[nodiscard]] double size_m() const { return (upper() - lower()).norm(); }
  [[nodiscard]] SurfaceBvh make_bvh() const { return SurfaceBvh(surface.triangles, positions_m); }

  /// Adds the smooth displacement u(X) = a (sin(k Y), sin(k Z), sin(k X)) with k = 2 pi / size and
  /// a k = `strain`. Its gradient has three entries of size <= strain in a cycle, so
  /// det(I + grad u) >= 1 - strain^3: no tet inverts for strain < 1.
  void deform(double strain) {
    const double k = 2.0 * std::numbers::pi / size_m();
    const double a = strain / k;
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      const Eigen::Vector3d& p = mesh.rest_positions_m[at(v)];
      positions_m.segment<3>(3 * v) +=
          a * Eigen::Vector3d(std::sin(k * p.y()), std::sin(k * p.z()), std::sin(k * p.x()));
    }
  }
};

/// The two sweep triangles and their boundary, written out again from the algorithm's definition.
struct SweepQuad {
  std::array<std::array<Eigen::Vector3d, 3>, 2> triangles;
  std::array<std::array<Eigen::Vector3d, 2>, 4> boundary;

  SweepQuad(const Blade& p, const Blade& c)
      : triangles{{{p.tip_m, p.handle_m, c.tip_m}, {p.handle_m, c.handle_m, c.tip_m}}},
        boundary{{{p.tip_m, p.handle_m}, {c.tip_m, c.handle_m}, {p.tip_m, c.tip_m}, {p.handle_m, c.handle_m}}} {}

  /// Ratio along a -> b where the lengthened edge crosses the sweep (first triangle first), clamped to the edge.
  [[nodiscard]] std::optional<double> crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    const Eigen::Vector3d from = a - EDGE_ROUND_OFF_EXTENSION * (b - a);
    const Eigen::Vector3d to = b + EDGE_ROUND_OFF_EXTENSION * (b - a);
    for (const auto& t : triangles) {
      if (const auto hit = intersect_segment_triangle(from, to, t[0], t[1], t[2])) {
        return std::clamp(hit->segment_parameter * (1.0 + 2.0 * EDGE_ROUND_OFF_EXTENSION) - EDGE_ROUND_OFF_EXTENSION,
                          0.0, 1.0);
      }
    }
    return std::nullopt;
  }
  [[nodiscard]] bool meets(const Eigen::Vector3d& t0, const Eigen::Vector3d& t1, const Eigen::Vector3d& t2) const {
    if (crossing(t0, t1) || crossing(t1, t2) || crossing(t2, t0)) return true;
    return std::any_of(boundary.begin(), boundary.end(),
                       [&](const auto& s) { return intersect_segment_triangle(s[0], s[1], t0, t1, t2).has_value(); });
  }
};

/// Axis-aligned box of some points, padded by PAD_M: only to skip exact tests that must fail.
/// Plain doubles, so that the brute force stays quick in unoptimised (sanitizer) builds.
struct Box {
  /// Far above round-off and the edges' lengthening (1e-9 of an edge of at most a few cm).
  static constexpr double PAD_M = 1e-6;
  std::array<double, 3> lower{};
  std::array<double, 3> upper{};

  Box(std::initializer_list<Eigen::Vector3d> points) {
    lower.fill(std::numeric_limits<double>::infinity());
    upper.fill(-std::numeric_limits<double>::infinity());
    for (const auto& p : points) {
      for (int k = 0; k < 3; ++k) {
        lower[at(k)] = std::min(lower[at(k)], p[k] - PAD_M);
        upper[at(k)] = std::max(upper[at(k)], p[k] + PAD_M);
      }
    }
  }
  [[nodiscard]] bool overlaps(const Box& other) const {
    for (std::size_t k = 0; k < 3; ++k) {
      if (lower[k] > other.upper[k] || other.lower[k] > upper[k]) return false;
    }
    return true;
  }
};

inline bool blade_touches_tet(const Blade& blade, const std::array<Eigen::Vector3d, 4>& x) {
  for (const Eigen::Vector3d& end : {blade.tip_m, blade.handle_m}) {
    const auto b = tet_barycentric(end, x[0], x[1], x[2], x[3]);
    if (b && b->minCoeff() >= 0.0) return true;
  }
  for (const auto& f : TET_FACES) {
    if (intersect_segment_triangle(blade.tip_m, blade.handle_m, x[at(f[0])], x[at(f[1])], x[at(f[2])])) return true;
  }
  return false;
}

/// How the reference decides that a tet is cut completely.
enum class CompletionRule {
  /// The crossed edges are exactly those between the two groups of one of the 7 splits
  /// (independent of the cutter; valid without vertex snapping).
  cut_set,
  /// classify_tet_cut on the brute-force crossings (with snapping; checks the search only).
  classify,
};

/// Algorithms 1-5 by exhaustion: every step tests all surface triangles for a session start,
/// every edge against the sweep and every tet for completion and against the blade.
/// The body must not move while the reference is in use.
class ReferenceCutter {
 public:
  ReferenceCutter(const Body& body, CutterSettings settings, CompletionRule rule)
      : m_body(body), m_settings(settings), m_rule(rule) {
    m_records.assign(body.adjacency.edges.size(), -1.0);
    m_cut_session.assign(body.mesh.tets.size(), -1);
    m_ignored_session.assign(body.mesh.tets.size(), -1);
    m_cut_count.assign(body.mesh.tets.size(), 0);
    for (const auto& ends : body.adjacency.edges) m_edge_boxes.push_back(Box{body.x(ends[0]), body.x(ends[1])});
    for (int t = 0; t < body.mesh.tet_count(); ++t) {
      const auto x = body.tet_points(t);
      m_tet_boxes.push_back(Box{x[0], x[1], x[2], x[3]});
    }
    for (const auto& tri : body.surface.triangles) {
      m_triangle_boxes.push_back(Box{body.x(tri[0]), body.x(tri[1]), body.x(tri[2])});
    }
  }

  struct Step {
    bool in_session = false;
    bool cutting_after = false;
    int session = -1;
    std::vector<int> new_cuts;  ///< sorted
    int ignored = 0;
    std::vector<int> touched;  ///< tets the current blade touches, sorted (empty when not cutting after)
  };

  Step step(const Blade& previous_blade, const Blade& current) {
    const Blade previous = swept_from(previous_blade, current);  // the cutter's sweep, with its overlap
    const SweepQuad sweep(previous, current);
    Step result;
    if (!m_cutting) {
      if (!meets_surface(SweepQuad(previous_blade, current), current)) return result;  // without the overlap
      ++m_session;
      m_cutting = true;
      std::fill(m_records.begin(), m_records.end(), -1.0);
    }
    result.in_session = true;
    result.session = m_session;
    const Box sweep_box{previous.tip_m, previous.handle_m, current.tip_m, current.handle_m};
    for (std::size_t e = 0; e < m_records.size(); ++e) {
      if (m_records[e] >= 0.0) continue;  // the first crossing in a session wins
      if (!sweep_box.overlaps(m_edge_boxes[e])) continue;
      const auto& ends = m_body.adjacency.edges[e];
      if (const auto r = sweep.crossing(m_body.x(ends[0]), m_body.x(ends[1]))) m_records[e] = *r;
    }
    for (int t = 0; t < m_body.mesh.tet_count(); ++t) {
      if (m_cut_session[at(t)] == m_session || !completes(t)) continue;
      if (m_cut_count[at(t)] >= MAX_PIECE_CUTS) {  // a tet takes at most this many cuts
        if (m_ignored_session[at(t)] != m_session) ++result.ignored;
        m_ignored_session[at(t)] = m_session;
        continue;
      }
      ++m_cut_count[at(t)];
      m_cut_session[at(t)] = m_session;
      result.new_cuts.push_back(t);
    }
    const Box blade_box{current.tip_m, current.handle_m};
    for (int t = 0; t < m_body.mesh.tet_count(); ++t) {
      if (blade_box.overlaps(m_tet_boxes[at(t)]) && blade_touches_tet(current, m_body.tet_points(t))) {
        result.touched.push_back(t);
      }
    }
    m_cutting = !result.touched.empty();
    result.cutting_after = m_cutting;
    return result;
  }

  void end_cut() { m_cutting = false; }
  [[nodiscard]] std::optional<double> record(int edge) const {
    if (m_records[at(edge)] < 0.0) return std::nullopt;
    return m_records[at(edge)];
  }
  /// Crossings of the local edges of `tet` in the current session, oriented as TET_EDGES.
  [[nodiscard]] TetEdgeCrossings crossings(int tet) const {
    TetEdgeCrossings crossings;
    const Tet& v = m_body.mesh.tets[at(tet)];
    for (std::size_t k = 0; k < 6; ++k) {
      const int edge = m_body.adjacency.tet_edges[at(tet)][k];
      const double r = m_records[at(edge)];
      if (r < 0.0) continue;
      crossings.ratio[k] = v[at(TET_EDGES[k][0])] == m_body.adjacency.edges[at(edge)][0] ? r : 1.0 - r;
    }
    return crossings;
  }

 private:
  [[nodiscard]] bool meets_surface(const SweepQuad& sweep, const Blade& blade) const {
    const Box sweep_box{sweep.triangles[0][0], sweep.triangles[0][1], sweep.triangles[0][2], sweep.triangles[1][1]};
    for (std::size_t k = 0; k < m_body.surface.triangles.size(); ++k) {
      if (!sweep_box.overlaps(m_triangle_boxes[k])) continue;
      const auto& tri = m_body.surface.triangles[k];
      const Eigen::Vector3d t0 = m_body.x(tri[0]), t1 = m_body.x(tri[1]), t2 = m_body.x(tri[2]);
      if (intersect_segment_triangle(blade.tip_m, blade.handle_m, t0, t1, t2) || sweep.meets(t0, t1, t2)) return true;
    }
    return false;
  }

  [[nodiscard]] bool completes(int tet) const {
    const TetEdgeCrossings c = crossings(tet);
    if (m_rule == CompletionRule::classify) {
      const Tet& v = m_body.mesh.tets[at(tet)];
      const std::array<Eigen::Vector3d, 4> rest = {
          m_body.mesh.rest_positions_m[at(v[0])], m_body.mesh.rest_positions_m[at(v[1])],
          m_body.mesh.rest_positions_m[at(v[2])], m_body.mesh.rest_positions_m[at(v[3])]};
      return classify_tet_cut(rest, c, m_settings.vertex_snap_fraction, m_settings.min_volume_fraction).has_value();
    }
    unsigned crossed = 0;
    for (unsigned k = 0; k < 6; ++k) {
      if (c.ratio[k] >= 0.0) crossed |= 1u << k;
    }
    for (unsigned group = 1; group < 15; ++group) {
      unsigned between = 0;
      for (unsigned k = 0; k < 6; ++k) {
        const bool i_in = ((group >> TET_EDGES[k][0]) & 1u) != 0u;
        const bool j_in = ((group >> TET_EDGES[k][1]) & 1u) != 0u;
        if (i_in != j_in) between |= 1u << k;
      }
      if (crossed == between) return true;
    }
    return false;
  }

  const Body& m_body;
  CutterSettings m_settings;
  CompletionRule m_rule;
  bool m_cutting = false;
  int m_session = -1;
  std::vector<double> m_records;
  std::vector<int> m_cut_session;
  std::vector<int> m_ignored_session;
  std::vector<int> m_cut_count;
  std::vector<Box> m_edge_boxes;  ///< the body does not move while the reference runs
  std::vector<Box> m_tet_boxes;
  std::vector<Box> m_triangle_boxes;
};

/// Properties every emitted cut must have, whatever the geometry: both signs, a fraction in
/// [min, 1 - min], edge ratios in [0, 1] or -1 with at least three cut points.
inline void expect_valid_cut(const TetCut& cut, const Body& body, const CutterSettings& settings) {
  ASSERT_GE(cut.tet, 0);
  ASSERT_LT(cut.tet, body.mesh.tet_count());
  int above = 0;
  int below = 0;
  for (const auto s : cut.side) {
    above += s == 1;
    below += s == -1;
  }
  EXPECT_EQ(above + below, 4);
  EXPECT_GE(above, 1);
  EXPECT_GE(below, 1);
  EXPECT_TRUE(std::isfinite(cut.volume_fraction_above));
  EXPECT_GE(cut.volume_fraction_above, settings.min_volume_fraction);
  EXPECT_LE(cut.volume_fraction_above, 1.0 - settings.min_volume_fraction);
  int cut_points = 0;
  for (std::size_t k = 0; k < 6; ++k) {
    const double r = cut.edge_ratio[k];
    EXPECT_TRUE(r == -1.0 || (r >= 0.0 && r <= 1.0)) << r;
    const bool between = cut.side[at(TET_EDGES[k][0])] != cut.side[at(TET_EDGES[k][1])];
    EXPECT_EQ(r >= 0.0, between) << "edge " << k << " of tet " << cut.tet;
    cut_points += r >= 0.0;
  }
  EXPECT_GE(cut_points, 3);
}

/// Components of the tets not in `removed`, connected across shared faces; `label` gets each
/// tet's component (-1 for removed tets).
inline int count_components(const Body& body, const std::vector<bool>& removed, std::vector<int>& label) {
  label.assign(body.mesh.tets.size(), -1);
  int components = 0;
  std::vector<int> stack;
  for (int seed = 0; seed < body.mesh.tet_count(); ++seed) {
    if (removed[at(seed)] || label[at(seed)] >= 0) continue;
    label[at(seed)] = components;
    stack.push_back(seed);
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      for (const int n : body.adjacency.face_neighbor[at(t)]) {
        if (n < 0 || removed[at(n)] || label[at(n)] >= 0) continue;
        label[at(n)] = components;
        stack.push_back(n);
      }
    }
    ++components;
  }
  return components;
}

/// Blade positions from `start` to `end` in `steps` equal steps (tip and handle moved linearly).
/// Written as start + s (end - start), so that a coordinate equal at both ends stays exact.
inline std::vector<Blade> linear_path(const Blade& start, const Blade& end, int steps) {
  std::vector<Blade> path;
  for (int i = 0; i <= steps; ++i) {
    const double s = static_cast<double>(i) / steps;
    path.push_back({start.tip_m + s * (end.tip_m - start.tip_m), start.handle_m + s * (end.handle_m - start.handle_m)});
  }
  return path;
}

}  // namespace tissue::test_cut
