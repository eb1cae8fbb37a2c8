// The intermediate representation and the unilateral constraint (contact_force.hpp): the rendered
// force is f0 - K_c (x - x0) inside the contact plane, nothing outside, and never a pull inward.
#include "haptic_loop/core/contact_force.hpp"
#include "haptic_loop/core/haptic_renderer.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

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

TEST(ContactForce, OutsideTheContactPlaneThereIsNoForce) {
  const TissueSample s = tilted_contact();
  const Eigen::Vector3d tangent = s.contact_normal.unitOrthogonal();
  for (double height_m : {1e-9, 1e-4, 1e-2}) {
    const Eigen::Vector3d x = s.contact_point_m + height_m * s.contact_normal + 3e-3 * tangent;
    // The linear model would still push (it extrapolates beyond the surface)...
    ASSERT_GT(intermediate_force(s, x).norm(), 0.0);
    // ...the constraint does not.
    EXPECT_EQ(unilateral_force(intermediate_force(s, x), s, x), Eigen::Vector3d::Zero()) << height_m;
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
