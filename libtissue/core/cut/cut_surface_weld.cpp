// CutSurface's weld (see cut_surface.hpp, issue 43): which corners of the cut faces and skin pieces are
// one point of the drawn surface. Decided from topology when the faces are made: a corner's mesh
// vertices, the copy of each its piece uses (the real vertex or a ghost row: pieces that the same
// cuts separate from a vertex and that touch share its ghost, so equal rows mean joined material),
// and the cuts it lies on. Never by distance between points: two sides that separated keep theirs.
#include "core/cut/cut_surface.hpp"

#include "core/mesh/topology.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <functional>
#include <iterator>
#include <numeric>
#include <utility>

namespace tissue {

namespace {

// A multi-cut piece's corner is carried by the tet vertices whose barycentric weight exceeds this
// (the clipper's corners lie on the tet's faces to rounding, ~1e-16).
constexpr double SUPPORT_WEIGHT = 1e-9;
// A corner lies on a cut's plane within this fraction of the tet's largest edge.
constexpr double ON_PLANE_FRACTION = 1e-9;

// The weights of the point (1 - ratio) x_from + ratio x_to.
std::array<double, 4> on_edge(int from, int to, double ratio) {
  std::array<double, 4> weights{};
  weights[static_cast<size_t>(from)] = 1.0 - ratio;
  weights[static_cast<size_t>(to)] = ratio;
  return weights;
}

// Barycentric weights of x in the tet `corners`.
std::array<double, 4> barycentric(const std::array<Eigen::Vector3d, 4>& corners, const Eigen::Vector3d& x) {
  Eigen::Matrix3d edges;
  for (int i = 0; i < 3; ++i) edges.col(i) = corners[static_cast<size_t>(i + 1)] - corners[0];
  const Eigen::Vector3d tail = edges.partialPivLu().solve(x - corners[0]);
  return {1.0 - tail.sum(), tail(0), tail(1), tail(2)};
}

// Sorts the first n entries by `less` (a few: insertion; std::sort on a std::array of 4 trips GCC 12's
// array-bounds warning).
template <class T, std::size_t N, class Less>
void sort_first(std::array<T, N>& values, int n, Less less) {
  for (int i = 1; i < n; ++i) {
    for (int j = i; j > 0 && less(values[static_cast<size_t>(j)], values[static_cast<size_t>(j - 1)]); --j) {
      std::swap(values[static_cast<size_t>(j)], values[static_cast<size_t>(j - 1)]);
    }
  }
}

// Whether some tet around mesh edge `edge` is not cut by session `cut_id`: the material is joined
// around the edge there (the crack's front).
bool at_front(const DeformableBody& body, int cut_id, int edge) {
  const TetAdjacency& adjacency = body.adjacency();
  for (int i = adjacency.edge_tets_begin[static_cast<size_t>(edge)];
       i < adjacency.edge_tets_begin[static_cast<size_t>(edge) + 1]; ++i) {
    if (!cut_by(body, adjacency.edge_tets[static_cast<size_t>(i)], cut_id)) return true;
  }
  return false;
}

}  // namespace

std::size_t CutSurface::WeldKeyHash::operator()(const WeldKey& key) const {
  std::size_t hash = 0;
  const auto mix = [&hash](int value) {
    hash ^= std::hash<int>{}(value) + 0x9e3779b97f4a7c15ULL + (hash << 6) + (hash >> 2);
  };
  for (const int v : key.vertex) mix(v);
  for (const int g : key.ghost_row) mix(g);
  for (const int c : key.cut_id) mix(c);
  return hash;
}

int CutSurface::weld_key_id(const WeldKey& key, int point) {
  const auto [it, inserted] = m_key_ids.try_emplace(key, static_cast<int>(m_key_drawn.size()));
  if (inserted) {
    const bool real_vertex = key.vertex[1] < 0 && key.ghost_row[0] == -1;  // not a ghost or a held copy
    m_key_drawn.push_back(real_vertex ? key.vertex[0] : point);
    m_keys.push_back(key);
  }
  return it->second;
}

int CutSurface::add_real_point(const std::array<int, 4>& vertices, const std::array<double, 4>& weights) {
  m_points.push_back(Point{-1, 0, weights, vertices});
  m_live_runs_current = false;
  m_point_owner.push_back(-1);
  m_point_key.push_back(-1);
  return m_vertex_count + static_cast<int>(m_points.size()) - 1;
}

void CutSurface::note_crossed_edge(const WeldKey& key, int edge, double ratio_from_lower, bool lower_side, int point) {
  const int cut_id = key.cut_id[0];
  const std::int64_t id = (static_cast<std::int64_t>(cut_id) << 32) | static_cast<std::uint32_t>(edge);
  const auto [it, inserted] = m_crossed_ids.try_emplace(id, static_cast<int>(m_crossed.size()));
  if (inserted) m_crossed.push_back(CrossedEdge{cut_id, edge, ratio_from_lower});
  m_touched_edges.push_back(it->second);
  CrossedEdge& crossed = m_crossed[static_cast<size_t>(it->second)];
  int& side = lower_side ? crossed.lower_side : crossed.upper_side;
  if (side < 0) side = point;
}

int CutSurface::add_edge_point(const DeformableBody& body, int k, int piece, int a, int b, double ratio_from_a) {
  const CutTet& cut_tet = body.cut_tets()[static_cast<size_t>(k)];
  const CutPiece& of = body.xfem().piece(k, piece);
  const bool a_lower = cut_tet.vertices[static_cast<size_t>(a)] < cut_tet.vertices[static_cast<size_t>(b)];
  const auto lower = static_cast<size_t>(a_lower ? a : b);
  const auto upper = static_cast<size_t>(a_lower ? b : a);
  WeldKey key;
  key.vertex = {cut_tet.vertices[lower], cut_tet.vertices[upper], -1, -1};
  key.ghost_row = {of.ghost_row[lower], of.ghost_row[upper], -1, -1};
  key.cut_id[0] = cut_tet.cut.cut_id;
  const int id = add_point(k, piece, on_edge(a, b, ratio_from_a), key);
  const int edge =
      body.adjacency().tet_edges[static_cast<size_t>(cut_tet.cut.tet)][static_cast<size_t>(local_edge(a, b))];
  // The side a corner is on: the end of the edge its piece holds (sees as the real vertex).
  note_crossed_edge(key, edge, a_lower ? ratio_from_a : 1.0 - ratio_from_a, key.ghost_row[0] == -1, id);
  return id;
}

int CutSurface::add_corner_point(const DeformableBody& body, int k, int piece, const Eigen::Vector3d& corner_m) {
  const CutTet& cut_tet = body.cut_tets()[static_cast<size_t>(k)];
  const CutPiece& of = body.xfem().piece(k, piece);
  const std::array<Eigen::Vector3d, 4> rest = body.mesh().rest_corners(cut_tet.cut.tet);
  const std::array<double, 4> weights = barycentric(rest, corner_m);
  std::array<int, 4> local{};  // the local vertices carrying the corner, by mesh vertex id
  int n = 0;
  for (int j = 0; j < 4; ++j) {
    if (std::abs(weights[static_cast<size_t>(j)]) > SUPPORT_WEIGHT) local[static_cast<size_t>(n++)] = j;
  }
  const auto vertex_of = [&](int j) { return cut_tet.vertices[static_cast<size_t>(j)]; };
  sort_first(local, n, [&](int i, int j) { return vertex_of(i) < vertex_of(j); });
  WeldKey key;
  for (int i = 0; i < n; ++i) {
    key.vertex[static_cast<size_t>(i)] = vertex_of(local[static_cast<size_t>(i)]);
    key.ghost_row[static_cast<size_t>(i)] = of.ghost_row[static_cast<size_t>(local[static_cast<size_t>(i)])];
  }
  if (n == 1) return add_point(k, piece, weights, key);  // a tet vertex (real: drawn as the vertex)
  // The cuts it lies on: an edge crossing's nearest plane; a face or inner corner's planes through it.
  const CutTetGeometry& geometry = body.cut_geometry(k);
  std::vector<std::pair<double, int>> distances;  // (distance, cut id)
  for (size_t c = 0; c < geometry.planes.size(); ++c) {
    const CutPlane& plane = geometry.planes[c];
    distances.emplace_back(std::abs(plane.signed_distance(corner_m)) / plane.normal.norm(), geometry.cuts[c].cut_id);
  }
  std::sort(distances.begin(), distances.end());
  const double on_plane_m = ON_PLANE_FRACTION * largest_edge_m(rest);
  int found = 0;
  for (size_t c = 0; c < distances.size() && found < static_cast<int>(key.cut_id.size()); ++c) {
    if (n == 2 ? c == 0 : distances[c].first <= on_plane_m)
      key.cut_id[static_cast<size_t>(found++)] = distances[c].second;
  }
  sort_first(key.cut_id, found, std::less<int>());
  const int id = add_point(k, piece, weights, key);
  if (n == 2 && key.cut_id[0] >= 0) {
    const int edge =
        body.adjacency()
            .tet_edges[static_cast<size_t>(cut_tet.cut.tet)][static_cast<size_t>(local_edge(local[0], local[1]))];
    const double lower = weights[static_cast<size_t>(local[0])];
    const double upper = weights[static_cast<size_t>(local[1])];
    // The side a corner is on: its piece's side of the cut, which may hold neither end of the edge
    // when another cut crosses the edge too.
    size_t ci = 0;  // the index of its cut in geometry.cuts
    while (ci + 1 < geometry.cuts.size() && geometry.cuts[ci].cut_id != key.cut_id[0]) ++ci;
    const bool piece_above = ((geometry.pieces[static_cast<size_t>(piece)].sides.above >> ci) & 1U) != 0;
    const bool lower_above = geometry.cuts[ci].side[static_cast<size_t>(local[0])] > 0;
    note_crossed_edge(key, edge, upper / (lower + upper), piece_above == lower_above, id);
  }
  return id;
}

void CutSurface::update_fronts(const DeformableBody& body) {
  std::sort(m_touched_edges.begin(), m_touched_edges.end());
  m_touched_edges.erase(std::unique(m_touched_edges.begin(), m_touched_edges.end()), m_touched_edges.end());
  for (const int e : m_touched_edges) {
    CrossedEdge& crossed = m_crossed[static_cast<size_t>(e)];
    const bool front = at_front(body, crossed.cut_id, crossed.edge);
    if (front == crossed.front) continue;
    crossed.front = front;
    if (front) {
      m_front_edges.push_back(e);
    } else {
      std::erase(m_front_edges, e);
    }
  }
  m_touched_edges.clear();
}

void CutSurface::fix_retired_representatives() {
  const auto retired_point = [this](int id) {
    if (id < m_vertex_count) return false;
    const int owner = m_point_owner[static_cast<size_t>(id - m_vertex_count)];
    return owner >= 0 && m_retired[static_cast<size_t>(owner)] != 0;
  };
  for (int& representative : m_key_drawn) {
    if (retired_point(representative)) representative = -1;
  }
  for (size_t p = 0; p < m_points.size(); ++p) {
    const int key = m_point_key[p];
    const int id = m_vertex_count + static_cast<int>(p);
    if (key >= 0 && m_key_drawn[static_cast<size_t>(key)] < 0 && !retired_point(id))
      m_key_drawn[static_cast<size_t>(key)] = id;
  }
}

int CutSurface::key_root(int key) const {
  while (m_key_parent[static_cast<size_t>(key)] != key) key = m_key_parent[static_cast<size_t>(key)];
  return key;
}

namespace {

// The cuts that separate a piece from a vertex it sees through `row` (CutPiece::ghost_row: -1, the
// real vertex, none), kept to the cuts in `common` (ascending).
SeparatingCuts separating_among(const DeformableBody& body, int row, const std::vector<int>& common) {
  SeparatingCuts kept;
  const SeparatingCuts& all = body.copy_separated_by(row);
  for (int i = 0; i < all.count; ++i) {
    if (!std::binary_search(common.begin(), common.end(), all.cut_id[static_cast<size_t>(i)])) continue;
    kept.cut_id[static_cast<size_t>(kept.count)] = all.cut_id[static_cast<size_t>(i)];
    kept.side[static_cast<size_t>(kept.count++)] = all.side[static_cast<size_t>(i)];
  }
  return kept;
}

std::vector<int> sorted_cut_ids(const DeformableBody& body, int k) {
  std::vector<int> ids;
  for (const TetCut& cut : body.cut_geometry(k).cuts) ids.push_back(cut.cut_id);
  std::sort(ids.begin(), ids.end());
  return ids;
}


}  // namespace

// A corner's place: its key without the rows.
CutSurface::WeldKey CutSurface::key_place(int key) const {
  WeldKey place = m_keys[static_cast<size_t>(key)];
  place.ghost_row = {-1, -1, -1, -1};
  return place;
}

// Corners at one place (mesh vertices, cuts) made by tets that different sets of cuts cut: where a
// cut's front ends in tets another cut cut too, the tet cut twice sees an edge's end beyond the second
// cut through a ghost its neighbour, cut once, does not use. The two corners are one point when their
// pieces lie on the same sides of the cuts both tets have: their rows agree once kept to those cuts.
// Tets cut by the same cuts are never joined here (their rows are the whole answer).
void CutSurface::join_compatible_keys(const DeformableBody& body) {
  m_key_parent.resize(m_keys.size());
  std::iota(m_key_parent.begin(), m_key_parent.end(), 0);
  const auto live_on_edge_or_inside = [&](size_t p) {
    const int key = m_point_key[p], owner = m_point_owner[p];
    return key >= 0 && owner >= 0 && m_retired[static_cast<size_t>(owner)] == 0 &&
           m_keys[static_cast<size_t>(key)].vertex[1] >= 0;  // a tet vertex's pieces all see it real
  };
  std::unordered_map<WeldKey, std::vector<size_t>, WeldKeyHash> at_place;  // place -> its points
  for (size_t p = 0; p < m_points.size(); ++p) {
    if (live_on_edge_or_inside(p) && body.cut_geometry(m_point_owner[p]).cuts.size() > 1)
      at_place.try_emplace(key_place(m_point_key[p]));
  }
  for (size_t p = 0; p < m_points.size() && !at_place.empty(); ++p) {
    if (!live_on_edge_or_inside(p)) continue;
    const auto it = at_place.find(key_place(m_point_key[p]));
    if (it != at_place.end()) it->second.push_back(p);
  }
  std::vector<std::vector<int>> cuts_of;  // per point of the place: its tet's cut ids, ascending
  for (const auto& [place, points] : at_place) {
    cuts_of.clear();
    for (const size_t p : points) cuts_of.push_back(sorted_cut_ids(body, m_point_owner[p]));
    for (size_t i = 0; i < points.size(); ++i) {
      const std::vector<int>& cuts_i = cuts_of[i];
      for (size_t j = i + 1; j < points.size(); ++j) {
        const int key_i = m_point_key[points[i]], key_j = m_point_key[points[j]];
        if (key_root(key_i) == key_root(key_j)) continue;
        const std::vector<int>& cuts_j = cuts_of[j];
        if (cuts_i == cuts_j) continue;
        std::vector<int> common;
        std::set_intersection(cuts_i.begin(), cuts_i.end(), cuts_j.begin(), cuts_j.end(), std::back_inserter(common));
        bool same_sides = true;
        for (size_t v = 0; v < 4 && same_sides && place.vertex[v] >= 0; ++v) {
          same_sides = separating_among(body, m_keys[static_cast<size_t>(key_i)].ghost_row[v], common) ==
                       separating_among(body, m_keys[static_cast<size_t>(key_j)].ghost_row[v], common);
        }
        if (same_sides) m_key_parent[static_cast<size_t>(key_root(key_j))] = key_root(key_i);
      }
    }
  }
  m_root_drawn.assign(m_keys.size(), -1);
  for (size_t key = 0; key < m_keys.size(); ++key) {
    int& drawn = m_root_drawn[static_cast<size_t>(key_root(static_cast<int>(key)))];
    if (drawn < 0) drawn = m_key_drawn[key];
  }
  m_joined_keys.clear();  // the keys drawn at another key's point (update_drawn watches them)
  for (size_t key = 0; key < m_keys.size(); ++key) {
    if (m_root_drawn[static_cast<size_t>(key_root(static_cast<int>(key)))] != m_key_drawn[key])
      m_joined_keys.push_back(static_cast<int>(key));
  }
}

int CutSurface::drawn_point(int id) const {
  if (id < m_vertex_count) return id;
  const int key = m_point_key[static_cast<size_t>(id - m_vertex_count)];
  if (key < 0) return id;
  const auto k = static_cast<size_t>(key);
  const bool joined = k < m_root_drawn.size() && !(k < m_key_apart.size() && m_key_apart[k] != 0);
  const int representative = joined ? m_root_drawn[static_cast<size_t>(key_root(key))] : m_key_drawn[k];
  return representative >= 0 ? representative : id;
}

std::array<int, 3> CutSurface::drawn(const std::array<int, 3>& triangle) const {
  return {drawn_point(triangle[0]), drawn_point(triangle[1]), drawn_point(triangle[2])};
}

void CutSurface::note_crack_edges(int k, int cut_id, const std::vector<int>& crossed, int first_above,
                                  bool above_forward) {
  const int n = static_cast<int>(crossed.size());
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    // The face holding both crossed edges is the one opposite the vertex neither has.
    const auto& e = TET_EDGES[static_cast<size_t>(crossed[static_cast<size_t>(i)])];
    const auto& f = TET_EDGES[static_cast<size_t>(crossed[static_cast<size_t>(j)])];
    int face = 0;
    while (face == e[0] || face == e[1] || face == f[0] || face == f[1]) ++face;
    CrackEdge edge{k, cut_id, face, {first_above + i, first_above + j}, {first_above + n + i, first_above + n + j}};
    if (!above_forward) {
      std::swap(edge.above[0], edge.above[1]);
      std::swap(edge.below[0], edge.below[1]);
    }
    m_crack_edges.push_back(edge);
  }
}

