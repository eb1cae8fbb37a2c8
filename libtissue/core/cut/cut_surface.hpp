// CutSurface: the faces a cut opens. Each part (above, below) of each tet cut once gets the cut polygon
// through its edge crossings (a triangle for a 1-3 split, two for a 2-2 split), oriented outward
// from that part, with its corners at the part's current positions (they follow the ghosts). The
// corners are numbered after the mesh vertices, so a positions array extended by them serves the
// surface BVH and the surface output alike.
// The skin: a mesh surface triangle of a cut tet spans both parts; drawn with the real vertex
// positions it would stretch across the opening once the parts separate. For the surface output it
// is replaced by its pieces on either side of the cut (the part of the triangle each part owns,
// corners on the crossed edges following that part), in the triangle's own winding.
// A tet cut again (issue 21) gets the faces of its pieces' convex cells instead: each piece's caps on
// the cut planes, and its share of the tet's surface triangles, fanned from the first corner (outward,
// ConvexPiece's order), each corner following its piece by its barycentric weights. The faces of the
// cut tet it replaced (retired) collapse to a point: they stay in the BVH (ids never change) with
// zero area, and are no longer drawn.
// The drawn surface is welded (issue 43): the faces above keep corners of their own (the BVH's
// triangles), but the triangles to draw name one point per corner of the material. Two corners are
// one when they have the same weld key: the mesh vertices that carry them, the copy of each (real or
// which ghost row) and the cuts they lie on; a corner that is a real mesh vertex is that vertex.
// Where the blade stopped inside (the crack's front: a cut face's edge on a tet face whose other tet
// the cut did not cut), the two sides' cut faces are joined by a strip of two triangles (zero area
// at rest, the crack tip's wedge as the sides open), and the uncut surface triangles on an edge at
// the front are drawn split at both sides' crossings; so are the skin pieces of a tet cut by other
// cuts along such an edge. Keys are hashed when the faces are made
// (add_cut_tets), never per frame; sides that separated have different ghost rows, so their corners
// stay apart.
#pragma once

#include "core/fem/deformable_body.hpp"
#include "core/mesh/topology.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace tissue {

/// Whether session `cut_id` cut tet `tet` (its current cut, DeformableBody::cut_tet_index).
[[nodiscard]] bool cut_by(const DeformableBody& body, int tet, int cut_id);

class CutSurface {
 public:
  explicit CutSurface(int vertex_count) : m_vertex_count(vertex_count) {}

  /// Adds the faces of the cut tets [first_cut_tet, body.cut_tets().size()), and the skin pieces of
  /// their triangles in `surface` (the body's mesh surface), and retires the faces of the cut tets
  /// they replaced. Returns how many triangles were added (they are the last ones of triangles()).
  /// The drawn lists are made again at the next update_drawn(), not here.
  int add_cut_tets(const DeformableBody& body, int first_cut_tet, const SurfaceMesh& surface);

  /// The faces (indices into triangles(), retired ones left out) of pieces that are parked
  /// (XfemElasticity::parked: their part left the operating field), appended to `faces`.
  void parked_faces(const DeformableBody& body, std::vector<int>& faces) const;
  /// The faces retired since the last call (indices into triangles(): the faces of the cut tets a
  /// later cut replaced, collapsed to a point), for the BVH to take out; then forgets them.
  [[nodiscard]] std::vector<int> take_retired_faces();

  /// Resizes `positions_m` to 3 (vertex_count + point_count()) and writes the cut-face corners after
  /// the mesh vertices, whose positions (the first 3 vertex_count entries) the caller has written.
  /// The corners of retired faces (nothing reads them) are placed once, at their collapse point's
  /// rest position, and not read again: `positions_m` is the same vector at every call.
  void update_points(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                     Eigen::VectorXd& positions_m) const;

  [[nodiscard]] int point_count() const { return static_cast<int>(m_points.size()); }
  [[nodiscard]] int cut_tet_count() const { return m_cut_tets; }
  /// Every cut face made, in the BVH's order: corner ids >= the mesh's vertex count (id -
  /// vertex_count indexes the points). The faces of retired cut tets are collapsed to a point.
  [[nodiscard]] const std::vector<std::array<int, 3>>& triangles() const { return m_triangles; }
  // The drawn lists below are those of the last update_drawn().
  /// The cut faces to draw: triangles() without the retired ones, corners welded (drawn_point).
  [[nodiscard]] const std::vector<std::array<int, 3>>& drawn_triangles() const { return m_drawn; }
  /// The pieces that replace the surface triangles of cut tets in the output (not in the BVH: the
  /// contact and the cutter work on the mesh's own triangles), corners welded; then the uncut surface
  /// triangles split at the crack's front.
  [[nodiscard]] const std::vector<std::array<int, 3>>& skin_triangles() const { return m_skin; }
  /// Indices into SurfaceMesh::triangles of the triangles the skin pieces replace, ascending.
  [[nodiscard]] const std::vector<int>& replaced_triangles() const { return m_replaced; }
  /// How many times the drawn lists were made (a reader that never draws the tet skin pays none).
  [[nodiscard]] long drawn_rebuilds() const { return m_drawn_rebuilds; }
  /// The point drawn for corner id `id` (a mesh vertex, or a cut-face corner as triangles() names it):
  /// the vertex itself, or the first live corner made with the same weld key or one joined to it.
  [[nodiscard]] int drawn_point(int id) const;

