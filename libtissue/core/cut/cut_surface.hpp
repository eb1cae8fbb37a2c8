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
#pragma once

#include "core/fem/deformable_body.hpp"
#include "core/mesh/topology.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace tissue {

class CutSurface {
 public:
  explicit CutSurface(int vertex_count) : m_vertex_count(vertex_count) {}

  /// Adds the faces of the cut tets [first_cut_tet, body.cut_tets().size()), and the skin pieces of
  /// their triangles in `surface` (the body's mesh surface), and retires the faces of the cut tets
  /// they replaced. Returns how many triangles were added (they are the last ones of triangles()).
  int add_cut_tets(const DeformableBody& body, int first_cut_tet, const SurfaceMesh& surface);

  /// Resizes `positions_m` to 3 (vertex_count + point_count()) and writes the cut-face corners after
  /// the mesh vertices, whose positions (the first 3 vertex_count entries) the caller has written.
  void update_points(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                     Eigen::VectorXd& positions_m) const;

  [[nodiscard]] int point_count() const { return static_cast<int>(m_points.size()); }
  [[nodiscard]] int cut_tet_count() const { return m_cut_tets; }
  /// Every cut face made, in the BVH's order: corner ids >= the mesh's vertex count (id -
  /// vertex_count indexes the points). The faces of retired cut tets are collapsed to a point.
  [[nodiscard]] const std::vector<std::array<int, 3>>& triangles() const { return m_triangles; }
  /// The cut faces to draw: triangles() without the retired ones.
  [[nodiscard]] const std::vector<std::array<int, 3>>& drawn_triangles() const { return m_drawn; }
  /// The pieces that replace the surface triangles of cut tets in the output (not in the BVH: the
  /// contact and the cutter work on the mesh's own triangles). Corner ids as in triangles().
  [[nodiscard]] const std::vector<std::array<int, 3>>& skin_triangles() const { return m_skin; }
  /// Indices into SurfaceMesh::triangles of the triangles the skin pieces replace, ascending.
  [[nodiscard]] const std::vector<int>& replaced_triangles() const { return m_replaced; }

 private:
  struct Point {
    int cut_tet = -1;
    int piece = 0;
    std::array<double, 4> weights{};  ///< the corner is sum_j weights_j p_j of the piece's vertices
  };
  int add_point(int cut_tet, int piece, const std::array<double, 4>& weights);
  void add_once_cut_faces(const DeformableBody& body, int k, const SurfaceMesh& surface);
  void add_piece_faces(const DeformableBody& body, int k, const SurfaceMesh& surface);
  void replace_surface_triangles(int tet, const SurfaceMesh& surface);
  void retire(const DeformableBody& body, int k);

  int m_vertex_count = 0;
  int m_cut_tets = 0;
  std::vector<Point> m_points;
  std::vector<std::array<int, 3>> m_triangles;
  std::vector<int> m_triangle_cut_tet;  // per triangle, the cut tet it belongs to
  std::vector<std::array<int, 3>> m_drawn;
  std::vector<std::array<int, 3>> m_skin;
  std::vector<int> m_skin_cut_tet;      // per skin triangle, the cut tet it belongs to
  std::vector<std::uint8_t> m_retired;  // per cut tet: its faces retired
  std::vector<int> m_replaced;
};

}  // namespace tissue
