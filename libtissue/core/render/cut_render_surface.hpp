// The render surface cut with the tets (issue 22): the embedded render surface (embedded_surface.hpp)
// follows the pieces of the cut tets, is split where the XFEM's cuts separate its vertices, and the
// openings are capped, so that a piece cut free is a closed surface.
// * Each render point rides on a cell: its tet and, in a cut tet, the piece (the tet clipped by the
//   planes that bound the piece, extended beyond the tet for points just outside) that holds it; it
//   is at sum_j w_j X_j over that piece's vertex positions (real or ghost, piece_positions).
// * A render edge is cut when one end lies beyond a plane that bounds the other's piece. It is split
//   once, where it leaves that piece, into two points, one on each side; the triangles around it are
//   split the same way (one cut edge: a crack tip, split through the opposite corner; two: the corner
//   cut off; three: the three corners, where two cuts meet). Points next to a junction may be split
//   by either cut: runs of fewer than 4 points between two other runs take a neighbour's cut.
// * Caps: the split surface's border runs in loops (in cap order, against the skin). A loop on one
//   cut is the opening of a piece cut free: ear-clipped in its best-fit plane. Otherwise a loop is
//   cut into chains of points split by one cut; a face is made per chain walk on one cut, closed
//   across to the next chain by a straight line of new points: where two cuts meet (a switch
//   between two chains), the junction line to the other switch of the same material part, cut pair
//   and quadrant (the chains' sides of the two cuts), and where a partial cut ends (a crack tip, an
//   uncut surface vertex between two chains of one cut), the crack front to the tip of the same part
//   and cut whose loop turns the other way, nearest first. Where a partial cut meets another only part
//   of the way (a notch: two switches without a partner and a tip between the notched cut's walls),
//   the junction runs into the body to the tip's projection on the other plane and back, the crack
//   front from the tip to there. Each face is ear-clipped, never along an
//   edge the mesh has. The line's points ride on the cell of their nearer end.
// * Material parts: cells joined where they share a copy of a vertex (real or ghost), the simulation's
//   own connectivity.
// * An edge whose ends lie in two material parts that neither end's piece tells apart (it passes over
//   a cut tet between theirs) is split where it crosses a cut plane of the cut tets around its ends.
// * Re-meshing is incremental: only the points on tets whose cut changed (and on their face
//   neighbours) are located and their edges and triangles split again; the other edges keep their
//   split points, the other triangles their pieces; the caps are made again. Where the material parts
//   regroup (a piece came free), the edges whose ends went from one part to two (or back) are split
//   again too. From scratch the first time and when the split points dropped by re-splits exceed a
//   quarter of the surface's vertices.
// * Holes the walk leaves (a switch with no partner): the surface's border loops then; one in one
//   material part that is flat (within 0.1 mm of a plane), or two flat faces either side of a
//   chord (a junction), is what the walk missed, ear-clipped.
// * A closed shell holding a cap and enclosing less than a cube of 0.1 mm (a render point alone on a
//   sliver piece where cuts cross) is not drawn (cut_render_detail::drop_bubbles).
// Limits: the crack front is the straight line between the tips (right for a stroke through the
// full depth), and its points follow one side; where two partial cuts cross, a switch may have no
// partner and no tip to close on (the junction line ends inside the body) and the hole stays open
// unless it is flat or two flat faces.
#pragma once

#include "core/fem/deformable_body.hpp"
#include "core/render/cut_render_detail.hpp"
#include "core/render/embedded_surface.hpp"

#include <Eigen/Core>

#include <array>
#include <map>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace tissue {

class CutRenderSurface {
 public:
  /// `mesh` must be the body's mesh and outlive this. Throws as embed_surface.
  CutRenderSurface(const TetMesh& mesh, TriangleSurface surface, double max_outside_m,
                   const std::string& source_name = "render surface");

  /// Re-meshes the surface for the body's cuts: again only where the cut tets changed since the
  /// last call (from the surface as given the first time).
  void rebuild(const DeformableBody& body);
  /// Positions for the body's state (after rebuild for the body's current cuts); the normals are
  /// found when next read.
  void update(const DeformableBody& body, const Eigen::VectorXd& displacement_m);

