// The Tissue facade and fixed-region selection: settings are checked when given, regions pick
// exactly the vertices they describe, and the fixed vertices stay at rest while the rest falls.
#include "core/integrate/integrator.hpp"
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <limits>
#include <memory>

namespace tissue {
namespace {

TEST(FixedRegion, BoxAndMinimumSlabPickTheRightVertices) {
  const TetMesh mesh = make_box_mesh(4, 2, 2, 0.01);          // 5 x 3 x 3 vertex grid
  EXPECT_EQ(vertices_at_minimum(mesh, 0, 0.0).size(), 9u);    // the x = 0 face
  EXPECT_EQ(vertices_at_minimum(mesh, 0, 0.25).size(), 18u);  // x <= 0.01: two layers
  EXPECT_EQ(vertices_at_minimum(mesh, 2, 0.0).size(), 15u);   // the z = 0 face
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
  EXPECT_THROW(make([](TissueSettings& s) { s.interaction.blade_length_m = 0.0; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.interaction.contact.spring_stiffness_n_per_m = -1.0; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.interaction.contact.stiffness_refresh_steps = 0; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.interaction.cutter.min_volume_fraction = 0.5; }), ParameterError);
  EXPECT_THROW(make([](TissueSettings& s) { s.interaction.cutter.min_volume_fraction = 0.0; }), ParameterError);
  EXPECT_THROW(parse_tool_mode("laser"), ParameterError);
  EXPECT_EQ(parse_tool_mode("scalpel"), ToolMode::scalpel);
}

TEST(Tissue, RefusesABadToolPoseAndKeepsTheLastOne) {
  const TetMesh mesh = make_box_mesh(2, 1, 1, 0.01);
  Tissue tissue(mesh, TissueSettings{});
  const ToolPose good{Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Quaterniond(2.0, 0.0, 0.0, 0.0), ToolMode::probe};
  tissue.set_tool(good);
  EXPECT_DOUBLE_EQ(tissue.tool().orientation.norm(), 1.0);  // normalized
  ToolPose bad = good;
  bad.tip_position_m.y() = std::nan("");
  EXPECT_THROW(tissue.set_tool(bad), ParameterError);
  bad = good;
  bad.orientation = Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0);
  EXPECT_THROW(tissue.set_tool(bad), ParameterError);
  bad.orientation = Eigen::Quaterniond(std::numeric_limits<double>::infinity(), 0.0, 0.0, 0.0);
  EXPECT_THROW(tissue.set_tool(bad), ParameterError);
  EXPECT_EQ(tissue.tool().tip_position_m, good.tip_position_m);
}

// A probe pressed into the top of a block clamped at its bottom: contact starts when the tip crosses
// the surface, the tool is pushed back out (force along +z), the contact stiffness is SPD and, in
// the linear regime, the settled force is K_c d to the spring's share of the compliance; lifting
// the tip ends the contact.
/// A 0.04 x 0.04 x 0.02 m block (top at z = 0.02 m) clamped at its bottom, no gravity, CHOLMOD,
/// 10 ms steps, with `damping`.
TissueSettings clamped_block_settings(const TetMesh& mesh, RayleighDamping damping) {
  TissueSettings settings;
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 2, 0.0);
  settings.body.gravity_m_per_s2.setZero();
  settings.body.damping = damping;
  settings.solver.kind = LinearSolverKind::cholmod;
  settings.step_size_s = 0.01;
  return settings;
}

TetMesh clamped_block_mesh() { return make_box_mesh(4, 4, 2, 0.01); }

Tissue clamped_block() {
  const TetMesh mesh = clamped_block_mesh();
  return Tissue(mesh, clamped_block_settings(mesh, RayleighDamping{20.0, 0.0}));
}

