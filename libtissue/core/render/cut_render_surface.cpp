#include "core/render/cut_render_surface.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>
#include <utility>

namespace tissue {

namespace {

// How far `p` lies outside piece `piece` of a cut tet (the largest distance beyond the planes that
// bound it; <= 0 inside). [m]
double outside_piece_m(const CutTetGeometry& geometry, size_t piece, const Eigen::Vector3d& p) {
  const PieceSides& sides = geometry.pieces[piece].sides;
  double outside = -std::numeric_limits<double>::infinity();
  for (size_t c = 0; c < geometry.cuts.size(); ++c) {
    if ((sides.bounded & (1u << c)) == 0) continue;
    const double toward_inside = (sides.above & (1u << c)) != 0 ? 1.0 : -1.0;
    outside = std::max(outside, -toward_inside * geometry.planes[c].signed_distance(p));
  }
  return outside;
}

// Where the segment from `from` to `to` leaves the piece holding `from` (a fraction in [0, 1]), or
// -1 if `to` is in the piece too.
double leaves_piece_at(const CutTetGeometry& geometry, size_t piece, const Eigen::Vector3d& from,
                       const Eigen::Vector3d& to) {
  const PieceSides& sides = geometry.pieces[piece].sides;
  double first = std::numeric_limits<double>::infinity();
  for (size_t c = 0; c < geometry.cuts.size(); ++c) {
    if ((sides.bounded & (1u << c)) == 0) continue;
    const double toward_inside = (sides.above & (1u << c)) != 0 ? 1.0 : -1.0;
    const double d_from = toward_inside * geometry.planes[c].signed_distance(from);
    const double d_to = toward_inside * geometry.planes[c].signed_distance(to);
    if (d_to >= 0.0) continue;
    first = std::min(first, d_from <= 0.0 ? 0.0 : d_from / (d_from - d_to));
  }
  return std::isfinite(first) ? first : -1.0;
}

// Triangulates the closed polygon `loop` (point indices, positions `x`) by ear clipping in its
// best-fit plane, each triangle wound as the polygon (counter-clockwise about its Newell normal).
void ear_clip(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x,
              std::vector<std::array<int, 3>>& triangles) {
  const size_t n = loop.size();
  if (n < 3) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    normal += x[static_cast<size_t>(loop[i])].cross(x[static_cast<size_t>(loop[(i + 1) % n])]);
  }
  std::vector<int> left = loop;
  if (normal.norm() <= 0.0) {  // no area: a fan closes it
    for (size_t i = 1; i + 1 < n; ++i) triangles.push_back({loop[0], loop[i], loop[i + 1]});
    return;
  }
  normal.normalize();
  const Eigen::Vector3d e1 = normal.unitOrthogonal();
  const Eigen::Vector3d e2 = normal.cross(e1);
  const auto at = [&](int point) {
    const Eigen::Vector3d& p = x[static_cast<size_t>(point)];
    return Eigen::Vector2d(p.dot(e1), p.dot(e2));
  };
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  };
  while (left.size() > 3) {
    const size_t m = left.size();
    size_t ear = m;
    for (size_t i = 0; i < m && ear == m; ++i) {
      const Eigen::Vector2d a = at(left[(i + m - 1) % m]), b = at(left[i]), c = at(left[(i + 1) % m]);
      if (cross(a, b, c) <= 0.0) continue;  // reflex or flat
      bool empty = true;
      for (size_t j = 0; j < m && empty; ++j) {
        if (j == i || j == (i + m - 1) % m || j == (i + 1) % m) continue;
        const Eigen::Vector2d p = at(left[j]);
        empty = !(cross(a, b, p) > 0.0 && cross(b, c, p) > 0.0 && cross(c, a, p) > 0.0);
      }
      if (empty) ear = i;
    }
    if (ear == m) ear = 0;  // no clean ear (a degenerate loop): cut one anyway, the topology stays closed
    triangles.push_back({left[(ear + m - 1) % m], left[ear], left[(ear + 1) % m]});
    left.erase(left.begin() + static_cast<std::ptrdiff_t>(ear));
  }
  triangles.push_back({left[0], left[1], left[2]});
}

}  // namespace

