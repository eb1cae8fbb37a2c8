// force_watchdog.hpp - the silence watchdog of the network devices (UDP, OpenIGTLink): the force
// sent to the hand is scaled by a factor that ramps to zero when accepted poses stop arriving and
// back up when they resume. Driven by the session times the device is called with (not a wall
// clock), so a run's result depends only on the call times.
#pragma once

#include <atomic>
#include <cstdint>

namespace tissue::host {

struct ForceWatchdogSettings {
  /// Session time without an accepted pose after which the force ramps down. Infinity switches
  /// the watchdog off (the force is never scaled down: for tests that show what it protects).
  double timeout_s = 0.050;
  /// Time of a full ramp between scale 1 and 0, in both directions (0: a step).
  double ramp_time_s = 0.100;
};

class ForceWatchdog {
 public:
  /// Throws std::invalid_argument (naming watchdog_timeout_s or ramp_time_s) unless timeout_s > 0 (finite or infinity)
  /// and ramp_time_s is finite and >= 0.
  explicit ForceWatchdog(const ForceWatchdogSettings& settings = {});

  /// True while a stream is open: a pose was accepted and the watchdog has not tripped since. A
  /// pose that arrives when no stream is open starts a new one (a restarted driver).
  [[nodiscard]] bool stream_open() const { return m_connected && !m_tripped; }
  /// A pose was accepted at @p time_s: the stream is (re)opened and the ramp up starts from the
  /// scale the old state reached at @p time_s.
  void pose_accepted(double time_s);
  /// Advances the scale to @p time_s (non-finite times are ignored; times before the last are
  /// clamped, the scale never goes back).
  void advance(double time_s);
  /// The factor in [0, 1] for the force at the last advance() time.
  [[nodiscard]] double scale() const { return m_scale; }
  /// The latest time advance() took (0 before the first).
  [[nodiscard]] double last_time_s() const { return m_scale_time_s; }
  /// How many times the stream went silent. Safe to call from any thread.
  [[nodiscard]] std::uint64_t trips() const { return m_trips.load(std::memory_order_relaxed); }

 private:
  ForceWatchdogSettings m_settings;
  bool m_connected = false;  // a pose was accepted since construction
  bool m_tripped = false;    // the watchdog tripped and no pose was accepted since
  double m_last_accept_time_s = 0.0;
  double m_scale = 0.0;
  double m_scale_time_s = 0.0;
  bool m_scale_time_set = false;
  std::atomic<std::uint64_t> m_trips{0};  // written by the device's thread only
};

}  // namespace tissue::host