// A cap's corners first_corner .. + count (made in a row, counter-clockwise from outside its piece):
// its edges that lie on a face of the tet (both ends with zero weight on the vertex opposite it).
void CutSurface::note_cap_edges(int cut_id, int first_corner, int count) {
  for (int i = 0; i < count; ++i) {
    const int from = first_corner + i;
    const int to = first_corner + (i + 1) % count;
    const auto& w_from = m_points[static_cast<size_t>(from - m_vertex_count)].weights;
    const auto& w_to = m_points[static_cast<size_t>(to - m_vertex_count)].weights;
    for (int face = 0; face < 4; ++face) {
      const auto j = static_cast<size_t>(face);
      if (std::abs(w_from[j]) <= SUPPORT_WEIGHT && std::abs(w_to[j]) <= SUPPORT_WEIGHT)
        m_cap_edges.push_back({face, cut_id, from, to});
    }
  }
}

// Pairs the cap edges of cut tet k's pieces that run between the same two places of the same face
// and cut in opposite directions (the two sides of the cut there) into crack edges for the strips.
void CutSurface::match_cap_edges(int k) {
  const auto place = [this](int id) -> const WeldKey& {
    return m_keys[static_cast<size_t>(m_point_key[static_cast<size_t>(id - m_vertex_count)])];
  };
  const auto same_place = [&](int a, int b) {
    return place(a).vertex == place(b).vertex && place(a).cut_id == place(b).cut_id;
  };
  for (size_t i = 0; i < m_cap_edges.size(); ++i) {
    const CapEdge& one = m_cap_edges[i];
    for (size_t j = i + 1; j < m_cap_edges.size(); ++j) {
      const CapEdge& other = m_cap_edges[j];
      if (other.face != one.face || other.cut_id != one.cut_id) continue;
      if (!same_place(one.from, other.to) || !same_place(one.to, other.from)) continue;
      m_crack_edges.push_back(CrackEdge{k, one.cut_id, one.face, {one.from, one.to}, {other.to, other.from}});
      break;
    }
  }
  m_cap_edges.clear();
}

