// The clamp and the rate limiter (force_limits.hpp), alone and in the renderer: a cut that releases
// the tissue's tension (3 N to 0 at once) and a contact appearing at 3 N under a resting tool reach
// the hand at no more than max_force_rate_n_per_s, and nothing ever exceeds max_force_n.
#include "haptic/force_limits.hpp"
#include "haptic/haptic_renderer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace tissue::haptic {
namespace {

constexpr double DT_S = 1e-3;
/// Rounding slack on the limits: the scalings land within an ulp or two of the bound.
constexpr double SLACK_N = 1e-12;

TEST(ForceLimits, ClampScalesTheMagnitudeDownAndKeepsTheDirection) {
  const Eigen::Vector3d f(3.0, 4.0, 12.0);  // 13 N
  const LimitedForce clamped = clamp_magnitude(f, 3.3);
  EXPECT_TRUE(clamped.acted);
  EXPECT_NEAR(clamped.force_n.norm(), 3.3, SLACK_N);
  EXPECT_LT((clamped.force_n - f * (3.3 / 13.0)).norm(), SLACK_N);
  const LimitedForce untouched = clamp_magnitude(Eigen::Vector3d(1.0, -2.0, 0.5), 3.3);
  EXPECT_FALSE(untouched.acted);
  EXPECT_EQ(untouched.force_n, Eigen::Vector3d(1.0, -2.0, 0.5));
}

TEST(ForceLimits, RateLimiterMovesAtMostTheAllowedChangeAlongTheStraightLine) {
  const Eigen::Vector3d previous(0.0, 1.0, 2.0);
  const Eigen::Vector3d target(2.0, -1.0, 3.0);  // 3 N away
  const LimitedForce limited = limit_rate(previous, target, 0.3);
  EXPECT_TRUE(limited.acted);
  EXPECT_NEAR((limited.force_n - previous).norm(), 0.3, SLACK_N);
  EXPECT_LT((limited.force_n - (previous + 0.1 * (target - previous))).norm(), SLACK_N);
  EXPECT_EQ(limit_rate(previous, target, std::numeric_limits<double>::infinity()).force_n, target);
}

/// A resting tool in a contact whose force is exactly f0 (K_c = 0): 60 ticks of contact appearing at
/// 3 N, then a cut releasing it (contact flagged inactive), then 60 ticks without, then the contact
/// back. Returns the commanded forces.
std::vector<Eigen::Vector3d> release_and_new_contact(const RendererSettings& settings) {
  HapticRenderer renderer(settings);
  TissueSample contact;
  contact.contact_active = true;
  contact.contact_normal = Eigen::Vector3d(0.0, 0.6, 0.8);
  contact.contact_point_m = Eigen::Vector3d(0.02, 0.0, 0.05);
  contact.tool_position_m = contact.contact_point_m - 1e-3 * contact.contact_normal;
  contact.force_on_tool_n = 3.0 * contact.contact_normal;
  TissueSample released = contact;
  released.contact_active = false;
  released.force_on_tool_n.setZero();

  std::vector<Eigen::Vector3d> forces;
  for (const TissueSample* sample : {&contact, &released, &contact}) {
    renderer.set_sample(*sample);
    for (int i = 0; i < 60; ++i) forces.push_back(renderer.tick(contact.tool_position_m, ToolMode::probe, DT_S));
  }
  return forces;
}

double largest_change_n(const std::vector<Eigen::Vector3d>& forces) {
  double largest = forces.front().norm();  // from zero before the first tick
  for (std::size_t i = 1; i < forces.size(); ++i) largest = std::max(largest, (forces[i] - forces[i - 1]).norm());
  return largest;
}

// 300 N/s x 1 ms = 0.3 N per tick: 3 N is reached (or left) in exactly 10 ticks, never faster.
TEST(ForceLimits, ACutReleasingTensionAndANewContactReachTheHandAtTheRateLimit) {
  RendererSettings settings;
  settings.max_force_rate_n_per_s = 300.0;  // not the default: ten ticks to watch
  const std::vector<Eigen::Vector3d> forces = release_and_new_contact(settings);
  const double step_n = settings.max_force_rate_n_per_s * DT_S;
  EXPECT_LE(largest_change_n(forces), step_n + SLACK_N);
  for (const Eigen::Vector3d& f : forces) EXPECT_LE(f.norm(), settings.max_force_n + SLACK_N);
  // The contact appearing: 0.3 N, 0.6 N, ... 3 N at the 10th tick.
  EXPECT_NEAR(forces[0].norm(), 0.3, SLACK_N);
  EXPECT_NEAR(forces[8].norm(), 2.7, 1e-9);
  EXPECT_NEAR(forces[9].norm(), 3.0, 1e-9);
  // The release: 2.7 N after the first tick, zero at the 10th.
  EXPECT_NEAR(forces[60].norm(), 2.7, 1e-9);
  EXPECT_GT(forces[68].norm(), 0.0);
  EXPECT_LT(forces[69].norm(), 1e-9);
}

// The same script with the limiter off: the commanded force jumps by the full 3 N in one tick, which
// the assertion above would catch.
TEST(ForceLimits, WithoutTheRateLimitTheReleaseIsAJump) {
  RendererSettings settings;
  settings.max_force_rate_n_per_s = std::numeric_limits<double>::infinity();
  const std::vector<Eigen::Vector3d> forces = release_and_new_contact(settings);
  std::printf("  largest change per tick without the limit: %.3f N\n", largest_change_n(forces));
  EXPECT_NEAR(largest_change_n(forces), 3.0, 1e-9);
}

// A tissue force beyond the device: the command saturates at max_force_n along f0, never above,
// also with the tool moving in the contact and the passivity controller adding damping.
TEST(ForceLimits, NothingExceedsTheMaximumForceOrTheRateEvenWithTheControllerActing) {
  const RendererSettings settings;
  HapticRenderer renderer(settings);
  TissueSample contact;
  contact.contact_active = true;
  contact.contact_normal = Eigen::Vector3d::UnitZ();
  contact.force_on_tool_n = {1.0, 0.0, 5.0};  // beyond the 3.3 N device
  contact.contact_stiffness_n_per_m = 3000.0 * Eigen::Matrix3d::Identity();
  contact.tool_position_m = {0.0, 0.0, -2e-3};
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  double largest_n = 0.0;
  double largest_change = 0.0;
  int controller_ticks = 0;
  for (int k = 0; k < 3000; ++k) {
    const double t = k * DT_S;
    if (k % 33 == 0) {  // stale samples at 30 Hz, force jumping between 0 and 5.1 N every other one
      contact.force_on_tool_n = (k / 33) % 2 == 0 ? Eigen::Vector3d(1.0, 0.0, 5.0) : Eigen::Vector3d(0.0, 0.0, 0.1);
      renderer.set_sample(contact);
    }
    const Eigen::Vector3d x(3e-3 * std::sin(9.0 * t), 0.0, -2e-3 + 1.5e-3 * std::sin(13.0 * t));
    const Eigen::Vector3d f = renderer.tick(x, ToolMode::probe, DT_S);
    largest_n = std::max(largest_n, f.norm());
    largest_change = std::max(largest_change, (f - previous).norm());
    controller_ticks += renderer.last_tick().passivity_acted ? 1 : 0;
    previous = f;
  }
  std::printf("  largest |f| %.6f N, largest change %.6f N per tick, controller acted in %d ticks\n", largest_n,
              largest_change, controller_ticks);
  EXPECT_LE(largest_n, settings.max_force_n + SLACK_N);
  EXPECT_NEAR(largest_n, settings.max_force_n, 1e-9);  // it does saturate
  EXPECT_LE(largest_change, settings.max_force_rate_n_per_s * DT_S + SLACK_N);
  EXPECT_GT(controller_ticks, 0);
}

}  // namespace
}  // namespace tissue::haptic
