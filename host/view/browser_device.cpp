// browser_device.cpp - see browser_device.hpp.
#include "view/browser_device.hpp"

#include "view/pose_message.hpp"

namespace tissue::host {

BrowserDevice::BrowserDevice(const DevicePose& initial)
    : m_pose(initial), m_current(initial), m_last_published(initial) {}

DevicePose BrowserDevice::read(double /*time_s*/) {
  if (m_pose.update()) m_current = m_pose.read_buffer();
  return m_current;
}

std::array<double, 3> BrowserDevice::write_force(double /*time_s*/, const std::array<double, 3>& force_n) {
  return force_n;
}

DeviceCounters BrowserDevice::counters() const {
  DeviceCounters c;
  c.received = m_received.load();
  c.accepted = m_accepted.load();
  c.malformed = m_malformed.load();
  c.out_of_order = m_out_of_order.load();
  c.watchdog_trips = m_withdrawals.load();
  return c;
}

void BrowserDevice::publish(const DevicePose& pose) {
  m_pose.write_buffer() = pose;
  m_pose.publish();
  m_last_published = pose;
}

void BrowserDevice::handle_message(std::uint64_t connection, const std::string& text) {
  ++m_received;
  const std::optional<PoseMessage> message = parse_pose_message(text);
  if (!message) {
    ++m_malformed;
    return;
  }
  auto [last, first] = m_last_seq.try_emplace(connection, message->seq);
  if (!first) {
    if (message->seq <= last->second) {
      ++m_out_of_order;
      return;
    }
    last->second = message->seq;
  }
  ++m_accepted;
  m_holder = connection;
  m_last_message = std::chrono::steady_clock::now();
  publish(message->pose);
}

void BrowserDevice::connection_closed(std::uint64_t connection) {
  m_last_seq.erase(connection);
  if (connection != m_holder) return;
  m_holder = 0;
  if (m_last_published.mode != ToolMode::none) {
    DevicePose withdrawn = m_last_published;
    withdrawn.mode = ToolMode::none;
    publish(withdrawn);
    ++m_withdrawals;
  }
}

void BrowserDevice::tick() {
  if (m_last_published.mode == ToolMode::none) return;
  if (std::chrono::steady_clock::now() - m_last_message < SILENCE_LIMIT) return;
  DevicePose withdrawn = m_last_published;
  withdrawn.mode = ToolMode::none;
  publish(withdrawn);
  ++m_withdrawals;
}

}  // namespace tissue::host
