// The contact model of a force-only tissue from its samples (normal_model_estimate.hpp, issue 42):
// a Kelvin-Voigt wall f_n = K p + c q (p the depth along a tilted normal, q its rate over the sample
// period, as the tissue computes it) gives back K and c exactly once the tool's speed changes between
// two sample pairs; at a constant speed c cannot be told from the offset and stays, K exact; a
// reported D_c is kept and only K estimated; out-of-range solutions fall back. The last force-only
// contact's plane is rendered, at the crossing tick, while the tool stays near where it touched, and
// nowhere else.
#include "haptic/haptic_renderer.hpp"
#include "haptic/normal_model_estimate.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <optional>

namespace tissue::haptic {
namespace {

constexpr double K = 1800.0;   // N/m
constexpr double C = 27.0;     // N s/m
constexpr double PERIOD_S = 0.01;

// The wall's sample for a tool at depth p(t) along n (the tissue's rate from its own last two samples).
TissueSample wall_sample(double time_s, double depth_m, double previous_depth_m, bool reports_damping) {
  TissueSample s;
  s.time_s = time_s;
  s.contact_active = true;
  s.contact_normal = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  s.contact_point_m = Eigen::Vector3d(0.01, 0.02, 0.0);
  s.tool_position_m = s.contact_point_m - depth_m * s.contact_normal + Eigen::Vector3d(1e-4, 2e-4, 0.0).cross(s.contact_normal);
  const double rate = (depth_m - previous_depth_m) / PERIOD_S;
  s.force_on_tool_n = (K * depth_m + C * rate) * s.contact_normal;
  if (reports_damping) s.contact_damping_n_s_per_m = C * s.contact_normal * s.contact_normal.transpose();
  return s;
}

double depth_at(int k) { return 1e-3 + 4e-4 * std::sin(0.9 * k); }  // a hand ringing at ~14 Hz

TEST(NormalModelEstimate, AKelvinVoigtWallGivesBackItsStiffnessAndDamping) {
  for (const bool reports_damping : {false, true}) {
    HapticRenderer renderer;
    for (int k = 1; k <= 6; ++k) {
      renderer.set_sample(wall_sample(k * PERIOD_S, depth_at(k), depth_at(k - 1), reports_damping));
      const Eigen::Vector3d& n = renderer.sample().contact_normal;
      const double k_n = n.dot(renderer.sample().contact_stiffness_n_per_m * n);
      const double c_n = n.dot(renderer.sample().contact_damping_n_s_per_m * n);
      if (k == 1) {
        EXPECT_EQ(k_n, 0.0) << "the contact's first sample is held";
      } else if (k >= (reports_damping ? 3 : 4)) {
        // The first sample's rate is unknown to the loop (no sample before it), so the first pair's
        // rate change is off: one pair after it gives K with c known, two split K from c.
        EXPECT_NEAR(k_n, K, 1e-6 * K) << "sample " << k;
        EXPECT_NEAR(c_n, C, 1e-6 * C) << "sample " << k;
        EXPECT_NEAR((renderer.sample().contact_stiffness_n_per_m - k_n * n * n.transpose()).norm(), 0.0, 1e-9 * K);
      }
    }
  }
}

TEST(NormalModelEstimate, AtAConstantSpeedTheDampingStaysAndTheStiffnessIsExact) {
  const NormalModelLimits limits;
  const NormalModel last{500.0, 10.0};
  // Pairs at the same speed: dq = 0, the two equations are one; df = K dp.
  const NormalPair pair{2e-4, 0.0, K * 2e-4}, previous{2e-4, 0.0, K * 2e-4};
  const NormalModel model = estimate_normal_model(last, pair, previous, false, limits);
  EXPECT_NEAR(model.stiffness_n_per_m, K, 1e-9 * K);
  EXPECT_EQ(model.damping_n_s_per_m, 10.0);
  // Motion at the rounding level (a hand at rest): the joint solve is not tried, the model stands.
  const NormalModel at_rest =
      estimate_normal_model(last, NormalPair{-1.4e-18, 5.4e-17, 6.7e-16}, NormalPair{1.2e-18, 9.6e-16, 7.8e-14}, false,
                            limits);
  EXPECT_EQ(at_rest.stiffness_n_per_m, 500.0);
  EXPECT_EQ(at_rest.damping_n_s_per_m, 10.0);
  // No motion: the last model stands.
  const NormalModel held = estimate_normal_model(last, NormalPair{1e-8, 0.0, 0.3}, previous, false, limits);
  EXPECT_EQ(held.stiffness_n_per_m, 500.0);
  EXPECT_EQ(held.damping_n_s_per_m, 10.0);
}

TEST(NormalModelEstimate, SolutionsOutOfRangeFallBackToTheSecant) {
  NormalModelLimits limits;
  const NormalModel last{500.0, 10.0};
  // A force that fell as the tool went deeper, with a rate change that makes the joint solve negative:
  // the secant (clamped at 0) and the last c.
  const NormalPair pair{2e-4, 0.02, -0.5}, previous{-1e-4, 0.03, 0.2};
  const NormalModel model = estimate_normal_model(last, pair, previous, false, limits);
  EXPECT_EQ(model.damping_n_s_per_m, 10.0);
  EXPECT_EQ(model.stiffness_n_per_m, 0.0);
  // A stiffness above the limit is clamped.
  limits.max_stiffness_n_per_m = 1000.0;
  const NormalModel stiff = estimate_normal_model(NormalModel{}, NormalPair{1e-4, 0.0, 0.5}, std::nullopt, false, limits);
  EXPECT_EQ(stiff.stiffness_n_per_m, 1000.0);
  // max_estimated_stiffness 0 (no estimate) allows no damping either.
  limits.max_stiffness_n_per_m = 0.0;
  const NormalModel none = estimate_normal_model(NormalModel{}, NormalPair{2e-4, 0.02, 0.6}, previous, false, limits);
  EXPECT_EQ(none.stiffness_n_per_m, 0.0);
  EXPECT_EQ(none.damping_n_s_per_m, 0.0);
}

// After a force-only contact the samples say neither contact nor near (such a tissue has no near
// report): the plane of the last contact, with its estimated K, is rendered from the tick the tool
// crosses it, as long as the tool stays within 1 cm of where it touched; once it has left, the plane
// is dropped (a plane says nothing of the tissue elsewhere: a tool going down beside the body must
// feel nothing).
TEST(NormalModelEstimate, TheLastForceOnlyContactsPlaneStandsInForTheSurfaceNear) {
  RendererSettings settings;
  settings.contact_damping_n_s_per_m = 0.0;
  settings.hold_damping = false;
  settings.passivity_control = false;
  settings.max_force_rate_n_per_s = 1e12;
  HapticRenderer renderer(settings);
  for (int k = 1; k <= 5; ++k) renderer.set_sample(wall_sample(k * PERIOD_S, depth_at(k), depth_at(k - 1), false));
  TissueSample away;  // the tool drawn out: no contact, no near
  away.time_s = 6 * PERIOD_S;
  away.tool_position_m = Eigen::Vector3d(0.01, 0.02, 0.005);
  renderer.set_sample(away);
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const Eigen::Vector3d point(0.01, 0.02, 0.0);
  const double dt = 1e-3;
  (void)renderer.tick(point + 2e-3 * n, ToolMode::probe, dt);
  EXPECT_EQ(renderer.last_tick().contact_force_n.norm(), 0.0) << "outside the plane";
  (void)renderer.tick(point - 1e-4 * n, ToolMode::probe, dt);  // 0.1 mm in, at once: the damper too
  EXPECT_NEAR(renderer.last_tick().contact_force_n.dot(n), K * 1e-4 + C * (2.1e-3 / dt), 1e-6 * C * (2.1e-3 / dt));
  (void)renderer.tick(point - 1e-4 * n, ToolMode::probe, dt);  // held there: K 0.1 mm along n
  EXPECT_NEAR(renderer.last_tick().contact_force_n.dot(n), K * 1e-4, 1e-6 * K * 1e-4);
  // Saved and restored, the plane goes on.
  HapticRenderer restored(settings);
  restored.restore_state(renderer.save_state());
  (void)restored.tick(point - 2e-4 * n, ToolMode::probe, dt);
  (void)renderer.tick(point - 2e-4 * n, ToolMode::probe, dt);
  EXPECT_EQ(restored.last_tick().contact_force_n, renderer.last_tick().contact_force_n);
  // 2 cm aside, then down through the plane's height: nothing, and nothing once back either.
  const Eigen::Vector3d aside = point + Eigen::Vector3d(0.02, 0.0, 0.0);
  (void)renderer.tick(aside + 2e-3 * n, ToolMode::probe, dt);
  (void)renderer.tick(aside - 1e-3 * n, ToolMode::probe, dt);
  EXPECT_EQ(renderer.last_tick().contact_force_n.norm(), 0.0) << "the plane extended beside the body";
  (void)renderer.tick(point - 1e-4 * n, ToolMode::probe, dt);
  EXPECT_EQ(renderer.last_tick().contact_force_n.norm(), 0.0) << "the plane came back after the tool left";
}

// The plane is the tissue's last word, not a wall of the loop's own: a sample that says "no contact"
// for a tool the plane has inside (the tissue sagged, fell or was cut away) drops it, so that the
// loop renders no phantom wall where the tissue no longer is (at most until that sample arrives).
TEST(NormalModelEstimate, ASampleWithoutContactInsideThePlaneDropsIt) {
  RendererSettings settings;
  settings.passivity_control = false;
  HapticRenderer renderer(settings);
  for (int k = 1; k <= 5; ++k) renderer.set_sample(wall_sample(k * PERIOD_S, depth_at(k), depth_at(k - 1), false));
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const Eigen::Vector3d point(0.01, 0.02, 0.0);
  TissueSample gone;  // the tool 1 mm inside the old plane, and the tissue touched nothing
  gone.time_s = 6 * PERIOD_S;
  gone.tool_position_m = point - 1e-3 * n;
  renderer.set_sample(gone);
  (void)renderer.tick(point - 1e-3 * n, ToolMode::probe, 1e-3);
  (void)renderer.tick(point - 1e-3 * n, ToolMode::probe, 1e-3);
  EXPECT_EQ(renderer.last_tick().contact_force_n.norm(), 0.0) << "a phantom wall where the tissue was";
}

}  // namespace
}  // namespace tissue::haptic
