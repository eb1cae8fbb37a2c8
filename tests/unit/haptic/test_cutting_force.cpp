// The cutting force (cutting_force.hpp): J_c x depth (with blade friction, after the tanh
// smoothing) against the hand's velocity, only in scalpel mode with the blade in the tissue, never
// along the hand's own motion; and the work the hand does is the fracture work J_c x crack area.
#include "haptic/cutting_force.hpp"
#include "haptic/haptic_renderer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace tissue::haptic {
namespace {

constexpr double DT_S = 1e-3;

TissueSample blade_in_tissue(double depth_m) {
  TissueSample sample;
  sample.blade_depth_m = depth_m;  // cutting, not in probe contact
  return sample;
}

TEST(CuttingForce, MagnitudeIsToughnessPlusFrictionTimesDepthAfterSmoothing) {
  CuttingSettings settings;
  settings.blade_friction_n_per_m = 40.0;
  const double depth_m = 4e-3;
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  for (double speed : {0.1 * settings.smoothing_speed_m_per_s, settings.smoothing_speed_m_per_s, 0.05}) {
    const Eigen::Vector3d v = speed * direction;
    const Eigen::Vector3d f = cutting_force(settings, depth_m, v, v);
    const double expected_n = (164.0 + 40.0) * depth_m * std::tanh(speed / settings.smoothing_speed_m_per_s);
    EXPECT_NEAR(f.norm(), expected_n, 1e-14) << speed;
    EXPECT_NEAR(f.normalized().dot(-direction), 1.0, 1e-14) << speed;
  }
  // At v_ref the force is tanh(1) = 76% of J_c d; a resting blade feels nothing.
  EXPECT_NEAR(cutting_force(settings, depth_m, settings.smoothing_speed_m_per_s * direction, direction).norm(),
              std::tanh(1.0) * 204.0 * depth_m, 1e-14);
  EXPECT_EQ(cutting_force(settings, depth_m, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()),
            Eigen::Vector3d::Zero());
}

// Through the renderer, a hand drawing the scalpel at a steady 5 cm/s, 5 mm deep in liver (the
// default J_c = 164 J/m^2): once the velocity filter has settled (200 ticks, (1 - a)^200 < 1e-14)
// the hand feels J_c d tanh(5) = 0.8199 N straight against its motion. Tolerance 1e-9 N (rounding
// of the backward difference of positions ~0.1 m apart by 5e-5 m: 1e-12 relative).
TEST(CuttingForce, TheHandFeelsToughnessTimesDepthAgainstItsMotion) {
  HapticRenderer renderer;
  renderer.set_sample(blade_in_tissue(5e-3));
  const Eigen::Vector3d start(0.1, -0.05, 0.02);
  const Eigen::Vector3d velocity = 0.05 * Eigen::Vector3d(2.0, 1.0, -0.3).normalized();
  Eigen::Vector3d f;
  for (int k = 0; k <= 200; ++k) f = renderer.tick(start + k * DT_S * velocity, ToolMode::scalpel, DT_S);
  const double expected_n = 164.0 * 5e-3 * std::tanh(0.05 / 0.01);
  std::printf("  steady cut at 5 cm/s, 5 mm deep: |f| = %.6f N (J_c d tanh(5) = %.6f N)\n", f.norm(), expected_n);
  EXPECT_NEAR(f.norm(), expected_n, 1e-9);
  EXPECT_NEAR(f.normalized().dot(-velocity.normalized()), 1.0, 1e-12);
  EXPECT_EQ(renderer.last_tick().cutting_force_n, f);
  EXPECT_FALSE(renderer.last_tick().passivity_acted);  // the cut only absorbs energy
}

// The work the hand does while cutting is the fracture work J_c x (depth x length): what the
// passivity observer books. A 2 cm cut, 5 mm deep, at 5 cm/s: 164 x 1e-4 = 16.4 mJ. The force builds
// up with the velocity filter (time constant tau = 5.3 ms) and the tanh, so the hand does a little
// less, at most |f| v tau = 0.82 x 0.05 x 0.0053 = 0.2 mJ (1.3%); tolerance 2%.
TEST(CuttingForce, TheWorkOfTheHandIsTheFractureWork) {
  HapticRenderer renderer;
  renderer.set_sample(blade_in_tissue(5e-3));
  const Eigen::Vector3d velocity(0.05, 0.0, 0.0);
  const int ticks = 400;  // 0.4 s: 2 cm
  for (int k = 0; k <= ticks; ++k) renderer.tick(k * DT_S * velocity, ToolMode::scalpel, DT_S);
  const double fracture_work_j = 164.0 * 5e-3 * (ticks * DT_S * velocity.norm());
  std::printf("  2 cm cut: work booked %.4e J, fracture work J_c d L %.4e J\n", renderer.observed_energy_j(),
              fracture_work_j);
  EXPECT_LT(renderer.observed_energy_j(), fracture_work_j);
  EXPECT_NEAR(renderer.observed_energy_j(), fracture_work_j, 0.02 * fracture_work_j);
}

TEST(CuttingForce, NothingOutsideScalpelModeOrWithoutTheBladeInTheTissue) {
  const Eigen::Vector3d velocity(0.05, 0.0, 0.0);
  for (ToolMode mode : {ToolMode::none, ToolMode::probe}) {
    HapticRenderer renderer;
    renderer.set_sample(blade_in_tissue(5e-3));
    Eigen::Vector3d f;
    for (int k = 0; k <= 100; ++k) f = renderer.tick(k * DT_S * velocity, mode, DT_S);
    EXPECT_EQ(f, Eigen::Vector3d::Zero());
  }
  HapticRenderer renderer;
  renderer.set_sample(blade_in_tissue(0.0));
  Eigen::Vector3d f;
  for (int k = 0; k <= 100; ++k) f = renderer.tick(k * DT_S * velocity, ToolMode::scalpel, DT_S);
  EXPECT_EQ(f, Eigen::Vector3d::Zero());
}

// A hand that reverses: the filtered velocity lags (it still points the old way for a few ticks),
// so -v would push the hand along its new motion. The force's component along the last measured
// motion is removed: f . (x_k - x_{k-1}) <= 0 at every tick. The test also checks that the lag
// happens, i.e. that without the guard the force would have pushed.
TEST(CuttingForce, TheCuttingForceNeverPushesTheHandAlongItsMotion) {
  HapticRenderer renderer;
  renderer.set_sample(blade_in_tissue(5e-3));
  Eigen::Vector3d previous_x(0.0, 0.0, 0.0);
  int lagging_ticks = 0;
  for (int k = 0; k < 2000; ++k) {
    const double t = k * DT_S;
    // Back and forth along a slanted line at 4 Hz, with a sideways drift.
    const Eigen::Vector3d x(0.01 * std::sin(2.0 * 3.141592653589793 * 4.0 * t), 0.002 * t, 0.0);
    renderer.tick(x, ToolMode::scalpel, DT_S);
    const Eigen::Vector3d motion = x - previous_x;
    const Eigen::Vector3d& f_cut = renderer.last_tick().cutting_force_n;
    EXPECT_LE(f_cut.dot(motion), 1e-18) << "tick " << k;
    if (renderer.last_tick().velocity_m_per_s.dot(motion) < 0.0) ++lagging_ticks;
    previous_x = x;
  }
  std::printf("  ticks where the filtered velocity opposed the motion: %d\n", lagging_ticks);
  EXPECT_GT(lagging_ticks, 10);
}

}  // namespace
}  // namespace tissue::haptic