// Where a cut face's edge lies on a face whose other tet the cut did not cut, the above side runs
// A_s -> A_t along it and the below side B_t -> B_s: the strip A_t A_s B_s B_t closes the two.
void CutSurface::add_front_strips(const DeformableBody& body) {
  const TetAdjacency& adjacency = body.adjacency();
  for (size_t i = 0; i < m_crack_edges.size(); ++i) {
    const CrackEdge& edge = m_crack_edges[i];
    const bool apart = i < m_strip_apart.size() && m_strip_apart[i] != 0;
    if (m_retired[static_cast<size_t>(edge.cut_tet)] != 0 || apart) continue;
    const int tet = body.cut_tets()[static_cast<size_t>(edge.cut_tet)].cut.tet;
    const int neighbour = adjacency.face_neighbor[static_cast<size_t>(tet)][static_cast<size_t>(edge.face)];
    if (neighbour < 0 || cut_by(body, neighbour, edge.cut_id)) continue;
    const int a_s = drawn_point(edge.above[0]), a_t = drawn_point(edge.above[1]);
    const int b_s = drawn_point(edge.below[0]), b_t = drawn_point(edge.below[1]);
    m_drawn.push_back({a_t, a_s, b_s});
    m_drawn.push_back({a_t, b_s, b_t});
  }
}

