// HandDevice (see hand_device.hpp).
#include "device/hand_device.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace tissue::host {
namespace {

double norm3(const std::array<double, 3>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

std::size_t window_ticks(double window_s, double tick_s) {
  if (!(window_s > 0.0 && window_s <= 100.0)) throw std::invalid_argument("hand: the window must be in (0, 100] s");
  return static_cast<std::size_t>(std::max(1.0, std::round(window_s / tick_s)));
}

}  // namespace

HandDevice::HandDevice(std::vector<DeviceWaypoint> path, const HandSettings& hand, double tick_s,
                       double settle_speed_m_per_s, double window_s)
    : m_path(std::move(path)),
      m_hand(hand, tick_s, m_path.pose_at(-std::numeric_limits<double>::infinity()).position_m),
      m_settle_speed_m_per_s(settle_speed_m_per_s),
      m_window(window_ticks(window_s, tick_s)) {
  if (!(settle_speed_m_per_s > 0.0 && std::isfinite(settle_speed_m_per_s))) {
    throw std::invalid_argument("hand: the settle speed must be finite and > 0 m/s");
  }
}

DevicePose HandDevice::read(double time_s) {
  m_reads.fetch_add(1, std::memory_order_relaxed);
  DevicePose pose = m_path.pose_at(time_s);
  pose.position_m = m_hand.position_m();
  return pose;
}

std::array<double, 3> HandDevice::write_force(double time_s, const std::array<double, 3>& force_n) {
  const double tick_s = m_hand.tick_s();
  m_hand.advance(force_n, m_path.pose_at(time_s).position_m, m_path.pose_at(time_s + tick_s).position_m);
  m_time_s = time_s + tick_s;
  const double speed = norm3(m_hand.velocity_m_per_s());
  if (!(speed < m_settle_speed_m_per_s)) m_last_fast_time_s = m_time_s;
  std::array<double, 3> held{};
  for (std::size_t a = 0; a < 3; ++a) held[a] = std::isfinite(force_n[a]) ? force_n[a] : 0.0;
  m_window[m_ticks % m_window.size()] = Sample{m_hand.position_m(), held, speed};
  ++m_ticks;
  return force_n;
}

DeviceCounters HandDevice::counters() const {
  DeviceCounters c;
  c.received = c.accepted = m_reads.load(std::memory_order_relaxed);
  return c;
}

HandFigures HandDevice::figures() const {
  HandFigures f;
  f.settle_speed_m_per_s = m_settle_speed_m_per_s;
  f.device_work_j = m_hand.device_work_j();
  const std::size_t count = std::min(m_ticks, m_window.size());
  f.window_s = static_cast<double>(count) * m_hand.tick_s();
  f.settle_time_s = std::max(0.0, m_last_fast_time_s);
  if (m_time_s - f.settle_time_s < SETTLED_HOLD_S) f.settle_time_s = std::numeric_limits<double>::quiet_NaN();
  if (count == 0) return f;
  // The window in time order.
  const std::size_t first = m_ticks - count;
  const auto at = [&](std::size_t k) -> const Sample& { return m_window[(first + k) % m_window.size()]; };
  double squared_speed = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const Sample& s = at(k);
    squared_speed += s.speed_m_per_s * s.speed_m_per_s;
    for (std::size_t a = 0; a < 3; ++a) {
      f.mean_force_n[a] += s.force_n[a] / static_cast<double>(count);
      f.mean_position_m[a] += s.position_m[a] / static_cast<double>(count);
    }
  }
  f.residual_speed_m_per_s = std::sqrt(squared_speed / static_cast<double>(count));
  // The axis the hand moved most along, its oscillation about the mean.
  std::size_t axis = 0;
  double largest_spread = -1.0;
  for (std::size_t a = 0; a < 3; ++a) {
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (std::size_t k = 0; k < count; ++k) {
      low = std::min(low, at(k).position_m[a]);
      high = std::max(high, at(k).position_m[a]);
    }
    if (high - low > largest_spread) {
      largest_spread = high - low;
      axis = a;
    }
  }
  f.chatter_amplitude_m = 0.5 * largest_spread;
  if (f.chatter_amplitude_m < 1e-6) {
    f.chatter_amplitude_m = 0.0;
    return f;
  }
  int crossings = 0;
  double previous = at(0).position_m[axis] - f.mean_position_m[axis];
  for (std::size_t k = 1; k < count; ++k) {
    const double now = at(k).position_m[axis] - f.mean_position_m[axis];
    if ((previous < 0.0 && now >= 0.0) || (previous >= 0.0 && now < 0.0)) ++crossings;
    previous = now;
  }
  f.chatter_frequency_hz = crossings / (2.0 * f.window_s);
  return f;
}

}  // namespace tissue::host
