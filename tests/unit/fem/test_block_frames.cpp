// DeformableBody::block_frames, the rows' rotations a lagged Cholesky factor turns with: a body
// turned rigidly gives every row that turn; a deformed one, rotations near its tets'.
#include "core/fem/deformable_body.hpp"
#include "core/mesh/box_mesh.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <vector>

namespace tissue {
namespace {

TEST(BlockFrames, ABodyTurnedRigidlyGivesEveryRowTheTurn) {
  const TetMesh mesh = make_box_mesh(4, 3, 2, 0.01);
  BodySettings settings;
  settings.material = Material{1.0e5, 0.4, 1000.0};
  DeformableBody body(mesh, settings);  // nothing fixed: every vertex is a row
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  Eigen::VectorXd displacement_m(body.dof_count());
  for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
    const Eigen::Vector3d rest = mesh.rest_positions_m[static_cast<size_t>(body.dofs().row_vertex[static_cast<size_t>(row)])];
    displacement_m.segment<3>(3 * row) = turn * rest - rest;
  }
  Eigen::VectorXd force_n;
  body.evaluate(displacement_m, force_n, /*update_tangent=*/true);
  const std::vector<Eigen::Matrix3d>* frames = body.block_frames();
  ASSERT_NE(frames, nullptr);
  ASSERT_EQ(static_cast<int>(frames->size()), body.tangent().block_rows());
  for (const Eigen::Matrix3d& frame : *frames) {
    // The tets' rotations stop within RotationSettings::max_error_rad (1e-6 rad) of the turn.
    EXPECT_LT((frame - turn).cwiseAbs().maxCoeff(), 1e-5);
    EXPECT_NEAR(frame.determinant(), 1.0, 1e-12);
  }
}


// A twisted bar: each tet turns its own way. A vertex's frame is the mean of its tets' turns, so it
// lies among them: no farther from any of them than the farthest two are from each other. And a
// tet's turn as a quaternion is its rotation.
TEST(BlockFrames, AVertexFrameLiesAmongItsTetsTurns) {
  const TetMesh mesh = make_box_mesh(8, 2, 2, 0.01);
  BodySettings settings;
  settings.material = Material{1.0e5, 0.4, 1000.0};
  DeformableBody body(mesh, settings);
  Eigen::VectorXd displacement_m(body.dof_count());
  for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
    const Eigen::Vector3d rest = mesh.rest_positions_m[static_cast<size_t>(body.dofs().row_vertex[static_cast<size_t>(row)])];
    const Eigen::Matrix3d twist = Eigen::AngleAxisd(20.0 * rest.x(), Eigen::Vector3d::UnitX()).toRotationMatrix();
    displacement_m.segment<3>(3 * row) = twist * rest - rest;  // 1.6 rad from end to end
  }
  Eigen::VectorXd force_n;
  body.evaluate(displacement_m, force_n, /*update_tangent=*/true);
  const std::vector<Eigen::Matrix3d>& frames = *body.block_frames();
  const CorotationalElasticity& elasticity = body.elasticity();
  const auto angle = [](const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
    return Eigen::AngleAxisd(a.transpose() * b).angle();
  };
  for (int t = 0; t < mesh.tet_count(); ++t) {
    EXPECT_LT((elasticity.turn(t).toRotationMatrix() - elasticity.rotation(t)).cwiseAbs().maxCoeff(), 1e-12);
  }
  int apart = 0;
  for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
    const int vertex = body.dofs().row_vertex[static_cast<size_t>(row)];
    std::vector<int> tets;
    for (int t = 0; t < mesh.tet_count(); ++t) {
      for (const int v : mesh.tets[static_cast<size_t>(t)]) {
        if (v == vertex) tets.push_back(t);
      }
    }
    double spread = 0.0;
    for (const int a : tets) {
      for (const int b : tets) spread = std::max(spread, angle(elasticity.rotation(a), elasticity.rotation(b)));
    }
    for (const int t : tets) EXPECT_LE(angle(frames[static_cast<size_t>(row)], elasticity.rotation(t)), spread + 1e-9);
    apart += spread > 0.1 ? 1 : 0;
  }
  EXPECT_GT(apart, body.dofs().free_vertex_count() / 2);  // most vertices' tets turn apart: the check means something
}

}  // namespace
}  // namespace tissue
