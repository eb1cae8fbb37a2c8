// What a careless hand found (issue 10): touching a piece that nothing holds made the effective
// contact stiffness fail after the dynamics step had advanced the time; poses that jump farther
// than a hand can move went straight into the contact and the cutter; a random hand on the frog
// (probe and scalpel alternating, poses anywhere in and around it, now and then a jump far away)
// must never end a session. And the integrators' restart contract, as the Tissue uses it.
#include "core/fixed_region.hpp"
#include "core/integrate/ida_integrator.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace tissue {
namespace {

// Two 2 x 2 x 2 cm boxes side by side with a 1 cm gap: the first held at its x = 0 face, the
// second held by nothing (the piece a complete cut sets free, without depending on a cut).
TetMesh held_and_free_boxes() {
  TetMesh mesh = make_box_mesh(2, 2, 2, 0.01);
  const TetMesh second = make_box_mesh(2, 2, 2, 0.01);
  const int offset = mesh.vertex_count();
  for (const Eigen::Vector3d& x : second.rest_positions_m) mesh.rest_positions_m.push_back(x + Eigen::Vector3d(0.03, 0.0, 0.0));
  for (Tet tet : second.tets) {
    for (int& v : tet) v += offset;
    mesh.tets.push_back(tet);
  }
  return mesh;
}

TissueSettings boxes_settings(const TetMesh& mesh) {
  TissueSettings settings;
  settings.body.gravity_m_per_s2 = Eigen::Vector3d::Zero();
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.step_size_s = 1e-3;
  return settings;
}

double min_eigenvalue(const Eigen::Matrix3d& m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
}

// Found by fuzzing (issue 44): a vertex no tet uses (readers take it with a warning) had an unknown
// with no mass and no stiffness, and the default PCG refused the singular system on the first step.
// Held now: the body falls freely under gravity (g t^2 / 2 after 10 steps of 10 ms, to the backward
// Euler error of the drop) and the stray vertex stays where the file put it.
TEST(TissueRobustness, AVertexNoTetUsesIsHeldAndTheBodyStillFalls) {
  TetMesh mesh = make_box_mesh(2, 1, 1, 0.01);
  const Eigen::Vector3d stray(0.5, 0.5, 0.5);
  mesh.rest_positions_m.push_back(stray);
  TissueSettings settings;  // the defaults: PCG, nothing fixed
  settings.step_size_s = 0.01;
  Tissue tissue(mesh, settings);
  for (int n = 0; n < 10; ++n) tissue.step();
  const Eigen::VectorXd& x = tissue.current_positions_m();
  ASSERT_TRUE(x.allFinite());
  const auto stray_index = static_cast<Eigen::Index>(3 * (mesh.vertex_count() - 1));
  EXPECT_EQ(x.segment<3>(stray_index), stray);
  const double g = settings.body.gravity_m_per_s2.norm();
  const double drop_m = (x.segment<3>(0) - mesh.rest_positions_m[0]).dot(settings.body.gravity_m_per_s2) / g;
  const double t_s = 10 * settings.step_size_s;
  // Backward Euler's drop after n steps is g h^2 n (n + 1) / 2: 10% more than g t^2 / 2 at n = 10.
  EXPECT_NEAR(drop_m, 0.5 * g * t_s * t_s * 1.1, 0.02 * 0.5 * g * t_s * t_s);
}

TEST(TissueRobustness, ProbingAPieceNothingHoldsRendersTheStepStiffness) {
  const TetMesh mesh = held_and_free_boxes();
  for (const IntegratorKind kind : {IntegratorKind::backward_euler, IntegratorKind::ida}) {
    TissueSettings settings = boxes_settings(mesh);
    settings.integrator.kind = kind;
    Tissue tissue(mesh, settings);
    tissue.set_tool({Eigen::Vector3d(0.04, 0.01, 0.025), Eigen::Quaterniond::Identity(), ToolMode::probe});
    tissue.step();
    // Press the free box's top at its middle; it is pushed away, the probe follows.
    int touching = 0;
    for (int n = 0; n < 10; ++n) {
      tissue.set_tool({Eigen::Vector3d(0.04, 0.01, 0.0195 - 0.001 * n), Eigen::Quaterniond::Identity(),
                       ToolMode::probe});
      const double before_s = tissue.time_s();
      ASSERT_NO_THROW(tissue.step()) << to_string(kind) << " step " << n;
      EXPECT_GT(tissue.time_s(), before_s);
      if (!tissue.contact().active) continue;
      ++touching;
      const Eigen::Matrix3d& k_c = tissue.contact().stiffness_n_per_m;
      EXPECT_TRUE(k_c.allFinite());
      // Condensed from the step's Newton matrix: at least the inertia of the contacted corner,
      // m / h^2 with m a few tets' share of the box's 8 g, where the static K_c is zero.
      EXPECT_GT(min_eigenvalue(k_c), 1e-4 / (1e-3 * 1e-3)) << to_string(kind) << " step " << n;
      // The old rule condensed the static K, singular on this piece: either CHOLMOD refuses it
      // (the error that ended the session) or its K_c is rounding noise: at rounding level
      // (1e-12 N/m here) or, where the factorization's last pivots come out larger, not even
      // positive definite (-6.8 N/m at one step under the sanitizer build's summation order). Either
      // way no stiffness to render: its smallest eigenvalue stays under 1e-3 of the step's.
      EffectiveContactStiffness static_stiffness;
      Eigen::VectorXd zero;
      try {
        static_stiffness.factorize(static_contact_system(tissue.body().tangent(), zero));
        const SurfacePoint& proxy = tissue.point_contact().proxy();
        const PointSpring& spring = *tissue.contact_spring().spring();
        const auto k_static = static_stiffness.stiffness_n_per_m(
            contact_interpolation(tissue.body().dofs(), tissue.surface_bvh().triangle(proxy.triangle),
                                  proxy.barycentric),
            contact_interpolation(tissue.body().dofs(), spring.vertices, spring.weights),
            spring.tangent_fraction * spring.stiffness_n_per_m, spring.direction);
        if (k_static && k_static->allFinite()) {  // or not finite at all (the spring along the normal alone)
          EXPECT_LT(min_eigenvalue(*k_static), 1e-3 * min_eigenvalue(k_c))
              << "static " << min_eigenvalue(*k_static) << ", step " << min_eigenvalue(k_c);
        }
      } catch (const SolverError&) {
      }
    }
    EXPECT_GT(touching, 0) << to_string(kind);
    EXPECT_EQ(tissue.contact_stiffness_fallbacks(), 0);
  }
}

TEST(TissueRobustness, AToolThatJumpsIsHeldToTheHandsTopSpeed) {
  const ToolPose from{Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Quaterniond::Identity(), ToolMode::probe};
  ToolPose to = from;
  to.tip_position_m = Eigen::Vector3d(0.5, 0.0, 0.0);
  const ToolPose reached = reachable_pose(from, to, 0.03, 0.005);
  EXPECT_NEAR(reached.tip_position_m.x(), 0.005, 1e-15);
  // Within reach, a mode switch, or a tool that does nothing: the pose itself.
  EXPECT_EQ(reachable_pose(from, from, 0.03, 0.005).tip_position_m, from.tip_position_m);
  ToolPose switched = to;
  switched.mode = ToolMode::scalpel;
  EXPECT_EQ(reachable_pose(from, switched, 0.03, 0.005).tip_position_m, to.tip_position_m);
  // A blade turned by 3 rad about its tip: its far end travels the arc L * 3 = 9 cm; held to 1.5 cm,
  // it turns by 0.5 rad, a chord of 2 L sin(0.25).
  ToolPose turned = from;
  turned.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(3.0, Eigen::Vector3d::UnitX()));
  const ToolPose part = reachable_pose(from, turned, 0.03, 0.015);
  const Eigen::Vector3d end_before = 0.03 * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d end_after = 0.03 * (part.orientation * Eigen::Vector3d::UnitZ());
  EXPECT_NEAR((end_after - end_before).norm(), 2.0 * 0.03 * std::sin(0.25), 1e-12);

