// CutSurface (see cut_surface.hpp).
#include "core/cut/cut_surface.hpp"

#include "core/fem/piece_outside.hpp"
#include "core/fem/tet_pieces.hpp"
#include "core/mesh/topology.hpp"

#include <Eigen/Geometry>

#include <algorithm>

namespace tissue {

namespace {

// The crossing on the local edge a-b as a ratio from a: edge_ratio is stored along TET_EDGES' order.
double ratio_from(const TetCut& cut, int a, int b) {
  for (int e = 0; e < 6; ++e) {
    const auto& edge = TET_EDGES[static_cast<size_t>(e)];
    if (edge[0] == a && edge[1] == b) return cut.edge_ratio[static_cast<size_t>(e)];
    if (edge[0] == b && edge[1] == a) return 1.0 - cut.edge_ratio[static_cast<size_t>(e)];
  }
  return 0.5;  // unreachable for two distinct local vertices
}

}  // namespace

int CutSurface::add_point(int cut_tet, int piece, const std::array<double, 4>& weights, const WeldKey& key) {
  m_points.push_back(Point{cut_tet, piece, weights});
  m_live_runs_current = false;
  m_point_owner.push_back(cut_tet);
  const int id = m_vertex_count + static_cast<int>(m_points.size()) - 1;
  m_point_key.push_back(weld_key_id(key, id));
  return id;
}

int CutSurface::add_cut_tets(const DeformableBody& body, int first_cut_tet, const SurfaceMesh& surface) {
  const int cut_tets = static_cast<int>(body.cut_tets().size());
  const int triangles_before = static_cast<int>(m_triangles.size());
  m_retired.resize(static_cast<size_t>(cut_tets), 0);
  for (int k = first_cut_tet; k < cut_tets; ++k) {
    if (body.cut_geometry(k).cuts.size() == 1) {
      add_once_cut_faces(body, k, surface);
    } else {
      add_piece_faces(body, k, surface);
    }
  }
  std::vector<std::uint8_t> retiring(static_cast<size_t>(cut_tets), 0);
  bool retired_any = false;
  for (int k = 0; k < cut_tets; ++k) {
    if (body.retired(k) && m_retired[static_cast<size_t>(k)] == 0) {
      retiring[static_cast<size_t>(k)] = 1;
      retired_any = true;
    }
  }
  if (retired_any) {
    retire(body, retiring);
    fix_retired_representatives();
  }
  update_fronts(body);
  m_drawn_stale = true;
  m_cut_tets = cut_tets;
  return static_cast<int>(m_triangles.size()) - triangles_before;
}

void CutSurface::retire(const DeformableBody& body, const std::vector<std::uint8_t>& retiring) {
  const auto is_retiring = [&](int k) { return k >= 0 && retiring[static_cast<size_t>(k)] != 0; };
  for (size_t k = 0; k < retiring.size(); ++k) {
    if (retiring[k] != 0) m_retired[k] = 1;
  }
  // Their corners all follow vertex 0 of the first piece of the tet's current cut tet (zero area),
  // and are no longer updated (nothing draws them: the weld's keys turn to live corners).
  for (size_t p = 0; p < m_points.size(); ++p) {
    const int k = m_point_owner[p];
    if (!is_retiring(k)) continue;
    const int current = body.cut_tet_index(body.cut_tets()[static_cast<size_t>(k)].cut.tet);
    m_points[p] = Point{current, 0, {1.0, 0.0, 0.0, 0.0}};
    m_points[p].retired = Point::Retired::to_place;
    m_live_runs_current = false;
  }
  for (size_t t = 0; t < m_triangles.size(); ++t) {
    if (is_retiring(m_triangle_cut_tet[t])) m_retired_faces.push_back(static_cast<int>(t));
  }
}

void CutSurface::parked_faces(const DeformableBody& body, std::vector<int>& faces) const {
  for (size_t t = 0; t < m_triangles.size(); ++t) {
    const int owner = m_triangle_cut_tet[t];
    if (owner < 0 || m_retired[static_cast<size_t>(owner)] != 0) continue;
    // A face's corners follow one piece: the first corner that is a cut-face point says which.
    for (const int id : m_triangles[t]) {
      if (id < m_vertex_count) continue;
      const Point& point = m_points[static_cast<size_t>(id - m_vertex_count)];
      if (point.cut_tet < 0) continue;
      if (body.xfem().parked(point.cut_tet, point.piece)) faces.push_back(static_cast<int>(t));
      break;
    }
  }
}

std::vector<int> CutSurface::take_retired_faces() {
  std::vector<int> faces;
  faces.swap(m_retired_faces);
  return faces;
}

void CutSurface::replace_surface_triangles(int tet, const SurfaceMesh& surface) {
  const auto [first, last] = std::equal_range(surface.triangle_tet.begin(), surface.triangle_tet.end(), tet);
  for (auto it = first; it != last; ++it) {
    const int triangle_index = static_cast<int>(it - surface.triangle_tet.begin());
    const auto at = std::lower_bound(m_cut_replaced.begin(), m_cut_replaced.end(), triangle_index);
    if (at == m_cut_replaced.end() || *at != triangle_index) m_cut_replaced.insert(at, triangle_index);
  }
}

void CutSurface::add_piece_faces(const DeformableBody& body, int k, const SurfaceMesh& surface) {
  const CutTetGeometry& geometry = body.cut_geometry(k);
  const TetMesh& mesh = body.mesh();
  const int tet_index = body.cut_tets()[static_cast<size_t>(k)].cut.tet;
  const std::array<Eigen::Vector3d, 4> rest = mesh.rest_corners(tet_index);
  // Which local faces of the tet are on the mesh's surface.
  std::array<bool, 4> on_surface{};
  std::array<int, 4> surface_triangle{-1, -1, -1, -1};
  const auto [first, last] = std::equal_range(surface.triangle_tet.begin(), surface.triangle_tet.end(), tet_index);
  for (auto it = first; it != last; ++it) {
    const auto t = static_cast<size_t>(it - surface.triangle_tet.begin());
    on_surface[static_cast<size_t>(surface.triangle_local_face[t])] = true;
    surface_triangle[static_cast<size_t>(surface.triangle_local_face[t])] = static_cast<int>(t);
  }
  replace_surface_triangles(tet_index, surface);
  for (int p = 0; p < static_cast<int>(geometry.pieces.size()); ++p) {
    const ConvexPiece piece = piece_geometry(rest, geometry.cuts, geometry.pieces[static_cast<size_t>(p)].sides);
    for (int f = 0; f < piece.face_count(); ++f) {
      const int tag = piece.face_tag(f);
      const bool cap = tag >= 4;
      if (!cap && !on_surface[static_cast<size_t>(tag)]) continue;  // inside the mesh
      const int first_corner = add_corner_point(body, k, p, piece.corner(f, 0));
      int previous = add_corner_point(body, k, p, piece.corner(f, 1));
      for (int c = 2; c < piece.corner_count(f); ++c) {
        const int next = add_corner_point(body, k, p, piece.corner(f, c));
        if (cap) {
          m_triangles.push_back({first_corner, previous, next});
          m_triangle_cut_tet.push_back(k);
        } else {
          m_skin_made.push_back({first_corner, previous, next});
          m_skin_cut_tet.push_back(k);
          m_skin_surface.push_back(surface_triangle[static_cast<size_t>(tag)]);
        }
        previous = next;
      }
      if (cap) note_cap_edges(geometry.cuts[static_cast<size_t>(tag - 4)].cut_id, first_corner, piece.corner_count(f));
    }
  }
  match_cap_edges(k);
}

void CutSurface::add_once_cut_faces(const DeformableBody& body, int k, const SurfaceMesh& surface) {
  const auto& cut_tets = body.cut_tets();
  const TetMesh& mesh = body.mesh();
  {
    const TetCut& cut = cut_tets[static_cast<size_t>(k)].cut;
    const Tet& tet = mesh.tets[static_cast<size_t>(cut.tet)];
    // The crossed edges between the two groups, ordered around the polygon: walk from edge to edge
    // through shared triangles (for a 2-2 split {a,b}|{c,d}: ac, ad, bd, bc).
    std::vector<int> crossed;
    for (int e = 0; e < 6; ++e) {
      const auto& edge = TET_EDGES[static_cast<size_t>(e)];
      if (cut.side[static_cast<size_t>(edge[0])] != cut.side[static_cast<size_t>(edge[1])]) crossed.push_back(e);
    }
    if (crossed.size() == 4) {
      // Two crossed edges are consecutive when they share a vertex; reorder into a cycle.
      const auto shares = [](int e, int f) {
        const auto& a = TET_EDGES[static_cast<size_t>(e)];
        const auto& b = TET_EDGES[static_cast<size_t>(f)];
        return a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
      };
      if (!shares(crossed[0], crossed[1])) std::swap(crossed[1], crossed[2]);
      if (!shares(crossed[1], crossed[2])) std::swap(crossed[2], crossed[3]);
    }
    // Rest-state corners and the outward normal of part "above" (toward the below vertices).
    std::vector<Eigen::Vector3d> rest;
    Eigen::Vector3d above_centre = Eigen::Vector3d::Zero();
    Eigen::Vector3d below_centre = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d& x = mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(i)])];
      (cut.side[static_cast<size_t>(i)] > 0 ? above_centre : below_centre) += x;
    }
    for (int e : crossed) {
      const auto& edge = TET_EDGES[static_cast<size_t>(e)];
      const double r = cut.edge_ratio[static_cast<size_t>(e)];
      rest.push_back((1.0 - r) * mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(edge[0])])] +
                     r * mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(edge[1])])]);
    }
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // of the polygon in the order of `crossed`
    for (size_t p = 0; p < rest.size(); ++p) normal += rest[p].cross(rest[(p + 1) % rest.size()]);
    int above_count = 0;
    for (auto s : cut.side) above_count += s > 0 ? 1 : 0;
    const Eigen::Vector3d above_to_below = below_centre / (4 - above_count) - above_centre / above_count;
    const bool polygon_faces_below = normal.dot(above_to_below) >= 0.0;

    const int first_above = m_vertex_count + static_cast<int>(m_points.size());
    for (CutPart part : {CutPart::above, CutPart::below}) {
      const int piece = part == CutPart::above ? 0 : 1;
      const int first_point = m_vertex_count + static_cast<int>(m_points.size());
      for (int e : crossed) {
        const auto& edge = TET_EDGES[static_cast<size_t>(e)];
        add_edge_point(body, k, piece, edge[0], edge[1], cut.edge_ratio[static_cast<size_t>(e)]);
      }
      // Outward from the part: toward below for part above, toward above for part below.
      const bool keep_order = (part == CutPart::above) == polygon_faces_below;
      const int n = static_cast<int>(crossed.size());
      for (int t = 1; t + 1 < n; ++t) {
        std::array<int, 3> triangle{first_point, first_point + t, first_point + t + 1};
        if (!keep_order) std::swap(triangle[1], triangle[2]);
        m_triangles.push_back(triangle);
        m_triangle_cut_tet.push_back(k);
      }
    }
    note_crack_edges(k, cut.cut_id, crossed, first_above, polygon_faces_below);

    // The skin: the tet's surface triangles (triangle_tet is in tet order), split along the cut.
    replace_surface_triangles(cut.tet, surface);
    const auto [first, last] = std::equal_range(surface.triangle_tet.begin(), surface.triangle_tet.end(), cut.tet);
    for (auto it = first; it != last; ++it) {
      const int triangle_index = static_cast<int>(it - surface.triangle_tet.begin());
      const std::array<int, 3>& triangle = surface.triangles[static_cast<size_t>(triangle_index)];
      std::array<int, 3> local{};
      for (int c = 0; c < 3; ++c) {
        for (int i = 0; i < 4; ++i) {
          if (tet[static_cast<size_t>(i)] == triangle[static_cast<size_t>(c)]) local[static_cast<size_t>(c)] = i;
        }
      }
      for (CutPart part : {CutPart::above, CutPart::below}) {
        const int side = part == CutPart::above ? 1 : -1;
        std::vector<int> polygon;  // walked in the triangle's order, so the winding stays outward
        for (int c = 0; c < 3; ++c) {
          const int a = local[static_cast<size_t>(c)];
          const int b = local[static_cast<size_t>((c + 1) % 3)];
          if (cut.side[static_cast<size_t>(a)] == side) polygon.push_back(triangle[static_cast<size_t>(c)]);
          if (cut.side[static_cast<size_t>(a)] != cut.side[static_cast<size_t>(b)]) {
            polygon.push_back(add_edge_point(body, k, part == CutPart::above ? 0 : 1, a, b, ratio_from(cut, a, b)));
          }
        }
        for (size_t t = 1; t + 1 < polygon.size(); ++t) {
          m_skin_made.push_back({polygon[0], polygon[t], polygon[t + 1]});
          m_skin_cut_tet.push_back(k);
          m_skin_surface.push_back(triangle_index);
        }
      }
    }
  }
}

