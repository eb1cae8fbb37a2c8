// The simulated hand (issue 20): each tick is the exact solution of the linear ODE (checked against
// closed forms: a pushed free hand, a gripped hand following a ramp, an undamped oscillation), the
// device's work is booked exactly, bad settings are refused naming the range, and HandDevice's
// figures say what a haptics engineer reads (settling on an ideal wall at the static depth, the
// frequency and amplitude of an oscillation).
#include "device/hand_device.hpp"
#include "device/simulated_hand.hpp"
#include "support/oscillation_envelope.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace tissue::host {
namespace {

constexpr double TICK_S = 1e-3;
const std::array<double, 3> ZERO{0.0, 0.0, 0.0};

// m x'' = -b x' + p from rest at 0: x(t) = (p/b) t - (p m / b^2) (1 - exp(-b t / m)).
TEST(SimulatedHand, APushedFreeHandMovesAsTheClosedForm) {
  HandSettings settings;
  settings.mass_kg = 0.2;
  settings.damping_n_s_per_m = 2.0;
  settings.push_n = {0.0, 0.3, -1.0};
  SimulatedHand hand(settings, TICK_S, ZERO);
  for (int n = 0; n < 1000; ++n) hand.advance(ZERO, ZERO, ZERO);
  const double t = 1.0, m = settings.mass_kg, b = settings.damping_n_s_per_m;
  for (std::size_t a = 0; a < 3; ++a) {
    const double p = settings.push_n[a];
    const double decay = 1.0 - std::exp(-b * t / m);
    EXPECT_NEAR(hand.position_m()[a], p / b * t - p * m / (b * b) * decay, 1e-13) << "axis " << a;
    EXPECT_NEAR(hand.velocity_m_per_s()[a], p / b * decay, 1e-13) << "axis " << a;
  }
  EXPECT_EQ(hand.device_work_j(), 0.0);
}

// A device force held on the hand moves it as the same push would, and its work is F . dx exactly.
TEST(SimulatedHand, ADeviceForceIsAPushAndItsWorkIsBooked) {
  HandSettings pushed;
  pushed.push_n = {0.0, 0.0, 0.7};
  SimulatedHand by_push(pushed, TICK_S, ZERO);
  SimulatedHand by_device(HandSettings{}, TICK_S, ZERO);
  for (int n = 0; n < 300; ++n) {
    by_push.advance(ZERO, ZERO, ZERO);
    by_device.advance({0.0, 0.0, 0.7}, ZERO, ZERO);
  }
  EXPECT_EQ(by_device.position_m(), by_push.position_m());
  EXPECT_NEAR(by_device.device_work_j(), 0.7 * by_device.position_m()[2], 1e-15);
  EXPECT_GT(by_device.device_work_j(), 0.0);
  by_device.advance({std::nan(""), 0.0, 0.0}, ZERO, ZERO);  // a device that sends nothing
  EXPECT_TRUE(std::isfinite(by_device.position_m()[0]));
}

// m x'' + b x' + k x = k r(t) + p with r = v t: once the transient has died, x = v t - (b v - p) / k.
TEST(SimulatedHand, AGrippedHandFollowsARampWithTheSteadyLag) {
  HandSettings settings;
  settings.mass_kg = 0.2;
  settings.damping_n_s_per_m = 5.0;
  settings.grip_stiffness_n_per_m = 200.0;
  settings.push_n = {0.0, 0.0, -0.5};
  const double speed = 0.05;  // m/s along x and z
  SimulatedHand hand(settings, TICK_S, ZERO);
  for (int n = 0; n < 3000; ++n) {
    const double t = n * TICK_S;
    hand.advance(ZERO, {speed * t, 0.0, speed * t}, {speed * (t + TICK_S), 0.0, speed * (t + TICK_S)});
  }
  const double t = 3.0, k = settings.grip_stiffness_n_per_m, b = settings.damping_n_s_per_m;
  EXPECT_NEAR(hand.position_m()[0], speed * t - b * speed / k, 1e-12);
  EXPECT_NEAR(hand.position_m()[1], 0.0, 1e-15);
  EXPECT_NEAR(hand.position_m()[2], speed * t - (b * speed - settings.push_n[2]) / k, 1e-12);
  EXPECT_NEAR(hand.velocity_m_per_s()[0], speed, 1e-12);
}

TEST(SimulatedHand, BadSettingsAreRefusedWithTheRange) {
  const auto refused = [](HandSettings settings, const std::string& words) {
    try {
      SimulatedHand hand(settings, TICK_S, ZERO);
      ADD_FAILURE() << "accepted: " << words;
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
    }
  };
  HandSettings s;
  s.mass_kg = 0.0;
  refused(s, "hand mass must be in [0.010000, 10.000000] kg");
  s.mass_kg = std::nan("");
  refused(s, "hand mass");
  s = HandSettings{};
  s.damping_n_s_per_m = -1.0;
  refused(s, "hand damping must be in [0.000000, 100.000000] N s/m");
  s = HandSettings{};
  s.grip_stiffness_n_per_m = 1e9;
  refused(s, "hand grip stiffness");
  s = HandSettings{};
  s.push_n = {0.0, 0.0, std::numeric_limits<double>::infinity()};
  refused(s, "hand push");
  EXPECT_THROW(SimulatedHand(HandSettings{}, 0.0, ZERO), std::invalid_argument);
  EXPECT_THROW(SimulatedHand(HandSettings{}, TICK_S, {0.0, std::nan(""), 0.0}), std::invalid_argument);
}

std::vector<DeviceWaypoint> still_at(const std::array<double, 3>& position_m, ToolMode mode) {
  DeviceWaypoint w;
  w.pose.position_m = position_m;
  w.pose.mode = mode;
  return {w};
}

// A 0.2 kg hand damped by 2 N s/m pushing 1 N drops 1 cm onto an ideal 2000 N/m wall at z = 0,
// rendered at 1 kHz (f = -K z held over each tick). It settles at the static depth f / K.
HandFigures wall_drop(double duration_s, double window_s, std::vector<std::array<double, 2>>* states = nullptr) {
  HandSettings settings;
  settings.damping_n_s_per_m = 2.0;
  settings.push_n = {0.0, 0.0, -1.0};
  HandDevice device(still_at({0.0, 0.0, 0.01}, ToolMode::probe), settings, TICK_S, 1e-3, window_s);
  const auto ticks = static_cast<int>(std::lround(duration_s / TICK_S));
  for (int n = 0; n < ticks; ++n) {
    const double t = n * TICK_S;
    const DevicePose pose = device.read(t);
    EXPECT_EQ(pose.mode, ToolMode::probe);
    const double force = pose.position_m[2] < 0.0 ? -2000.0 * pose.position_m[2] : 0.0;
    device.write_force(t, {0.0, 0.0, force});
    if (states != nullptr) states->push_back({device.hand().position_m()[2], device.hand().velocity_m_per_s()[2]});
  }
  return device.figures();
}

TEST(HandDevice, SettlesOnAnIdealWallAtTheStaticDepth) {
  const HandFigures f = wall_drop(6.0, 1.0);
  EXPECT_NEAR(f.mean_position_m[2], -1.0 / 2000.0, 1e-3 / 2000.0);
  EXPECT_NEAR(f.mean_force_n[2], 1.0, 1e-3);
  EXPECT_LT(f.residual_speed_m_per_s, 1e-4);
  EXPECT_TRUE(std::isfinite(f.settle_time_s));
  EXPECT_GT(f.settle_time_s, 0.05);  // it fell and bounced first
  EXPECT_LT(f.settle_time_s, 4.0);
  EXPECT_EQ(f.chatter_frequency_hz, 0.0);
  EXPECT_NEAR(f.window_s, 1.0, 1e-12);
}

// Colgate and Schenkel (1997): a spring K sampled and held over T acts like the spring with a negative
// damping K T / 2, so on the wall the hand's oscillation decays at (b - K T / 2) / (2 m) = 2.5 /s, not
// the 5 /s of b alone (to O((omega T)^2) = 1%: omega T = 0.1). Measured by the envelope
// sqrt((z - z_eq)^2 + (v / omega)^2), averaged over a period, at 1 s and 2 s (in contact throughout).
TEST(HandDevice, OnASampledWallTheHandDecaysAtTheRateColgateAndSchenkelPredict) {
  std::vector<std::array<double, 2>> states;
  (void)wall_drop(2.1, 1.0, &states);
  const double m = 0.2, b = 2.0, k = 2000.0, omega = std::sqrt(k / m), z_eq = -1.0 / k;
  const auto envelope = [&](double t) { return test_support::oscillation_envelope(states, t, TICK_S, omega, z_eq); };
  const double rate_per_s = std::log(envelope(1.0) / envelope(2.0));
  EXPECT_NEAR(rate_per_s, (b - k * TICK_S / 2.0) / (2.0 * m), 0.01 * 2.5);
}

// An undamped hand on its grip spring, let go 1 mm off the path, oscillates at sqrt(k/m) / 2 pi with
// an amplitude of 1 mm: the chatter figures find both (the frequency to the crossing count's
// resolution, 1 / (2 window); the amplitude to the 1 kHz sampling of the peaks).
TEST(HandDevice, FindsTheFrequencyAndAmplitudeOfAnOscillation) {
  HandSettings settings;
  settings.damping_n_s_per_m = 0.0;
  settings.grip_stiffness_n_per_m = 2000.0;
  // The hand starts on the path's first point, 1 mm off; from before t = 0 the path is at 0.
  std::vector<DeviceWaypoint> path = still_at({0.0, 0.001, 0.0}, ToolMode::none);
  path.front().time_s = -1.0;
  path.push_back(still_at({0.0, 0.0, 0.0}, ToolMode::none).front());
  path.back().time_s = -1.0 + 1e-9;
  HandDevice device(path, settings, TICK_S, 1e-3, 1.0);
  for (int n = 0; n < 2000; ++n) device.write_force(n * TICK_S, ZERO);
  const HandFigures f = device.figures();
  const double expected_hz = std::sqrt(settings.grip_stiffness_n_per_m / settings.mass_kg) / (2.0 * std::numbers::pi);
  EXPECT_NEAR(f.chatter_frequency_hz, expected_hz, 0.5);
  EXPECT_NEAR(f.chatter_amplitude_m, 1e-3, 2e-6);
  EXPECT_TRUE(std::isnan(f.settle_time_s)) << "it never settles";
  EXPECT_EQ(f.device_work_j, 0.0);
}

}  // namespace
}  // namespace tissue::host