  /// Points the weld draws as one that come from different pieces (keys joined across cut sets,
  /// the two sides at a crack front: their rows differ) are one while the material holds them
  /// together; where a join or a front was wrong (near crossing strokes, a piece the later stroke
  /// would have cut to a sliver) they part as the pieces move apart and drew sheets metres long
  /// (15 + 15 hatched strokes on the frog). So each such join holds only while its points are within
  /// WELD_APART_FRACTION of their tet's largest rest edge (a front's sides: of the material at the
  /// crossing in a tet around the edge that the cut left whole); apart, they are drawn apart (the
  /// surface shows the gap).
  /// Brings the drawn lists to the body's cuts (made again after add_cut_tets) and to `positions_m`
  /// (update_points() of `displacement_m`: where a join held or let go). Making them may add points
  /// (the centres of surface triangles split at a front): then call update_points() again. Only a
  /// reader of the drawn surface needs it, when it reads.
  void update_drawn(const DeformableBody& body, const SurfaceMesh& surface, const Eigen::VectorXd& displacement_m,
                    const Eigen::VectorXd& positions_m);
  static constexpr double WELD_APART_FRACTION = 0.5;

 private:
  struct Point {
    int cut_tet = -1;  ///< -1: a point of real mesh vertices, sum_j weights_j x(vertices_j)
    int piece = 0;
    std::array<double, 4> weights{};  ///< the corner is sum_j weights_j p_j of the piece's vertices
    std::array<int, 4> vertices{-1, -1, -1, -1};
    /// A corner of a retired face: update_points() places it once (at its collapse point's rest
    /// position), then leaves it there.
    enum class Retired : std::uint8_t { no, to_place, placed };
    mutable Retired retired = Retired::no;
  };
  /// What a corner is in the material (cut_surface_weld.cpp): its mesh vertices (ascending, -1
  /// after), the ghost row each is seen through (-1: the real vertex), the cut ids it lies on.
  struct WeldKey {
    std::array<int, 4> vertex{-1, -1, -1, -1};
    std::array<int, 4> ghost_row{-1, -1, -1, -1};
    std::array<int, 3> cut_id{-1, -1, -1};
    bool operator==(const WeldKey&) const = default;
  };
  struct WeldKeyHash {
    std::size_t operator()(const WeldKey& key) const;
  };
  /// A mesh edge crossed by a cut; at the crack's front (a tet around it not cut by the cut) the
  /// uncut surface triangles on it are drawn split at its corners on either side.
  struct CrossedEdge {
    int cut_id = -1;
    int edge = -1;       ///< TetAdjacency edge id
    double ratio = 0.5;  ///< the crossing from the edge's lower vertex
    bool front = false;
    int lower_side = -1;  ///< a corner of the side holding the edge's lower vertex (its id)
    int upper_side = -1;  ///< and of the side holding its upper vertex
  };
  /// An edge of a cut tet's cut face on the tet's local face `face` (cut `cut_id`): `above` as one
  /// side's cut face runs along it, `below` the other side's corners at the same places. At the
  /// crack's front the strip between them is drawn (add_front_strips).
  struct CrackEdge {
    int cut_tet = -1;
    int cut_id = -1;
    int face = -1;
    std::array<int, 2> above{};
    std::array<int, 2> below{};
  };
  int add_point(int cut_tet, int piece, const std::array<double, 4>& weights, const WeldKey& key);
  int add_edge_point(const DeformableBody& body, int k, int piece, int a, int b, double ratio_from_a);
  int add_corner_point(const DeformableBody& body, int k, int piece, const Eigen::Vector3d& corner_m);
  int add_real_point(const std::array<int, 4>& vertices, const std::array<double, 4>& weights);
  int weld_key_id(const WeldKey& key, int point);
  void note_crossed_edge(const WeldKey& key, int edge, double ratio_from_lower, bool lower_side, int point);
  void note_crack_edges(int k, int cut_id, const std::vector<int>& crossed, int first_above, bool above_forward);
  void note_cap_edges(int cut_id, int first_corner, int count);
  void match_cap_edges(int k);
  void add_front_strips(const DeformableBody& body);
  void update_fronts(const DeformableBody& body);
  void fix_retired_representatives();
  void join_compatible_keys(const DeformableBody& body);
  [[nodiscard]] int key_root(int key) const;
  [[nodiscard]] WeldKey key_place(int key) const;
  void rebuild_drawn(const DeformableBody& body, const SurfaceMesh& surface);
  void collect_front_triangles(const DeformableBody& body, const SurfaceMesh& surface);
  void split_front_triangles(const DeformableBody& body, const SurfaceMesh& surface);
  void split_skin_piece(const DeformableBody& body, const std::array<int, 3>& made, std::size_t begin, std::size_t end);
  [[nodiscard]] double ratio_on_edge(const DeformableBody& body, int id, int lower, int upper) const;
  void split_front_triangle(const DeformableBody& body, const SurfaceMesh& surface, int t, std::size_t begin,
                            std::size_t end);
  [[nodiscard]] std::array<int, 3> drawn(const std::array<int, 3>& triangle) const;
  void add_once_cut_faces(const DeformableBody& body, int k, const SurfaceMesh& surface);
  void add_piece_faces(const DeformableBody& body, int k, const SurfaceMesh& surface);
  void replace_surface_triangles(int tet, const SurfaceMesh& surface);
  void retire(const DeformableBody& body, const std::vector<std::uint8_t>& retiring);