void CutSurface::update_points(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                               Eigen::VectorXd& positions_m) const {
  positions_m.conservativeResize(3 * (m_vertex_count + point_count()));
  int last_cut_tet = -1;
  int last_piece = -1;
  TetPositions piece_positions{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                               Eigen::Vector3d::Zero()};
  const auto update_live = [&](size_t p) {
    const Point& point = m_points[p];
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    if (point.cut_tet < 0) {  // of real vertices, whose positions the caller wrote
      for (size_t j = 0; j < 4; ++j) {
        if (point.vertices[j] >= 0) x += point.weights[j] * positions_m.segment<3>(3 * point.vertices[j]);
      }
    } else {
      if (point.cut_tet != last_cut_tet || point.piece != last_piece) {
        piece_positions = body.piece_positions(displacement_m, point.cut_tet, point.piece);
        last_cut_tet = point.cut_tet;
        last_piece = point.piece;
      }
      for (size_t j = 0; j < 4; ++j) {
        if (point.weights[j] != 0.0) x += point.weights[j] * piece_positions[j];
      }
    }
    positions_m.segment<3>(3 * (m_vertex_count + static_cast<Eigen::Index>(p))) = x;
  };
  if (m_live_runs_current) {  // the points retired since the runs were found are placed already
    for (const auto& [begin, end] : m_live_runs) {
      for (auto p = static_cast<size_t>(begin); p < static_cast<size_t>(end); ++p) update_live(p);
    }
    return;
  }
  // Every point, and the runs of live ones for the next calls: a diced body's retired corners (a
  // third of them after 30 + 30 strokes) are then not read again.
  m_live_runs.clear();
  for (size_t p = 0; p < m_points.size(); ++p) {
    const Point& point = m_points[p];
    if (point.retired != Point::Retired::no) {
      // A retired face's corner: nothing reads it. Placed once, where its collapse point (vertex 0
      // of its tet) is at rest, so that a state replayed into a fresh instance has the same positions.
      if (point.retired == Point::Retired::to_place) {
        const int vertex = body.cut_tets()[static_cast<size_t>(point.cut_tet)].vertices[0];
        positions_m.segment<3>(3 * (m_vertex_count + static_cast<Eigen::Index>(p))) =
            body.mesh().rest_positions_m[static_cast<size_t>(vertex)];
        point.retired = Point::Retired::placed;
      }
      continue;
    }
    update_live(p);
    const int id = static_cast<int>(p);
    if (m_live_runs.empty() || m_live_runs.back()[1] != id)
      m_live_runs.push_back({id, id + 1});
    else
      ++m_live_runs.back()[1];
  }
  m_live_runs_current = true;
}

