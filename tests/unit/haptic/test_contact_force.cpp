// The intermediate representation and the unilateral constraint (contact_force.hpp): the rendered
// force is f0 - K_c (x - x0) inside the contact plane and as far out as the pressed surface rebounds,
// nothing beyond, and never a pull inward.
#include "haptic/contact_force.hpp"
#include "haptic/haptic_renderer.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <limits>

namespace tissue::haptic {
namespace {

/// A contact on a tilted surface with an anisotropic, coupled K_c (eigenvalues 300, 800, 2000 N/m
/// along rotated axes), so that a wrong sign, transpose or axis shows.
TissueSample tilted_contact() {
  TissueSample sample;
  sample.contact_active = true;
  sample.contact_point_m = {0.01, -0.02, 0.03};
  sample.contact_normal = Eigen::Vector3d(1.0, 2.0, 3.0).normalized();
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1.0, 0.5).normalized()).toRotationMatrix();
  sample.contact_stiffness_n_per_m =
      rotation * Eigen::Vector3d(300.0, 800.0, 2000.0).asDiagonal() * rotation.transpose();
  sample.tool_position_m = sample.contact_point_m - 1e-3 * sample.contact_normal + Eigen::Vector3d(2e-4, 1e-4, -1e-4);
  sample.force_on_tool_n = sample.contact_stiffness_n_per_m * (sample.contact_point_m - sample.tool_position_m);
  return sample;
}

/// f0 - K_c (x - x0) written out component by component (independent of the library's expression).
Eigen::Vector3d expected_force(const TissueSample& s, const Eigen::Vector3d& x) {
  Eigen::Vector3d f;
  for (int i = 0; i < 3; ++i) {
    f[i] = s.force_on_tool_n[i];
    for (int j = 0; j < 3; ++j) f[i] -= s.contact_stiffness_n_per_m(i, j) * (x[j] - s.tool_position_m[j]);
  }
  return f;
}

// Tolerance 1e-12 N: a few products of ~2000 N/m and ~1e-3 m, each rounded at 1e-16 relative.
TEST(ContactForce, InsideThePlaneTheForceIsF0MinusKcTimesTheDisplacement) {
  const TissueSample s = tilted_contact();
  ASSERT_GT(s.force_on_tool_n.dot(s.contact_normal), 0.0);
  const Eigen::Vector3d tangent = s.contact_normal.unitOrthogonal();
  for (double depth_m : {5e-4, 1e-3, 1.5e-3}) {
    for (double slide_m : {-2e-4, 0.0, 2e-4}) {
      const Eigen::Vector3d x = s.contact_point_m - depth_m * s.contact_normal + slide_m * tangent;
      const Eigen::Vector3d f = unilateral_force(intermediate_force(s, x), s, x);
      ASSERT_GE(expected_force(s, x).dot(s.contact_normal), 0.0);
      EXPECT_LT((f - expected_force(s, x)).norm(), 1e-12) << "depth " << depth_m << " slide " << slide_m;
    }
  }
  // At the sample's own tool position the force is f0 itself.
  EXPECT_EQ(intermediate_force(s, s.tool_position_m), s.force_on_tool_n);
}

// The sign convention: pushing the tool deeper by d along -n adds d K_c n, so the outward (normal)
// force grows by d n^T K_c n > 0.
TEST(ContactForce, PushingDeeperIncreasesTheOutwardForceByTheNormalStiffness) {
  const TissueSample s = tilted_contact();
  const Eigen::Vector3d& n = s.contact_normal;
  const double normal_stiffness = n.dot(s.contact_stiffness_n_per_m * n);
  const Eigen::Vector3d x = s.contact_point_m - 5e-4 * n;
  const double d = 1e-4;
  const double gain_n = (intermediate_force(s, x - d * n) - intermediate_force(s, x)).dot(n);
  EXPECT_GT(gain_n, 0.0);
  EXPECT_NEAR(gain_n, d * normal_stiffness, 1e-12);
}