  /// The render surface's triangles: the surface's, split along the cuts, then cap_triangle_count()
  /// caps.
  [[nodiscard]] const std::vector<std::array<int, 3>>& triangles() const { return m_triangles; }
  [[nodiscard]] int cap_triangle_count() const { return m_cap_triangles; }
  [[nodiscard]] const std::vector<Eigen::Vector3d>& positions_m() const { return m_positions_m; }
  /// Unit vertex normals of positions_m(), found at the first read after an update (82k triangles:
  /// ~1 ms, which a reader of the embedding and the nodes alone, as the FMU's, does not pay).
  [[nodiscard]] const std::vector<Eigen::Vector3d>& normals() const;
  /// Rest position of each point (the surface's vertices, then the split points). [m]
  [[nodiscard]] const std::vector<Eigen::Vector3d>& rest_positions_m() const { return m_rest_m; }
  /// Render points: the surface's vertices first, then two per cut edge (and, after incremental
  /// re-meshes, split points no triangle uses any more), then the caps' line points.
  [[nodiscard]] int point_count() const { return static_cast<int>(m_points.size()); }
  [[nodiscard]] int cut_edge_count() const { return m_cut_edges; }
  /// Holes the last rebuild left: the finished surface's border loops (faces the chain walk could
  /// not close, neither flat nor two flat faces, or between two material parts).
  [[nodiscard]] int open_loop_count() const { return m_open_loops; }
  /// The points and triangles the surface holds room for (written at construction): a reader that
  /// copies them (an FMU's outputs) reserves as much, so that a cut's first split points grow
  /// neither its arrays nor this surface's inside a step's slot.
  [[nodiscard]] size_t point_room() const { return m_points.capacity(); }
  [[nodiscard]] size_t triangle_room() const { return m_triangles.capacity(); }
  /// Whether the last rebuild started from the surface as given (else it redid only what changed).
  [[nodiscard]] bool rebuilt_from_scratch() const { return m_from_scratch; }

  // The surface as a linear map of a few coarse nodes (for a viewer that maps on its side: the
  // mapping is sent once per rebuild, the nodes every frame). Nodes: the mesh's vertices, then four
  // per piece of a cut tet that holds points (the piece's corners, real or ghost). Point i is at
  // sum_k point_weights()[i](k) * node point_nodes()[i][k].
  [[nodiscard]] int node_count() const { return m_mesh.vertex_count() + 4 * static_cast<int>(m_slots.size()); }
  [[nodiscard]] const std::vector<std::array<int, 4>>& point_nodes() const { return m_point_nodes; }
  [[nodiscard]] Eigen::Vector4d point_weights(int point) const { return m_points[static_cast<size_t>(point)].weights; }
  /// The nodes' positions at the last update(). [m]
  [[nodiscard]] const std::vector<Eigen::Vector3d>& node_positions_m() const { return m_node_positions_m; }
  /// The nodes' positions for the body's state (after rebuild for the body's current cuts). [m]
  void node_positions(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                      std::vector<Eigen::Vector3d>& nodes_m) const;

 private:
  /// Per-point arrays hold room for this fraction (1 / it) more points than the surface has
  /// vertices, written at construction (a first cut then grows none of them).
  static constexpr size_t SPLIT_POINT_ROOM_DIVISOR = 2;
  /// Pieces per cut tet the node slots are laid out for at least: a tet cut once or twice maps only
  /// its own points (a stride too small re-maps every point: 2 ms on the organ's surface).
  static constexpr size_t MIN_SLOT_STRIDE = 4;
  struct Point {
    int tet = -1;
    Eigen::Vector4d weights = Eigen::Vector4d::Zero();
    int cut_tet = -1;  // the body's live cut tet of `tet`, or -1
    int piece = -1;    // its piece holding the point
  };
  [[nodiscard]] Point locate(const DeformableBody& body, int tet, const Eigen::Vector3d& rest_m) const;
  // rebuild's stages: which surface vertices to locate again, and where (cut_render_locate.cpp); the
  // skin split along the cuts (cut_render_split.cpp); the caps (cut_render_caps.cpp).
  /// Marks the surface vertices on tets whose cut changed (or their neighbours) dirty and gives the
  /// others their material parts; whether to re-mesh from scratch (then `dirty` is incomplete).
  [[nodiscard]] bool mark_dirty_points(const DeformableBody& body, std::vector<char>& dirty,
                                       std::vector<int>& part) const;
  void relocate_points(const DeformableBody& body, const std::vector<char>& dirty, std::vector<int>& part);
  void drop_moved_splits(const std::vector<char>& dirty);
  /// Splits the skin into m_next_skin (m_next_skin_first), then swaps it with m_skin.
  void split_skin(const DeformableBody& body, const std::vector<char>& dirty, const std::vector<int>& part);
  const std::array<int, 2>* split_edge(const DeformableBody& body, const std::vector<int>& uncut_part, int u, int v);
  void cap_loops(const DeformableBody& body);
  /// A hole filled by peel_by_cuts: its material part and its triangles in m_triangles.
  struct FilledHole {
    int part = -1;
    size_t first_triangle = 0, end_triangle = 0;
  };
  /// A part whose filled holes leave its volume off its simulated one (times the uncut surface's
  /// ratio to the tets') by more than this, or that keeps an open hole, keeps only those of them that
  /// bound the solid they close as drawn (cut_render_detail::fills_bounding_solids).
  static constexpr double FILLED_PART_VOLUME_TOLERANCE = 0.15;
  /// Drops the triangles of the filled holes that neither rule keeps (cut_render_fill.cpp;
  /// `open_parts`: the parts of the holes left open, -1 for a hole in two). Returns the holes it
  /// opened again (indices into `filled`).
  std::vector<size_t> drop_unsound_fills(const DeformableBody& body, const std::vector<FilledHole>& filled,
                                         const std::vector<int>& open_parts);
  void find_material_parts(const DeformableBody& body);
  /// The nodes of the points (after the points are final): all of them after a re-mesh from scratch,
  /// else those of `dirty_vertices` and from `first_new` on.
  void map_points_to_nodes(size_t first_new, const std::vector<char>& dirty_vertices);
  [[nodiscard]] int copy_of(const DeformableBody& body, int tet, int cut_tet, int piece, size_t j) const;
  /// Where the segment a-b crosses a cut plane of the cut tets at or next to tet_a and tet_b (the
  /// crossing nearest its middle): the fraction along it and the cut id (0.5 and the latest cut of
  /// either tet when no plane lies between them; cut id -1 when neither is cut).
  [[nodiscard]] std::pair<double, int> crossing_near(const DeformableBody& body, int tet_a, int tet_b,
                                                     const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m) const;
  /// The material part of a point's cell (after find_material_parts).
  [[nodiscard]] int part_of(const DeformableBody& body, const Point& point) const;
  /// A point at `rest_m` riding on the cell of point `model`.
  int add_point_like(int model, const Eigen::Vector3d& rest_m);
  /// Points on the straight rest segment between two points (ends excluded).
  std::vector<int> line_points(int from, int to);

