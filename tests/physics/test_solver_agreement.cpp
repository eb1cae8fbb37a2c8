// Backward Euler with CHOLMOD and with strict PCG follow the same trajectory.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>

namespace tissue {
namespace {

Eigen::VectorXd trajectory_end(LinearSolverKind kind) {
  TetMesh mesh = make_box_mesh(20, 4, 4, 0.005);
  TissueSettings settings;
  settings.body.material = {1.0e5, 0.4, 1000.0};
  settings.body.damping = {1.0, 0.01};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.solver.kind = kind;
  settings.solver.pcg = {1e-12, 10000};
  settings.step_size_s = 0.01;
  Tissue tissue(std::move(mesh), settings);
  for (int step = 0; step < 30; ++step) tissue.step();
  return tissue.state().displacement_m;
}

TEST(SolverAgreement, CholmodAndStrictPcgAgree) {
  const Eigen::VectorXd direct = trajectory_end(LinearSolverKind::cholmod);
  const Eigen::VectorXd iterative = trajectory_end(LinearSolverKind::pcg);
  // PCG stops at ||r|| <= 1e-12 ||b||; the error is at most cond(A) times that (cond ~1e4 here),
  // accumulated over 30 steps: 1e-6 of the displacement bounds it with room to spare.
  ASSERT_GT(direct.cwiseAbs().maxCoeff(), 1e-3);  // it sagged: the comparison means something
  EXPECT_LT((direct - iterative).cwiseAbs().maxCoeff(), 1e-6 * direct.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace tissue