/// How far the pressed surface of `s` follows the tool back: f_n / k_n.
double rebound_m(const TissueSample& s) {
  const Eigen::Vector3d& n = s.contact_normal;
  return s.force_on_tool_n.dot(n) / n.dot(s.contact_stiffness_n_per_m * n);
}

TEST(ContactForce, BeyondThePressedSurfacesReboundThereIsNoForce) {
  const TissueSample s = tilted_contact();
  const Eigen::Vector3d tangent = s.contact_normal.unitOrthogonal();
  for (double beyond : {1e-9, 0.1, 10.0}) {
    const Eigen::Vector3d x = s.contact_point_m + (1.0 + beyond) * rebound_m(s) * s.contact_normal + 3e-3 * tangent;
    // The linear model would still push (it extrapolates beyond the surface)...
    ASSERT_GT(intermediate_force(s, x).norm(), 0.0);
    // ...the constraint does not.
    EXPECT_EQ(unilateral_force(intermediate_force(s, x), s, x), Eigen::Vector3d::Zero()) << beyond;
  }
}

// The sample's contact point is the surface pressed down to within microns of the tool (the Tissue's
// contact spring), so a tool drawn back by more than that is outside the plane through it; the
// pressed surface follows it back (its rebound f_n / k_n, 1 mm here), and the force is the linear
// model's, not nothing (issue 20: the hand easing off a press lost the whole force and chattered).
TEST(ContactForce, APressedSurfaceFollowsTheToolBackByItsRebound) {
  TissueSample s = tilted_contact();
  const Eigen::Vector3d& n = s.contact_normal;
  s.tool_position_m = s.contact_point_m - 1e-6 * n;  // the spring's gap
  s.force_on_tool_n = 1.0 * n;
  ASSERT_GT(rebound_m(s), 1e-4);
  for (double back_m : {1e-5, 1e-4, 0.9 * rebound_m(s)}) {
    const Eigen::Vector3d x = s.contact_point_m + back_m * n;
    ASSERT_GT((x - s.contact_point_m).dot(n), 0.0);  // outside the plane through the contact point
    const Eigen::Vector3d f = unilateral_force(intermediate_force(s, x), s, x);
    EXPECT_LT((f - expected_force(s, x)).norm(), 1e-12) << back_m;
    EXPECT_GT(f.dot(n), 0.0) << back_m;
  }
}

// A sample whose f0 is small and whose K_c couples sliding into the normal direction: sliding far
// enough, the linear model pulls inward. The constraint then gives nothing at all (tangential part
// included); elsewhere it gives the linear model unchanged. Checked over a grid of tool positions.
TEST(ContactForce, TheForceNeverPullsTheToolIntoTheSurface) {
  TissueSample s = tilted_contact();
  s.force_on_tool_n = 0.05 * s.contact_normal;
  s.tool_position_m = s.contact_point_m - 1e-5 * s.contact_normal;
  const Eigen::Vector3d& n = s.contact_normal;
  const Eigen::Vector3d t1 = n.unitOrthogonal();
  const Eigen::Vector3d t2 = n.cross(t1);
  int pulling = 0;
  int pushing = 0;
  for (int i = -10; i <= 10; ++i) {
    for (int j = -10; j <= 10; ++j) {
      for (int k = 1; k <= 5; ++k) {
        const Eigen::Vector3d x = s.contact_point_m + 4e-4 * (i * t1 + j * t2) - 1e-5 * k * n;
        const Eigen::Vector3d linear = intermediate_force(s, x);
        const Eigen::Vector3d f = unilateral_force(linear, s, x);
        EXPECT_GE(f.dot(n), 0.0);
        if (linear.dot(n) < 0.0) {
          ++pulling;
          EXPECT_EQ(f, Eigen::Vector3d::Zero());
        } else {
          ++pushing;
          EXPECT_EQ(f, linear);
        }
      }
    }
  }
  // Both cases occur, so the grid exercises the constraint.
  EXPECT_GT(pulling, 100);
  EXPECT_GT(pushing, 100);
}

