// CutSurface: the faces a cut opens. Each part (above, below) of each cut tet gets the cut polygon
// through its edge crossings (a triangle for a 1-3 split, two for a 2-2 split), oriented outward
// from that part, with its corners at the part's current positions (they follow the ghosts). The
// corners are numbered after the mesh vertices, so a positions array extended by them serves the
// surface BVH and the surface output alike.
// The skin: a mesh surface triangle of a cut tet spans both parts; drawn with the real vertex
// positions it would stretch across the opening once the parts separate. For the surface output it
// is replaced by its pieces on either side of the cut (the part of the triangle each part owns,
// corners on the crossed edges following that part), in the triangle's own winding.
#pragma once

#include "core/fem/deformable_body.hpp"
#include "core/mesh/topology.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace tissue {

class CutSurface {
 public:
  explicit CutSurface(int vertex_count) : m_vertex_count(vertex_count) {}

  /// Adds the faces of the cut tets [first_cut_tet, body.cut_tets().size()), and the skin pieces of
  /// their triangles in `surface` (the body's mesh surface). Returns how many triangles were added
  /// (they are the last ones of triangles()).
  int add_cut_tets(const DeformableBody& body, int first_cut_tet, const SurfaceMesh& surface);

  /// Resizes `positions_m` to 3 (vertex_count + point_count()) and writes the cut-face corners after
  /// the mesh vertices, whose positions (the first 3 vertex_count entries) the caller has written.
  void update_points(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                     Eigen::VectorXd& positions_m) const;

  [[nodiscard]] int point_count() const { return static_cast<int>(m_points.size()); }
  [[nodiscard]] int cut_tet_count() const { return m_cut_tets; }
  /// Triangles with corner ids >= the mesh's vertex count (id - vertex_count indexes the points).
  [[nodiscard]] const std::vector<std::array<int, 3>>& triangles() const { return m_triangles; }
  /// The pieces that replace the surface triangles of cut tets in the output (not in the BVH: the
  /// contact and the cutter work on the mesh's own triangles). Corner ids as in triangles().
  [[nodiscard]] const std::vector<std::array<int, 3>>& skin_triangles() const { return m_skin; }
  /// Indices into SurfaceMesh::triangles of the triangles the skin pieces replace, ascending.
  [[nodiscard]] const std::vector<int>& replaced_triangles() const { return m_replaced; }

 private:
  struct Point {
    int cut_tet = -1;
    CutPart part = CutPart::above;
    int from = 0;  ///< local vertices of the crossed edge
    int to = 0;
    double ratio = 0.0;  ///< the corner is (1 - ratio) x_from + ratio x_to of the part's positions
  };
  int m_vertex_count = 0;
  int m_cut_tets = 0;
  std::vector<Point> m_points;
  std::vector<std::array<int, 3>> m_triangles;
  std::vector<std::array<int, 3>> m_skin;
  std::vector<int> m_replaced;
};

}  // namespace tissue
