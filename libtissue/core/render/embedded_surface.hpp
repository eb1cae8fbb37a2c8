// A render surface that rides on the tets (issue 22): a finer triangle mesh of the same shape whose
// every vertex is embedded by barycentric coordinates in a tet (the one that contains it, or for a
// vertex just outside the tet mesh, the nearest tet, with coordinates extrapolated), so that it
// follows the simulation mesh: x = sum_i w_i x_i over that tet's vertices. At rest the affine
// combination gives the vertex back to round-off, a rigid motion of the tets moves it rigidly, and a
// smooth deformation reaches it with the linear interpolation error of the tet (at most
// 1/2 h^2 max|D^2 u| for a tet of diameter h). Normals are recomputed at each update.
// (The cut render surface is the next part of issue 22; this part knows nothing of cuts.)
#pragma once

#include "core/mesh/mesh_io.hpp"
#include "core/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace tissue {

/// Where a render vertex rides: a tet and its barycentric weights (sum 1; some negative for a vertex
/// outside the tet).
struct SurfaceEmbedding {
  int tet = -1;
  Eigen::Vector4d weights = Eigen::Vector4d::Zero();
};

/// The barycentric weights of `p` in the mesh tet `x` (affine: they reproduce p exactly, negative
/// outside): collide/geometry's tet_barycentric for a tet the mesh readers let through (never degenerate).
Eigen::Vector4d barycentric_weights(const std::array<Eigen::Vector3d, 4>& x, const Eigen::Vector3d& p);

/// How far outside the tet mesh a render vertex may lie, by default: a quarter of the mesh's mean
/// edge (a smooth surface bulges out of its tets' flat faces by the sagitta, h^2 / (8 R)). [m]
double default_max_outside_m(const TetMesh& mesh);

/// Embeds every vertex of `surface` in `mesh` (rest positions): in the tet that contains it (where
/// several do, on a shared face, the one whose smallest weight is largest), else in the nearest tet.
/// Throws MeshError naming `source_name` and the vertex for a vertex farther than `max_outside_m`
/// from every tet.
std::vector<SurfaceEmbedding> embed_surface(const TetMesh& mesh, const TriangleSurface& surface,
                                            double max_outside_m, const std::string& source_name);

/// Unit vertex normals of `triangles` over `positions_m`: area-weighted means of the triangles around
/// each vertex (zero for a vertex no triangle uses). `normals` is resized to the positions.
void vertex_normals(const std::vector<Eigen::Vector3d>& positions_m, const std::vector<std::array<int, 3>>& triangles,
                    std::vector<Eigen::Vector3d>& normals);

/// A render surface moved by the tets' vertex positions.
class EmbeddedSurface {
 public:
  /// Throws MeshError as embed_surface; std::invalid_argument for max_outside_m < 0 or NaN.
  EmbeddedSurface(const TetMesh& mesh, TriangleSurface surface, double max_outside_m,
                  const std::string& source_name = "render surface");

  /// Positions and normals for the tet mesh's current vertex positions (3 per mesh vertex, at least
  /// the mesh's vertices; more are ignored). No allocation.
  void update(const Eigen::VectorXd& vertex_positions_m);

  [[nodiscard]] const TriangleSurface& surface() const { return m_surface; }
  [[nodiscard]] const std::vector<SurfaceEmbedding>& embedding() const { return m_embedding; }
  [[nodiscard]] const std::vector<Eigen::Vector3d>& positions_m() const { return m_positions_m; }
  /// Unit vertex normals (area-weighted means of the triangles around each vertex).
  [[nodiscard]] const std::vector<Eigen::Vector3d>& normals() const { return m_normals; }

 private:
  const TetMesh& m_mesh;
  TriangleSurface m_surface;
  std::vector<SurfaceEmbedding> m_embedding;
  std::vector<Eigen::Vector3d> m_positions_m;
  std::vector<Eigen::Vector3d> m_normals;
};

}  // namespace tissue