void CutSurface::rebuild_drawn(const DeformableBody& body, const SurfaceMesh& surface) {
  const auto add_live = [this](std::vector<std::array<int, 3>>& out, const std::array<int, 3>& made, int cut_tet) {
    if (m_retired[static_cast<size_t>(cut_tet)] != 0) return;
    const std::array<int, 3> t = drawn(made);
    if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) out.push_back(t);  // a face the weld folded away: none
  };
  ++m_drawn_rebuilds;
  join_compatible_keys(body);
  m_drawn.clear();
  for (size_t t = 0; t < m_triangles.size(); ++t) add_live(m_drawn, m_triangles[t], m_triangle_cut_tet[t]);
  add_front_strips(body);
  m_skin.clear();
  collect_front_triangles(body, surface);
  const auto by_triangle = [](const std::pair<int, int>& a, const std::pair<int, int>& b) { return a.first < b.first; };
  for (size_t t = 0; t < m_skin_made.size(); ++t) {
    const auto [first, last] = std::equal_range(m_on_cut_front.begin(), m_on_cut_front.end(),
                                                std::pair<int, int>{m_skin_surface[t], 0}, by_triangle);
    if (first == last || m_retired[static_cast<size_t>(m_skin_cut_tet[t])] != 0) {
      add_live(m_skin, m_skin_made[t], m_skin_cut_tet[t]);
    } else {
      split_skin_piece(body, m_skin_made[t], static_cast<size_t>(first - m_on_cut_front.begin()),
                       static_cast<size_t>(last - m_on_cut_front.begin()));
    }
  }
  m_replaced = m_cut_replaced;
  split_front_triangles(body, surface);
}