// Through the renderer (default settings: clamp, rate limit, controller on): a tool held still in
// the contact settles on the intermediate-representation force, and a contact flagged inactive
// renders nothing. Tolerance 1e-12 N as above (a still tool: no damping, no cutting).
TEST(ContactForce, TheRendererHoldsTheContactForceOnAStillTool) {
  const TissueSample s = tilted_contact();
  HapticRenderer renderer;
  renderer.set_sample(s);
  const Eigen::Vector3d x = s.contact_point_m - 6e-4 * s.contact_normal;
  ASSERT_LT(expected_force(s, x).norm(), renderer.settings().max_force_n);
  Eigen::Vector3d f;
  for (int i = 0; i < 50; ++i) f = renderer.tick(x, ToolMode::probe, 1e-3);
  EXPECT_LT((f - expected_force(s, x)).norm(), 1e-12);
  EXPECT_FALSE(renderer.last_tick().passivity_acted);

  TissueSample released = s;
  released.contact_active = false;
  renderer.set_sample(released);
  for (int i = 0; i < 50; ++i) f = renderer.tick(x, ToolMode::probe, 1e-3);
  EXPECT_EQ(f, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace tissue::haptic

namespace tissue::haptic {
namespace {

// The tissue's viscosity (D_c): f0 holds D_c v0, v0 the tool's velocity over the tissue's step, which
// the renderer takes from the last two samples' tool positions and times; it renders f0 - K_c (x -
// x0) - D_c (v - v0) with v the hand's velocity now (backward difference). A hand moving on as the
// tool did feels f0 at x0; a hand stopping feels the viscous part gone. Limits, controller and the
// loop's own damping off so that the formula is all there is. Tolerance 1e-9 N: velocities are
// differences of positions ~1e-2 m over 1e-3 s (rounding ~1e-13 m/s) times D_c ~ 10 N s/m.
TEST(ContactForce, TheTissuesViscosityIsRenderedAtTheVelocityNow) {
  RendererSettings settings;
  settings.max_force_n = 100.0;
  settings.max_force_rate_n_per_s = std::numeric_limits<double>::infinity();
  settings.passivity_control = false;
  settings.contact_damping_n_s_per_m = 0.0;
  settings.hold_damping = false;
  HapticRenderer renderer(settings);
  TissueSample s = tilted_contact();
  const Eigen::Vector3d& n = s.contact_normal;
  s.contact_damping_n_s_per_m = 10.0 * (n * n.transpose()).eval() + 2.0 * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d v0 = -0.05 * n + 0.01 * n.unitOrthogonal();  // pressing in, sliding a little
  const double dt = 1e-3, period = 1e-2;
  TissueSample first = s;
  first.time_s = 1.0;
  first.tool_position_m = s.tool_position_m - period * v0;
  renderer.set_sample(first);
  s.time_s = first.time_s + period;
  renderer.set_sample(s);
  EXPECT_LT((renderer.sample_tool_velocity_m_per_s() - v0).norm(), 1e-12);
  for (const Eigen::Vector3d& v : {v0, Eigen::Vector3d::Zero().eval(), (2.0 * v0).eval()}) {
    renderer.tick(s.tool_position_m - dt * v, ToolMode::probe, dt);
    const Eigen::Vector3d f = renderer.tick(s.tool_position_m, ToolMode::probe, dt);
    const Eigen::Vector3d expected = s.force_on_tool_n - s.contact_damping_n_s_per_m * (v - v0);
    EXPECT_LT((f - expected).norm(), 1e-9) << "v = " << v.transpose();
  }
  // A sample after one out of contact has no v0: the tool's motion before is not the tissue's.
  TissueSample away = s;
  away.contact_active = false;
  renderer.set_sample(away);
  s.time_s += period;
  renderer.set_sample(s);
  EXPECT_EQ(renderer.sample_tool_velocity_m_per_s(), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace tissue::haptic
