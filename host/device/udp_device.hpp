// udp_device.hpp - the UDP bridge device: a separate driver process sends the hand's pose to
// tissue-host and receives the force to render (packet format and rules: UDP_PROTOCOL.md).
//
// Loopback only unless allow_remote is set. read() drains the socket without blocking and keeps
// the newest valid pose; malformed, out-of-order, duplicate and stale packets are dropped and
// counted. write_force() answers the sender of the newest accepted pose. A ForceWatchdog driven
// by the session time passed to read()/write_force() ramps the force to zero when accepted poses
// stop arriving.
#pragma once

#include "device/device.hpp"
#include "device/force_watchdog.hpp"
#include "device/udp_packet.hpp"

#include <sys/socket.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

namespace tissue::host {

struct UdpDeviceSettings {
  /// Numeric IPv4 or IPv6 address to listen on. Anything but loopback (127.0.0.0/8, ::1),
  /// including the wildcards 0.0.0.0 and ::, is refused unless allow_remote is set.
  std::string bind_address = "127.0.0.1";
  /// UDP port; 0 asks the system for an ephemeral port (see UdpDevice::local_port()).
  std::uint16_t port = udp::DEFAULT_PORT;
  /// Listen on a non-loopback address: anyone who can reach it moves the tool.
  bool allow_remote = false;
  /// Session time without an accepted pose after which the force ramps down (ForceWatchdog).
  double watchdog_timeout_s = ForceWatchdogSettings{}.timeout_s;
  /// Time of a full ramp between scale 1 and 0, in both directions (0: a step).
  double ramp_time_s = ForceWatchdogSettings{}.ramp_time_s;
  /// A packet whose one-way delay (receive - send time) exceeds the smallest one seen by more
  /// than this is stale (UDP_PROTOCOL.md "Stale packets").
  double stale_window_s = 0.020;
  /// The smallest delay is taken over the last one to two such periods, so that the drift between
  /// two machines' clocks is followed instead of making every packet stale eventually.
  double delay_floor_period_s = 10.0;
};

/// Socket errors met by read()/write_force(), which never throw: counted, and the first one kept.
struct UdpSocketErrors {
  std::uint64_t count = 0;
  int first_errno = 0;          ///< 0: none yet
  const char* first_call = "";  ///< "recvfrom" or "sendto"
};

class UdpDevice final : public Device {
 public:
  /// Checks the settings, opens a non-blocking UDP socket and binds it. Throws std::runtime_error
  /// naming the address and the reason: invalid settings, a non-numeric address, a non-loopback
  /// address without allow_remote, or a failed socket()/bind() (e.g. the port is in use).
  explicit UdpDevice(const UdpDeviceSettings& settings = {});
  ~UdpDevice() override;
  UdpDevice(const UdpDevice&) = delete;
  UdpDevice& operator=(const UdpDevice&) = delete;
  UdpDevice(UdpDevice&&) = delete;
  UdpDevice& operator=(UdpDevice&&) = delete;

  /// Drains up to MAX_DATAGRAMS_PER_READ pending datagrams (the rest wait for the next call),
  /// validates each with @p time_s as its receive time, and returns the newest accepted pose; the
  /// last accepted pose (held, also after a watchdog trip) when none arrived; the default pose
  /// before the first one. The orientation is normalized. The watchdog is advanced after
  /// draining, so a late call that finds a fresh pose waiting does not trip it.
  DevicePose read(double time_s) override;
  /// Scales @p force_n by the watchdog at @p time_s (a non-finite force becomes zero), sends it
  /// to the source address of the newest accepted pose, and returns what was sent (a failed
  /// sendto is counted in socket_errors(), and the scaled force still returned). Before the
  /// first accepted pose nothing is sent and zero is returned.
  std::array<double, 3> write_force(double time_s, const std::array<double, 3>& force_n) override;
  [[nodiscard]] DeviceCounters counters() const override;
  [[nodiscard]] std::string_view name() const override { return m_name; }

  /// The bound port (the ephemeral one when settings.port was 0).
  [[nodiscard]] std::uint16_t local_port() const { return m_local_port; }
  /// The factor in [0, 1] applied to the force at the last read()/write_force() time. Haptic thread only.
  [[nodiscard]] double watchdog_scale() const { return m_watchdog.scale(); }
  /// Safe to call from any thread.
  [[nodiscard]] UdpSocketErrors socket_errors() const;

  /// Datagrams handled per read() at most: bounds the tick's work under a flood.
  static constexpr std::size_t MAX_DATAGRAMS_PER_READ = 256;
  /// Receive buffer size: larger datagrams are still detected (MSG_TRUNC) and counted as malformed.
  static constexpr std::size_t RECEIVE_BUFFER_SIZE = 2048;

 private:
  void handle_datagram(std::size_t size, double time_s, const sockaddr_storage& from, socklen_t from_length);
  void note_socket_error(int error, const char* call);
  static void bump(std::atomic<std::uint64_t>& counter);

  UdpDeviceSettings m_settings;
  std::string m_name;
  int m_socket = -1;
  std::uint16_t m_local_port = 0;
  std::array<std::uint8_t, RECEIVE_BUFFER_SIZE> m_receive_buffer{};

  // Stream state (haptic thread only).
  ForceWatchdog m_watchdog;
  std::uint64_t m_last_sequence = 0;
  DevicePose m_pose;
  sockaddr_storage m_peer{};
  socklen_t m_peer_length = 0;
  std::uint64_t m_force_sequence = 0;

  // One-way delay floor over two periods (UDP_PROTOCOL.md "Stale packets").
  double m_delay_floor_current_s = std::numeric_limits<double>::infinity();
  double m_delay_floor_previous_s = std::numeric_limits<double>::infinity();
  double m_delay_period_start_s = 0.0;

  // Written by the haptic thread, read by any thread.
  std::atomic<std::uint64_t> m_received{0}, m_accepted{0}, m_malformed{0}, m_out_of_order{0}, m_duplicate{0},
      m_stale{0}, m_socket_errors{0};
  std::atomic<int> m_first_errno{0};
  std::atomic<const char*> m_first_error_call{""};
};

}  // namespace tissue::host
