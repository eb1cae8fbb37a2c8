// igtl_server.hpp - tissue-host's OpenIGTLink server (OPENIGTLINK.md): one TCP client at a time
// (3D Slicer's OpenIGTLinkIF, PLUS, a tracker's bridge) sends the tool's pose as TRANSFORM or
// POSITION messages and receives the device force (SENSOR) and the deformed surface (POLYDATA).
//
// A thread of its own does the networking, so the haptic thread never touches the socket: it takes
// the newest accepted pose and hands over the force through lock-free latest-value slots, and the
// dynamics thread hands over surface frames the same way. Loopback only unless allow_remote is
// set. Messages that are malformed, larger than max_body_bytes, older than the last accepted one of
// the same tool (by the header's timestamp) or a repeat of it are dropped and counted; other
// message types and device names are counted as ignored. A client that does not read loses force
// messages and surface frames (counted), never blocks the server.
#pragma once

#include "device/device.hpp"
#include "device/igtl_counters.hpp"
#include "device/socket_address.hpp"
#include "igtl/igtl_codec.hpp"
#include "output/surface_frame.hpp"
#include "sync/latest_value.hpp"

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

namespace tissue::host {

struct IgtlServerSettings {
  /// Numeric IPv4 or IPv6 address to listen on; only loopback unless allow_remote.
  std::string address = "127.0.0.1";
  /// TCP port; 18944 is OpenIGTLink's registered port (IANA), 0 asks for an ephemeral one.
  std::uint16_t port = 18944;
  bool allow_remote = false;
  igtl_link::CodecSettings codec;
  /// POLYDATA surfaces per second of session time (0: none).
  double surface_rate_hz = 30.0;
  /// A received message with a larger body is oversized: dropped unread (pose messages are 48 bytes).
  std::uint64_t max_body_bytes = 65536;
};

/// The newest accepted pose and how many poses were accepted up to it.
struct IgtlPoseSample {
  DevicePose pose;
  std::uint64_t accepted = 0;
};

class IgtlServer {
 public:
  /// Checks the settings, binds and listens, and starts the server's thread. Throws
  /// std::runtime_error / std::invalid_argument naming the address or the setting and the reason.
  explicit IgtlServer(const IgtlServerSettings& settings);
  ~IgtlServer();
  IgtlServer(const IgtlServer&) = delete;
  IgtlServer& operator=(const IgtlServer&) = delete;
  IgtlServer(IgtlServer&&) = delete;
  IgtlServer& operator=(IgtlServer&&) = delete;

  [[nodiscard]] std::uint16_t port() const { return m_address.port(); }
  /// "openigtlink 127.0.0.1:18944".
  [[nodiscard]] const std::string& name() const { return m_name; }
  /// Counted by the server's thread; a snapshot, safe to take from any thread.
  [[nodiscard]] IgtlCounters counters() const;

  // --- the haptic thread (no allocation, no lock, no system call but one eventfd write) ---
  /// The newest pose accepted since the last call, if any.
  bool take_pose(IgtlPoseSample& sample);
  /// Sends @p force_n to the client (the newest force wins when the network lags); nothing without a client.
  void send_force(const std::array<double, 3>& force_n);

  // --- the dynamics thread ---
  /// Whether a surface is due at session time @p time_s (surface_rate_hz).
  [[nodiscard]] bool surface_due(double time_s) const;
  /// Fill surface_buffer(), then publish_surface(time_s).
  SurfaceFrame& surface_buffer() { return m_surface.write_buffer(); }
  void publish_surface(double time_s);

 private:
  void run();
  void accept_client();
  void read_client();
  void handle_message(const igtl_link::Header& header, std::size_t offset, std::size_t size);
  void queue_outgoing();
  void flush();
  void close_client();
  void wake();
  static void bump(std::atomic<std::uint64_t>& counter);

  IgtlServerSettings m_settings;
  SocketAddress m_address;
  std::string m_name;
  int m_listen = -1;
  int m_wake = -1;  // eventfd: new force, new surface, stop
  std::atomic<bool> m_stop{false};

  // Exchanged with the other threads.
  LatestValue<IgtlPoseSample> m_pose;
  LatestValue<std::array<double, 3>> m_force;
  LatestValue<SurfaceFrame> m_surface;
  double m_next_surface_s = 0.0;  // dynamics thread's

  // The server thread's own.
  int m_client = -1;
  igtl_link::Codec m_codec;
  std::vector<std::uint8_t> m_in, m_out;
  std::size_t m_out_sent = 0;
  std::uint64_t m_discard = 0;                      // bytes of an oversized body still to skip
  std::array<std::uint64_t, 3> m_last_timestamp{};  // per ToolMode

  std::atomic<std::uint64_t> m_connections{0}, m_refused{0}, m_received{0}, m_accepted{0}, m_malformed{0},
      m_oversized{0}, m_out_of_order{0}, m_duplicate{0}, m_ignored{0}, m_forces_sent{0}, m_forces_dropped{0},
      m_surfaces_sent{0}, m_surfaces_skipped{0};
  std::thread m_thread;  // last: started when everything else is ready
};

}  // namespace tissue::host