TEST(Tissue, ProbeTouchesPushesBackAndLetsGo) {
  Tissue tissue = clamped_block();
  const Eigen::Vector3d above(0.0213, 0.0187, 0.025);
  tissue.set_tool({above, Eigen::Quaterniond::Identity(), ToolMode::probe});
  tissue.step();
  EXPECT_FALSE(tissue.contact().active);
  EXPECT_EQ(tissue.contact().force_on_tool_n, Eigen::Vector3d::Zero());
  constexpr double DEPTH_M = 1e-4;
  tissue.set_tool(
      {Eigen::Vector3d(above.x(), above.y(), 0.02 - DEPTH_M), Eigen::Quaterniond::Identity(), ToolMode::probe});
  for (int n = 0; n < 300; ++n) tissue.step();
  const ContactOutput& contact = tissue.contact();
  ASSERT_TRUE(contact.active);
  EXPECT_GT(contact.force_on_tool_n.z(), 0.0);
  EXPECT_LT(contact.force_on_tool_n.head<2>().norm(), 0.05 * contact.force_on_tool_n.z());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(contact.stiffness_n_per_m);
  EXPECT_GT(eigen.eigenvalues().minCoeff(), 0.0);
  EXPECT_LT((contact.stiffness_n_per_m - contact.stiffness_n_per_m.transpose()).norm(),
            1e-9 * contact.stiffness_n_per_m.norm());
  // Springs in series: f = (K_c^-1 + I/k)^-1 d along the normal, the tangential force ~0.
  const double k_n = 1.0 / contact.stiffness_n_per_m.inverse()(2, 2);
  const double k = tissue.contact_spring_stiffness_n_per_m();
  const double expected = DEPTH_M / (1.0 / k_n + 1.0 / k);
  EXPECT_NEAR(contact.force_on_tool_n.z(), expected, 0.02 * expected);
  tissue.set_tool({above, Eigen::Quaterniond::Identity(), ToolMode::probe});
  tissue.step();
  EXPECT_FALSE(tissue.contact().active);
  EXPECT_EQ(tissue.contact_spring().spring(), std::nullopt);
}

// The same press, then the tip drawn back by a quarter of the depth: far more than the microns the
// contact spring leaves between the pressed surface and the tip, so the tip is outside the surface
// as the last step left it, but well within the pressed block's rebound f_n / k_n. The surface rises
// with the tip: the contact holds at every step (it used to end at the first, and the block then
// sprang up through the tip unresisted: issue 20's chattering hand) and settles at the force of the
// shallower press, springs in series as above.
TEST(Tissue, APressedSurfaceFollowsATipDrawnBackALittle) {
  Tissue tissue = clamped_block();
  const Eigen::Vector3d above(0.0213, 0.0187, 0.025);
  tissue.set_tool({above, Eigen::Quaterniond::Identity(), ToolMode::probe});
  tissue.step();
  constexpr double DEPTH_M = 1e-4;
  const auto press = [&](double depth_m) {
    tissue.set_tool(
        {Eigen::Vector3d(above.x(), above.y(), 0.02 - depth_m), Eigen::Quaterniond::Identity(), ToolMode::probe});
  };
  press(DEPTH_M);
  for (int n = 0; n < 300; ++n) tissue.step();
  ASSERT_TRUE(tissue.contact().active);
  const double gap_m = tissue.contact().force_on_tool_n.norm() / tissue.contact_spring_stiffness_n_per_m();
  ASSERT_LT(gap_m, 0.05 * DEPTH_M);  // the tip is drawn back by 5x more than the spring's gap
  press(0.75 * DEPTH_M);
  for (int n = 0; n < 300; ++n) {
    tissue.step();
    ASSERT_TRUE(tissue.contact().active) << "lost at step " << n;
  }
  const double k_n = 1.0 / tissue.contact().stiffness_n_per_m.inverse()(2, 2);
  const double expected = 0.75 * DEPTH_M / (1.0 / k_n + 1.0 / tissue.contact_spring_stiffness_n_per_m());
  EXPECT_NEAR(tissue.contact().force_on_tool_n.z(), expected, 0.02 * expected);
}

