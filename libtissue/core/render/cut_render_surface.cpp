#include "core/render/cut_render_surface.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <unordered_map>
#include <unordered_set>
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

// An edge as one integer: (u, v) directed, and the same for either direction (lower, higher).
long long directed_key(int u, int v) { return (static_cast<long long>(u) << 32) | static_cast<unsigned int>(v); }
long long edge_key(int u, int v) { return directed_key(std::min(u, v), std::max(u, v)); }

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

// Triangulates the closed polygon `loop` (point indices, positions `x`) by ear clipping in its
// best-fit plane, each triangle wound as the polygon (counter-clockwise about its Newell normal),
// never cutting along an edge the mesh has already (edge_exists(u, v), either way: it would then
// have four triangles).
template <typename EdgeExists>
void ear_clip(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x,
              std::vector<std::array<int, 3>>& triangles, const EdgeExists& edge_exists) {
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
  // The loop's points in the plane, once, beside `left`.
  std::vector<Eigen::Vector2d> flat(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = x[static_cast<size_t>(loop[i])];
    flat[i] = Eigen::Vector2d(p.dot(e1), p.dot(e2));
  }
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  };
  // Only a corner that is not convex can lie inside a convex corner's triangle: the test of an ear
  // looks at those (flagged, kept up to date for the two corners next to each ear cut).
  const auto convex_at = [&](size_t i, size_t m) {
    const Eigen::Vector2d& a = flat[(i + m - 1) % m];
    const Eigen::Vector2d& b = flat[i];
    const Eigen::Vector2d& c = flat[(i + 1) % m];
    return cross(a, b, c) > 1e-9 * (b - a).norm() * (c - b).norm();
  };
  std::vector<char> convex(n);
  for (size_t i = 0; i < n; ++i) convex[i] = convex_at(i, n) ? 1 : 0;
  size_t from = 0;  // the search goes on where the last ear was cut
  while (left.size() > 3) {
    const size_t m = left.size();
    size_t ear = m;
    for (size_t k = 0; k < m && ear == m; ++k) {
      const size_t i = (from + k) % m;
      if (convex[i] == 0) continue;  // reflex or flat
      const Eigen::Vector2d& a = flat[(i + m - 1) % m];
      const Eigen::Vector2d& b = flat[i];
      const Eigen::Vector2d& c = flat[(i + 1) % m];
      if (m > 3 && edge_exists(left[(i + 1) % m], left[(i + m - 1) % m])) continue;  // a diagonal the mesh has
      bool empty = true;
      for (size_t j = 0; j < m && empty; ++j) {
        if (convex[j] != 0 || j == i || j == (i + m - 1) % m || j == (i + 1) % m) continue;
        const Eigen::Vector2d& p = flat[j];
        empty = !(cross(a, b, p) > 0.0 && cross(b, c, p) > 0.0 && cross(c, a, p) > 0.0);
      }
      if (empty) ear = i;
    }
    // No clean ear (a degenerate loop): cut one anyway, the topology stays closed; one whose
    // diagonal the mesh lacks, so that no edge gets four triangles (cutting the first corner along a
    // surface edge made the complete-cut frog non-manifold in 4 frames under baseline x86-64).
    for (size_t i = 0; i < m && ear == m; ++i) {
      if (!edge_exists(left[(i + 1) % m], left[(i + m - 1) % m])) ear = i;
    }
    if (ear == m) ear = 0;
    triangles.push_back({left[(ear + m - 1) % m], left[ear], left[(ear + 1) % m]});
    left.erase(left.begin() + static_cast<std::ptrdiff_t>(ear));
    flat.erase(flat.begin() + static_cast<std::ptrdiff_t>(ear));
    convex.erase(convex.begin() + static_cast<std::ptrdiff_t>(ear));
    const size_t before = (ear + m - 2) % (m - 1), after = ear % (m - 1);
    convex[before] = convex_at(before, m - 1) ? 1 : 0;
    convex[after] = convex_at(after, m - 1) ? 1 : 0;
    from = after;
  }
  triangles.push_back({left[0], left[1], left[2]});
}