  // In the Tissue: a probe teleported 0.5 m into and through the held box advances at
  // max_tool_speed_m_per_s, and the step it lands in sees a penetration no deeper than that reach.
  const TetMesh mesh = make_box_mesh(4, 2, 2, 0.01);
  TissueSettings settings;
  settings.body.gravity_m_per_s2 = Eigen::Vector3d::Zero();
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.step_size_s = 1e-3;
  Tissue tissue(mesh, settings);
  const double reach_m = settings.interaction.max_tool_speed_m_per_s * settings.step_size_s;
  tissue.set_tool({Eigen::Vector3d(0.03, 0.01, 0.0205), Eigen::Quaterniond::Identity(), ToolMode::probe});
  tissue.step();
  tissue.set_tool({Eigen::Vector3d(0.03, 0.01, -0.48), Eigen::Quaterniond::Identity(), ToolMode::probe});
  Eigen::Vector3d last = tissue.applied_tool().tip_position_m;
  for (int n = 0; n < 20; ++n) {
    tissue.step();
    const Eigen::Vector3d now = tissue.applied_tool().tip_position_m;
    EXPECT_LE((now - last).norm(), reach_m * (1.0 + 1e-12)) << "step " << n;
    last = now;
    // The first step lands 5 mm into the top, not 0.5 m below it.
    if (n == 0) {
      EXPECT_LE(tissue.contact().penetration_depth_m, reach_m + 1e-9);
    }
    EXPECT_TRUE(tissue.state().displacement_m.allFinite());
  }
  EXPECT_LT(last.z(), -0.07);  // it keeps going where the hand is (at 5 mm per step)
}