// The surface triangles on the front's crossed edges whose other triangle's tet the front's cut cut
// (the crack opens to the surface there): of uncut tets (m_on_front, drawn split whole) and of tets
// cut by other cuts only (m_on_cut_front, their skin pieces on the edge drawn split).
void CutSurface::collect_front_triangles(const DeformableBody& body, const SurfaceMesh& surface) {
  const TetAdjacency& adjacency = body.adjacency();
  m_on_front.clear();
  m_on_cut_front.clear();
  for (const int e : m_front_edges) {
    const CrossedEdge& crossed = m_crossed[static_cast<size_t>(e)];
    const bool apart = static_cast<size_t>(e) < m_front_apart.size() && m_front_apart[static_cast<size_t>(e)] != 0;
    if (crossed.lower_side < 0 || crossed.upper_side < 0 || apart) continue;
    // The surface triangles on the edge (two on a closed surface): one of an uncut tet is split where
    // the other's tet is cut by the session (the crack opens to the surface there). Two uncut ones
    // stay whole: the front only touches the surface at the crossing.
    std::array<int, 2> on_edge{-1, -1};
    int found = 0;
    const auto& ends = adjacency.edges[static_cast<size_t>(crossed.edge)];
    for (int i = adjacency.edge_tets_begin[static_cast<size_t>(crossed.edge)];
         i < adjacency.edge_tets_begin[static_cast<size_t>(crossed.edge) + 1]; ++i) {
      const int tet = adjacency.edge_tets[static_cast<size_t>(i)];
      const auto [first, last] = std::equal_range(surface.triangle_tet.begin(), surface.triangle_tet.end(), tet);
      for (auto it = first; it != last && found < 2; ++it) {
        const auto& triangle = surface.triangles[static_cast<size_t>(it - surface.triangle_tet.begin())];
        const auto has = [&](int v) { return std::find(triangle.begin(), triangle.end(), v) != triangle.end(); };
        if (has(ends[0]) && has(ends[1]))
          on_edge[static_cast<size_t>(found++)] = static_cast<int>(it - surface.triangle_tet.begin());
      }
    }
    if (found != 2) continue;
    for (size_t i = 0; i < 2; ++i) {
      const int tet = surface.triangle_tet[static_cast<size_t>(on_edge[i])];
      const int other = surface.triangle_tet[static_cast<size_t>(on_edge[1 - i])];
      if (!cut_by(body, other, crossed.cut_id) || cut_by(body, tet, crossed.cut_id)) continue;
      (body.cut_tet_index(tet) < 0 ? m_on_front : m_on_cut_front).emplace_back(on_edge[i], e);
    }
  }
  std::sort(m_on_front.begin(), m_on_front.end());
  std::sort(m_on_cut_front.begin(), m_on_cut_front.end());
}