bool cut_by(const DeformableBody& body, int tet, int cut_id) {
  const int k = body.cut_tet_index(tet);
  if (k < 0) return false;
  const auto& cuts = body.cut_geometry(k).cuts;
  return std::any_of(cuts.begin(), cuts.end(), [cut_id](const TetCut& cut) { return cut.cut_id == cut_id; });
}

namespace {

// Where the material of cut tet `k` is now at the point `ratio` along its edge `ends`: in the piece
// that holds the point at rest (within the planes that bound it). False when none does.
bool material_at(const DeformableBody& body, const Eigen::VectorXd& displacement_m, int k, std::array<int, 2> ends,
                 double ratio, Eigen::Vector3d& at) {
  const auto& rest = body.mesh().rest_positions_m;
  const Eigen::Vector3d point =
      (1.0 - ratio) * rest[static_cast<size_t>(ends[0])] + ratio * rest[static_cast<size_t>(ends[1])];
  const CutTetGeometry& geometry = body.cut_geometry(k);
  const Tet& vertices = body.cut_tets()[static_cast<size_t>(k)].vertices;
  const auto local = [&](int v) {
    return static_cast<size_t>(std::find(vertices.begin(), vertices.end(), v) - vertices.begin());
  };
  for (size_t q = 0; q < geometry.pieces.size(); ++q) {
    if (outside_piece_m(geometry, q, point) > 0.0) continue;
    const TetPositions x = body.piece_positions(displacement_m, k, static_cast<int>(q));
    at = (1.0 - ratio) * x[local(ends[0])] + ratio * x[local(ends[1])];
    return true;
  }
  return false;
}

}  // namespace