CutRenderSurface::CutRenderSurface(const TetMesh& mesh, TriangleSurface surface, double max_outside_m,
                                   const std::string& source_name)
    : m_mesh(mesh),
      m_surface(std::move(surface)),
      m_embedding(embed_surface(m_mesh, m_surface, max_outside_m, source_name)) {
  m_points.reserve(m_embedding.size());
  for (const SurfaceEmbedding& e : m_embedding) m_points.push_back(Point{e.tet, e.weights, -1, -1});
  m_rest_m = m_surface.vertices_m;
  m_triangles = m_surface.triangles;
}

CutRenderSurface::Point CutRenderSurface::locate(const DeformableBody& body, int tet,
                                                 const Eigen::Vector3d& rest_m) const {
  Point point{tet, barycentric_weights(m_mesh.rest_corners(tet), rest_m), body.cut_tet_index(tet), -1};
  if (point.cut_tet < 0) return point;
  const CutTetGeometry& geometry = body.cut_geometry(point.cut_tet);
  double best = std::numeric_limits<double>::infinity();
  for (size_t q = 0; q < geometry.pieces.size(); ++q) {
    const double outside = outside_piece_m(geometry, q, rest_m);
    if (outside < best) {
      best = outside;
      point.piece = static_cast<int>(q);
    }
  }
  return point;
}

void CutRenderSurface::rebuild(const DeformableBody& body) {
  const size_t vertices = m_surface.vertices_m.size();
  m_points.resize(vertices);
  m_rest_m.resize(vertices);
  for (size_t v = 0; v < vertices; ++v) m_points[v] = locate(body, m_embedding[v].tet, m_surface.vertices_m[v]);

  // Each edge once: is it cut, and its two split points (the lower vertex's side first).
  std::map<std::pair<int, int>, std::array<int, 2>> splits;
  const auto split = [&](int u, int v) -> const std::array<int, 2>* {
    const std::pair<int, int> key{std::min(u, v), std::max(u, v)};
    if (const auto it = splits.find(key); it != splits.end()) return it->second[0] < 0 ? nullptr : &it->second;
    const Point low = m_points[static_cast<size_t>(key.first)];  // copies: m_points grows below
    const Point high = m_points[static_cast<size_t>(key.second)];
    const Eigen::Vector3d& x_low = m_surface.vertices_m[static_cast<size_t>(key.first)];
    const Eigen::Vector3d& x_high = m_surface.vertices_m[static_cast<size_t>(key.second)];
    double s = -1.0;
    if (low.cut_tet >= 0) s = leaves_piece_at(body.cut_geometry(low.cut_tet), static_cast<size_t>(low.piece), x_low, x_high);
    if (s < 0.0 && high.cut_tet >= 0) {
      const double back = leaves_piece_at(body.cut_geometry(high.cut_tet), static_cast<size_t>(high.piece), x_high, x_low);
      if (back >= 0.0) s = 1.0 - back;
    }
    if (s < 0.0) {
      splits.emplace(key, std::array<int, 2>{-1, -1});
      return nullptr;
    }
    const Eigen::Vector3d q = x_low + s * (x_high - x_low);
    std::array<int, 2> copies{};
    for (size_t side = 0; side < 2; ++side) {
      const Point& end = side == 0 ? low : high;
      copies[side] = static_cast<int>(m_points.size());
      m_points.push_back(Point{end.tet, barycentric_weights(m_mesh.rest_corners(end.tet), q), end.cut_tet, end.piece});
      m_rest_m.push_back(q);
    }
    return &splits.emplace(key, copies).first->second;
  };
  // The copy of the split point of edge (u, v) on `end`'s side.
  const auto near = [](const std::array<int, 2>& copies, int end, int other) { return copies[end < other ? 0 : 1]; };

  m_triangles.clear();
  for (const auto& triangle : m_surface.triangles) {
    std::array<const std::array<int, 2>*, 3> cut{};
    int cuts = 0;
    for (size_t k = 0; k < 3; ++k) {
      cut[k] = split(triangle[k], triangle[(k + 1) % 3]);
      cuts += cut[k] != nullptr ? 1 : 0;
    }
    if (cuts == 0) {
      m_triangles.push_back(triangle);
      continue;
    }
    if (cuts == 3) {  // where two cuts meet: the three corners
      for (size_t k = 0; k < 3; ++k) {
        const int v = triangle[k], next = triangle[(k + 1) % 3], previous = triangle[(k + 2) % 3];
        m_triangles.push_back({v, near(*cut[k], v, next), near(*cut[(k + 2) % 3], v, previous)});
      }
      continue;
    }
    // Rotate so that the pattern starts at corner r: one cut on edge (r, r+1), or two on the edges
    // around corner r (edges r-1 and r).
    size_t r = 0;
    if (cuts == 1) {
      while (cut[r] == nullptr) ++r;
    } else {
      while (!(cut[r] != nullptr && cut[(r + 2) % 3] != nullptr)) ++r;
    }
    const int a = triangle[r], b = triangle[(r + 1) % 3], c = triangle[(r + 2) % 3];
    if (cuts == 1) {  // a crack tip: split through the opposite corner, which both sides keep
      m_triangles.push_back({a, near(*cut[r], a, b), c});
      m_triangles.push_back({near(*cut[r], b, a), b, c});
    } else {  // corner a cut off
      const std::array<int, 2>& ab = *cut[r];
      const std::array<int, 2>& ca = *cut[(r + 2) % 3];
      m_triangles.push_back({a, near(ab, a, b), near(ca, a, c)});
      m_triangles.push_back({near(ab, b, a), b, c});
      m_triangles.push_back({near(ab, b, a), c, near(ca, c, a)});
    }
  }
  m_cut_edges = static_cast<int>((m_points.size() - vertices) / 2);
  cap_loops();
}