void CutSurface::split_front_triangles(const DeformableBody& body, const SurfaceMesh& surface) {
  for (size_t i = 0; i < m_on_front.size();) {
    size_t end = i;
    while (end < m_on_front.size() && m_on_front[end].first == m_on_front[i].first) ++end;
    split_front_triangle(body, surface, m_on_front[i].first, i, end);
    i = end;
  }
}

// Surface triangle t with the front edges m_on_front[begin, end): drawn as its corners in its winding
// with, on each side at the front, the corner of the side holding the side's start, then the other's;
// fanned from its centre (a point of its vertices, made once), so that no sliver joins two points
// of one side.
void CutSurface::split_front_triangle(const DeformableBody& body, const SurfaceMesh& surface, int t, size_t begin,
                                      size_t end) {
  const auto& triangle = surface.triangles[static_cast<size_t>(t)];
  m_polygon.clear();
  for (size_t c = 0; c < 3; ++c) {
    const int a = triangle[c];
    const int b = triangle[(c + 1) % 3];
    m_polygon.push_back(a);
    m_along.clear();
    for (size_t j = begin; j < end; ++j) {
      const CrossedEdge& crossed = m_crossed[static_cast<size_t>(m_on_front[j].second)];
      const auto& ends = body.adjacency().edges[static_cast<size_t>(crossed.edge)];
      if (ends[0] == a && ends[1] == b) {
        m_along.push_back({crossed.ratio, {drawn_point(crossed.lower_side), drawn_point(crossed.upper_side)}});
      } else if (ends[0] == b && ends[1] == a) {
        m_along.push_back({1.0 - crossed.ratio, {drawn_point(crossed.upper_side), drawn_point(crossed.lower_side)}});
      }
    }
    std::sort(m_along.begin(), m_along.end());
    for (const auto& [ratio, sides] : m_along) m_polygon.insert(m_polygon.end(), sides.begin(), sides.end());
  }
  auto [centre, made] = m_centres.try_emplace(t, -1);
  if (made)
    centre->second =
        add_real_point({triangle[0], triangle[1], triangle[2], -1}, {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.0});
  for (size_t c = 0; c < m_polygon.size(); ++c)
    m_skin.push_back({centre->second, m_polygon[c], m_polygon[(c + 1) % m_polygon.size()]});
  m_replaced.insert(std::lower_bound(m_replaced.begin(), m_replaced.end(), t), t);
}

