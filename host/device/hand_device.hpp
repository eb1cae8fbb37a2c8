// HandDevice: the scenario's waypoints held by a simulated hand (simulated_hand.hpp) instead of
// followed exactly. The hand's position answers the device force at the haptic rate; orientation and
// tool mode follow the path. It also measures what a haptics engineer reads of a contact: when the
// hand settled, how fast it still moves, how it chatters, and the energy the device gave it.
// read() and write_force() allocate nothing (the window of the last second is made at construction).
#pragma once

#include "device/device.hpp"
#include "device/scripted_device.hpp"
#include "device/simulated_hand.hpp"

#include <array>
#include <atomic>
#include <vector>

namespace tissue::host {

/// How long a hand must stay below the settle speed at the end of a run to count as settled: a
/// tenth of a second, many periods of any chatter worth the name (an oscillating hand passes
/// through zero speed at every turn).
inline constexpr double SETTLED_HOLD_S = 0.1;

/// The hand's motion as measured over a session (HandDevice::figures), SI units.
struct HandFigures {
  /// From this time on the hand's speed stayed below the settle speed, for at least the last
  /// SETTLED_HOLD_S of the run; NaN: it never settled (it was faster within that).
  double settle_time_s = 0.0;
  double settle_speed_m_per_s = 1e-3;
  /// RMS speed over the last window (the last second, or the whole run if shorter).
  double residual_speed_m_per_s = 0.0;
  /// The work of the device's force on the hand [J] (> 0: the device gave the hand energy).
  double device_work_j = 0.0;
  /// Over the last window, along the axis the hand moved most: the oscillation's frequency (from its
  /// crossings of the mean) and amplitude (half its peak-to-peak); 0 Hz when the amplitude is below
  /// 1 um (no chatter).
  double chatter_frequency_hz = 0.0;
  double chatter_amplitude_m = 0.0;
  /// Means over the last window: the device force on the hand and the hand's position.
  std::array<double, 3> mean_force_n{};
  std::array<double, 3> mean_position_m{};
  double window_s = 0.0;
};

class HandDevice final : public Device {
 public:
  /// The hand starts at rest on the path's first position and is advanced in ticks of `tick_s` (the
  /// session's haptic period). Throws std::invalid_argument for bad waypoints or hand settings.
  HandDevice(std::vector<DeviceWaypoint> path, const HandSettings& hand, double tick_s,
             double settle_speed_m_per_s = 1e-3, double window_s = 1.0);

  /// The hand's position; the path's orientation and mode at t.
  DevicePose read(double time_s) override;
  /// Advances the hand one tick from t under `force_n` (its grip's target moving along the path from
  /// t to t + tick). Returns the force as given.
  std::array<double, 3> write_force(double time_s, const std::array<double, 3>& force_n) override;
  [[nodiscard]] DeviceCounters counters() const override;
  [[nodiscard]] std::string_view name() const override { return "hand"; }

  /// The figures so far; call when the haptic thread is done (not concurrently with it).
  [[nodiscard]] HandFigures figures() const;
  [[nodiscard]] const SimulatedHand& hand() const { return m_hand; }

 private:
  struct Sample {
    std::array<double, 3> position_m;
    std::array<double, 3> force_n;
    double speed_m_per_s;
  };

  ScriptedDevice m_path;
  SimulatedHand m_hand;
  double m_settle_speed_m_per_s;
  std::vector<Sample> m_window;  // ring buffer of the last window's ticks
  std::size_t m_ticks = 0;
  double m_last_fast_time_s = -1.0;  // the end of the last tick faster than the settle speed
  double m_time_s = 0.0;             // the end of the last tick
  std::atomic<std::uint64_t> m_reads{0};
};

}  // namespace tissue::host