void CutSurface::update_drawn(const DeformableBody& body, const SurfaceMesh& surface,
                              const Eigen::VectorXd& displacement_m, const Eigen::VectorXd& positions_m) {
  if (m_drawn_stale) {
    rebuild_drawn(body, surface);
    m_drawn_stale = false;
  }
  // Whether point b is farther from position `at` than the fraction of the largest rest edge of the
  // cut tet that made point a (or, for a point of real vertices, b; two such points: never).
  const auto far = [&](const Eigen::Vector3d& at, int a, int b) {
    int owner = a >= m_vertex_count ? m_point_owner[static_cast<size_t>(a - m_vertex_count)] : -1;
    if (owner < 0 && b >= m_vertex_count) owner = m_point_owner[static_cast<size_t>(b - m_vertex_count)];
    if (owner < 0) return false;
    const double largest_m = largest_edge_m(body.cut_tets()[static_cast<size_t>(owner)].rest_m);
    return (positions_m.segment<3>(3 * b) - at).norm() > WELD_APART_FRACTION * largest_m;
  };
  const auto apart = [&](int a, int b) {
    return a >= 0 && b >= 0 && a != b && far(positions_m.segment<3>(3 * a), a, b);
  };
  bool changed = false;
  const auto set = [&changed](std::vector<std::uint8_t>& flags, size_t i, bool value) {
    if (flags.size() <= i) flags.resize(i + 1, 0);
    if ((flags[i] != 0) == value) return;
    flags[i] = value ? 1 : 0;
    changed = true;
  };
  for (const int key : m_joined_keys) {
    set(m_key_apart, static_cast<size_t>(key),
        apart(m_key_drawn[static_cast<size_t>(key)], m_root_drawn[static_cast<size_t>(key_root(key))]));
  }
  for (size_t i = 0; i < m_crack_edges.size(); ++i) {
    const CrackEdge& edge = m_crack_edges[i];
    set(m_strip_apart, i,
        apart(drawn_point(edge.above[0]), drawn_point(edge.below[0])) ||
            apart(drawn_point(edge.above[1]), drawn_point(edge.below[1])));
  }
  // A front joins its sides through a tet around the edge the cut left whole: both lie at the
  // edge's point between its real vertices and at the material's point in such a tet (one cut by
  // other cuts: its piece's). Either alone let a split stretch: after 30 + 30 strokes the first, after
  // 20 + 20 the second.
  const TetAdjacency& adjacency = body.adjacency();
  for (const int e : m_front_edges) {
    const CrossedEdge& crossed = m_crossed[static_cast<size_t>(e)];
    if (crossed.lower_side < 0 || crossed.upper_side < 0) continue;
    const auto edge = static_cast<size_t>(crossed.edge);
    const auto& ends = adjacency.edges[edge];
    const Eigen::Vector3d on_edge = (1.0 - crossed.ratio) * positions_m.segment<3>(3 * ends[0]) +
                                    crossed.ratio * positions_m.segment<3>(3 * ends[1]);
    const int lower = drawn_point(crossed.lower_side), upper = drawn_point(crossed.upper_side);  // as drawn
    bool held = false;
    if (far(on_edge, lower, lower) || far(on_edge, upper, upper)) {
      set(m_front_apart, static_cast<size_t>(e), true);
      continue;
    }
    for (int i = adjacency.edge_tets_begin[edge]; i < adjacency.edge_tets_begin[edge + 1] && !held; ++i) {
      const int tet = adjacency.edge_tets[static_cast<size_t>(i)];
      if (cut_by(body, tet, crossed.cut_id)) continue;
      const int k = body.cut_tet_index(tet);  // an uncut tet's material is at on_edge: held
      Eigen::Vector3d at;
      held = k < 0 || (material_at(body, displacement_m, k, ends, crossed.ratio, at) && !far(at, lower, lower) &&
                       !far(at, upper, upper));
    }
    set(m_front_apart, static_cast<size_t>(e), !held);
  }
  if (changed) rebuild_drawn(body, surface);
}

}  // namespace tissue