// Where corner `id` lies on the mesh edge lower-upper, as a ratio from lower: at either end, or on a
// crossing of that edge by one cut; -1 elsewhere.
double CutSurface::ratio_on_edge(const DeformableBody& body, int id, int lower, int upper) const {
  if (id < m_vertex_count) return id == lower ? 0.0 : id == upper ? 1.0 : -1.0;
  const int key = m_point_key[static_cast<size_t>(id - m_vertex_count)];
  if (key < 0) return -1.0;
  const WeldKey& weld = m_keys[static_cast<size_t>(key)];
  if (weld.vertex[1] < 0 && weld.cut_id[0] < 0)
    return weld.vertex[0] == lower ? 0.0 : weld.vertex[0] == upper ? 1.0 : -1.0;
  if (weld.vertex[0] != lower || weld.vertex[1] != upper || weld.vertex[2] >= 0 || weld.cut_id[1] >= 0) return -1.0;
  const Point& point = m_points[static_cast<size_t>(id - m_vertex_count)];
  const auto& vertices = body.cut_tets()[static_cast<size_t>(point.cut_tet)].vertices;
  double at_lower = 0.0, at_upper = 0.0;
  for (size_t j = 0; j < 4; ++j) {
    if (vertices[j] == lower) at_lower = point.weights[j];
    if (vertices[j] == upper) at_upper = point.weights[j];
  }
  return at_upper / (at_lower + at_upper);
}

