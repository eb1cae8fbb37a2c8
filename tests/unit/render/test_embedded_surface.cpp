// The render surface rides on the tets (issue 22, first part): read and checked (OBJ), embedded by
// barycentric coordinates, and moved with the tets.
// * At rest it is reproduced to round-off (< 1e-12 m), on the frog's >= 20k-triangle surface made by
//   meshes/make_frog.py, and under a rigid motion it moves rigidly.
// * Under a cantilever's bending (Euler-Bernoulli field given at the tets' vertices) a render vertex
//   lies within the linear interpolation error of its tet: |I u - u| <= 1/2 h^2 max ||D^2 u||, h the
//   tet's longest edge (for weights >= 0: e(p) = 1/2 sum_i w_i (x_i - p)^T D^2u (x_i - p), and
//   |x_i - p| <= h), and the bound is not loose by more than a factor 20.
// * Bad input is refused naming the file, line and element.
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/render/embedded_surface.hpp"
#include "unit/render/box_surface.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <string>
#include <tuple>

namespace tissue {
namespace {

Eigen::VectorXd flat_positions(const TetMesh& mesh) {
  Eigen::VectorXd x(3 * mesh.vertex_count());
  for (int v = 0; v < mesh.vertex_count(); ++v) x.segment<3>(3 * v) = mesh.rest_positions_m[static_cast<size_t>(v)];
  return x;
}

double signed_volume_m3(const std::vector<Eigen::Vector3d>& x, const TriangleSurface& surface) {
  double six_volume = 0.0;
  for (const auto& [a, b, c] : surface.triangles)
    six_volume += x[static_cast<size_t>(a)].dot(x[static_cast<size_t>(b)].cross(x[static_cast<size_t>(c)]));
  return six_volume / 6.0;
}

TEST(EmbeddedSurface, TheFrogsRenderSurfaceIsReproducedAtRestAndMovesRigidly) {
  const TetMesh mesh = read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  TriangleSurface surface = read_obj(std::string(TISSUE_MESH_DIR) + "/frog_surface.obj");
  ASSERT_GE(surface.triangles.size(), 20000U);
  const std::vector<Eigen::Vector3d> rest = surface.vertices_m;
  EmbeddedSurface render(mesh, std::move(surface), default_max_outside_m(mesh), "frog_surface.obj");

  render.update(flat_positions(mesh));
  double worst_m = 0.0;
  for (size_t v = 0; v < rest.size(); ++v) worst_m = std::max(worst_m, (render.positions_m()[v] - rest[v]).norm());
  EXPECT_LT(worst_m, 1e-12);
  // The same solid as the tets (so wound outward), within the sagitta of their flat faces (a few per
  // cent here).
  double tets_m3 = 0.0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const auto x = mesh.rest_corners(t);
    tets_m3 += signed_tet_volume(x[0], x[1], x[2], x[3]);
  }
  const double render_m3 = signed_volume_m3(render.positions_m(), render.surface());
  EXPECT_NEAR(render_m3, tets_m3, 0.05 * tets_m3);
  // A rigid motion of the tets moves every render vertex the same way.
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(0.03, -0.2, 0.11);
  Eigen::VectorXd moved = flat_positions(mesh);
  for (int v = 0; v < mesh.vertex_count(); ++v) moved.segment<3>(3 * v) = rotation * moved.segment<3>(3 * v) + shift;
  render.update(moved);
  worst_m = 0.0;
  for (size_t v = 0; v < rest.size(); ++v) {
    worst_m = std::max(worst_m, (render.positions_m()[v] - (rotation * rest[v] + shift)).norm());
    EXPECT_NEAR(render.normals()[v].norm(), 1.0, 1e-12);
  }
  EXPECT_LT(worst_m, 1e-12);
}

TEST(EmbeddedSurface, UnderACantileversBendingItLiesWithinTheTetsInterpolationError) {
  constexpr double EDGE_M = 0.01;
  const TetMesh mesh = make_box_mesh(10, 2, 2, EDGE_M);
  const double length_m = 0.1, centre_z_m = 0.01, tip_m = 0.02;
  TriangleSurface surface = box_surface(Eigen::Vector3d(length_m, 0.02, 0.02), 40);
  const std::vector<Eigen::Vector3d> rest = surface.vertices_m;
  EmbeddedSurface render(mesh, std::move(surface), 0.0);
  // Euler-Bernoulli under an end load: w(x) = tip (x/L)^2 (3 - x/L) / 2, the sections turning with
  // the slope: u = (-(z - c) w'(x), 0, w(x)).
  const auto field = [&](const Eigen::Vector3d& p) {
    const double s = p.x() / length_m;
    const double w = 0.5 * tip_m * s * s * (3.0 - s);
    const double slope = 0.5 * tip_m * (6.0 * s - 3.0 * s * s) / length_m;
    return Eigen::Vector3d(-(p.z() - centre_z_m) * slope, 0.0, w);
  };
  // max ||D^2 u||: w'' = 3 tip (1 - s) / L^2 <= 3 tip / L^2; u_x has d2/dx2 = (z - c) 3 tip / L^3 and
  // d2/dxdz = -w''; Frobenius norms over both components bound the spectral norm.
  const double w2 = 3.0 * tip_m / (length_m * length_m);
  const double ux_xx = 0.01 * 3.0 * tip_m / (length_m * length_m * length_m);
  const double hessian_per_m = std::sqrt(w2 * w2 + ux_xx * ux_xx + 2.0 * w2 * w2);
  Eigen::VectorXd deformed = flat_positions(mesh);
  for (int v = 0; v < mesh.vertex_count(); ++v)
    deformed.segment<3>(3 * v) += field(mesh.rest_positions_m[static_cast<size_t>(v)]);
  render.update(deformed);
  double worst_ratio = 0.0;
  for (size_t v = 0; v < rest.size(); ++v) {
    const SurfaceEmbedding& e = render.embedding()[v];
    ASSERT_GE(e.weights.minCoeff(), -1e-12);  // the box's surface lies on its tets' faces
    const auto x = mesh.rest_corners(e.tet);
    double h = 0.0;
    for (size_t a = 0; a < 4; ++a)
      for (size_t b = a + 1; b < 4; ++b) h = std::max(h, (x[a] - x[b]).norm());
    const double bound_m = 0.5 * h * h * hessian_per_m;
    const double error_m = (render.positions_m()[v] - (rest[v] + field(rest[v]))).norm();
    EXPECT_LE(error_m, bound_m * (1.0 + 1e-9)) << "vertex " << v;
    worst_ratio = std::max(worst_ratio, error_m / bound_m);
  }
  EXPECT_GT(worst_ratio, 0.05);  // the bound is not vacuous
}

TEST(EmbeddedSurface, BadSurfacesAreRefusedNamingTheFileLineAndElement) {
  const std::string tetrahedron = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  const auto refused = [](const std::string& text, const std::string& expected) {
    try {
      (void)parse_obj(text, "bad.obj");
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const MeshError& error) {
      EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
      EXPECT_EQ(error.file(), "bad.obj");
    }
  };
  // A closed tetrahedron, outward, is accepted.
  const std::string faces = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  EXPECT_EQ(parse_obj(tetrahedron + faces, "ok.obj").triangles.size(), 4U);
  refused("v 0 nan 0\n" + faces, "bad.obj:1: vertex 1: coordinate 'nan' is not a finite number");
  refused(tetrahedron + "f 1 3 9\n", "bad.obj:5: face corner '9' is not a vertex");
  refused(tetrahedron + "f 1 1 2\n", "bad.obj:5: face 1 repeats vertex 1");
  refused(tetrahedron + "f 1 3 2\nf 1 2 4\nf 1 4 3\n", "not closed");
  refused(tetrahedron + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 4 3\n", "not consistently oriented");
  refused(tetrahedron + faces + "f 1 2 3\n", "shared by more than two triangles");
  refused(tetrahedron, "no triangle");
  // A vertex far outside the tet mesh.
  const TetMesh mesh = make_box_mesh(1, 1, 1, 0.01);
  TriangleSurface far = parse_obj("v 0 0 0\nv 0.05 0 0\nv 0 0.01 0\nv 0 0 0.01\n" + faces, "far.obj");
  try {
    EmbeddedSurface render(mesh, far, default_max_outside_m(mesh), "far.obj");
    ADD_FAILURE() << "a vertex 4 cm outside was embedded";
  } catch (const MeshError& error) {
    EXPECT_NE(std::string(error.what()).find("far.obj: vertex 2 (0.05, 0, 0) lies"), std::string::npos) << error.what();
    EXPECT_EQ(error.element(), 2);
  }
  EXPECT_THROW(EmbeddedSurface(mesh, far, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace tissue
