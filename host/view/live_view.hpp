// live_view.hpp - the session's live view (issue 11): the newest surface frame and live figures,
// handed over by the haptic and dynamics threads without waiting (LatestValue), encoded and sent
// to the pages by a view thread of its own through the ViewServer. The view never slows the
// haptic or dynamics threads: they publish and go on; the view thread takes what is newest and
// drops the rest; a slow page is skipped (view_server.hpp).
#pragma once

#include "output/surface_frame.hpp"
#include "sync/latest_value.hpp"
#include "view/browser_device.hpp"
#include "view/view_server.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>

namespace tissue::host {

struct LiveViewSettings {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8080;
  std::string token;  ///< required (and printed) when the address is not a loopback one
  std::filesystem::path static_dir;
  double max_frame_rate_hz = 60.0;
  // For the pages' hello.
  std::string scenario;
  std::array<double, 3> rest_lower{}, rest_upper{};
  double device_max_force_n = 0.0;
  double blade_length_m = 0.0;
};

/// The haptic thread's figures for the view: the periods of its last ticks and its misses.
struct HapticLive {
  static constexpr std::size_t PERIODS = 20;
  std::array<double, PERIODS> periods_s{};
  std::size_t count = 0;
  std::uint64_t ticks = 0, deadline_misses = 0;
  std::array<double, 3> device_force_n{};
};

/// The dynamics thread's figures for the view, after each tissue step.
struct TissueLive {
  double time_s = 0.0;
  double step_s = 0.0;
  std::uint64_t cut_tets = 0;
};

/// What the view did, for summary.json.
struct LiveViewCounters {
  ViewServerCounters server;
  DeviceCounters device;
  std::uint64_t frames_encoded = 0;
};

/// True for 127.0.0.0/8 and ::1.
bool is_loopback_address(const std::string& address);

class LiveView {
 public:
  /// `device`: the browser device the pages drive, or nullptr (the pages only watch).
  LiveView(LiveViewSettings settings, BrowserDevice* device);
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  /// Starts the server and the view thread; throws ViewServerError.
  void start();
  void stop();
  [[nodiscard]] std::uint16_t port() const { return m_server.port(); }
  [[nodiscard]] LiveViewCounters counters() const;

  // --- dynamics thread ---
  /// True when a frame would be sent now (at most max_frame_rate_hz of wall time).
  [[nodiscard]] bool frame_due();
  /// Fill frame_buffer(), then publish_frame().
  SurfaceFrame& frame_buffer() { return m_frames.write_buffer(); }
  void publish_frame() { m_frames.publish(); }
  void publish_tissue(const TissueLive& tissue);

  // --- haptic thread (no allocation, no lock) ---
  void record_tick(double period_s, std::uint64_t deadline_misses, const std::array<double, 3>& device_force_n);

 private:
  void run();
  std::string stats_json();

  LiveViewSettings m_settings;
  BrowserDevice* m_device;
  ViewServer m_server;
  LatestValue<SurfaceFrame> m_frames;
  LatestValue<HapticLive> m_haptic;
  LatestValue<TissueLive> m_tissue;
  HapticLive m_haptic_pending;  // haptic thread's own
  std::chrono::steady_clock::time_point m_last_frame{};  // dynamics thread's own
  std::thread m_thread;
  std::atomic<bool> m_running{false};
  std::atomic<std::uint64_t> m_frames_encoded{0};
  // View thread's own.
  std::vector<double> m_recent_periods_s;  // ring of the last 2000
  std::size_t m_recent_next = 0;
  std::vector<double> m_recent_steps_s;  // ring of the last 200
  std::size_t m_steps_next = 0;
  HapticLive m_last_haptic;
  TissueLive m_last_tissue;
  std::chrono::steady_clock::time_point m_started{};
};

}  // namespace tissue::host
