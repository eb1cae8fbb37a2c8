// browser_device.hpp - the page's mouse and keyboard as a haptic device (VIEW_PROTOCOL.md): pose
// messages from the live view's pages become the hand's pose, read by the haptic thread through a
// LatestValue (no lock, no allocation), the same Device interface as the UDP bridge. A page that
// disconnects, or goes silent for 0.5 s while holding a tool, withdraws the tool (mode none, the
// pose kept). There is no hand to push: the force written is returned as sent (the view shows the
// haptic thread's force from its own figures, live_view.hpp).
//
// Threads: handle_message(), connection_closed() and tick() belong to the view server's thread;
// read() and write_force() to the haptic thread; counters() to any.
#pragma once

#include "device/device.hpp"
#include "sync/latest_value.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace tissue::host {

class BrowserDevice final : public Device {
 public:
  /// A page silent this long while holding a tool (mode not none) has its tool withdrawn.
  static constexpr std::chrono::milliseconds SILENCE_LIMIT{500};

  explicit BrowserDevice(const DevicePose& initial);

  DevicePose read(double time_s) override;
  std::array<double, 3> write_force(double time_s, const std::array<double, 3>& force_n) override;
  [[nodiscard]] DeviceCounters counters() const override;
  [[nodiscard]] std::string_view name() const override { return "browser (the live view's mouse and keyboard)"; }

  // --- the view server's thread ---
  /// One text message of page `connection`: a pose, or dropped and counted.
  void handle_message(std::uint64_t connection, const std::string& text);
  /// The page is gone: its tool is withdrawn if it held the hand.
  void connection_closed(std::uint64_t connection);
  /// The silence watchdog (about every 100 ms).
  void tick();

 private:
  void publish(const DevicePose& pose);

  LatestValue<DevicePose> m_pose;  // server thread -> haptic thread
  DevicePose m_current;            // haptic thread: the last pose read
  // Server thread.
  DevicePose m_last_published;
  std::uint64_t m_holder = 0;  // the connection whose pose is the hand's (0: none)
  std::chrono::steady_clock::time_point m_last_message{};
  std::map<std::uint64_t, std::uint64_t> m_last_seq;  // per connection
  // Any thread.
  std::atomic<std::uint64_t> m_received{0}, m_accepted{0}, m_malformed{0}, m_out_of_order{0}, m_withdrawals{0};
};

}  // namespace tissue::host
