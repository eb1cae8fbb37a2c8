// CutRenderSurface: the surface split along the cuts: each cut edge once, into two points, and the
// triangles around it the same way.
#include "core/render/cut_render_surface.hpp"

#include "core/render/cut_render_detail.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace tissue {

using cut_render_detail::edge_key;

namespace {

// Where the segment from `from` to `to` leaves the piece holding `from`: a fraction in [0, 1] and the
// index of the cut whose plane it crosses there; fraction -1 if `to` is in the piece too.
std::pair<double, int> leaves_piece_at(const CutTetGeometry& geometry, size_t piece, const Eigen::Vector3d& from,
                                       const Eigen::Vector3d& to) {
  const PieceSides& sides = geometry.pieces[piece].sides;
  double first = std::numeric_limits<double>::infinity();
  int crossed = -1;
  for (size_t c = 0; c < geometry.cuts.size(); ++c) {
    if ((sides.bounded & (1u << c)) == 0) continue;
    const double toward_inside = (sides.above & (1u << c)) != 0 ? 1.0 : -1.0;
    const double d_from = toward_inside * geometry.planes[c].signed_distance(from);
    const double d_to = toward_inside * geometry.planes[c].signed_distance(to);
    if (d_to >= 0.0) continue;
    const double at = d_from <= 0.0 ? 0.0 : d_from / (d_from - d_to);
    if (at < first) {
      first = at;
      crossed = static_cast<int>(c);
    }
  }
  return {crossed >= 0 ? first : -1.0, crossed};
}

// The copy of the split point of edge (u, v) on `end`'s side.
int near(const std::array<int, 2>& copies, int end, int other) { return copies[end < other ? 0 : 1]; }

// The pieces of a surface triangle whose edges k = (k, k + 1) are cut where cut[k] is not null (the
// edge's split points), `cuts` of them.
void split_triangle(const std::array<int, 3>& triangle, const std::array<const std::array<int, 2>*, 3>& cut, int cuts,
                    std::vector<std::array<int, 3>>& skin) {
  if (cuts == 0) {
    skin.push_back(triangle);
    return;
  }
  if (cuts == 3) {  // where two cuts meet: the three corners
    for (size_t k = 0; k < 3; ++k) {
      const int v = triangle[k], next = triangle[(k + 1) % 3], previous = triangle[(k + 2) % 3];
      skin.push_back({v, near(*cut[k], v, next), near(*cut[(k + 2) % 3], v, previous)});
    }
    return;
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
    skin.push_back({a, near(*cut[r], a, b), c});
    skin.push_back({near(*cut[r], b, a), b, c});
  } else {  // corner a cut off
    const std::array<int, 2>& ab = *cut[r];
    const std::array<int, 2>& ca = *cut[(r + 2) % 3];
    skin.push_back({a, near(ab, a, b), near(ca, a, c)});
    skin.push_back({near(ab, b, a), b, c});
    skin.push_back({near(ab, b, a), c, near(ca, c, a)});
  }
}

}  // namespace

std::pair<double, int> CutRenderSurface::crossing_near(const DeformableBody& body, int tet_a, int tet_b,
                                                       const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m) const {
  std::pair<double, int> best{0.5, -1};
  double nearest_middle = std::numeric_limits<double>::infinity();
  for (const int around : {tet_a, tet_b}) {
    std::array<int, 5> tets{around, -1, -1, -1, -1};
    for (size_t f = 0; f < 4; ++f) tets[f + 1] = body.adjacency().face_neighbor[static_cast<size_t>(around)][f];
    for (const int t : tets) {
      if (t < 0 || body.cut_tet_index(t) < 0) continue;
      const CutTetGeometry& geometry = body.cut_geometry(body.cut_tet_index(t));
      for (size_t c = 0; c < geometry.cuts.size(); ++c) {
        const double da = geometry.planes[c].signed_distance(a_m), db = geometry.planes[c].signed_distance(b_m);
        if ((da > 0.0) == (db > 0.0)) continue;
        const double at = da / (da - db);
        if (std::abs(at - 0.5) < nearest_middle) {
          nearest_middle = std::abs(at - 0.5);
          best = {at, geometry.cuts[c].cut_id};
        }
      }
    }
  }
  if (best.second < 0) {  // no plane between them: the latest cut of either tet
    for (const int t : {tet_a, tet_b}) {
      if (body.cut_tet_index(t) >= 0) best.second = body.cut_geometry(body.cut_tet_index(t)).cuts.back().cut_id;
    }
  }
  return best;
}

// The split points of an edge at a moved point are dropped (left unused, on no piece).
void CutRenderSurface::drop_moved_splits(const std::vector<char>& dirty) {
  const size_t vertices = m_surface.vertices_m.size();
  for (size_t v = 0; v < vertices; ++v) {
    if (dirty[v] == 0) continue;
    for (int i = m_vertex_triangles_first[v]; i < m_vertex_triangles_first[v + 1]; ++i) {
      const auto& triangle = m_surface.triangles[static_cast<size_t>(m_vertex_triangles[static_cast<size_t>(i)])];
      for (size_t k = 0; k < 3; ++k) {
        const int u = triangle[k], w = triangle[(k + 1) % 3];
        if (dirty[static_cast<size_t>(u)] == 0 && dirty[static_cast<size_t>(w)] == 0) continue;
        const auto it = m_splits.find(edge_key(u, w));
        if (it == m_splits.end()) continue;
        if (it->second[0] >= 0) {
          for (const int p : it->second)
            m_points[static_cast<size_t>(p)].cut_tet = m_points[static_cast<size_t>(p)].piece = -1;
          m_orphan_points += 2;
          --m_cut_edges;
        }
        m_splits.erase(it);
      }
    }
  }
}