// A skin piece `made` (of a tet not cut by the front's cut) with an edge along front edges
// m_on_cut_front[begin, end): drawn with both sides' crossings inserted on that edge where they lie
// between its ends, fanned from the corner opposite it (the wedge the crack opens at the surface is a
// middle triangle of the fan).
void CutSurface::split_skin_piece(const DeformableBody& body, const std::array<int, 3>& made, size_t begin,
                                  size_t end) {
  const std::array<int, 3> t = drawn(made);
  if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) return;
  m_polygon.clear();
  int apex = -1;  // the corner opposite the first edge split
  std::array<int, 3> at{};
  for (size_t c = 0; c < 3; ++c) {
    at[c] = static_cast<int>(m_polygon.size());
    m_polygon.push_back(t[c]);
    m_along.clear();
    for (size_t j = begin; j < end; ++j) {
      const CrossedEdge& crossed = m_crossed[static_cast<size_t>(m_on_cut_front[j].second)];
      const auto& ends = body.adjacency().edges[static_cast<size_t>(crossed.edge)];
      const double from = ratio_on_edge(body, made[c], ends[0], ends[1]);
      const double to = ratio_on_edge(body, made[(c + 1) % 3], ends[0], ends[1]);
      if (from < 0.0 || to < 0.0 || (crossed.ratio - from) * (to - crossed.ratio) <= 0.0) continue;
      const std::array<int, 2> sides{drawn_point(crossed.lower_side), drawn_point(crossed.upper_side)};
      m_along.push_back({std::abs(crossed.ratio - from), from < to ? sides : std::array<int, 2>{sides[1], sides[0]}});
    }
    if (m_along.empty()) continue;
    if (apex < 0) apex = static_cast<int>((c + 2) % 3);
    std::sort(m_along.begin(), m_along.end());
    for (const auto& [distance, sides] : m_along) m_polygon.insert(m_polygon.end(), sides.begin(), sides.end());
  }
  if (apex < 0) {
    m_skin.push_back(t);
    return;
  }
  const auto n = m_polygon.size();
  const auto from = static_cast<size_t>(at[static_cast<size_t>(apex)]);
  for (size_t i = 1; i + 1 < n; ++i)
    m_skin.push_back({m_polygon[from], m_polygon[(from + i) % n], m_polygon[(from + i + 1) % n]});
}

}  // namespace tissue
