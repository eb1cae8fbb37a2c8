// udp_device.cpp - UdpDevice: non-blocking socket, packet validation, stale check, watchdog.
#include "device/udp_device.hpp"

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

std::string errno_text(int error) { return std::system_category().message(error); }

bool is_loopback(const sockaddr_storage& address) {
  if (address.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(address);
    return (ntohl(v4.sin_addr.s_addr) >> 24U) == 127U;
  }
  const auto& v6 = reinterpret_cast<const sockaddr_in6&>(address);
  if (IN6_IS_ADDR_LOOPBACK(&v6.sin6_addr)) return true;
  // ::ffff:127.x.y.z, an IPv4 loopback address written as IPv6.
  return IN6_IS_ADDR_V4MAPPED(&v6.sin6_addr) && v6.sin6_addr.s6_addr[12] == 127;
}

void check_settings(const UdpDeviceSettings& s) {
  if (!(std::isfinite(s.watchdog_timeout_s) && s.watchdog_timeout_s > 0.0)) {
    refuse("watchdog_timeout_s must be finite and > 0, got " + std::to_string(s.watchdog_timeout_s));
  }
  if (!(std::isfinite(s.ramp_time_s) && s.ramp_time_s >= 0.0)) {
    refuse("ramp_time_s must be finite and >= 0, got " + std::to_string(s.ramp_time_s));
  }
  if (!(s.stale_window_s > 0.0)) {
    refuse("stale_window_s must be > 0 (infinity turns the check off), got " + std::to_string(s.stale_window_s));
  }
  if (!(std::isfinite(s.delay_floor_period_s) && s.delay_floor_period_s > 0.0)) {
    refuse("delay_floor_period_s must be finite and > 0, got " + std::to_string(s.delay_floor_period_s));
  }
}

}  // namespace

UdpDevice::UdpDevice(const UdpDeviceSettings& settings) : m_settings(settings) {
  check_settings(m_settings);

  sockaddr_storage address{};
  socklen_t address_length = 0;
  const std::string& host = m_settings.bind_address;
  auto& v4 = reinterpret_cast<sockaddr_in&>(address);
  auto& v6 = reinterpret_cast<sockaddr_in6&>(address);
  if (inet_pton(AF_INET, host.c_str(), &v4.sin_addr) == 1) {
    v4.sin_family = AF_INET;
    v4.sin_port = htons(m_settings.port);
    address_length = sizeof(sockaddr_in);
  } else if (inet_pton(AF_INET6, host.c_str(), &v6.sin6_addr) == 1) {
    v6.sin6_family = AF_INET6;
    v6.sin6_port = htons(m_settings.port);
    address_length = sizeof(sockaddr_in6);
  } else {
    refuse("bind address '" + host + "' is not a numeric IPv4 or IPv6 address (e.g. 127.0.0.1 or ::1)");
  }
  const std::string endpoint =
      (address.ss_family == AF_INET6 ? "[" + host + "]" : host) + ":" + std::to_string(m_settings.port);
  if (!is_loopback(address) && !m_settings.allow_remote) {
    refuse("refusing to listen on " + endpoint +
           ": not a loopback address, so any host that reaches it could move the tool. Bind to 127.0.0.1 "
           "or ::1, or set allow_remote to listen on it anyway");
  }

  m_socket = ::socket(address.ss_family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (m_socket < 0) refuse("cannot create a UDP socket for " + endpoint + ": " + errno_text(errno));
  if (::bind(m_socket, reinterpret_cast<const sockaddr*>(&address), address_length) != 0) {
    const int error = errno;
    ::close(m_socket);
    m_socket = -1;
    refuse("cannot bind udp " + endpoint + ": " + errno_text(error));
  }
  sockaddr_storage bound{};
  socklen_t bound_length = sizeof(bound);
  if (::getsockname(m_socket, reinterpret_cast<sockaddr*>(&bound), &bound_length) == 0) {
    m_local_port = ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<const sockaddr_in6&>(bound).sin6_port
                                                     : reinterpret_cast<const sockaddr_in&>(bound).sin_port);
  }
  m_name = "udp " + (address.ss_family == AF_INET6 ? "[" + host + "]" : host) + ":" + std::to_string(m_local_port);
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
  c.watchdog_trips = m_watchdog_trips.load(std::memory_order_relaxed);
  return c;
}

// The scale follows the session time piecewise: up at 1/ramp while accepted poses are at most
// watchdog_timeout_s old, down at 1/ramp from the instant they became too old (last accept +
// timeout, even if that lies between two calls), so the result depends only on the call times.
void UdpDevice::advance_watchdog(double time_s) {
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
  if (m_connected && !m_tripped) {
    const double trip_time_s = m_last_accept_time_s + m_settings.watchdog_timeout_s;
    const double up_until_s = std::min(time_s, trip_time_s);
    if (up_until_s >= from) m_scale = ramp_up(m_scale, up_until_s - from);
    if (time_s <= trip_time_s) {
      m_scale_time_s = std::max(m_scale_time_s, time_s);
      return;
    }
    m_tripped = true;
    bump(m_watchdog_trips);
    from = std::max(from, trip_time_s);
  }
  if (time_s >= from) m_scale = ramp_down(m_scale, time_s - from);
  m_scale_time_s = std::max(m_scale_time_s, time_s);
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
  advance_watchdog(time_s);
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
  const bool new_stream = !m_connected || m_tripped;
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
    advance_watchdog(time_s);  // the ramp up starts from the scale the old state reached now
  } else {
    m_delay_floor_current_s = std::min(m_delay_floor_current_s, delay_s);
  }
  m_last_sequence = packet.sequence;
  m_last_accept_time_s = time_s;
  m_connected = true;
  m_tripped = false;
  m_pose = packet.pose;
  const std::array<double, 4>& q = packet.pose.orientation_wxyz;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (std::size_t i = 0; i < 4; ++i) m_pose.orientation_wxyz[i] = q[i] / norm;
  std::memcpy(&m_peer, &from, sizeof(from));
  m_peer_length = from_length;
  bump(m_accepted);
}

std::array<double, 3> UdpDevice::write_force(double time_s, const std::array<double, 3>& force_n) {
  advance_watchdog(time_s);
  if (m_peer_length == 0) return {0.0, 0.0, 0.0};
  udp::ForcePacket packet;
  packet.sequence = ++m_force_sequence;
  packet.send_time_s = std::isfinite(time_s) ? time_s : m_scale_time_s;
  packet.watchdog_scale = m_scale;
  packet.ack_sequence = m_last_sequence;
  const bool finite = std::isfinite(force_n[0]) && std::isfinite(force_n[1]) && std::isfinite(force_n[2]);
  for (std::size_t i = 0; i < 3; ++i) packet.force_n[i] = finite ? m_scale * force_n[i] : 0.0;
  const std::array<std::uint8_t, udp::FORCE_PACKET_SIZE> bytes = udp::encode_force(packet);
  if (::sendto(m_socket, bytes.data(), bytes.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
               reinterpret_cast<const sockaddr*>(&m_peer), m_peer_length) < 0) {
    note_socket_error(errno, "sendto");
  }
  return packet.force_n;
}

}  // namespace tissue::host