// A ball probe of radius r posed by its centre touches as a point probe posed at its pole, r along the
// tool axis toward the tip: the two tissues step bitwise alike, and each reports as applied the
// position it was given. A refused radius is refused when given.
TEST(Tissue, ABallProbeTouchesWithItsPole) {
  const TetMesh mesh = clamped_block_mesh();
  TissueSettings settings = clamped_block_settings(mesh, RayleighDamping{});
  Tissue point_probe(mesh, settings);
  settings.interaction.probe_radius_m = 0.002;
  Tissue ball_probe(mesh, settings);
  const Eigen::Quaterniond tilted = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()));
  for (const double depth_m : {-0.001, 1e-4, 2e-4}) {
    const Eigen::Vector3d pole(0.0213, 0.0187, 0.02 - depth_m);
    const Eigen::Vector3d centre = pole + 0.002 * tool_axis(tilted);
    point_probe.set_tool({pole, tilted, ToolMode::probe});
    ball_probe.set_tool({centre, tilted, ToolMode::probe});
    for (int n = 0; n < 20; ++n) {
      point_probe.step();
      ball_probe.step();
    }
    EXPECT_EQ(ball_probe.applied_tool().tip_position_m, point_probe.applied_tool().tip_position_m);
    EXPECT_EQ(ball_probe.applied_tool_position_m(), centre);
    EXPECT_EQ(point_probe.applied_tool_position_m(), pole);
    EXPECT_EQ(ball_probe.contact().active, depth_m > 0.0);
    EXPECT_EQ(ball_probe.contact().force_on_tool_n, point_probe.contact().force_on_tool_n);
    EXPECT_EQ(ball_probe.state().displacement_m, point_probe.state().displacement_m);
  }
  settings.interaction.probe_radius_m = -1e-3;
  EXPECT_THROW(Tissue(mesh, settings), ParameterError);
}

