// The Tissue facade and fixed-region selection: settings are checked when given, regions pick
// exactly the vertices they describe, and the fixed vertices stay at rest while the rest falls.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>

namespace tissue {
namespace {

TEST(FixedRegion, BoxAndMinimumSlabPickTheRightVertices) {
  const TetMesh mesh = make_box_mesh(4, 2, 2, 0.01);  // 5 x 3 x 3 vertex grid
  EXPECT_EQ(vertices_at_minimum(mesh, 0, 0.0).size(), 9u);   // the x = 0 face
  EXPECT_EQ(vertices_at_minimum(mesh, 0, 0.25).size(), 18u);  // x <= 0.01: two layers
  EXPECT_EQ(vertices_at_minimum(mesh, 2, 0.0).size(), 15u);  // the z = 0 face
  const std::vector<int> corner = vertices_in_box(mesh, Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1e-9, 1e-9, 1e-9));
  ASSERT_EQ(corner.size(), 1u);
  EXPECT_EQ(mesh.rest_positions_m[static_cast<size_t>(corner[0])].norm(), 0.0);
  EXPECT_THROW(vertices_at_minimum(mesh, 3, 0.1), ParameterError);
  EXPECT_THROW(vertices_in_box(mesh, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 1)), ParameterError);
}

TEST(Tissue, RefusesInvalidSettingsWhenGiven) {
  const TetMesh mesh = make_box_mesh(2, 1, 1, 0.01);
  const auto make = [&](auto change) {
    TissueSettings settings;
    change(settings);
    return Tissue(mesh, settings);
  };
  EXPECT_THROW(make([](TissueSettings& s) { s.step_size_s = 0.0; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.step_size_s = -1e-3; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.solver.pcg.tolerance = 0.0; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.solver.pcg.max_iterations = 0; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.body.material.poisson_ratio = 0.5; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.body.material.young_modulus_pa = 0.0; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.body.gravity_m_per_s2.x() = std::nan(""); }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.body.fixed_vertices = {1000}; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.body.fixed_vertices = {-1}; }), ParameterError);
  EXPECT_THROW(parse_linear_solver_kind("gauss-seidel"), ParameterError);
}

TEST(Tissue, FixedVerticesStayWhileTheFarEndStartsInFreeFall) {
  TetMesh mesh = make_box_mesh(4, 1, 1, 0.01);
  TissueSettings settings;
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.0);
  settings.step_size_s = 1e-4;
  Tissue tissue(mesh, settings);
  tissue.step();
  Eigen::VectorXd positions;
  tissue.vertex_positions(positions);
  for (int v : settings.body.fixed_vertices) {
    EXPECT_EQ(positions.segment<3>(3 * v), mesh.rest_positions_m[static_cast<size_t>(v)]);
  }
  // One backward-Euler step from rest moves the free vertices by u = h^2 (M + h^2 K)^-1 M g.
  // K annihilates the uniform g except next to the clamp, and the tip is 4 cells (4 couplings)
  // away from it, so u_tip = g h^2 (1 + O((h^2 k/m)^4)) with h^2 k/m ~ 0.04 here: free fall to 1e-4.
  const int tip = mesh.vertex_count() - 1;
  const double drop_m = mesh.rest_positions_m[static_cast<size_t>(tip)].y() - positions(3 * tip + 1);
  EXPECT_NEAR(drop_m, 9.81 * 1e-8, 1e-4 * 9.81 * 1e-8);
  EXPECT_EQ(tissue.body().dof_count(), 3 * (mesh.vertex_count() - 4));
}

}  // namespace
}  // namespace tissue