  const TetMesh& m_mesh;
  TriangleSurface m_surface;
  std::vector<SurfaceEmbedding> m_embedding;
  std::vector<Point> m_points;
  std::vector<Eigen::Vector3d> m_rest_m;
  std::vector<std::array<int, 3>> m_triangles;
  int m_cap_triangles = 0;
  int m_cut_edges = 0;
  int m_open_loops = 0;
  std::unordered_set<long long> m_surface_edges;  // the surface's own edges (lower vertex << 32 | higher)
  std::vector<int> m_point_cut;
  // What the next rebuild reuses: per tet its cut tet at the last re-mesh, per surface vertex its
  // material part then, each edge's split (its two points, or -1 -1: not split), the skin's pieces
  // per surface triangle (m_skin[m_skin_first[t] .. m_skin_first[t + 1]]), the points before the
  // caps', and the split points dropped since the last re-mesh from scratch.
  std::vector<int> m_tet_cut;
  std::vector<int> m_vertex_part;
  std::unordered_map<long long, std::array<int, 2>> m_splits;
  std::vector<std::array<int, 3>> m_skin;
  std::vector<int> m_skin_first;
  size_t m_part_ids = 0;  // how many part ids m_vertex_part's come from
  // The caps of the last re-mesh's single-cut loops, by loop (its points from the smallest on).
  std::map<std::vector<int>, std::vector<std::array<int, 3>>> m_simple_caps;
  size_t m_split_points = 0;
  std::vector<int> m_vertex_triangles_first, m_vertex_triangles;  // the surface's triangles at each vertex
  int m_orphan_points = 0;
  bool m_from_scratch = true;
  std::vector<int> m_copy_root;  // per copy of a vertex (real, then ghost rows): its material part
  // per point: the cut id of the plane that split it, -1 for others
  std::vector<std::array<int, 2>> m_slots;  // the (cut tet, piece) of each group of four nodes
  std::vector<int> m_slot_of;               // by cut tet * m_slot_stride + piece: its slot, or -1
  size_t m_slot_stride = 0;
  std::vector<std::array<int, 4>> m_point_nodes;
  std::vector<Eigen::Vector3d> m_node_positions_m;
  std::vector<Eigen::Vector3d> m_positions_m;
  mutable std::vector<Eigen::Vector3d> m_normals;  // of m_positions_m once m_normals_current
  mutable bool m_normals_current = false;
  mutable Eigen::VectorXd m_real_positions_m;
  // A re-mesh's working arrays, kept from one to the next and their room written at construction
  // (reserve_resident): per surface vertex whether it is located again and its material part (and,
  // riding on an uncut tet, in uncut_part), the skin being split, and drop_bubbles' arrays.
  std::vector<char> m_dirty;
  std::vector<int> m_part, m_uncut_part;
  std::vector<std::array<int, 3>> m_next_skin;
  std::vector<int> m_next_skin_first;
  cut_render_detail::BubbleScratch m_bubbles;
};

}  // namespace tissue