// A probe lowered onto a sagging beam in 10 ms strokes, stepped at 1 ms: nine of every ten steps the
// tool stands still while the beam sags and swings onto it. That contact must start (it never did:
// only a tool segment crossing the surface started one); a probe switched on deep inside must not.
TEST(TissueRobustness, ASurfaceMovingOntoARestingProbeTouchesIt) {
  const TetMesh mesh = read_veg(std::string(TISSUE_MESH_DIR) + "/beam_10x2x2.veg");
  Eigen::Vector3d lower = mesh.rest_positions_m[0], upper = lower;
  for (const Eigen::Vector3d& x : mesh.rest_positions_m) {
    lower = lower.cwiseMin(x);
    upper = upper.cwiseMax(x);
  }
  TissueSettings settings;
  settings.body.material.young_modulus_pa = 2e6;
  settings.body.damping = RayleighDamping{1.0, 1e-3};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.01);
  settings.step_size_s = 1e-3;
  const double y = 0.5 * (lower.y() + upper.y());
  Tissue tissue(mesh, settings);
  int touched_at = -1;
  for (int n = 0; n < 40 && touched_at < 0; ++n) {
    tissue.set_tool({Eigen::Vector3d(0.07, y, upper.z() + 0.005 - 0.0005 * n), Eigen::Quaterniond::Identity(),
                     ToolMode::probe});
    for (int k = 0; k < 10; ++k) tissue.step();
    if (tissue.contact().active) touched_at = n;
  }
  ASSERT_GE(touched_at, 0) << "the probe went 1.5 cm down into the beam without touching it";
  // The tip reaches the rest top at n = 10; the beam sags under gravity meanwhile (about 1 mm at x = 7 cm).
  EXPECT_LE(touched_at, 14);
  EXPECT_LT(tissue.contact().penetration_depth_m, 0.001);

  Tissue deep(mesh, settings);
  deep.set_tool({Eigen::Vector3d(0.07, y, upper.z() - 0.008), Eigen::Quaterniond::Identity(), ToolMode::probe});
  for (int k = 0; k < 5; ++k) deep.step();
  EXPECT_FALSE(deep.contact().active) << "a probe switched on 8 mm inside snapped to the surface";
}

TetMesh frog() { return read_veg(std::string(TISSUE_MESH_DIR) + "/frog.veg"); }

// Probe and scalpel alternating in strokes of random length, poses anywhere in and around the frog
// (its box grown by half its size), one step in ten a jump to a random point a metre away. The
// session goes on: every step either succeeds or refuses (IntegrationError) with the time kept;
// the state stays finite.
TEST(TissueRobustness, ARandomHandNeverEndsTheSession) {
  const TetMesh mesh = frog();
  Eigen::Vector3d lower = mesh.rest_positions_m[0], upper = lower;
  for (const Eigen::Vector3d& x : mesh.rest_positions_m) {
    lower = lower.cwiseMin(x);
    upper = upper.cwiseMax(x);
  }
  const Eigen::Vector3d size = upper - lower;
  for (const IntegratorKind kind : {IntegratorKind::backward_euler, IntegratorKind::ida}) {
    TissueSettings settings;
    settings.integrator.kind = kind;
    settings.integrator.ida.relative_tolerance = 1e-3;
    settings.integrator.ida.absolute_tolerance = 1e-6;
    settings.body.damping = RayleighDamping{1.0, 1e-3};
    settings.body.fixed_vertices = vertices_at_minimum(mesh, 2, 0.25);
    settings.solver.pcg = PcgSolver::Settings{1e-3, 10};
    settings.step_size_s = 0.01;
    settings.interaction.blade_length_m = 0.1;
    Tissue tissue(mesh, settings);
    std::mt19937 random(kind == IntegratorKind::ida ? 11U : 7U);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto anywhere = [&] {  // in the box grown by half its size
      return Eigen::Vector3d(lower + (Eigen::Vector3d(unit(random), unit(random), unit(random)) * 2.0 -
                                      Eigen::Vector3d::Constant(0.5))
                                         .cwiseProduct(size));
    };
    const auto inside = [&] {  // in the frog's box
      return Eigen::Vector3d(lower + Eigen::Vector3d(unit(random), unit(random), unit(random)).cwiseProduct(size));
    };
    int refused = 0;
    const int steps = kind == IntegratorKind::ida ? 45 : 300;
    ToolPose pose{anywhere(), Eigen::Quaterniond::Identity(), ToolMode::probe};
    Eigen::Vector3d target = anywhere();
    for (int n = 0; n < steps; ++n) {
      if (n % 15 == 0) {  // a new stroke: the other tool, a new target
        pose.mode = pose.mode == ToolMode::probe ? ToolMode::scalpel : ToolMode::probe;
        pose.orientation = Eigen::Quaterniond::UnitRandom();
        pose.tip_position_m = anywhere();
        target = inside();
      }
      if (n % 10 == 9) pose.tip_position_m += Eigen::Vector3d(1.0, -1.0, 0.5).normalized();  // a jump away
      pose.tip_position_m += 0.2 * (target - pose.tip_position_m);
      tissue.set_tool(pose);
      const double before_s = tissue.time_s();
      try {
        tissue.step();
      } catch (const IntegrationError&) {
        ++refused;
        EXPECT_EQ(tissue.time_s(), before_s);
      }
      ASSERT_TRUE(tissue.state().displacement_m.allFinite()) << to_string(kind) << " step " << n;
      ASSERT_TRUE(tissue.state().velocity_m_per_s.allFinite());
      ASSERT_TRUE(tissue.contact().stiffness_n_per_m.allFinite());
    }
    std::printf("%s: %d steps, %zu tets cut, %d refused, %d contact-stiffness fallbacks\n",
                std::string(to_string(kind)).c_str(), steps, tissue.body().cut_tets().size(), refused,
                tissue.contact_stiffness_fallbacks());
    EXPECT_GT(tissue.body().cut_tets().size(), 0u);
    EXPECT_EQ(refused, 0);
  }
}

