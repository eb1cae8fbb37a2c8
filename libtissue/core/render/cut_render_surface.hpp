// The render surface cut with the tets (issue 22): the embedded render surface (embedded_surface.hpp)
// follows the pieces of the cut tets, is split where the XFEM's cuts separate its vertices, and the
// openings are capped, so that a piece cut free is a closed surface.
// * Each render point rides on a cell: its tet and, in a cut tet, the piece (the tet clipped by the
//   planes that bound the piece, extended beyond the tet for points just outside) that holds it; it
//   is at sum_j w_j X_j over that piece's vertex positions (real or ghost, piece_positions).
// * A render edge is cut when one end lies beyond a plane that bounds the other's piece. It is split
//   once, where it leaves that piece, into two points, one on each side; the triangles around it are
//   split the same way (one cut edge: a crack tip, split through the opposite corner; two: the corner
//   cut off; three: the three corners, where two cuts meet).
// * Caps: the split surface's border runs in loops; each loop is triangulated by ear clipping in its
//   own best-fit plane, wound against the loop, so every edge then has two triangles. Exact for a
//   separated piece cut by one plane; a loop that runs through a crack tip (a partial cut) is capped
//   across the slit too, and a loop over two planes (a corner of an X) in one projection.
#pragma once

#include "core/fem/deformable_body.hpp"
#include "core/render/embedded_surface.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace tissue {

class CutRenderSurface {
 public:
  /// `mesh` must be the body's mesh and outlive this. Throws as embed_surface.
  CutRenderSurface(const TetMesh& mesh, TriangleSurface surface, double max_outside_m,
                   const std::string& source_name = "render surface");

  /// Re-meshes the surface for the body's cuts (from the surface as given: cheap to call after each
  /// batch of cuts).
  void rebuild(const DeformableBody& body);
  /// Positions and normals for the body's state (after rebuild for the body's current cuts).
  void update(const DeformableBody& body, const Eigen::VectorXd& displacement_m);

  /// The render surface's triangles: the surface's, split along the cuts, then cap_triangle_count()
  /// caps.
  [[nodiscard]] const std::vector<std::array<int, 3>>& triangles() const { return m_triangles; }
  [[nodiscard]] int cap_triangle_count() const { return m_cap_triangles; }
  [[nodiscard]] const std::vector<Eigen::Vector3d>& positions_m() const { return m_positions_m; }
  [[nodiscard]] const std::vector<Eigen::Vector3d>& normals() const { return m_normals; }
  /// Rest position of each point (the surface's vertices, then the split points). [m]
  [[nodiscard]] const std::vector<Eigen::Vector3d>& rest_positions_m() const { return m_rest_m; }
  /// Render points: the surface's vertices first, then two per cut edge.
  [[nodiscard]] int point_count() const { return static_cast<int>(m_points.size()); }
  [[nodiscard]] int cut_edge_count() const { return m_cut_edges; }

 private:
  struct Point {
    int tet = -1;
    Eigen::Vector4d weights = Eigen::Vector4d::Zero();
    int cut_tet = -1;  // the body's live cut tet of `tet`, or -1
    int piece = -1;    // its piece holding the point
  };
  [[nodiscard]] Point locate(const DeformableBody& body, int tet, const Eigen::Vector3d& rest_m) const;
  void cap_loops();

  const TetMesh& m_mesh;
  TriangleSurface m_surface;
  std::vector<SurfaceEmbedding> m_embedding;
  std::vector<Point> m_points;
  std::vector<Eigen::Vector3d> m_rest_m;
  std::vector<std::array<int, 3>> m_triangles;
  int m_cap_triangles = 0;
  int m_cut_edges = 0;
  std::vector<Eigen::Vector3d> m_positions_m;
  std::vector<Eigen::Vector3d> m_normals;
  Eigen::VectorXd m_real_positions_m;
};

}  // namespace tissue
