// The closed-loop harness's own checks (issue 20): a hand that answers the force, on HapticLoop.fmu
// through the importer, with 100 Hz samples one step late. Where the loop is known to be stable
// (a soft force-only wall, a 5 N s/m hand, the controller off) the hand rests at the static depth
// f / K; bad samples are refused and counted while the hand's loop goes on. (The loop's failures on stiff walls are
// measured by hand_on_walls, docs/BENCHMARKS.md "Haptic loop".)
#include "hand_on_tissue.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <limits>
#include <memory>
#include <string>

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

namespace tissue::host::hand_test {
namespace {

// Issue 20: a 0.2 kg hand damped by 1 N s/m pushing 1 N, dropped from 1 cm, settles on walls up to
// 2000 N/m whether the samples carry K_c or the force only: its speed over the last second under
// 2 mm/s, no chatter above 10 um, and its mean depth within 10% of the static f / K.
TEST(HandOnTissue, SettlesOnStiffWallsWithAndWithoutTheStiffness) {
  for (const double stiffness : {300.0, 1000.0, 2000.0}) {
    for (const bool reports_stiffness : {true, false}) {
      LoopSettings settings;
      settings.hand.damping_n_s_per_m = 1.0;
      settings.hand.push_n = {0.0, 0.0, -1.0};
      settings.duration_s = 5.0;
      Wall wall(stiffness, reports_stiffness);
      const LoopResult r = run_hand_on(wall, settings);
      ASSERT_TRUE(r.completed) << r.failure;
      std::printf("  %s: residual %.3g mm/s, chatter %.3g um, depth %.4g mm (static %.4g), settled at %.3f s, "
                  "lowest one-port energy %.3g J\n",
                  wall.name().c_str(), 1e3 * r.hand.residual_speed_m_per_s, 1e6 * r.hand.chatter_amplitude_m,
                  1e3 * r.penetration_m(), 1e3 / stiffness, r.hand.settle_time_s, r.lowest_one_port_energy_j);
      EXPECT_LT(r.hand.residual_speed_m_per_s, 2e-3) << wall.name();
      EXPECT_LT(r.hand.chatter_amplitude_m, 10e-6) << wall.name();
      EXPECT_NEAR(r.penetration_m(), 1.0 / stiffness, 0.1 / stiffness) << wall.name();
    }
  }
}

struct Hand {
  double mass_kg, damping_n_s_per_m;
};

struct Worst {
  double lowest_one_port_energy_j = std::numeric_limits<double>::infinity();
  double deepest_m = -std::numeric_limits<double>::infinity();
  std::string which;
};

// Hands of 0.05-1 kg and 0.5-10 N s/m pushing 1 N, dropped on a 2000 N/m wall (K_c reported), with
// device.maxForce 3.3 N (rate limited) or 100 N (no rate limit): the worst of each figure.
Worst worst_run(double min_hand_mass_kg) {
  Worst worst;
  for (const Hand hand : {Hand{0.05, 0.5}, Hand{0.05, 10.0}, Hand{0.2, 1.0}, Hand{0.2, 5.0}, Hand{1.0, 0.5},
                          Hand{1.0, 10.0}}) {
    for (const double max_force_n : {3.3, 100.0}) {
      LoopSettings settings;
      settings.hand.mass_kg = hand.mass_kg;
      settings.hand.damping_n_s_per_m = hand.damping_n_s_per_m;
      settings.hand.push_n = {0.0, 0.0, -1.0};
      settings.max_force_n = max_force_n;
      settings.max_force_rate_n_per_s = max_force_n > 10.0 ? 1e9 : 300.0;
      settings.min_hand_mass_kg = min_hand_mass_kg;
      Wall wall(2000.0, true);
      const LoopResult r = run_hand_on(wall, settings);
      EXPECT_TRUE(r.completed) << r.failure;
      std::printf("  hand %.2f kg, %4.1f N s/m, maxForce %5.1f N: lowest one-port energy %9.3g J, depth %8.3g mm, "
                  "residual %8.3g mm/s\n",
                  hand.mass_kg, hand.damping_n_s_per_m, max_force_n, r.lowest_one_port_energy_j,
                  1e3 * r.penetration_m(), 1e3 * r.hand.residual_speed_m_per_s);
      if (r.lowest_one_port_energy_j < worst.lowest_one_port_energy_j) {
        worst.lowest_one_port_energy_j = r.lowest_one_port_energy_j;
        worst.which = std::to_string(hand.mass_kg) + " kg, " + std::to_string(hand.damping_n_s_per_m) +
                      " N s/m, maxForce " + std::to_string(max_force_n) + " N";
      }
      worst.deepest_m = std::max(worst.deepest_m, r.penetration_m());
    }
  }
  return worst;
}

// The passivity controller's damping is bounded by passivity.minHandMass / (2 dt) (passivity.hpp), so
// that it never throws a hand back within a tick. Unbounded, it runs away: a light hand on a stiff
// wall with a strong device gains joules and is driven decimetres into the wall (the fix switched
// off, asserted below). Bounded, what the loop still gives a hand is the late onset of a contact
// (samples at 100 Hz, one step late: the wall pushes out harder than it was pushed in), a few
// millijoules per impact: under 50 mJ and 3 cm for every hand here (measured: 19 mJ, 21 mm at
// worst, the 0.05 kg hand at 0.5 N s/m). Issue 20's -1 mJ needs the contact to start at the tick
// the tool crosses the surface (docs/BENCHMARKS.md, Haptic loop).
TEST(HandOnTissue, TheBoundedControllerDoesNotRunAway) {
  const Worst bounded = worst_run(0.05);
  std::printf(" bounded (passivity.minHandMass 0.05 kg): lowest %.3g J (%s), deepest %.3g mm\n",
              bounded.lowest_one_port_energy_j, bounded.which.c_str(), 1e3 * bounded.deepest_m);
  EXPECT_GT(bounded.lowest_one_port_energy_j, -0.05);
  EXPECT_LT(bounded.deepest_m, 0.03);
  const Worst unbounded = worst_run(1e300);
  std::printf(" unbounded: lowest %.3g J (%s), deepest %.3g mm\n", unbounded.lowest_one_port_energy_j,
              unbounded.which.c_str(), 1e3 * unbounded.deepest_m);
  EXPECT_LT(unbounded.lowest_one_port_energy_j, -1.0) << "the fix switched off runs away";
  EXPECT_GT(unbounded.deepest_m, 0.1);
}

}  // namespace
}  // namespace tissue::host::hand_test
