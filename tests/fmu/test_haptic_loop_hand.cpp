// The closed-loop harness's own checks (issue 20): a hand that answers the force, on HapticLoop.fmu
// through the importer, with 100 Hz samples one step late. Where the loop is known to be stable
// (a soft force-only wall, a 5 N s/m hand, the controller off) the hand rests at the static depth
// f / K; bad samples are refused and counted while the hand's loop goes on. (The loop's failures on stiff walls are
// measured by hand_on_walls, docs/BENCHMARKS.md "Haptic loop".)
#include "hand_on_tissue.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

namespace tissue::host::hand_test {
namespace {

TEST(HandOnTissue, RestsAtTheStaticDepthOnASoftWall) {
  LoopSettings settings;
  settings.hand.damping_n_s_per_m = 5.0;
  settings.hand.push_n = {0.0, 0.0, -0.5};
  settings.passivity_control = false;
  settings.duration_s = 6.0;
  Wall wall(300.0, false);
  const LoopResult r = run_hand_on(wall, settings);
  ASSERT_TRUE(r.completed) << r.failure;
  std::printf("  window %.3f s, residual %.3g m/s, penetration %.4g m, settle %.3f s, work %.3g J\n", r.hand.window_s,
              r.hand.residual_speed_m_per_s, r.penetration_m(), r.hand.settle_time_s, r.hand.device_work_j);
  // Statics: the hand's push against the wall's force, K d = p (the samples' lag does not move the
  // rest point). 1% for what is left of the settling after 6 s.
  EXPECT_NEAR(r.penetration_m(), 0.5 / 300.0, 0.01 * 0.5 / 300.0);
  EXPECT_NEAR(r.hand.mean_force_n[2], 0.5, 0.005);
  EXPECT_LT(r.hand.residual_speed_m_per_s, 2e-3);
  EXPECT_TRUE(std::isfinite(r.hand.settle_time_s));
}

TEST(HandOnTissue, BadSamplesAreRefusedAndTheHandsLoopGoesOn) {
  LoopSettings settings;
  settings.hand.damping_n_s_per_m = 5.0;
  settings.hand.push_n = {0.0, 0.0, -0.5};
  settings.passivity_control = false;
  settings.duration_s = 6.0;
  CorruptedSamples tissue(std::make_unique<Wall>(300.0, false), 7);
  const LoopResult r = run_hand_on(tissue, settings);
  ASSERT_TRUE(r.completed) << r.failure;
  // 599 samples delivered in 6 s (the 600th, in flight, is not a bad one: 600 = 85 x 7 + 5): the
  // 85 with a NaN force are not forwarded (FMI refuses a non-finite Float64), and of the 86 with a
  // normal of length 2 the loop refuses exactly those in contact (not while the hand falls or bounces
  // off; an out-of-contact sample's normal is not used).
  EXPECT_EQ(r.samples_not_finite, 85u);
  EXPECT_EQ(r.samples_refused, static_cast<std::uint64_t>(tissue.long_normals_in_contact()));
  EXPECT_GT(tissue.long_normals_in_contact(), 60);
  EXPECT_TRUE(std::isfinite(r.penetration_m()));
  EXPECT_NEAR(r.penetration_m(), 0.5 / 300.0, 0.05 * 0.5 / 300.0);
}

}  // namespace
}  // namespace tissue::host::hand_test
