// IgtlDevice (see igtl_device.hpp).
#include "igtl/igtl_device.hpp"

#include <cmath>
#include <utility>

namespace tissue::host {

IgtlDevice::IgtlDevice(std::shared_ptr<IgtlServer> server, const ForceWatchdogSettings& watchdog)
    : m_server(std::move(server)), m_watchdog(watchdog) {}

DevicePose IgtlDevice::read(double time_s) {
  if (m_server->take_pose(m_sample) && m_sample.accepted != m_accepted_seen) {
    m_accepted_seen = m_sample.accepted;
    m_watchdog.pose_accepted(time_s);
  }
  m_watchdog.advance(time_s);
  return m_sample.pose;
}

std::array<double, 3> IgtlDevice::write_force(double time_s, const std::array<double, 3>& force_n) {
  m_watchdog.advance(time_s);
  if (m_accepted_seen == 0) return {0.0, 0.0, 0.0};
  const bool finite = std::isfinite(force_n[0]) && std::isfinite(force_n[1]) && std::isfinite(force_n[2]);
  std::array<double, 3> sent{};
  for (std::size_t i = 0; i < 3; ++i) sent[i] = finite ? m_watchdog.scale() * force_n[i] : 0.0;
  m_server->send_force(sent);
  return sent;
}

DeviceCounters IgtlDevice::counters() const {
  const IgtlCounters s = m_server->counters();
  DeviceCounters c;
  c.received = s.received;
  c.accepted = s.accepted;
  c.malformed = s.malformed;
  c.oversized = s.oversized;
  c.out_of_order = s.out_of_order;
  c.duplicate = s.duplicate;
  c.ignored = s.ignored;
  c.watchdog_trips = m_watchdog.trips();
  return c;
}

}  // namespace tissue::host
