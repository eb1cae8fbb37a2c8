// udp_device.cpp - UdpDevice: non-blocking socket, packet validation, stale check, watchdog.
#include "device/udp_device.hpp"

#include "device/socket_address.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <system_error>

namespace tissue::host {
namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

[[noreturn]] void refuse(const std::string& what) { throw std::runtime_error("UdpDevice: " + what); }

ForceWatchdog make_watchdog(const UdpDeviceSettings& s) {
  try {
    return ForceWatchdog(ForceWatchdogSettings{s.watchdog_timeout_s, s.ramp_time_s});
  } catch (const std::invalid_argument& e) {
    refuse(e.what());
  }
}

void check_settings(const UdpDeviceSettings& s) {
  if (!(s.stale_window_s > 0.0)) {
    refuse("stale_window_s must be > 0 (infinity turns the check off), got " + std::to_string(s.stale_window_s));
  }
  if (!(std::isfinite(s.delay_floor_period_s) && s.delay_floor_period_s > 0.0)) {
    refuse("delay_floor_period_s must be finite and > 0, got " + std::to_string(s.delay_floor_period_s));
  }
}

}  // namespace

UdpDevice::UdpDevice(const UdpDeviceSettings& settings) : m_settings(settings), m_watchdog(make_watchdog(settings)) {
  check_settings(m_settings);

  const SocketAddress address = listen_address("UdpDevice", m_settings.bind_address, m_settings.port,
                                               m_settings.allow_remote);
  m_socket = open_bound_socket("UdpDevice", address, SOCK_DGRAM);
  const SocketAddress bound = bound_address(m_socket);
  m_local_port = bound.port();
  m_name = "udp " + bound.text();
}

UdpDevice::~UdpDevice() {
  if (m_socket >= 0) ::close(m_socket);
}

void UdpDevice::bump(std::atomic<std::uint64_t>& counter) {
  // One writer (the haptic thread): a plain load and store, no locked read-modify-write.
  counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

void UdpDevice::note_socket_error(int error, const char* call) {
  if (m_socket_errors.load(std::memory_order_relaxed) == 0) {
    m_first_error_call.store(call, std::memory_order_relaxed);
    m_first_errno.store(error, std::memory_order_release);
  }
  bump(m_socket_errors);
}

UdpSocketErrors UdpDevice::socket_errors() const {
  UdpSocketErrors errors;
  errors.first_errno = m_first_errno.load(std::memory_order_acquire);
  errors.first_call = m_first_error_call.load(std::memory_order_relaxed);
  errors.count = m_socket_errors.load(std::memory_order_relaxed);
  return errors;
}

DeviceCounters UdpDevice::counters() const {
  DeviceCounters c;
  c.received = m_received.load(std::memory_order_relaxed);
  c.accepted = m_accepted.load(std::memory_order_relaxed);
  c.malformed = m_malformed.load(std::memory_order_relaxed);
  c.out_of_order = m_out_of_order.load(std::memory_order_relaxed);
  c.duplicate = m_duplicate.load(std::memory_order_relaxed);
  c.stale = m_stale.load(std::memory_order_relaxed);
  c.watchdog_trips = m_watchdog.trips();
  return c;
}

DevicePose UdpDevice::read(double time_s) {
  if (time_s - m_delay_period_start_s >= m_settings.delay_floor_period_s) {
    m_delay_floor_previous_s = m_delay_floor_current_s;
    m_delay_floor_current_s = INF;
    m_delay_period_start_s = time_s;
  }
  for (std::size_t n = 0; n < MAX_DATAGRAMS_PER_READ; ++n) {
    sockaddr_storage from{};
    socklen_t from_length = sizeof(from);
    // MSG_TRUNC: the return value is the datagram's real size even when it did not fit.
    const ssize_t size = ::recvfrom(m_socket, m_receive_buffer.data(), m_receive_buffer.size(),
                                    MSG_TRUNC | MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&from), &from_length);
    if (size < 0) {
      const int error = errno;
      if (error == EAGAIN || error == EWOULDBLOCK) break;
      if (error == EINTR) continue;
      note_socket_error(error, "recvfrom");
      break;
    }
    bump(m_received);
    if (static_cast<std::size_t>(size) > m_receive_buffer.size()) {
      bump(m_malformed);
      continue;
    }
    handle_datagram(static_cast<std::size_t>(size), time_s, from, from_length);
  }
  // After draining: a fresh pose waiting in the socket keeps the stream alive even when this
  // call itself comes late (a host hiccup is not a silent driver).
  m_watchdog.advance(time_s);
  return m_pose;
}

void UdpDevice::handle_datagram(std::size_t size, double time_s, const sockaddr_storage& from, socklen_t from_length) {
  udp::PosePacket packet;
  if (udp::decode_pose(std::span<const std::uint8_t>(m_receive_buffer.data(), size), packet) !=
      udp::DecodeError::none) {
    bump(m_malformed);
    return;
  }
  // A new stream (first pose, or after a watchdog trip) takes any sequence and measures its
  // delay afresh: a restarted driver counts from 1 again.
  const bool new_stream = !m_watchdog.stream_open();
  if (!new_stream && packet.sequence <= m_last_sequence) {
    bump(packet.sequence == m_last_sequence ? m_duplicate : m_out_of_order);
    return;
  }
  const double delay_s = time_s - packet.send_time_s;
  const double floor_s = new_stream ? INF : std::min(m_delay_floor_current_s, m_delay_floor_previous_s);
  if (!std::isfinite(delay_s) || delay_s > floor_s + m_settings.stale_window_s) {
    bump(m_stale);
    return;
  }
  if (new_stream) {
    m_delay_floor_previous_s = INF;
    m_delay_floor_current_s = delay_s;
    m_delay_period_start_s = time_s;
  } else {
    m_delay_floor_current_s = std::min(m_delay_floor_current_s, delay_s);
  }
  m_last_sequence = packet.sequence;
  m_watchdog.pose_accepted(time_s);
  m_pose = packet.pose;
  const std::array<double, 4>& q = packet.pose.orientation_wxyz;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (std::size_t i = 0; i < 4; ++i) m_pose.orientation_wxyz[i] = q[i] / norm;
  std::memcpy(&m_peer, &from, sizeof(from));
  m_peer_length = from_length;
  bump(m_accepted);
}

std::array<double, 3> UdpDevice::write_force(double time_s, const std::array<double, 3>& force_n) {
  m_watchdog.advance(time_s);
  if (m_peer_length == 0) return {0.0, 0.0, 0.0};
  udp::ForcePacket packet;
  packet.sequence = ++m_force_sequence;
  packet.send_time_s = std::isfinite(time_s) ? time_s : m_watchdog.last_time_s();
  packet.watchdog_scale = m_watchdog.scale();
  packet.ack_sequence = m_last_sequence;
  const bool finite = std::isfinite(force_n[0]) && std::isfinite(force_n[1]) && std::isfinite(force_n[2]);
  for (std::size_t i = 0; i < 3; ++i) packet.force_n[i] = finite ? m_watchdog.scale() * force_n[i] : 0.0;
  const std::array<std::uint8_t, udp::FORCE_PACKET_SIZE> bytes = udp::encode_force(packet);
  if (::sendto(m_socket, bytes.data(), bytes.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
               reinterpret_cast<const sockaddr*>(&m_peer), m_peer_length) < 0) {
    note_socket_error(errno, "sendto");
  }
  return packet.force_n;
}

}  // namespace tissue::host