// The complete contact output a haptic loop renders (Tissue::tool_contact, the Tissue FMU's contact
// outputs) for a ball probe of radius r over the flat top (z = 0.02 m) of a clamped block, no gravity:
// hovering 3 mm above it (within the 1 cm margin) it reports the surface below, the point offset by
// the ball's centre - pole (r along the axis) and the outward normal; pressed, the contact's own point
// with the same offset; in both, the damping is beta K_c. The report is the sample's: of the pose the
// last step took (or the pose set before the first step), not of a pose set since.
TEST(Tissue, TheToolContactIsWhatAHapticLoopRenders) {
  const TetMesh mesh = clamped_block_mesh();
  TissueSettings settings = clamped_block_settings(mesh, RayleighDamping{0.0, 0.01});
  settings.interaction.probe_radius_m = 0.002;
  settings.interaction.contact.near_surface_margin_m = 0.01;
  Tissue tissue(mesh, settings);
  const Eigen::Vector3d ball_offset(0.0, 0.0, 0.002);  // identity orientation: the axis is +z
  const Eigen::Vector3d hover_pole(0.0213, 0.0187, 0.023);
  tissue.set_tool({hover_pole + ball_offset, Eigen::Quaterniond::Identity(), ToolMode::probe});
  const auto expect_near_top = [&](const ToolContact& near, const char* when) {
    SCOPED_TRACE(when);
    EXPECT_FALSE(near.active);
    ASSERT_TRUE(near.near);
    const Eigen::Vector3d expected = Eigen::Vector3d(hover_pole.x(), hover_pole.y(), 0.02) + ball_offset;
    EXPECT_NEAR((near.point_m - expected).norm(), 0.0, 1e-12) << near.point_m.transpose();
    EXPECT_NEAR((near.normal - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
    EXPECT_GT(near.stiffness_n_per_m(2, 2), 0.0);
    EXPECT_EQ(near.damping_n_s_per_m, 0.01 * near.stiffness_n_per_m);
    EXPECT_EQ(near.force_on_tool_n, Eigen::Vector3d::Zero());
  };
  expect_near_top(tissue.tool_contact(), "before the first step: of the pose set");
  tissue.step();
  expect_near_top(tissue.tool_contact(), "after a step");
  const Eigen::Vector3d far_pole(0.0213, 0.0187, 0.05);
  tissue.set_tool({far_pole + ball_offset, Eigen::Quaterniond::Identity(), ToolMode::probe});
  expect_near_top(tissue.tool_contact(), "a pose set since is the next step's");
  tissue.step();
  EXPECT_FALSE(tissue.tool_contact().near);  // 3 cm above: beyond the margin

  const Eigen::Vector3d pressed_pole(0.0213, 0.0187, 0.02 - 1e-4);
  tissue.set_tool({pressed_pole + ball_offset, Eigen::Quaterniond::Identity(), ToolMode::probe});
  for (int n = 0; n < 50; ++n) tissue.step();
  const ToolContact pressed = tissue.tool_contact();
  ASSERT_TRUE(pressed.active);
  EXPECT_FALSE(pressed.near);
  EXPECT_NEAR((pressed.point_m - (tissue.contact().point_m + ball_offset)).norm(), 0.0, 1e-15);  // rounding
  EXPECT_EQ(pressed.force_on_tool_n, tissue.contact().force_on_tool_n);
  EXPECT_GT(pressed.force_on_tool_n.z(), 0.0);
  // The contact slides (frictionless): K_c's normal part along the contact's normal, no tangential stiffness.
  const Eigen::Matrix3d sliding =
      sliding_contact_stiffness_n_per_m(tissue.contact().stiffness_n_per_m, tissue.contact().normal);
  EXPECT_EQ(pressed.stiffness_n_per_m, sliding);
  EXPECT_NEAR((sliding * tissue.contact().normal).norm(),
              frictionless_normal_stiffness_n_per_m(tissue.contact().stiffness_n_per_m, tissue.contact().normal),
              1e-9 * sliding.norm());
  EXPECT_EQ(pressed.damping_n_s_per_m, 0.01 * sliding);

  settings.interaction.contact.near_surface_margin_m = 0.0;  // never reported
  Tissue no_margin(mesh, settings);
  no_margin.set_tool({hover_pole + ball_offset, Eigen::Quaterniond::Identity(), ToolMode::probe});
  no_margin.step();
  EXPECT_FALSE(no_margin.tool_contact().near);
}

// A body with nothing fixed condenses its contact stiffness from the step matrix
// M/h^2 + D/h + K, which holds the contact spring while the probe touches, scaled like K; the
// spring is taken out exactly, whatever share of it the tangent holds (issue 9: it enters the
// tangent with the share that keeps Rayleigh damping off it).
TEST(Tissue, FreeBodyContactStiffnessLeavesTheSpringOut) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  TissueSettings settings;
  settings.body.gravity_m_per_s2.setZero();
  settings.body.damping = RayleighDamping{1.0, 0.01};
  settings.solver.kind = LinearSolverKind::cholmod;
  settings.step_size_s = 0.01;
  Tissue tissue(mesh, settings);
  const Eigen::Vector3d above(0.0213, 0.0187, 0.025);
  tissue.set_tool({above, Eigen::Quaterniond::Identity(), ToolMode::probe});
  tissue.step();
  tissue.set_tool(
      {Eigen::Vector3d(above.x(), above.y(), 0.02 - 1e-4), Eigen::Quaterniond::Identity(), ToolMode::probe});
  tissue.step();  // the contact starts: K_c from the tangent of this step, at rest
  ASSERT_TRUE(tissue.contact().active);

  DeformableBody body(mesh, settings.body);
  Eigen::VectorXd internal_force, diagonal;
  body.evaluate(Eigen::VectorXd::Zero(body.dof_count()), internal_force, /*update_tangent=*/true);
  EffectiveContactStiffness reference;
  reference.factorize(newton_stiffness_system(body, 1.0 / (settings.step_size_s), diagonal));
  const SurfacePoint& proxy = tissue.point_contact().proxy();
  const std::optional<Eigen::Matrix3d> k_c = reference.stiffness_n_per_m(
      contact_interpolation(body.dofs(), tissue.surface_bvh().triangle(proxy.triangle), proxy.barycentric));
  ASSERT_TRUE(k_c.has_value());
  EXPECT_LT((tissue.contact().stiffness_n_per_m - *k_c).norm(), 1e-9 * k_c->norm());
}

// A box held at x = 0, its K_c refreshed in the background at every step (with a latency), pressed
// from above 0.2 mm deeper each step; condensed_now() is the K_c the caller's thread condenses from
// the static K and the proxy as they are when a step ends.
struct BackgroundPress {
  static TissueSettings settings(const TetMesh& mesh, int latency_steps) {
    TissueSettings settings;
    settings.body.gravity_m_per_s2.setZero();
    settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.0);
    settings.step_size_s = 0.01;
    settings.interaction.contact.stiffness_in_background = true;
    settings.interaction.contact.stiffness_refresh_steps = 1;
    settings.interaction.contact.stiffness_latency_steps = latency_steps;
    return settings;
  }
  explicit BackgroundPress(int latency_steps)
      : mesh(make_box_mesh(6, 4, 2, 0.01)), tissue(mesh, settings(mesh, latency_steps)) {
    press(0);
  }
  void press(int n) {
    const double height_m = n == 0 ? ABOVE.z() : 0.02 - 2e-4 * n;
    tissue.set_tool({Eigen::Vector3d(ABOVE.x(), ABOVE.y(), height_m), Eigen::Quaterniond::Identity(), ToolMode::probe});
    tissue.step();
  }
  [[nodiscard]] Eigen::Matrix3d element_local() const {
    return element_local_contact_stiffness(tissue.body().elasticity(), tissue.surface(),
                                           tissue.point_contact().proxy().triangle);
  }
  [[nodiscard]] std::optional<Eigen::Matrix3d> condensed_now() {
    const SurfacePoint& proxy = tissue.point_contact().proxy();
    return condensed_contact_stiffness(
        reference, static_contact_system(tissue.body().tangent(), zero_diagonal), tissue.body().dofs(),
        contact_interpolation(tissue.body().dofs(), tissue.surface_bvh().triangle(proxy.triangle), proxy.barycentric),
        tissue.contact_spring().spring(), tissue.contact_spring_stiffness_n_per_m(), 0.0);
  }

  static inline const Eigen::Vector3d ABOVE{0.0413, 0.0187, 0.025};
  TetMesh mesh;
  Tissue tissue;
  EffectiveContactStiffness reference;
  Eigen::VectorXd zero_diagonal;
};

