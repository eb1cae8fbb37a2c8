// ForceWatchdog (see force_watchdog.hpp).
#include "device/force_watchdog.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue::host {

ForceWatchdog::ForceWatchdog(const ForceWatchdogSettings& settings) : m_settings(settings) {
  if (!(settings.timeout_s > 0.0)) {
    throw std::invalid_argument("watchdog_timeout_s must be > 0 (infinity switches the watchdog off), got " +
                                std::to_string(settings.timeout_s));
  }
  if (!(std::isfinite(settings.ramp_time_s) && settings.ramp_time_s >= 0.0)) {
    throw std::invalid_argument("ramp_time_s must be finite and >= 0, got " + std::to_string(settings.ramp_time_s));
  }
}

void ForceWatchdog::pose_accepted(double time_s) {
  if (!stream_open()) advance(time_s);  // the ramp up starts from the scale the old state reached now
  m_last_accept_time_s = time_s;
  m_connected = true;
  m_tripped = false;
}

// The scale follows the session time piecewise: up at 1/ramp while accepted poses are at most
// timeout_s old, down at 1/ramp from the instant they became too old (last accept + timeout,
// even if that lies between two calls), so the result depends only on the call times.
void ForceWatchdog::advance(double time_s) {
  if (!std::isfinite(time_s)) return;
  if (!m_scale_time_set) {
    m_scale_time_s = time_s;
    m_scale_time_set = true;
  }
  const double ramp = m_settings.ramp_time_s;
  const auto ramp_up = [ramp](double scale, double dt) { return ramp > 0.0 ? std::min(1.0, scale + dt / ramp) : 1.0; };
  const auto ramp_down = [ramp](double scale, double dt) {
    return ramp > 0.0 ? std::max(0.0, scale - dt / ramp) : 0.0;
  };
  double from = m_scale_time_s;
  if (stream_open()) {
    const double trip_time_s = m_last_accept_time_s + m_settings.timeout_s;
    const double up_until_s = std::min(time_s, trip_time_s);
    if (up_until_s >= from) m_scale = ramp_up(m_scale, up_until_s - from);
    if (time_s <= trip_time_s) {
      m_scale_time_s = std::max(m_scale_time_s, time_s);
      return;
    }
    m_tripped = true;
    m_trips.store(m_trips.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    from = std::max(from, trip_time_s);
  }
  if (time_s >= from) m_scale = ramp_down(m_scale, time_s - from);
  m_scale_time_s = std::max(m_scale_time_s, time_s);
}

}  // namespace tissue::host