void CutRenderSurface::cap_loops() {
  // Directed edges of the split surface; a border edge has no twin.
  std::unordered_map<long long, int> directed;  // (u, v) -> count
  const auto key = [](int u, int v) { return (static_cast<long long>(u) << 32) | static_cast<unsigned int>(v); };
  for (const auto& [a, b, c] : m_triangles) {
    ++directed[key(a, b)];
    ++directed[key(b, c)];
    ++directed[key(c, a)];
  }
  std::multimap<int, int> next;  // border edges u -> v
  for (const auto& [a, b, c] : m_triangles) {
    for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      if (!directed.contains(key(v, u))) next.emplace(u, v);
    }
  }
  const size_t surface_triangles = m_triangles.size();
  while (!next.empty()) {
    std::vector<int> loop;
    const int start = next.begin()->first;
    int at = start;
    while (true) {
      const auto it = next.find(at);
      if (it == next.end()) break;  // an open border (should not happen on a closed surface)
      loop.push_back(at);
      at = it->second;
      next.erase(it);
      if (at == start) break;
    }
    std::reverse(loop.begin(), loop.end());  // the cap runs each border edge the other way
    ear_clip(loop, m_rest_m, m_triangles);
  }
  m_cap_triangles = static_cast<int>(m_triangles.size() - surface_triangles);
}

void CutRenderSurface::update(const DeformableBody& body, const Eigen::VectorXd& displacement_m) {
  body.positions(displacement_m, m_real_positions_m);
  std::unordered_map<long long, TetPositions> pieces;
  m_positions_m.resize(m_points.size());
  for (size_t i = 0; i < m_points.size(); ++i) {
    const Point& point = m_points[i];
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    if (point.cut_tet < 0) {
      const Tet& tet = m_mesh.tets[static_cast<size_t>(point.tet)];
      for (size_t j = 0; j < 4; ++j) x += point.weights(static_cast<Eigen::Index>(j)) * m_real_positions_m.segment<3>(3 * tet[j]);
    } else {
      const long long id = (static_cast<long long>(point.cut_tet) << 16) | point.piece;
      auto it = pieces.find(id);
      if (it == pieces.end()) it = pieces.emplace(id, body.piece_positions(displacement_m, point.cut_tet, point.piece)).first;
      for (size_t j = 0; j < 4; ++j) x += point.weights(static_cast<Eigen::Index>(j)) * it->second[j];
    }
    m_positions_m[i] = x;
  }
  vertex_normals(m_positions_m, m_triangles, m_normals);
}

}  // namespace tissue