// The contract (integrator.hpp): IDA's history is not exported; a restored state continues as a
// restart at the restored point does, bitwise, and close to the run that never stopped.
TEST(TissueRobustness, IdaRestoredContinuesAsARestartAtThatPoint) {
  const TetMesh mesh = make_box_mesh(8, 2, 2, 0.01);
  TissueSettings settings;
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.body.damping = RayleighDamping{0.0, 1e-4};
  settings.integrator.kind = IntegratorKind::ida;
  settings.integrator.ida.relative_tolerance = 1e-6;
  settings.integrator.ida.absolute_tolerance = 1e-9;
  settings.interaction.contact_enabled = false;
  settings.interaction.cutting_enabled = false;
  settings.step_size_s = 2e-3;
  Tissue tissue(mesh, settings);
  const auto& ida = dynamic_cast<const IdaIntegrator&>(tissue.integrator());
  for (int n = 0; n < 10; ++n) tissue.step();
  EXPECT_EQ(ida.creations(), 1);
  EXPECT_EQ(ida.reinitializations(), 0);
  TissueSnapshot snapshot;
  tissue.save(snapshot);
  EXPECT_EQ(snapshot.integrator_state.size(), 0);
  for (int n = 0; n < 10; ++n) tissue.step();
  const Eigen::VectorXd continued = tissue.state().displacement_m;

  tissue.restore(snapshot);
  for (int n = 0; n < 10; ++n) tissue.step();
  const Eigen::VectorXd restored_once = tissue.state().displacement_m;
  EXPECT_EQ(ida.reinitializations(), 1);
  tissue.restore(snapshot);
  for (int n = 0; n < 10; ++n) tissue.step();
  EXPECT_EQ(ida.reinitializations(), 2);
  EXPECT_TRUE((tissue.state().displacement_m.array() == restored_once.array()).all());
  // A fresh instance restored from the snapshot restarts there too: the same numbers.
  Tissue fresh(mesh, settings);
  fresh.restore(snapshot);
  for (int n = 0; n < 10; ++n) fresh.step();
  EXPECT_TRUE((fresh.state().displacement_m.array() == restored_once.array()).all());
  // And it stays within the tolerance's reach of the run that kept its history.
  const double scale = continued.cwiseAbs().maxCoeff();
  EXPECT_LT((restored_once - continued).cwiseAbs().maxCoeff(), 1e-3 * scale);
  EXPECT_GT((restored_once - continued).cwiseAbs().maxCoeff(), 0.0);  // it did restart
}

TEST(TissueRobustness, IdaGetsNewMemoryWhenACutGrowsTheSystem) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  TissueSettings settings;
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.integrator.kind = IntegratorKind::ida;
  settings.interaction.blade_length_m = 0.06;
  Tissue tissue(mesh, settings);
  const auto& ida = dynamic_cast<const IdaIntegrator&>(tissue.integrator());
  for (int n = 0; n <= 30; ++n) {
    const double y = -0.005 + 0.03 * n / 30.0;
    tissue.set_tool({Eigen::Vector3d(0.0553, y, -0.02), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
    tissue.step();
  }
  EXPECT_GT(tissue.body().cut_tets().size(), 0u);
  EXPECT_GT(ida.creations(), 1);
  EXPECT_TRUE(tissue.state().displacement_m.allFinite());
}

}  // namespace
}  // namespace tissue