// In the background (contact_stiffness_in_background), a refresh started at a step is what the next
// step renders (the default latency, one step). A new contact's first step renders the elementLocal
// estimate (what the near-surface report gives before the touch).
TEST(Tissue, ABackgroundContactStiffnessIsRenderedOneStepLate) {
  BackgroundPress press(1);
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  for (int n = 1; n <= 12; ++n) {
    press.press(n);
    ASSERT_TRUE(press.tissue.contact().active) << n;
    const Eigen::Matrix3d& rendered = press.tissue.contact().stiffness_n_per_m;
    if (n == 1) {
      EXPECT_TRUE(rendered == press.element_local());
    } else {
      EXPECT_TRUE(rendered == expected) << "step " << n << ": max difference "
                                        << (rendered - expected).cwiseAbs().maxCoeff();
    }
    const std::optional<Eigen::Matrix3d> now = press.condensed_now();  // what the next step will render
    ASSERT_TRUE(now.has_value());
    // The stiffness changes as the probe presses in, so that rendering it a step late is seen.
    if (n >= 3) {
      EXPECT_FALSE(rendered == *now) << n;
    }
    expected = *now;
  }
  EXPECT_EQ(press.tissue.contact_stiffness_fallbacks(), 0);
}

// With contact_stiffness_latency_steps = 3 (a factorization longer than a step: the organ), a refresh
// started at a step is rendered three steps later, the one before standing until then, and the next
// starts at that step: K_c is refreshed every 3 steps (the refresh period, 1 here, is shorter). The
// new contact's elementLocal estimate (of its first step) stands for the first three steps.
TEST(Tissue, ABackgroundContactStiffnessIsRenderedAfterItsLatency) {
  constexpr int LATENCY = 3;
  BackgroundPress press(LATENCY);
  std::vector<Eigen::Matrix3d> condensed;  // K_c condensed at the end of each step in contact
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  for (int n = 1; n <= 13; ++n) {
    press.press(n);
    ASSERT_TRUE(press.tissue.contact().active) << n;
    const Eigen::Matrix3d& rendered = press.tissue.contact().stiffness_n_per_m;
    // Refreshes start at steps 1, 4, 7, ... (the contact's first, then every LATENCY) and land
    // LATENCY steps later.
    if (n == 1) expected = press.element_local();
    if (n > LATENCY && (n - 1) % LATENCY == 0) expected = condensed[static_cast<size_t>(n - 1 - LATENCY)];
    EXPECT_TRUE(rendered == expected) << "step " << n << ": max difference "
                                      << (rendered - expected).cwiseAbs().maxCoeff();
    const std::optional<Eigen::Matrix3d> now = press.condensed_now();
    ASSERT_TRUE(now.has_value());
    condensed.push_back(*now);
  }
  // The stiffness changed between the refreshes, so that rendering the wrong one would be seen.
  EXPECT_FALSE(condensed[3] == condensed[6]);
  EXPECT_EQ(press.tissue.contact_stiffness_fallbacks(), 0);
}

