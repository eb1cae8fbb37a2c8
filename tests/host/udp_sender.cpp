// udp_sender.cpp - UdpSender: the driver side of the UDP device bridge.
#include "udp_sender.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <system_error>

namespace tissue::host::test {
namespace {

// Fills @p out with a numeric IPv4/IPv6 address and port; false if @p text is not one.
bool make_address(const std::string& text, std::uint16_t port, sockaddr_storage& out, socklen_t& length) {
  out = {};
  auto& v4 = reinterpret_cast<sockaddr_in&>(out);
  auto& v6 = reinterpret_cast<sockaddr_in6&>(out);
  if (inet_pton(AF_INET, text.c_str(), &v4.sin_addr) == 1) {
    v4.sin_family = AF_INET;
    v4.sin_port = htons(port);
    length = sizeof(sockaddr_in);
    return true;
  }
  if (inet_pton(AF_INET6, text.c_str(), &v6.sin6_addr) == 1) {
    v6.sin6_family = AF_INET6;
    v6.sin6_port = htons(port);
    length = sizeof(sockaddr_in6);
    return true;
  }
  return false;
}

[[noreturn]] void fail(const std::string& what, int error) {
  throw std::runtime_error("UdpSender: " + what + ": " + std::system_category().message(error));
}

}  // namespace

double monotonic_time_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

UdpSender::UdpSender(const std::string& device_address, std::uint16_t device_port, const std::string& local_address) {
  if (!make_address(device_address, device_port, m_device, m_device_length)) {
    throw std::runtime_error("UdpSender: device address '" + device_address + "' is not a numeric IPv4/IPv6 address");
  }
  sockaddr_storage local{};
  socklen_t local_length = 0;
  if (!make_address(local_address, 0, local, local_length) || local.ss_family != m_device.ss_family) {
    throw std::runtime_error("UdpSender: local address '" + local_address +
                             "' is not a numeric address of the device address's family");
  }
  m_socket = ::socket(m_device.ss_family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (m_socket < 0) fail("socket", errno);
  if (::bind(m_socket, reinterpret_cast<const sockaddr*>(&local), local_length) != 0) {
    const int error = errno;
    ::close(m_socket);
    fail("bind " + local_address, error);
  }
  sockaddr_storage bound{};
  socklen_t bound_length = sizeof(bound);
  if (::getsockname(m_socket, reinterpret_cast<sockaddr*>(&bound), &bound_length) == 0) {
    m_local_port = ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<const sockaddr_in6&>(bound).sin6_port
                                                     : reinterpret_cast<const sockaddr_in&>(bound).sin_port);
  }
}

UdpSender::~UdpSender() {
  if (m_socket >= 0) ::close(m_socket);
}

std::uint64_t UdpSender::send_pose(const DevicePose& pose, std::optional<double> send_time_s) {
  udp::PosePacket packet;
  packet.sequence = m_next_sequence++;
  packet.send_time_s = send_time_s ? *send_time_s : monotonic_time_s();
  packet.pose = pose;
  send_packet(packet);
  return packet.sequence;
}

void UdpSender::send_packet(const udp::PosePacket& packet) { send_raw(udp::encode_pose(packet)); }

void UdpSender::send_raw(std::span<const std::uint8_t> bytes) {
  // A driver would count a failed send and carry on; the tests want to know.
  if (::sendto(m_socket, bytes.data(), bytes.size(), MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&m_device),
               m_device_length) != static_cast<ssize_t>(bytes.size())) {
    fail("sendto", errno);
  }
}

std::optional<udp::ForcePacket> UdpSender::try_receive() {
  std::array<std::uint8_t, 2048> buffer{};
  for (;;) {
    const ssize_t size = ::recv(m_socket, buffer.data(), buffer.size(), MSG_DONTWAIT | MSG_TRUNC);
    if (size < 0) {
      if (errno == EINTR) continue;
      return std::nullopt;  // EAGAIN: nothing waiting (other errors: treated alike by a driver)
    }
    udp::ForcePacket packet;
    if (static_cast<std::size_t>(size) <= buffer.size() &&
        udp::decode_force(std::span<const std::uint8_t>(buffer.data(), static_cast<std::size_t>(size)), packet) ==
            udp::DecodeError::none) {
      return packet;
    }
    ++m_malformed_forces;
  }
}

std::optional<udp::ForcePacket> UdpSender::receive_force(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    if (std::optional<udp::ForcePacket> packet = try_receive()) return packet;
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return std::nullopt;
    pollfd descriptor{m_socket, POLLIN, 0};
    ::poll(&descriptor, 1, static_cast<int>(left.count()));
  }
}

std::size_t UdpSender::drain_forces(std::vector<udp::ForcePacket>& out) {
  std::size_t count = 0;
  while (std::optional<udp::ForcePacket> packet = try_receive()) {
    out.push_back(*packet);
    ++count;
  }
  return count;
}

}  // namespace tissue::host::test