// The border loops of a split surface from its directed edges at split points (a border edge has
// no twin), each in the order its cap runs them (against the skin).
std::vector<std::vector<int>> border_loops(const std::unordered_map<long long, int>& directed) {
  std::vector<std::pair<int, int>> next;  // border edges u -> v, sorted
  for (const auto& [edge, uses] : directed) {
    const auto u = static_cast<int>(edge >> 32), v = static_cast<int>(edge & 0xffffffffLL);
    if (!directed.contains(directed_key(v, u))) next.emplace_back(u, v);
  }
  std::sort(next.begin(), next.end());
  std::vector<char> used(next.size(), 0);
  // The first unused border edge from `at` (next.size(): none).
  const auto from = [&](int at) {
    for (auto i = static_cast<size_t>(std::lower_bound(next.begin(), next.end(), std::pair{at, INT_MIN}) - next.begin());
         i < next.size() && next[i].first == at; ++i) {
      if (used[i] == 0) return i;
    }
    return next.size();
  };
  std::vector<std::vector<int>> loops;
  for (size_t first = 0; first < next.size(); ++first) {
    if (used[first] != 0) continue;
    std::vector<int> loop;
    const int start = next[first].first;
    int at = start;
    while (true) {
      const size_t i = from(at);
      if (i == next.size()) break;
      loop.push_back(at);
      at = next[i].second;
      used[i] = 1;
      if (at == start) break;
    }
    std::reverse(loop.begin(), loop.end());
    loops.push_back(std::move(loop));
  }
  return loops;
}

// A loop's points' cuts (-1: a surface vertex, a crack tip). Where two cuts meet on the surface the
// points next to the junction may be split by either, so a run shorter than JUNCTION_RUN points
// between two other runs takes a neighbour's cut (the longer's); a tip between two runs of one cut
// (a slit's) stays.
std::vector<int> junction_smoothed(std::vector<int> label) {
  constexpr size_t JUNCTION_RUN = 4;
  const size_t n = label.size();
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t i = 0; i < n && !changed; ++i) {
      if (label[(i + n - 1) % n] == label[i]) continue;  // not a run's start
      size_t length = 1;
      while (length < n && label[(i + length) % n] == label[i]) ++length;
      if (length >= JUNCTION_RUN || length == n) continue;
      const int before = label[(i + n - 1) % n], after = label[(i + length) % n];
      if (label[i] < 0 && before == after) continue;  // a slit's tip
      if (before < 0 && after < 0) continue;
      size_t before_length = 1, after_length = 1;
      while (before_length < n && label[(i + n - 1 - before_length) % n] == before) ++before_length;
      while (after_length < n && label[(i + length + after_length) % n] == after) ++after_length;
      const int into = after < 0 || (before >= 0 && before_length >= after_length) ? before : after;
      for (size_t k = 0; k < length; ++k) label[(i + k) % n] = into;
      changed = true;
    }
  }
  return label;
}

// A maximal run of a loop's points split by one cut.
struct Chain {
  int loop, first, last;  // positions in the loop
  int cut;
  int facing;  // the side of the cut the chain's material lies on (majority of its points)
};

// How a chain's end continues to the next chain of its face: the points in between.
struct Link {
  std::vector<int> bridge;
  int next_first = -1;  // first point of the next chain; -1: the face cannot be closed
};

// A crack tip (surface points between two chains of one cut, where a partial cut ends): usually one
// unsplit surface vertex; with a run of split points no piece sides (the front meeting the surface
// obliquely) more.
struct Tip {
  size_t chain;           // the chain ending at the tip
  std::vector<int> run;   // the points up to the next chain; the front starts at the last
  int first_after;        // the next chain's first point
  int part, cut, before, after;  // before, after: the facings of the chains either side
  [[nodiscard]] int point() const { return run.back(); }
};

// The junctions' switch pairs (forward, backward): of the chains ending at a switch between two
// cuts, keyed by (material part, cut lo, cut hi, facing on lo, facing on hi), the two whose switches
// run opposite ways, forward leaving the lower cut. A key without exactly such a pair gets none.
std::vector<std::pair<size_t, size_t>> paired_switches(const std::map<std::array<int, 5>, std::vector<size_t>>& switches,
                                                       const std::vector<Chain>& chains) {
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const auto& [junction, ends] : switches) {
    if (ends.size() != 2) continue;
    size_t forward = ends[0], backward = ends[1];
    if (chains[forward].cut != junction[1]) std::swap(forward, backward);
    if (chains[forward].cut != junction[1] || chains[backward].cut != junction[2]) continue;
    pairs.emplace_back(forward, backward);
  }
  return pairs;
}

