// live_view.cpp - see live_view.hpp.
#include "view/live_view.hpp"

#include "view/view_frame.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>

namespace tissue::host {
namespace {

// FNV-1a over the triangle indices: the topology revision changes when they do.
std::uint64_t triangle_hash(const std::vector<std::uint32_t>& triangles) {
  std::uint64_t hash = 1469598103934665603ULL;
  for (const std::uint32_t index : triangles) {
    hash ^= index;
    hash *= 1099511628211ULL;
  }
  return hash ^ triangles.size();
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace

bool is_loopback_address(const std::string& address) { return address.rfind("127.", 0) == 0 || address == "::1"; }

LiveView::LiveView(LiveViewSettings settings, BrowserDevice* device)
    : m_settings(std::move(settings)),
      m_device(device),
      m_server(
          ViewServerSettings{m_settings.address, m_settings.port, m_settings.token, m_settings.static_dir.string()},
          [this](std::uint64_t connection, const std::string& text) {
            if (m_device != nullptr) m_device->handle_message(connection, text);
          },
          [this](std::uint64_t connection) {
            if (m_device != nullptr) m_device->connection_closed(connection);
          },
          [this] {
            if (m_device != nullptr) m_device->tick();
          }) {
  const nlohmann::json hello = {{"type", "hello"},
                                 {"version", 1},
                                 {"controls", m_device != nullptr},
                                 {"bounds", {{"lower", m_settings.rest_lower}, {"upper", m_settings.rest_upper}}},
                                 {"device_max_force_n", m_settings.device_max_force_n},
                                 {"blade_length_m", m_settings.blade_length_m},
                                 {"scenario", m_settings.scenario}};
  m_server.set_hello(hello.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  m_recent_periods_s.assign(2000, 0.0);
  m_recent_steps_s.assign(200, 0.0);
}

LiveView::~LiveView() { stop(); }

void LiveView::start() {
  m_server.start();
  m_started = std::chrono::steady_clock::now();
  m_running.store(true);
  m_thread = std::thread([this] { run(); });
}

void LiveView::stop() {
  if (m_running.exchange(false) && m_thread.joinable()) m_thread.join();
  m_server.stop();
}

LiveViewCounters LiveView::counters() const {
  LiveViewCounters c;
  c.server = m_server.counters();
  if (m_device != nullptr) c.device = m_device->counters();
  c.frames_encoded = m_frames_encoded.load();
  return c;
}

bool LiveView::frame_due() {
  const auto now = std::chrono::steady_clock::now();
  if (now - m_last_frame < std::chrono::duration<double>(1.0 / m_settings.max_frame_rate_hz)) return false;
  m_last_frame = now;
  return true;
}

void LiveView::publish_tissue(const TissueLive& tissue) {
  m_tissue.write_buffer() = tissue;
  m_tissue.publish();
}

void LiveView::record_tick(double period_s, std::uint64_t deadline_misses, const std::array<double, 3>& device_force_n) {
  HapticLive& live = m_haptic_pending;
  if (period_s > 0.0) live.periods_s[live.count++] = period_s;
  ++live.ticks;
  live.deadline_misses = deadline_misses;
  live.device_force_n = device_force_n;
  if (live.count < HapticLive::PERIODS) return;
  m_haptic.write_buffer() = live;
  m_haptic.publish();
  live.count = 0;
}

void LiveView::run() {
  std::string plain, with_triangles;
  std::uint64_t last_hash = 0;
  std::uint64_t last_embedding = 0;  // the FMU's surface.revision of the last frame's embedding
  std::uint32_t revision = 0;
  auto next_stats = std::chrono::steady_clock::now();
  while (m_running.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(4));
    if (m_haptic.update()) {
      m_last_haptic = m_haptic.read_buffer();
      for (std::size_t k = 0; k < m_last_haptic.count; ++k) {
        m_recent_periods_s[m_recent_next] = m_last_haptic.periods_s[k];
        m_recent_next = (m_recent_next + 1) % m_recent_periods_s.size();
      }
    }
    if (m_tissue.update()) {
      m_last_tissue = m_tissue.read_buffer();
      m_recent_steps_s[m_steps_next] = m_last_tissue.step_s;
      m_steps_next = (m_steps_next + 1) % m_recent_steps_s.size();
    }
    if (m_frames.update()) {
      const SurfaceFrame& frame = m_frames.read_buffer();
      const std::uint64_t hash = triangle_hash(frame.triangles);
      // A new embedding (a cut) may keep the triangles but move points onto new nodes.
      const std::uint64_t embedding = frame.embedding ? frame.embedding->revision : 0;
      if (hash != last_hash || embedding != last_embedding) {
        last_hash = hash;
        last_embedding = embedding;
        ++revision;
      }
      ViewOverlay overlay;
      overlay.device_force_n = m_last_haptic.device_force_n;
      overlay.device_max_force_n = m_settings.device_max_force_n;
      overlay.topology_revision = revision;
      try {
        encode_view_frames(frame, overlay, plain, with_triangles);
        m_server.publish_frame(std::make_shared<const std::string>(plain),
                               std::make_shared<const std::string>(with_triangles), revision);
        ++m_frames_encoded;
      } catch (const OutputError&) {
        // A frame with a non-finite number is not shown; the session counts NaN itself.
      }
    }
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_stats) {
      m_server.publish_stats(stats_json());
      next_stats = now + std::chrono::milliseconds(250);
    }
  }
}

std::string LiveView::stats_json() {
  std::vector<double> periods;
  for (const double p : m_recent_periods_s) {
    if (p > 0.0) periods.push_back(p);
  }
  std::vector<double> steps;
  for (const double s : m_recent_steps_s) {
    if (s > 0.0) steps.push_back(s);
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_started).count();
  const LiveViewCounters c = counters();
  const double haptic_max_s = periods.empty() ? 0.0 : *std::max_element(periods.begin(), periods.end());
  const nlohmann::json stats = {
      {"type", "stats"},
      {"sim_time_s", m_last_tissue.time_s},
      {"realtime_factor", wall_s > 0.0 ? m_last_tissue.time_s / wall_s : 0.0},
      {"haptic_period_us",
       {{"p50", 1e6 * percentile(periods, 0.5)}, {"p99", 1e6 * percentile(periods, 0.99)}, {"max", 1e6 * haptic_max_s}}},
      {"deadline_misses", m_last_haptic.deadline_misses},
      {"tissue_step_ms", {{"p50", 1e3 * percentile(steps, 0.5)}, {"p99", 1e3 * percentile(steps, 0.99)}}},
      {"cut_tets", m_last_tissue.cut_tets},
      {"viewers", c.server.open},
      {"frames_sent", c.server.frames_sent},
      {"frames_skipped", c.server.frames_skipped},
      {"messages",
       {{"received", c.server.messages},
        {"accepted", c.device.accepted},
        {"malformed", c.device.malformed + c.server.binary},
        {"oversized", c.server.oversized},
        {"flood", c.server.flood},
        {"out_of_order", c.device.out_of_order},
        {"withdrawals", c.device.watchdog_trips}}}};
  return stats.dump();
}

}  // namespace tissue::host
