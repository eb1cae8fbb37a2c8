// udp_sender.hpp - the driver side of the UDP device bridge (host/device/UDP_PROTOCOL.md): sends
// pose packets to a UdpDevice and receives its force packets. Used by test_udp_device and by the
// tissue-udp-sender tool; a model for a real device driver's networking.
#pragma once

#include "device/device.hpp"
#include "device/udp_packet.hpp"

#include <sys/socket.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace tissue::host::test {

/// The sender's monotonic clock [s] (CLOCK_MONOTONIC, as std::chrono::steady_clock on Linux).
[[nodiscard]] double monotonic_time_s();

class UdpSender {
 public:
  /// Opens a non-blocking UDP socket bound to an ephemeral port of @p local_address (numeric)
  /// and aims it at @p device_address:@p device_port. Throws std::runtime_error on failure.
  UdpSender(const std::string& device_address, std::uint16_t device_port,
            const std::string& local_address = "127.0.0.1");
  ~UdpSender();
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;
  UdpSender(UdpSender&&) = delete;
  UdpSender& operator=(UdpSender&&) = delete;

  /// Sends @p pose with the next sequence number (1, 2, ...) stamped with @p send_time_s
  /// (default: monotonic_time_s()); returns the sequence used.
  std::uint64_t send_pose(const DevicePose& pose, std::optional<double> send_time_s = std::nullopt);
  /// Sends a packet exactly as given (any sequence and time): for replays and stale packets.
  void send_packet(const udp::PosePacket& packet);
  /// Sends arbitrary bytes as one datagram: for malformed packets.
  void send_raw(std::span<const std::uint8_t> bytes);

  /// Waits up to @p timeout_s for a valid force packet; datagrams that do not decode are counted
  /// (malformed_forces()) and skipped. std::nullopt on timeout.
  std::optional<udp::ForcePacket> receive_force(double timeout_s);
  /// Appends every valid force packet already waiting to @p out, without blocking; returns how many.
  std::size_t drain_forces(std::vector<udp::ForcePacket>& out);

  [[nodiscard]] std::uint16_t local_port() const { return m_local_port; }
  /// The sequence the next send_pose() will use.
  [[nodiscard]] std::uint64_t next_sequence() const { return m_next_sequence; }
  void set_next_sequence(std::uint64_t sequence) { m_next_sequence = sequence; }
  [[nodiscard]] std::uint64_t malformed_forces() const { return m_malformed_forces; }

 private:
  std::optional<udp::ForcePacket> try_receive();

  int m_socket = -1;
  sockaddr_storage m_device{};
  socklen_t m_device_length = 0;
  std::uint16_t m_local_port = 0;
  std::uint64_t m_next_sequence = 1;
  std::uint64_t m_malformed_forces = 0;
};

}  // namespace tissue::host::test