// The crack fronts' tip pairs: each tip with the nearest unpaired tip of the same material part and
// cut whose loop turns the other way (its facings swapped).
std::vector<std::pair<size_t, size_t>> paired_tips(const std::vector<Tip>& tips, const std::vector<Eigen::Vector3d>& rest_m) {
  std::vector<std::pair<size_t, size_t>> pairs;
  std::vector<bool> paired(tips.size(), false);
  for (size_t a = 0; a < tips.size(); ++a) {
    if (paired[a]) continue;
    size_t best = tips.size();
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t b = 0; b < tips.size(); ++b) {
      if (b == a || paired[b] || tips[b].part != tips[a].part || tips[b].cut != tips[a].cut ||
          tips[b].before != tips[a].after || tips[b].after != tips[a].before)
        continue;
      const double distance = (rest_m[static_cast<size_t>(tips[a].point())] - rest_m[static_cast<size_t>(tips[b].point())]).norm();
      if (distance < nearest) {
        nearest = distance;
        best = b;
      }
    }
    if (best == tips.size()) continue;
    paired[a] = paired[best] = true;
    pairs.emplace_back(a, best);
  }
  return pairs;
}

// The faces: chain, link, chain, ... back to the first. Returns how many walks did not close.
int walk_faces(const std::vector<std::vector<int>>& loops, const std::vector<Chain>& chains,
               const std::map<size_t, Link>& link, const std::map<int, size_t>& chain_starting_at,
               std::vector<std::vector<int>>& faces) {
  int open = 0;
  std::vector<bool> used(chains.size(), false);
  for (size_t first = 0; first < chains.size(); ++first) {
    if (used[first]) continue;
    std::vector<int> face;
    size_t at = first;
    bool closed = false;
    for (size_t guard = 0; guard <= chains.size(); ++guard) {
      used[at] = true;
      const Chain& chain = chains[at];
      const std::vector<int>& loop = loops[static_cast<size_t>(chain.loop)];
      for (size_t i = static_cast<size_t>(chain.first);; i = (i + 1) % loop.size()) {
        face.push_back(loop[i]);
        if (i == static_cast<size_t>(chain.last)) break;
      }
      const auto out = link.find(at);
      if (out == link.end() || out->second.next_first < 0) break;
      face.insert(face.end(), out->second.bridge.begin(), out->second.bridge.end());
      const auto following = chain_starting_at.find(out->second.next_first);
      if (following == chain_starting_at.end()) break;
      if (following->second == first) {
        closed = true;
        break;
      }
      at = following->second;
      if (used[at]) break;
    }
    if (closed) {
      faces.push_back(std::move(face));
    } else {
      ++open;
    }
  }
  return open;
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
  m_vertex_triangles_first.assign(m_surface.vertices_m.size() + 1, 0);
  for (const auto& triangle : m_surface.triangles) {
    for (const int v : triangle) ++m_vertex_triangles_first[static_cast<size_t>(v) + 1];
  }
  std::partial_sum(m_vertex_triangles_first.begin(), m_vertex_triangles_first.end(), m_vertex_triangles_first.begin());
  m_vertex_triangles.resize(3 * m_surface.triangles.size());
  std::vector<int> fill(m_vertex_triangles_first.begin(), m_vertex_triangles_first.end() - 1);
  for (size_t t = 0; t < m_surface.triangles.size(); ++t) {
    for (const int v : m_surface.triangles[t]) m_vertex_triangles[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = static_cast<int>(t);
  }
  for (const auto& triangle : m_surface.triangles) {
    for (size_t k = 0; k < 3; ++k) m_surface_edges.insert(edge_key(triangle[k], triangle[(k + 1) % 3]));
  }
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

void CutRenderSurface::find_material_parts(const DeformableBody& body) {
  // Union-find over the copies of the vertices (real: the vertex id; ghost: vertex count + its row),
  // joined within each cell.
  const int vertex_count = m_mesh.vertex_count();
  m_copy_root.resize(static_cast<size_t>(vertex_count) + static_cast<size_t>(body.dof_count() / 3));
  std::iota(m_copy_root.begin(), m_copy_root.end(), 0);
  const auto find = [&](int i) {
    while (m_copy_root[static_cast<size_t>(i)] != i) {
      i = m_copy_root[static_cast<size_t>(i)] = m_copy_root[static_cast<size_t>(m_copy_root[static_cast<size_t>(i)])];
    }
    return i;
  };
  for (int t = 0; t < m_mesh.tet_count(); ++t) {
    const int k = body.cut_tet_index(t);
    const int pieces = k < 0 ? 1 : static_cast<int>(body.xfem().piece_count(k));
    for (int p = 0; p < pieces; ++p) {
      const int first = find(copy_of(body, t, k, p, 0));
      for (size_t j = 1; j < 4; ++j) m_copy_root[static_cast<size_t>(find(copy_of(body, t, k, p, j)))] = first;
    }
  }
  for (size_t i = 0; i < m_copy_root.size(); ++i) m_copy_root[i] = find(static_cast<int>(i));
}

int CutRenderSurface::copy_of(const DeformableBody& body, int tet, int cut_tet, int piece, size_t j) const {
  const int vertex = m_mesh.tets[static_cast<size_t>(tet)][j];
  if (cut_tet < 0) return vertex;
  const int row = body.xfem().piece(cut_tet, piece).ghost_row[j];
  return row < 0 ? vertex : m_mesh.vertex_count() + row;
}

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

int CutRenderSurface::part_of(const DeformableBody& body, const Point& point) const {
  return m_copy_root[static_cast<size_t>(copy_of(body, point.tet, point.cut_tet, point.piece, 0))];
}

void CutRenderSurface::rebuild(const DeformableBody& body) {
  find_material_parts(body);
  const size_t vertices = m_surface.vertices_m.size();
  const auto tet_count = static_cast<size_t>(m_mesh.tet_count());
  const auto locate_vertex = [&](size_t v) {
    const SurfaceEmbedding& e = m_embedding[v];
    m_points[v] = body.cut_tet_index(e.tet) < 0 ? Point{e.tet, e.weights, -1, -1}
                                                 : locate(body, e.tet, m_surface.vertices_m[v]);
  };

  // Incremental: only what rides on a tet whose cut changed since the last re-mesh, or on one of its
  // face neighbours (whose cut planes an edge's split may use), is located and split again; every
  // other edge keeps its split points and every other triangle its pieces. From scratch the first
  // time, when the material parts of the unchanged points regrouped (a piece came free: an uncut
  // edge may now be cut anywhere), and when dropped split points pile up.
  bool scratch = m_tet_cut.size() != tet_count || m_orphan_points > static_cast<int>(vertices) / 4;
  std::vector<char> dirty_tet(tet_count, scratch ? 1 : 0);
  for (size_t t = 0; t < tet_count && !scratch; ++t) {
    if (body.cut_tet_index(static_cast<int>(t)) == m_tet_cut[t]) continue;
    dirty_tet[t] = 1;
    for (const int n : body.adjacency().face_neighbor[t]) {
      if (n >= 0) dirty_tet[static_cast<size_t>(n)] = 1;
    }
  }
  std::vector<char> dirty(vertices, 1);
  std::vector<int> part(vertices, -1);
  if (!scratch) {
    // The unchanged points' parts must group them as before: old and new part ids in one-to-one
    // correspondence over them.
    std::vector<int> old_to_new(m_part_ids, -1), new_to_old(m_copy_root.size(), -1);
    for (size_t v = 0; v < vertices && !scratch; ++v) {
      dirty[v] = dirty_tet[static_cast<size_t>(m_embedding[v].tet)];
      if (dirty[v] != 0) continue;
      part[v] = part_of(body, m_points[v]);
      int& to_new = old_to_new[static_cast<size_t>(m_vertex_part[v])];
      int& to_old = new_to_old[static_cast<size_t>(part[v])];
      if (to_new < 0) to_new = part[v];
      if (to_old < 0) to_old = m_vertex_part[v];
      scratch = to_new != part[v] || to_old != m_vertex_part[v];
    }
  }
  m_from_scratch = scratch;
  const size_t old_split_points = m_split_points;
  if (scratch) {
    std::fill(dirty.begin(), dirty.end(), 1);
    m_splits.clear();
    m_points.resize(vertices);
    m_rest_m.resize(vertices);
    m_point_cut.assign(vertices, -1);
    m_cut_edges = 0;
    m_orphan_points = 0;
    m_skin.clear();
    m_skin_first.assign(m_surface.triangles.size() + 1, 0);
  } else {
    m_points.resize(m_split_points);  // the last caps' points go: the caps are made again
    m_rest_m.resize(m_split_points);
    m_point_cut.resize(m_split_points);
  }
  for (size_t v = 0; v < vertices; ++v) {
    if (dirty[v] != 0) {
      locate_vertex(v);
      part[v] = part_of(body, m_points[v]);
    }
  }
  m_vertex_part = part;
  m_part_ids = m_copy_root.size();
  m_tet_cut.resize(tet_count);
  for (size_t t = 0; t < tet_count; ++t) m_tet_cut[t] = body.cut_tet_index(static_cast<int>(t));
  // The split points of an edge at a moved point are dropped (left unused, on no piece).
  if (!scratch) {
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
          for (const int p : it->second) m_points[static_cast<size_t>(p)].cut_tet = m_points[static_cast<size_t>(p)].piece = -1;
          m_orphan_points += 2;
          --m_cut_edges;
        }
        m_splits.erase(it);
      }
      }
    }
  }

  // Each edge once: is it cut, and its two split points (the lower vertex's side first).
  // Only an edge with an end in a cut tet can be cut; the others are not looked up.
  // The material part of each surface vertex riding on an uncut tet (-1 for the others): an edge
  // between two of them is cut only if their parts differ.
  std::vector<int> uncut_part(vertices, -1);
  for (size_t v = 0; v < vertices; ++v) {
    if (m_points[v].cut_tet < 0) uncut_part[v] = part[v];
  }
  std::unordered_map<long long, std::array<int, 2>>& splits = m_splits;
  const auto split = [&](int u, int v) -> const std::array<int, 2>* {
    const int lo = std::min(u, v), hi = std::max(u, v);
    if (uncut_part[static_cast<size_t>(lo)] >= 0 && uncut_part[static_cast<size_t>(lo)] == uncut_part[static_cast<size_t>(hi)]) {
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
  };
  // The copy of the split point of edge (u, v) on `end`'s side.
  const auto near = [](const std::array<int, 2>& copies, int end, int other) { return copies[end < other ? 0 : 1]; };

  std::vector<std::array<int, 3>> skin;
  skin.reserve(m_surface.triangles.size() + m_skin.size() / 8);
  std::vector<int> skin_first(m_surface.triangles.size() + 1, 0);
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
      cut[k] = split(triangle[k], triangle[(k + 1) % 3]);
      cuts += cut[k] != nullptr ? 1 : 0;
    }
    if (cuts == 0) {
      skin.push_back(triangle);
      continue;
    }
    if (cuts == 3) {  // where two cuts meet: the three corners
      for (size_t k = 0; k < 3; ++k) {
        const int v = triangle[k], next = triangle[(k + 1) % 3], previous = triangle[(k + 2) % 3];
        skin.push_back({v, near(*cut[k], v, next), near(*cut[(k + 2) % 3], v, previous)});
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
  skin_first.back() = static_cast<int>(skin.size());
  m_skin = std::move(skin);
  m_skin_first = std::move(skin_first);
  const size_t first_new = scratch ? 0 : old_split_points;
  m_split_points = m_points.size();
  m_triangles = m_skin;
  cap_loops(body);
  map_points_to_nodes(first_new, dirty);
}

void CutRenderSurface::map_points_to_nodes(size_t first_new, const std::vector<char>& dirty_vertices) {
  // The slot of each (cut tet, piece) in use, by cut tet and piece. An incremental re-mesh keeps the
  // slots (a piece no point rides on any more keeps its slot until the next re-mesh from scratch) and
  // maps only the points it moved or added.
  int cut_tets = 0, pieces = 1;
  for (const Point& point : m_points) {
    cut_tets = std::max(cut_tets, point.cut_tet + 1);
    pieces = std::max(pieces, point.piece + 1);
  }
  const bool all = m_from_scratch || static_cast<size_t>(pieces) > m_slot_stride;
  if (all) {
    m_slot_stride = static_cast<size_t>(pieces);
    m_slot_of.clear();
    m_slots.clear();
  }
  m_slot_of.resize(std::max(m_slot_of.size(), static_cast<size_t>(cut_tets) * m_slot_stride), -1);
  m_point_nodes.resize(m_points.size());
  const auto map = [&](size_t i) {
    const Point& point = m_points[i];
    std::array<int, 4>& nodes = m_point_nodes[i];
    if (point.cut_tet < 0) {
      for (size_t j = 0; j < 4; ++j) nodes[j] = m_mesh.tets[static_cast<size_t>(point.tet)][j];
      return;
    }
    int& slot = m_slot_of[static_cast<size_t>(point.cut_tet) * m_slot_stride + static_cast<size_t>(point.piece)];
    if (slot < 0) {
      slot = static_cast<int>(m_slots.size());
      m_slots.push_back({point.cut_tet, point.piece});
    }
    for (size_t j = 0; j < 4; ++j) nodes[j] = m_mesh.vertex_count() + 4 * slot + static_cast<int>(j);
  };
  if (all) {
    for (size_t i = 0; i < m_points.size(); ++i) map(i);
    return;
  }
  for (size_t v = 0; v < dirty_vertices.size(); ++v) {
    if (dirty_vertices[v] != 0) map(v);
  }
  for (size_t i = first_new; i < m_points.size(); ++i) map(i);
}

void CutRenderSurface::node_positions(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                                      std::vector<Eigen::Vector3d>& nodes_m) const {
  body.positions(displacement_m, m_real_positions_m);
  nodes_m.resize(static_cast<size_t>(node_count()));
  for (int v = 0; v < m_mesh.vertex_count(); ++v) nodes_m[static_cast<size_t>(v)] = m_real_positions_m.segment<3>(3 * v);
  for (size_t s = 0; s < m_slots.size(); ++s) {
    const TetPositions corners = body.piece_positions(displacement_m, m_slots[s][0], m_slots[s][1]);
    for (size_t j = 0; j < 4; ++j) nodes_m[static_cast<size_t>(m_mesh.vertex_count()) + 4 * s + j] = corners[j];
  }
}

int CutRenderSurface::add_point_like(int model, const Eigen::Vector3d& rest_m) {
  const Point& like = m_points[static_cast<size_t>(model)];
  m_points.push_back(Point{like.tet, barycentric_weights(m_mesh.rest_corners(like.tet), rest_m), like.cut_tet, like.piece});
  m_rest_m.push_back(rest_m);
  m_point_cut.push_back(-1);
  return static_cast<int>(m_points.size()) - 1;
}

std::vector<int> CutRenderSurface::line_points(int from, int to) {
  // Interior points about JOIN_SPACING_M apart on the straight rest segment; each half rides on the
  // cell of its nearer end (exact under that piece's rigid motion).
  constexpr double JOIN_SPACING_M = 0.0015;
  const Eigen::Vector3d a = m_rest_m[static_cast<size_t>(from)];
  const Eigen::Vector3d b = m_rest_m[static_cast<size_t>(to)];
  // At least one point: the line must not coincide with an edge the skin may already have.
  const int segments = std::max(2, static_cast<int>(std::ceil((b - a).norm() / JOIN_SPACING_M)));
  std::vector<int> points;
  for (int k = 1; k < segments; ++k) {
    const double s = static_cast<double>(k) / segments;
    points.push_back(add_point_like(s < 0.5 ? from : to, a + s * (b - a)));
  }
  return points;
}

void CutRenderSurface::cap_loops(const DeformableBody& body) {
  // Directed edges of the split surface at its split points; a border edge has no twin. (An edge
  // between two of the surface's own vertices keeps both its triangles: it is never a border.)
  const auto vertices = static_cast<int>(m_surface.vertices_m.size());
  std::unordered_map<long long, int> directed;  // (u, v) -> count
  directed.reserve(8 * (m_points.size() - static_cast<size_t>(m_surface.vertices_m.size())) + 64);
  for (const auto& [a, b, c] : m_triangles) {
    if (a < vertices && b < vertices && c < vertices) continue;
    for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      if (u >= vertices || v >= vertices) ++directed[directed_key(u, v)];
    }
  }
  std::unordered_set<long long> cap_edges;  // (lower, higher) of the caps' edges so far
  cap_edges.reserve(directed.size() + 64);
  const auto has_edge = [&](int u, int v) {
    const long long undirected = edge_key(u, v);
    if (cap_edges.contains(undirected)) return true;
    if (u < vertices && v < vertices) return m_surface_edges.contains(undirected);
    return directed.contains(directed_key(u, v)) || directed.contains(directed_key(v, u));
  };
  const auto cap = [&](const std::vector<int>& polygon) {
    const size_t before = m_triangles.size();
    ear_clip(polygon, m_rest_m, m_triangles, has_edge);
    for (size_t t = before; t < m_triangles.size(); ++t) {
      for (size_t k = 0; k < 3; ++k) {
        const int u = m_triangles[t][k], v = m_triangles[t][(k + 1) % 3];
        cap_edges.insert(edge_key(u, v));
      }
    }
  };
  const std::vector<std::vector<int>> loops = border_loops(directed);
  std::map<std::vector<int>, std::vector<std::array<int, 3>>> simple_caps;  // this re-mesh's, for the next
  const size_t surface_triangles = m_triangles.size();
  m_open_loops = 0;
  const auto part_of_point = [&](int point) { return part_of(body, m_points[static_cast<size_t>(point)]); };
  // Which side of cut `cut` the material of a point's piece lies on (+1 above, -1 below, 0 unknown:
  // a point riding on an uncut tet).
  const auto facing = [&](int point, int cut) {
    const Point& at = m_points[static_cast<size_t>(point)];
    if (at.cut_tet < 0) return 0;
    const CutTetGeometry& geometry = body.cut_geometry(at.cut_tet);
    for (size_t c = 0; c < geometry.cuts.size(); ++c) {
      if (geometry.cuts[c].cut_id != cut) continue;
      return (geometry.pieces[static_cast<size_t>(at.piece)].sides.above & (1u << c)) != 0 ? 1 : -1;
    }
    return 0;
  };

  // Chains: maximal runs of points split by one cut, in loops that are not a single plane's opening.
  std::vector<Chain> chains;
  std::map<int, size_t> chain_starting_at;  // first point -> chain
  std::vector<std::vector<int>> labels;
  for (const std::vector<int>& loop : loops) {
    std::vector<int> cuts;
    for (const int point : loop) cuts.push_back(m_point_cut[static_cast<size_t>(point)]);
    labels.push_back(junction_smoothed(std::move(cuts)));
  }
  // A run of one cut whose points lie on no side of it (they ride on uncut tets: split only because
  // their ends lie in two material parts) between two unsplit points is where the crack front meets
  // the surface obliquely: unlabelled, it becomes part of the tip around it.
  for (size_t l = 0; l < loops.size(); ++l) {
    std::vector<int>& label = labels[l];
    const size_t n = label.size();
    for (size_t i = 0; i < n; ++i) {
      if (label[i] < 0 || label[(i + n - 1) % n] >= 0) continue;
      size_t j = i;
      int votes = 0;
      while (label[(j + 1) % n] == label[i] && j + 1 < i + n) {
        votes += std::abs(facing(loops[l][j % n], label[i]));
        ++j;
      }
      votes += std::abs(facing(loops[l][j % n], label[i]));
      if (votes == 0 && label[(j + 1) % n] < 0 && j + 1 < i + n) {
        for (size_t k = i; k <= j; ++k) label[k % n] = -1;
      }
    }
  }
  for (size_t l = 0; l < loops.size(); ++l) {
    const std::vector<int>& loop = loops[l];
    const size_t n = loop.size();
    const auto cut_at = [&](size_t i) { return labels[l][i % n]; };
    bool simple = true;
    for (size_t i = 0; i < n && simple; ++i) simple = cut_at(i) >= 0 && cut_at(i) == cut_at(0);
    if (simple) {  // the opening of a piece cut free by one plane
      // The same loop as at the last re-mesh (same points, which an incremental re-mesh keeps): its
      // cap as it was.
      std::vector<int> key_points(loop);
      std::rotate(key_points.begin(), std::min_element(key_points.begin(), key_points.end()), key_points.end());
      const auto kept = m_from_scratch ? m_simple_caps.end() : m_simple_caps.find(key_points);
      const size_t before = m_triangles.size();
      if (kept != m_simple_caps.end()) {
        for (const auto& triangle : kept->second) {
          m_triangles.push_back(triangle);
          for (size_t k = 0; k < 3; ++k) {
            const int u = triangle[k], v = triangle[(k + 1) % 3];
            cap_edges.insert(edge_key(u, v));
          }
        }
      } else {
        cap(loop);
      }
      simple_caps.emplace(std::move(key_points),
                          std::vector<std::array<int, 3>>(m_triangles.begin() + static_cast<std::ptrdiff_t>(before), m_triangles.end()));
      continue;
    }
    for (size_t i = 0; i < n; ++i) {
      if (cut_at(i) < 0 || cut_at(i + n - 1) == cut_at(i)) continue;
      size_t j = i;
      int votes = 0;
      while (cut_at(j + 1) == cut_at(i) && j + 1 < i + n) {
        votes += facing(loop[j % n], cut_at(i));
        ++j;
      }
      votes += facing(loop[j % n], cut_at(i));
      chains.push_back(Chain{static_cast<int>(l), static_cast<int>(i), static_cast<int>(j % n), cut_at(i),
                             votes > 0 ? 1 : (votes < 0 ? -1 : 0)});
      chain_starting_at[loop[i]] = chains.size() - 1;
    }
  }
  const auto point_after = [&](const Chain& chain, int steps) {
    const std::vector<int>& loop = loops[static_cast<size_t>(chain.loop)];
    return loop[(static_cast<size_t>(chain.last) + static_cast<size_t>(steps)) % loop.size()];
  };
  const auto label_after = [&](const Chain& chain, int steps) {
    const std::vector<int>& label = labels[static_cast<size_t>(chain.loop)];
    return label[(static_cast<size_t>(chain.last) + static_cast<size_t>(steps)) % label.size()];
  };

  // How each chain's end continues: the points to add and the chain to go on with.
  std::map<size_t, Link> link;
  // Switches (two cuts meet: a junction line through the body between the two switches of one part
  // and cut pair that run opposite ways) and tips (a partial cut: a crack front between two tips of
  // one part and cut whose loops turn opposite ways, nearest first).
  // (part, cut lo, cut hi, facing on lo, facing on hi: the quadrant) -> the chains ending there
  std::map<std::array<int, 5>, std::vector<size_t>> switches;
  std::vector<Tip> tips;
  for (size_t c = 0; c < chains.size(); ++c) {
    const Chain& chain = chains[c];
    const int beyond = point_after(chain, 1);
    const int beyond_cut = label_after(chain, 1);
    if (beyond_cut >= 0) {
      const auto after = chain_starting_at.find(beyond);
      if (after == chain_starting_at.end()) continue;
      const int after_facing = chains[after->second].facing;
      const bool up = chain.cut < beyond_cut;
      switches[{part_of_point(beyond), std::min(chain.cut, beyond_cut), std::max(chain.cut, beyond_cut),
                up ? chain.facing : after_facing, up ? after_facing : chain.facing}]
          .push_back(c);
    } else {
      std::vector<int> run{beyond};  // the unsplit points up to the next chain
      const auto length = static_cast<int>(loops[static_cast<size_t>(chain.loop)].size());
      int steps = 2;
      for (; steps <= length && label_after(chain, steps) < 0; ++steps) run.push_back(point_after(chain, steps));
      // (The next chain may be this one: a loop of one chain and its run.)
      const auto after = chain_starting_at.find(point_after(chain, steps));
      if (steps > length || after == chain_starting_at.end() || chains[after->second].cut != chain.cut) continue;
      const int after_facing = chains[after->second].facing;
      if ((chain.facing != 0 && after_facing == chain.facing) || after->second == c) {
        // Not where a cut ends: the material lies on one side before and after (or the loop is this
        // chain and its run alone: a pocket), the loop only passes surface points the split left on
        // the border (their edges' tests disagreed). The face goes on through them.
        link[c] = Link{run, point_after(chain, steps)};
        continue;
      }
      tips.push_back(Tip{c, run, point_after(chain, steps), part_of_point(run.back()), chain.cut, chain.facing,
                         after_facing});
    }
  }
  for (const auto& [forward, backward] : paired_switches(switches, chains)) {
    // The lower cut's face takes both switch edges and the line; the higher cut's runs it back.
    const int line_start = point_after(chains[forward], 1);  // on the higher cut
    const int line_end = loops[static_cast<size_t>(chains[backward].loop)][static_cast<size_t>(chains[backward].last)];
    const std::vector<int> line = line_points(line_start, line_end);
    Link& out = link[forward];
    out.bridge.push_back(line_start);
    out.bridge.insert(out.bridge.end(), line.begin(), line.end());
    out.bridge.push_back(line_end);
    out.next_first = point_after(chains[backward], 1);  // back on the lower cut
    Link& back = link[backward];
    back.bridge.assign(line.rbegin(), line.rend());
    back.next_first = line_start;
  }
  for (const auto& [a, best] : paired_tips(tips, m_rest_m)) {
    std::vector<int> front = line_points(tips[a].point(), tips[best].point());  // one crack front for both walls
    for (const auto& [from, to] : {std::pair{a, best}, std::pair{best, a}}) {
      // The wall's own tip run, the front, the other tip's front end; then the chain after it.
      Link& out = link[tips[from].chain];
      out.bridge = tips[from].run;
      out.bridge.insert(out.bridge.end(), front.begin(), front.end());
      out.bridge.push_back(tips[to].point());
      out.next_first = tips[to].first_after;
      std::reverse(front.begin(), front.end());
    }
  }
  std::vector<std::vector<int>> faces;
  m_open_loops += walk_faces(loops, chains, link, chain_starting_at, faces);
  for (const std::vector<int>& face : faces) cap(face);
  m_cap_triangles = static_cast<int>(m_triangles.size() - surface_triangles);
  m_simple_caps = std::move(simple_caps);
}

void CutRenderSurface::update(const DeformableBody& body, const Eigen::VectorXd& displacement_m) {
  node_positions(body, displacement_m, m_node_positions_m);
  m_positions_m.resize(m_points.size());
  for (size_t i = 0; i < m_points.size(); ++i) {
    const Eigen::Vector4d& weights = m_points[i].weights;
    const std::array<int, 4>& nodes = m_point_nodes[i];
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < 4; ++k) x += weights(static_cast<Eigen::Index>(k)) * m_node_positions_m[static_cast<size_t>(nodes[k])];
    m_positions_m[i] = x;
  }
  vertex_normals(m_positions_m, m_triangles, m_normals);
}

}  // namespace tissue
