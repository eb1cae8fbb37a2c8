// igtl_client.hpp - an OpenIGTLink client built on Debian's libopenigtlink, as 3D Slicer or PLUS
// would connect to tissue-host (host/igtl/OPENIGTLINK.md): sends the tool's pose as TRANSFORM or
// POSITION messages and collects the force (SENSOR) and surface (POLYDATA) messages on a thread
// of its own. Used by the OpenIGTLink tests and by the tissue-igtl-client tool.
#pragma once

#include "device/device.hpp"

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace tissue::host::test {

struct ReceivedForce {
  double receive_time_s = 0.0;  ///< the client's steady clock
  std::array<double, 3> force_n{};
  bool unit_is_newton = false;
};

struct ReceivedSurface {
  std::string name;
  std::size_t points = 0, polygons = 0;
  std::vector<std::array<float, 3>> point_list;  ///< in the wire's length unit
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

class IgtlClient {
 public:
  /// Connects to @p host:@p port (retrying for up to @p connect_timeout_s), then receives on a thread.
  /// Throws std::runtime_error when it cannot connect.
  IgtlClient(const std::string& host, int port, double connect_timeout_s = 5.0);
  ~IgtlClient();
  IgtlClient(const IgtlClient&) = delete;
  IgtlClient& operator=(const IgtlClient&) = delete;

  /// A TRANSFORM message named @p name with @p pose, lengths divided by @p length_unit_m, stamped
  /// with @p timestamp (seconds << 32 | fraction; 0: the current time).
  void send_transform(const std::string& name, const DevicePose& pose, double length_unit_m = 1e-3,
                      std::uint64_t timestamp = 0);
  /// A POSITION message (position and quaternion) likewise.
  void send_position(const std::string& name, const DevicePose& pose, double length_unit_m = 1e-3,
                     std::uint64_t timestamp = 0);
  /// Sends bytes as they are.
  void send_raw(const std::vector<std::uint8_t>& bytes);

  [[nodiscard]] std::vector<ReceivedForce> forces() const;
  [[nodiscard]] std::optional<ReceivedSurface> last_surface() const;
  [[nodiscard]] std::size_t surface_count() const;
  /// Messages of other types received, and whether the server closed the connection.
  [[nodiscard]] std::size_t other_messages() const { return m_other.load(); }
  [[nodiscard]] bool closed() const { return m_closed.load(); }

 private:
  struct Socket;
  void receive_loop();

  std::unique_ptr<Socket> m_socket;
  mutable std::mutex m_mutex;
  std::vector<ReceivedForce> m_forces;
  std::optional<ReceivedSurface> m_surface;
  std::size_t m_surface_count = 0;
  std::atomic<std::size_t> m_other{0};
  std::atomic<bool> m_stop{false}, m_closed{false};
  std::thread m_receiver;
};

/// A packed TRANSFORM message named @p name with @p pose, lengths divided by @p length_unit_m,
/// stamped with @p timestamp (seconds << 32 | fraction; 0: the current time).
std::vector<std::uint8_t> pack_transform(const std::string& name, const DevicePose& pose, double length_unit_m = 1e-3,
                                         std::uint64_t timestamp = 0);
/// A packed POSITION message likewise, with @p body_size 12 (position only), 24 (quaternion
/// without w) or 28 (all).
std::vector<std::uint8_t> pack_position(const std::string& name, const DevicePose& pose, double length_unit_m = 1e-3,
                                        std::uint64_t timestamp = 0, int body_size = 28);

/// The client's steady clock [s].
[[nodiscard]] double steady_time_s();

}  // namespace tissue::host::test