TEST(Tissue, BuildsOnlyWhatTheSceneRequires) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  const auto run_scene = [&](bool contact, bool cutting) {
    TissueSettings settings;
    settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.0);
    settings.interaction.contact_enabled = contact;
    settings.interaction.cutting_enabled = cutting;
    settings.interaction.blade_length_m = 0.06;
    auto tissue = std::make_unique<Tissue>(mesh, settings);
    EXPECT_EQ(tissue->has_cutter(), cutting);
    EXPECT_EQ(tissue->surface_bvh().triangle_count() > 0, contact || cutting);
    // A scalpel stroke across the beam, then a probe pressed onto its top.
    for (int n = 0; n <= 30; ++n) {
      const double y = -0.005 + 0.03 * n / 30.0;
      tissue->set_tool({Eigen::Vector3d(0.0553, y, -0.02), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
      tissue->step();
    }
    tissue->set_tool({Eigen::Vector3d(0.0853, 0.0107, 0.025), Eigen::Quaterniond::Identity(), ToolMode::probe});
    tissue->step();
    // 6 mm in a 1 ms step is faster than a hand (5 m/s): the tool gets there in a second step.
    tissue->set_tool({Eigen::Vector3d(0.0853, 0.0107, 0.019), Eigen::Quaterniond::Identity(), ToolMode::probe});
    tissue->step();
    tissue->step();
    return tissue;
  };
  const auto everything = run_scene(true, true);
  EXPECT_EQ(everything->body().cut_tets().size(), 20u);
  EXPECT_TRUE(everything->contact().active);
  const auto no_cutting = run_scene(true, false);
  EXPECT_TRUE(no_cutting->body().cut_tets().empty());
  EXPECT_THROW((void)no_cutting->cutter(), std::logic_error);
  EXPECT_TRUE(no_cutting->contact().active);
  const auto no_contact = run_scene(false, true);
  EXPECT_EQ(no_contact->body().cut_tets().size(), 20u);
  EXPECT_FALSE(no_contact->contact().active);
  const auto neither = run_scene(false, false);
  EXPECT_TRUE(neither->body().cut_tets().empty());
  EXPECT_FALSE(neither->contact().active);
  EXPECT_TRUE(neither->state().displacement_m.allFinite());
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