// Whether edge (u, v) is cut, and its two split points (the lower vertex's side first), each edge
// once (m_splits): null if not. Only an edge with an end in a cut tet can be cut; one between two
// vertices riding on uncut tets (uncut_part: their material parts, -1 for the others) only if their
// parts differ.
const std::array<int, 2>* CutRenderSurface::split_edge(const DeformableBody& body, const std::vector<int>& uncut_part,
                                                       int u, int v) {
  std::unordered_map<long long, std::array<int, 2>>& splits = m_splits;
  const int lo = std::min(u, v), hi = std::max(u, v);
  if (uncut_part[static_cast<size_t>(lo)] >= 0 &&
      uncut_part[static_cast<size_t>(lo)] == uncut_part[static_cast<size_t>(hi)]) {
    return nullptr;
  }
  const long long key = edge_key(lo, hi);
  if (const auto it = splits.find(key); it != splits.end()) return it->second[0] < 0 ? nullptr : &it->second;
  const Point low = m_points[static_cast<size_t>(lo)];  // copies: m_points grows below
  const Point high = m_points[static_cast<size_t>(hi)];
  const Eigen::Vector3d& x_low = m_surface.vertices_m[static_cast<size_t>(lo)];
  const Eigen::Vector3d& x_high = m_surface.vertices_m[static_cast<size_t>(hi)];
  double s = -1.0;
  int cut_id = -1;
  if (low.cut_tet >= 0) {
    const CutTetGeometry& geometry = body.cut_geometry(low.cut_tet);
    const auto [at, cut] = leaves_piece_at(geometry, static_cast<size_t>(low.piece), x_low, x_high);
    if (at >= 0.0) {
      s = at;
      cut_id = geometry.cuts[static_cast<size_t>(cut)].cut_id;
    }
  }
  if (s < 0.0 && high.cut_tet >= 0) {
    const CutTetGeometry& geometry = body.cut_geometry(high.cut_tet);
    const auto [back, cut] = leaves_piece_at(geometry, static_cast<size_t>(high.piece), x_high, x_low);
    if (back >= 0.0) {
      s = 1.0 - back;
      cut_id = geometry.cuts[static_cast<size_t>(cut)].cut_id;
    }
  }
  if (s < 0.0 && part_of(body, low) != part_of(body, high)) {
    // Ends in two material parts that neither end's piece tells apart (the edge passes over a cut
    // tet between theirs): split where it crosses a cut plane of the cut tets around its ends.
    const auto [at, cut] = crossing_near(body, low.tet, high.tet, x_low, x_high);
    s = at;
    cut_id = cut;
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
    m_point_cut.push_back(cut_id);
  }
  ++m_cut_edges;
  return &splits.emplace(key, copies).first->second;
}

// The skin: each surface triangle split along the cuts; a run of triangles whose vertices did not
// move is copied as it was.
void CutRenderSurface::split_skin(const DeformableBody& body, const std::vector<char>& dirty,
                                  const std::vector<int>& part) {
  const size_t vertices = m_surface.vertices_m.size();
  // The material part of each surface vertex riding on an uncut tet (-1 for the others): an edge
  // between two of them is cut only if their parts differ.
  std::vector<int>& uncut_part = m_uncut_part;
  uncut_part.assign(vertices, -1);
  for (size_t v = 0; v < vertices; ++v) {
    if (m_points[v].cut_tet < 0) uncut_part[v] = part[v];
  }
  std::vector<std::array<int, 3>>& skin = m_next_skin;
  skin.clear();
  skin.reserve(m_surface.triangles.size() + m_skin.size() / 8);
  std::vector<int>& skin_first = m_next_skin_first;
  skin_first.assign(m_surface.triangles.size() + 1, 0);
  const auto is_clean = [&](size_t t) {
    const auto& triangle = m_surface.triangles[t];
    return dirty[static_cast<size_t>(triangle[0])] == 0 && dirty[static_cast<size_t>(triangle[1])] == 0 &&
           dirty[static_cast<size_t>(triangle[2])] == 0;
  };
  for (size_t t = 0; t < m_surface.triangles.size(); ++t) {
    if (is_clean(t)) {  // a run of triangles as they were, copied at once
      size_t end = t + 1;
      while (end < m_surface.triangles.size() && is_clean(end)) ++end;
      const int shift = static_cast<int>(skin.size()) - m_skin_first[t];
      for (size_t u = t; u < end; ++u) skin_first[u] = m_skin_first[u] + shift;
      skin.insert(skin.end(), m_skin.begin() + m_skin_first[t], m_skin.begin() + m_skin_first[end]);
      t = end - 1;
      continue;
    }
    skin_first[t] = static_cast<int>(skin.size());
    const auto& triangle = m_surface.triangles[t];
    std::array<const std::array<int, 2>*, 3> cut{};
    int cuts = 0;
    for (size_t k = 0; k < 3; ++k) {
      cut[k] = split_edge(body, uncut_part, triangle[k], triangle[(k + 1) % 3]);
      cuts += cut[k] != nullptr ? 1 : 0;
    }
    split_triangle(triangle, cut, cuts, skin);
  }
  skin_first.back() = static_cast<int>(skin.size());
  m_skin.swap(skin);
  m_skin_first.swap(skin_first);
}

}  // namespace tissue