  int m_vertex_count = 0;
  int m_cut_tets = 0;
  std::vector<Point> m_points;
  // update_points()' runs [begin, end) of points not retired, current until a point is added or retired.
  mutable std::vector<std::array<int, 2>> m_live_runs;
  mutable bool m_live_runs_current = false;
  std::vector<std::array<int, 3>> m_triangles;
  std::vector<int> m_triangle_cut_tet;  // per triangle, the cut tet it belongs to
  std::vector<std::array<int, 3>> m_drawn;
  bool m_drawn_stale = false;  // cut tets added since the drawn lists were made
  long m_drawn_rebuilds = 0;
  std::vector<std::array<int, 3>> m_skin_made;  // the skin pieces as made (own corners)
  std::vector<int> m_skin_cut_tet;              // per made skin triangle, the cut tet it belongs to
  std::vector<int> m_skin_surface;              // and the surface triangle it is a piece of
  std::vector<std::array<int, 3>> m_skin;       // drawn: welded, live, then the front splits
  std::vector<std::uint8_t> m_retired;          // per cut tet: its faces retired
  std::vector<int> m_retired_faces;             // faces retired since take_retired_faces()
  std::vector<int> m_cut_replaced;              // surface triangles of cut tets, ascending
  std::vector<int> m_replaced;                  // those and the uncut ones split at a front, ascending
  // The weld (cut_surface_weld.cpp): per point its key and maker (-1: a point of real vertices);
  // per key the key and the point drawn for it.
  std::unordered_map<WeldKey, int, WeldKeyHash> m_key_ids;
  std::vector<int> m_point_key;
  std::vector<int> m_point_owner;
  std::vector<WeldKey> m_keys;
  std::vector<int> m_key_drawn;
  std::vector<int> m_key_parent;  // per key: the key it is joined to (join_compatible_keys), itself at a root
  std::vector<int> m_root_drawn;  // per root key: the point drawn for its keys
  // update_drawn(): per key, its point apart from its root's (drawn alone); per crack edge, its two
  // sides apart (no strip); per crossed edge, a side away from the edge's point (not drawn split).
  std::vector<std::uint8_t> m_key_apart, m_strip_apart, m_front_apart;
  std::vector<int> m_joined_keys;  // the keys drawn at another key's point (join_compatible_keys)
  std::unordered_map<std::int64_t, int> m_crossed_ids;  // (cut id, edge) -> index into m_crossed
  std::vector<CrossedEdge> m_crossed;
  std::vector<int> m_touched_edges;  // crossed edges given corners since the last update_fronts
  std::vector<int> m_front_edges;    // crossed edges at the front, in the order they got there
  std::vector<CrackEdge> m_crack_edges;
  /// A cap edge of a piece of a tet cut several times, on the tet's local face `face`, as the cap
  /// runs along it (from, to: corner ids); paired with the other side's in match_cap_edges.
  struct CapEdge {
    int face = -1;
    int cut_id = -1;
    int from = -1;
    int to = -1;
  };
  std::vector<CapEdge> m_cap_edges;                 // of the cut tet being made
  std::unordered_map<int, int> m_centres;           // surface triangle split at a front -> its centre point
  std::vector<std::pair<int, int>> m_on_front;      // (uncut surface triangle, front edge) to split
  std::vector<std::pair<int, int>> m_on_cut_front;  // (surface triangle of a cut tet, front edge)
  std::vector<std::pair<double, std::array<int, 2>>> m_along;
  std::vector<int> m_polygon;
};

}  // namespace tissue
