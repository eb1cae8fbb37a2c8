// Time-domain passivity (Hannaford and Ryu 2002) of the whole renderer: a stiff virtual wall whose
// tissue samples arrive at 30 Hz (zero-order hold of f0 and x0 from the true wall), and a scripted
// hand pushing in and out sinusoidally for 10 s at 1 kHz. The hand is position-driven (it absorbs
// nothing), so any energy the loop gives it is the loop's own.
#include "haptic/contact_force.hpp"
#include "haptic/force_limits.hpp"
#include "haptic/haptic_renderer.hpp"
#include "haptic/passivity.hpp"

#include <gtest/gtest.h>

#include <limits>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace tissue::haptic {
namespace {

constexpr double UNBOUNDED = std::numeric_limits<double>::infinity();  // the controller's damping, unbounded

constexpr double PI = std::numbers::pi;
constexpr double LATERAL_FREQUENCY_HZ = 0.37;

struct WallScenario {
  double wall_stiffness_n_per_m = 2000.0;      ///< the true wall: z < 0 is inside, f = k (-z) e_z
  double reported_stiffness_n_per_m = 2000.0;  ///< K_c = k_reported e_z e_z^T in the samples
  double sample_rate_hz = 30.0;
  double depth_amplitude_m = 1.5e-3;  ///< z(t) = A cos(2 pi f t): inside half the time, 3 N deepest
  double frequency_hz = 1.0;
  double lateral_amplitude_m = 2e-3;  ///< x(t) = a sin(2 pi 0.37 t): the contact point slides too
  double duration_s = 10.0;
  double dt_s = 1e-3;
};

Eigen::Vector3d hand_position(const WallScenario& s, double t) {
  return {s.lateral_amplitude_m * std::sin(2.0 * PI * LATERAL_FREQUENCY_HZ * t), 0.0,
          s.depth_amplitude_m * std::cos(2.0 * PI * s.frequency_hz * t)};
}

/// Largest hand acceleration [m/s^2].
double max_hand_acceleration(const WallScenario& s) {
  return s.depth_amplitude_m * std::pow(2.0 * PI * s.frequency_hz, 2) +
         s.lateral_amplitude_m * std::pow(2.0 * PI * LATERAL_FREQUENCY_HZ, 2);
}

/// integral of v_z^2 over the time in contact: half of each period, where <sin^2> = 1/2.
double contact_speed_squared_integral(const WallScenario& s) {
  const double speed_amplitude = s.depth_amplitude_m * 2.0 * PI * s.frequency_hz;
  return 0.5 * s.duration_s * 0.5 * speed_amplitude * speed_amplitude;
}

/// The tissue's sample at time t: the true wall evaluated at the tool position then.
TissueSample wall_sample(const WallScenario& s, double t) {
  const Eigen::Vector3d x0 = hand_position(s, t);
  TissueSample sample;
  sample.time_s = t;
  sample.contact_active = x0.z() < 0.0;
  sample.contact_point_m = {x0.x(), x0.y(), 0.0};
  sample.contact_normal = Eigen::Vector3d::UnitZ();
  if (sample.contact_active) sample.force_on_tool_n = {0.0, 0.0, -s.wall_stiffness_n_per_m * x0.z()};
  sample.contact_stiffness_n_per_m =
      s.reported_stiffness_n_per_m * Eigen::Vector3d::UnitZ() * Eigen::Vector3d::UnitZ().transpose();
  sample.tool_position_m = x0;
  return sample;
}

struct WallRun {
  double hand_energy_j = 0.0;  ///< sum f_k . (x(t_{k+1}) - x(t_k)): exact work of the held force on the hand
  double hand_pushed_j = 0.0;  ///< work the hand did against the force (for scale)
  double max_force_n = 0.0;
  double dissipated_j = 0.0;  ///< by the controller
  int controller_ticks = 0;
};

/// Calls `step(k, t, sample_or_null)` -> commanded force for every tick, delivering the samples.
template <class Step>
WallRun run_wall(const WallScenario& s, Step&& step) {
  WallRun run;
  const int ticks = static_cast<int>(std::lround(s.duration_s / s.dt_s));
  int delivered = 0;
  for (int k = 0; k < ticks; ++k) {
    const double t = k * s.dt_s;
    const double sample_time_s = delivered / s.sample_rate_hz;
    TissueSample sample;
    const bool new_sample = t >= sample_time_s - 1e-12;
    if (new_sample) {
      sample = wall_sample(s, sample_time_s);
      ++delivered;
    }
    const Eigen::Vector3d f = step(t, new_sample ? &sample : nullptr);
    const double work = f.dot(hand_position(s, t + s.dt_s) - hand_position(s, t));
    run.hand_energy_j += work;
    run.hand_pushed_j += std::max(0.0, -work);
    run.max_force_n = std::max(run.max_force_n, f.norm());
  }
  return run;
}

WallRun run_renderer(const WallScenario& s, const RendererSettings& settings) {
  HapticRenderer renderer(settings);
  int controller_ticks = 0;
  WallRun run = run_wall(s, [&](double t, const TissueSample* sample) {
    if (sample != nullptr) renderer.set_sample(*sample);
    Eigen::Vector3d f = renderer.tick(hand_position(s, t), ToolMode::probe, s.dt_s);
    controller_ticks += renderer.last_tick().passivity_acted ? 1 : 0;
    return f;
  });
  run.dissipated_j = renderer.dissipated_energy_j();
  run.controller_ticks = controller_ticks;
  return run;
}

void print(const char* name, const WallRun& run) {
  std::printf(
      "  %s: energy to the hand %+.3e J (hand pushed %.3e J), max |f| %.3f N, controller acted in %d ticks, "
      "dissipated %.3e J\n",
      name, run.hand_energy_j, run.hand_pushed_j, run.max_force_n, run.controller_ticks, run.dissipated_j);
}

// The hand here is driven by position: it goes where the script says whatever the force, a hand of
// unbounded mass, so the controller's damping need not be bounded (passivity.hpp) and these tests
// keep its full authority; the bound is tested with hands that answer the force
// (tests/fmu/test_haptic_loop_hand.cpp).
constexpr double KINEMATIC_HAND_KG = 1e300;

RendererSettings controller(bool on) {
  RendererSettings settings;
  settings.passivity_min_hand_mass_kg = KINEMATIC_HAND_KG;
  settings.contact_damping_n_s_per_m = 0.0;  // the leak asserted below is the undamped spring's
  settings.hold_damping = false;
  settings.passivity_control = on;
  return settings;
}

// With the controller on the hand gets nothing, for a K_c in the samples that is exact, half the
// wall's, or missing. Tolerance: the observer is exact, so the energy the loop has given can exceed
// zero only by what the controller's one-tick prediction (velocity constant over the tick) missed in
// the last tick: |f| |a| dt^2 <= 3.3 N x 0.070 m/s^2 x 1e-6 s^2 = 2.3e-7 J, against ~2e-2 J the hand
// stores in the wall. With it off, the 1 kHz hold of the rendered spring alone gives the hand
// (K/2) dt integral(v^2) (Colgate and Schenkel's leak of a sampled spring; 2.2e-4 J here), and the
// 30 Hz samples add to it (contact noticed up to 33 ms late, stiffness missing from K_c): the test
// asserts at least that leak, so it shows what the controller protects against.
TEST(Passivity, WallSampledAt30HzGivesTheHandNoEnergyWithTheControllerOn) {
  for (double fraction : {1.0, 0.5, 0.0}) {
    WallScenario s;
    s.reported_stiffness_n_per_m = fraction * s.wall_stiffness_n_per_m;
    const WallRun on = run_renderer(s, controller(true));
    const WallRun off = run_renderer(s, controller(false));
    std::printf(" wall 2000 N/m, K_c in the samples %.0f N/m, samples at 30 Hz:\n", s.reported_stiffness_n_per_m);
    print("controller on ", on);
    print("controller off", off);

    const double tolerance_j = RendererSettings{}.max_force_n * max_hand_acceleration(s) * s.dt_s * s.dt_s;
    EXPECT_LE(on.hand_energy_j, tolerance_j) << "K_c " << s.reported_stiffness_n_per_m;
    const double hold_leak_j = 0.5 * s.wall_stiffness_n_per_m * s.dt_s * contact_speed_squared_integral(s);
    EXPECT_GT(off.hand_energy_j, hold_leak_j) << "K_c " << s.reported_stiffness_n_per_m;
    // The controller takes energy, it does not remove the wall: the full 3 N are still felt.
    EXPECT_NEAR(on.max_force_n, 3.0, 0.05);
  }
}

// Without K_c the renderer holds f0 for a whole sample period T: the force lags the hand by T/2 on
// average, i.e. the wall acquires a negative damping -k T / 2, and the hand gains
// (k T / 2) integral(v^2 over the contact) = 2000 x (1/30) / 2 x 2.22e-4 = 7.4e-3 J. Tolerance 15%:
// the lag is T/2 only on average over the sample phase, and contact starts and ends between samples.
TEST(Passivity, WithoutStiffnessTheHeldForceActsAsNegativeDamping) {
  WallScenario s;
  s.reported_stiffness_n_per_m = 0.0;
  RendererSettings held = controller(false);
  held.max_estimated_stiffness_n_per_m = 0.0;  // the force held, no stiffness estimated
  const WallRun off = run_renderer(s, held);
  const double predicted_j =
      s.wall_stiffness_n_per_m * (1.0 / s.sample_rate_hz) / 2.0 * contact_speed_squared_integral(s);
  std::printf("  energy to the hand %.3e J, negative-damping prediction %.3e J\n", off.hand_energy_j, predicted_j);
  EXPECT_NEAR(off.hand_energy_j, predicted_j, 0.15 * predicted_j);
}

// Issue 20: the renderer estimates the missing stiffness from successive samples (the secant of the
// force along the normal over the tool's motion), so the same force-only wall is rendered as a
// spring at 1 kHz again: the hand gains under a quarter of what the held force gives it (measured
// 0.19 with the first sample period of each contact held). Issue 42: the estimate is kept from one
// contact to the next, and the last contact's plane stands in for the surface near report, so that
// the contacts after the first start at the crossing tick with the known spring, where the samples
// with K_c but no surface near start them a sample late: the estimate now gives the hand less than
// the reported K_c (measured 3.4e-4 against 4.6e-4 J; 0.05 of the held force's).
TEST(Passivity, AnEstimatedStiffnessRestoresTheSpring) {
  WallScenario s;
  s.reported_stiffness_n_per_m = 0.0;
  const WallRun estimated = run_renderer(s, controller(false));
  WallScenario exact = s;
  exact.reported_stiffness_n_per_m = s.wall_stiffness_n_per_m;
  const WallRun reported = run_renderer(exact, controller(false));
  const double held_j = s.wall_stiffness_n_per_m * (1.0 / s.sample_rate_hz) / 2.0 * contact_speed_squared_integral(s);
  std::printf("  energy to the hand: estimated K %.3e J, reported K_c %.3e J, held force (predicted) %.3e J\n",
              estimated.hand_energy_j, reported.hand_energy_j, held_j);
  EXPECT_LT(estimated.hand_energy_j, 0.25 * held_j);
  EXPECT_LT(estimated.hand_energy_j, reported.hand_energy_j);
}

// Why the observer books f_{k-1} . (x_k - x_{k-1}) and not, as printed, f_k . v_k dt: the same
// pipeline with the printed pairing (an independent few lines here), controller on, K_c exact. For a
// spring f_k - f_{k-1} = -K dx_k, so the printed pairing books every tick short of the true work by
// K |dx_k|^2: it sees the held spring as dissipative by (K/2) sum |dx|^2 where it really gives the
// hand that much (its hold leak), and lends the difference to the 30 Hz contact's activity. With the
// controller holding the booked balance at >= 0, the hand gains the whole gap,
// K dt integral(v^2) = 4.4e-4 J. Tolerance 5%: the integral is the analytic one of the script,
// the sum is over ticks, and the balance left at the end is not exactly zero.
TEST(Passivity, PairingEachForceWithTheVelocityOfItsOwnTickLetsTheHoldLeakThrough) {
  const WallScenario s;
  const RendererSettings settings;
  TissueSample held;
  Eigen::Vector3d previous_x = hand_position(s, 0.0);
  Eigen::Vector3d previous_f = Eigen::Vector3d::Zero();
  double energy_j = 0.0;
  const WallRun printed = run_wall(s, [&](double t, const TissueSample* sample) {
    if (sample != nullptr) held = *sample;
    const Eigen::Vector3d x = hand_position(s, t);
    const Eigen::Vector3d v = (x - previous_x) / s.dt_s;
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    if (held.contact_active) f = unilateral_force(intermediate_force(held, x), held, x);
    const double max_change_n = settings.max_force_rate_n_per_s * s.dt_s;
    f = limit_rate(previous_f, clamp_magnitude(f, settings.max_force_n).force_n, max_change_n).force_n;
    const PassivityAction action = passivity_damping(energy_j, f, v, s.dt_s, UNBOUNDED);
    if (action.damping_n_s_per_m > 0.0) {
      f = limit_rate(previous_f, clamp_magnitude(f + action.damping_force_n, settings.max_force_n).force_n,
                     max_change_n)
              .force_n;
    }
    energy_j -= f.dot(v) * s.dt_s;  // E_k = E_{k-1} - f_k . v_k dt
    previous_x = x;
    previous_f = f;
    return f;
  });
  const double gap_j = s.wall_stiffness_n_per_m * s.dt_s * contact_speed_squared_integral(s);
  std::printf("  f_k . v_k pairing, controller on: energy to the hand %+.3e J, K dt int v^2 = %.3e J\n",
              printed.hand_energy_j, gap_j);
  EXPECT_NEAR(printed.hand_energy_j, gap_j, 0.05 * gap_j);
}

// The observer alone: a spring held at 1 kHz is booked as the exact work, including its hold leak.
TEST(Passivity, ObserverBooksTheExactWorkOfTheHeldForce) {
  PassivityObserver observer;
  const double k = 2000.0;
  const double dx = 1e-5;
  double x = 0.0;
  // Push 100 steps into a spring f = -k x held over each step, then back out.
  for (int i = 0; i < 100; ++i, x -= dx) observer.book({-k * x, 0, 0}, Eigen::Vector3d::Zero(), {-dx, 0, 0});
  for (int i = 0; i < 100; ++i, x += dx) observer.book({-k * x, 0, 0}, Eigen::Vector3d::Zero(), {dx, 0, 0});
  // In, the force held over step i is k i dx: E gains k dx^2 sum_{i<100} i. Out, it is k (100 - i) dx:
  // E loses k dx^2 sum_{i<100} (100 - i). Net -100 k dx^2: the hold leak, k dx^2 / 2 per step.
  EXPECT_NEAR(observer.energy_j(), -k * 100 * dx * dx, 1e-15);
  observer.drop_credit();
  EXPECT_LT(observer.energy_j(), 0.0);  // a deficit is never dropped
}

TEST(Passivity, ControllerDampingDissipatesExactlyThePredictedDeficit) {
  const Eigen::Vector3d f(0.5, -1.0, 2.0);
  const Eigen::Vector3d v(0.02, 0.01, 0.05);
  const double dt = 1e-3;
  const double energy_j = 1e-6;
  const PassivityAction action = passivity_damping(energy_j, f, v, dt, UNBOUNDED);
  const double predicted = energy_j - f.dot(v) * dt;  // 1e-6 - 1.0e-4 < 0
  ASSERT_LT(predicted, 0.0);
  EXPECT_DOUBLE_EQ(action.predicted_energy_j, predicted);
  EXPECT_NEAR(action.damping_n_s_per_m, -predicted / (dt * v.squaredNorm()), 1e-12);
  // With the damping the predicted balance is exactly zero.
  EXPECT_NEAR(energy_j - (f + action.damping_force_n).dot(v) * dt, 0.0, 1e-18);
  // No deficit, or no motion: no action.
  EXPECT_EQ(passivity_damping(1.0, f, v, dt, UNBOUNDED).damping_n_s_per_m, 0.0);
  EXPECT_EQ(passivity_damping(-1.0, f, Eigen::Vector3d::Zero(), dt, UNBOUNDED).damping_n_s_per_m, 0.0);
  // Bounded (issue 20): at most the bound, the rest of the deficit left for the next ticks.
  const PassivityAction bounded = passivity_damping(energy_j, f, v, dt, 10.0);
  EXPECT_EQ(bounded.damping_n_s_per_m, 10.0);
  EXPECT_LT(energy_j - (f + bounded.damping_force_n).dot(v) * dt, 0.0);
}

}  // namespace
}  // namespace tissue::haptic
