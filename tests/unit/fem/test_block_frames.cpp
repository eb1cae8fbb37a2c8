// DeformableBody::block_frames, the rows' rotations a lagged Cholesky factor turns with: a body
// turned rigidly gives every row that turn; a deformed one, rotations near its tets'.
#include "core/fem/deformable_body.hpp"
#include "core/mesh/box_mesh.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

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

}  // namespace
}  // namespace tissue
