// ScriptedDevice (see scripted_device.hpp).
#include "device/scripted_device.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue::host {

std::array<double, 4> slerp(const std::array<double, 4>& a, const std::array<double, 4>& b, double s) {
  double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  std::array<double, 4> target = b;
  if (dot < 0.0) {  // the shorter arc
    dot = -dot;
    for (double& c : target) c = -c;
  }
  double wa = 1.0 - s, wb = s;
  if (dot < 0.9995) {
    const double angle = std::acos(std::min(1.0, dot));
    const double sine = std::sin(angle);
    wa = std::sin((1.0 - s) * angle) / sine;
    wb = std::sin(s * angle) / sine;
  }
  std::array<double, 4> q{};
  double norm = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    q[k] = wa * a[k] + wb * target[k];
    norm += q[k] * q[k];
  }
  norm = std::sqrt(norm);
  for (double& c : q) c /= norm;
  return q;
}

ScriptedDevice::ScriptedDevice(std::vector<DeviceWaypoint> waypoints) : m_waypoints(std::move(waypoints)) {
  if (m_waypoints.empty()) throw std::invalid_argument("scripted device: no waypoints");
  for (std::size_t k = 0; k < m_waypoints.size(); ++k) {
    DeviceWaypoint& w = m_waypoints[k];
    const std::string where = "scripted device: waypoint " + std::to_string(k);
    if (!std::isfinite(w.time_s)) throw std::invalid_argument(where + ": time is not finite");
    if (k > 0 && !(w.time_s > m_waypoints[k - 1].time_s)) throw std::invalid_argument(where + ": times must increase");
    double norm = 0.0;
    for (const double c : w.pose.orientation_wxyz) norm += c * c;
    norm = std::sqrt(norm);
    if (!std::isfinite(norm) || !(norm > 1e-12))
      throw std::invalid_argument(where + ": orientation is not a quaternion");
    for (double& c : w.pose.orientation_wxyz) c /= norm;
    for (const double c : w.pose.position_m) {
      if (!std::isfinite(c)) throw std::invalid_argument(where + ": position is not finite");
    }
  }
}

DevicePose ScriptedDevice::pose_at(double time_s) const {
  if (!(time_s > m_waypoints.front().time_s)) return m_waypoints.front().pose;
  if (time_s >= m_waypoints.back().time_s) return m_waypoints.back().pose;
  const auto after = std::upper_bound(m_waypoints.begin(), m_waypoints.end(), time_s,
                                      [](double t, const DeviceWaypoint& w) { return t < w.time_s; });
  const DeviceWaypoint& b = *after;
  const DeviceWaypoint& a = *(after - 1);
  const double s = (time_s - a.time_s) / (b.time_s - a.time_s);
  DevicePose pose;
  for (std::size_t k = 0; k < 3; ++k)
    pose.position_m[k] = a.pose.position_m[k] + s * (b.pose.position_m[k] - a.pose.position_m[k]);
  pose.orientation_wxyz = slerp(a.pose.orientation_wxyz, b.pose.orientation_wxyz, s);
  pose.mode = a.pose.mode;
  return pose;
}

DevicePose ScriptedDevice::read(double time_s) {
  m_reads.fetch_add(1, std::memory_order_relaxed);
  return pose_at(time_s);
}

std::array<double, 3> ScriptedDevice::write_force(double, const std::array<double, 3>& force_n) { return force_n; }

DeviceCounters ScriptedDevice::counters() const {
  DeviceCounters c;
  c.received = c.accepted = m_reads.load(std::memory_order_relaxed);
  return c;
}

}  // namespace tissue::host
