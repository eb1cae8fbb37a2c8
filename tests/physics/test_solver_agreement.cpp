// Backward Euler with CHOLMOD and with strict PCG follow the same trajectory; so does CG with a
// lagged Cholesky factor on the frog.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/tissue.hpp"
#include "support/under_sanitizer.hpp"

#include <cstdio>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace tissue {
namespace {

constexpr double OFF = std::numeric_limits<double>::infinity();

// A 10 cm beam (E 100 kPa, damped) sagging from rest for 30 steps of 10 ms. `trigger_rad`: the
// Newton corrections' trigger angle (OFF: the linearized step alone, nothing corrected).
Eigen::VectorXd trajectory_end(LinearSolverKind kind, double trigger_rad) {
  TetMesh mesh = make_box_mesh(20, 4, 4, 0.005);
  TissueSettings settings;
  settings.body.material = {1.0e5, 0.4, 1000.0};
  settings.body.damping = {1.0, 0.01};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.solver.kind = kind;
  settings.solver.pcg = {1e-12, 10000};
  settings.integrator.newton.trigger_angle_rad = trigger_rad;
  settings.step_size_s = 0.01;
  Tissue tissue(std::move(mesh), settings);
  for (int step = 0; step < 30; ++step) tissue.step();
  return tissue.state().displacement_m;
}

TEST(SolverAgreement, CholmodAndStrictPcgAgree) {
  // The linear solvers alone (no Newton corrections): PCG stops at ||r|| <= 1e-12 ||b||; the error is
  // at most cond(A) times that (cond ~1e4 here), accumulated over 30 steps: 1e-6 of the
  // displacement bounds it with room to spare.
  const Eigen::VectorXd direct = trajectory_end(LinearSolverKind::cholmod, OFF);
  const Eigen::VectorXd iterative = trajectory_end(LinearSolverKind::pcg, OFF);
  ASSERT_GT(direct.cwiseAbs().maxCoeff(), 1e-3);  // it sagged: the comparison means something
  EXPECT_LT((direct - iterative).cwiseAbs().maxCoeff(), 1e-6 * direct.cwiseAbs().maxCoeff());
}

TEST(SolverAgreement, CholmodsInexactCorrectionsStrayByLessThanTheirForcingTerm) {
  // With the Newton corrections (the core's default: up to 5 a step), CHOLMOD solves a correction
  // that is not the converged one only to the forcing term (1e-2; CholmodSolver::solve_roughly),
  // strict PCG each to 1e-12. Each correction's error is at most the forcing term's share of that
  // correction (the turned factor is a good preconditioner), so the two trajectories differ by less
  // than the forcing term times what the corrections changed at all (the trajectory against the
  // linearized step's).
  const Eigen::VectorXd direct = trajectory_end(LinearSolverKind::cholmod, 0.05);
  const Eigen::VectorXd iterative = trajectory_end(LinearSolverKind::pcg, 0.05);
  const Eigen::VectorXd linearized = trajectory_end(LinearSolverKind::pcg, OFF);
  const double corrected_m = (iterative - linearized).cwiseAbs().maxCoeff();
  const double stray_m = (direct - iterative).cwiseAbs().maxCoeff();
  std::printf("  the corrections moved the beam by %.3g m; CHOLMOD's inexact ones strayed %.3g m from exact ones\n",
              corrected_m, stray_m);
  ASSERT_GT(corrected_m, 1e-3 * iterative.cwiseAbs().maxCoeff());  // corrections happened and mattered
  EXPECT_LT(stray_m, CholmodSolver::NEARBY_FORCING_TERM * corrected_m);
}

constexpr int FROG_STEPS = test::UNDER_SANITIZER ? 40 : 200;  // 200 take minutes under a sanitizer

// The frog as tissue-bench runs it (tail held, gravity along -y, dt = 10 ms, large-turn
// protection on): 200 steps of a large swing, with many lagged-factor refreshes.
Eigen::VectorXd frog_trajectory_end(LinearSolverKind kind, bool background) {
  TetMesh mesh = read_veg(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  TissueSettings settings;
  settings.body.material = {1.0e5, 0.4, 1000.0};
  settings.body.gravity_m_per_s2 = Eigen::Vector3d(0.0, -9.81, 0.0);
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.01);
  settings.solver.kind = kind;
  settings.solver.pcg = {1e-6, 1000};
  settings.solver.refresh.background_refactor = background;
  settings.step_size_s = 0.01;
  Tissue tissue(std::move(mesh), settings);
  for (int step = 0; step < FROG_STEPS; ++step) tissue.step();
  return tissue.state().displacement_m;
}

TEST(SolverAgreement, LaggedCholeskyPcgFollowsCholmodOnTheFrog) {
  const Eigen::VectorXd direct = frog_trajectory_end(LinearSolverKind::cholmod, false);
  const Eigen::VectorXd lagged = frog_trajectory_end(LinearSolverKind::pcg_cholesky, true);
  const double scale = direct.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 1e-2);  // it swung: the comparison means something
  // Each solve stops at ||r|| <= 1e-6 ||b||, an error of at most cond(A) 1e-6 in dv (cond(A) ~1e2-1e3
  // at this step); 200 steps of a damped swing carry it forward without growth beyond ~10x, and the
  // large-turn protection's decisions (thresholds) did not flip: 1e-3 of the displacement bounds it.
  EXPECT_LT((direct - lagged).cwiseAbs().maxCoeff(), 1e-3 * scale);
  // Results do not depend on the worker thread.
  EXPECT_TRUE(lagged == frog_trajectory_end(LinearSolverKind::pcg_cholesky, false));
}

}  // namespace
}  // namespace tissue
