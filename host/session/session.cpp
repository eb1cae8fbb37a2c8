// run_session (see session.hpp).
#include "session/session.hpp"

#include "view/browser_device.hpp"
#include "view/live_view.hpp"

#include "device/replay_device.hpp"
#include "device/scripted_device.hpp"
#include "device/udp_device.hpp"
#include "importer/fmu3.hpp"
#include "output/json_text.hpp"
#include "output/png_renderer.hpp"
#include "output/pvd_writer.hpp"
#include "output/vtu_writer.hpp"
#include "session/fmu_links.hpp"
#include "session/latest_value.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <sstream>
#include <thread>
#include <vector>

namespace tissue::host {
namespace {

// --- time ---

using Nanoseconds = std::int64_t;

Nanoseconds now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<Nanoseconds>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleep_until_ns(Nanoseconds deadline) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(deadline % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

// CPU time of the calling thread: what a doStep cost, whatever else the machine runs.
Nanoseconds thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<Nanoseconds>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

Nanoseconds to_ns(double seconds) { return static_cast<Nanoseconds>(std::llround(seconds * 1e9)); }

Percentiles percentiles(std::vector<double> values, double scale) {
  Percentiles p;
  if (values.empty()) return p;
  std::sort(values.begin(), values.end());
  const auto at = [&](double q) {
    const auto index = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size()))) - 1;
    return values[std::min(values.size() - 1, index)] * scale;
  };
  p.p50 = at(0.5);
  p.p99 = at(0.99);
  p.max = values.back() * scale;
  return p;
}

// Shortest round-trip decimal: locale-independent, so equal runs write equal bytes.
void append_number(std::string& line, double value) {
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  line.append(buffer, error == std::errc() ? end : buffer);
}

bool finite3(const std::array<double, 3>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

double norm3(const std::array<double, 3>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// --- real-time priority ---

struct Priority {
  bool granted = false;
  std::string note;
};

Priority try_fifo_priority(int priority) {
  sched_param param{};
  param.sched_priority = priority;
  const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  if (error == 0) return {true, "SCHED_FIFO"};
  return {false, std::string("real-time priority not permitted (") + std::strerror(error) +
                     "): running at normal priority; run as root, or grant rtprio in /etc/security/limits.conf "
                     "or CAP_SYS_NICE"};
}

// --- what a tick logs ---

struct LogRow {
  double time_s = 0.0;
  DevicePose device;
  std::array<double, 3> tool_position_m{};
  std::int64_t tool_mode = 0;
  std::array<double, 3> force_n{};  // sent to the device
  bool contact = false;
  double tissue_time_s = 0.0;
  double observed_energy_j = 0.0;
};

std::string log_line(const LogRow& r) {
  std::string line;
  append_number(line, r.time_s);
  for (const double v : r.device.position_m) line += ',', append_number(line, v);
  for (const double v : r.tool_position_m) line += ',', append_number(line, v);
  line += ',' + std::to_string(r.tool_mode);
  for (const double v : r.force_n) line += ',', append_number(line, v);
  line += r.contact ? ",1," : ",0,";
  append_number(line, r.tissue_time_s);
  line += ',';
  append_number(line, r.observed_energy_j);
  return line;
}

std::string recording_line(const LogRow& r) {
  std::string line;
  append_number(line, r.time_s);
  for (const double v : r.device.position_m) line += ',', append_number(line, v);
  for (const double v : r.device.orientation_wxyz) line += ',', append_number(line, v);
  line += ',' + std::to_string(static_cast<int>(r.device.mode));
  return line;
}

// --- the device from the scenario ---

std::unique_ptr<Device> make_device(const DeviceConfig& config, const TissueLink& tissue) {
  switch (config.kind) {
    case DeviceKind::scripted: {
      std::vector<DeviceWaypoint> waypoints;
      for (const Waypoint& w : config.waypoints) {
        DeviceWaypoint d;
        d.time_s = w.time_s;
        for (std::size_t a = 0; a < 3; ++a) {
          d.pose.position_m[a] = w.box_relative ? tissue.rest_lower()[a] +
                                                      w.position[a] * (tissue.rest_upper()[a] - tissue.rest_lower()[a])
                                                : w.position[a];
        }
        d.pose.orientation_wxyz = w.orientation_wxyz;
        d.pose.mode = w.mode;
        waypoints.push_back(d);
      }
      return std::make_unique<ScriptedDevice>(std::move(waypoints));
    }
    case DeviceKind::replay:
      return std::make_unique<ReplayDevice>(config.replay_file);
    case DeviceKind::browser: {
      // Start put away, 2 cm above the middle of the body's top.
      DevicePose pose;
      for (std::size_t a = 0; a < 2; ++a) pose.position_m[a] = 0.5 * (tissue.rest_lower()[a] + tissue.rest_upper()[a]);
      pose.position_m[2] = tissue.rest_upper()[2] + 0.02;
      return std::make_unique<BrowserDevice>(pose);
    }
    case DeviceKind::udp: {
      UdpDeviceSettings settings;
      settings.bind_address = config.udp_address;
      settings.port = config.udp_port;
      settings.allow_remote = config.udp_allow_remote;
      return std::make_unique<UdpDevice>(settings);
    }
  }
  throw ScenarioError("device: unknown kind");
}

DeviceConfig browser_config() {
  DeviceConfig config;
  config.kind = DeviceKind::browser;
  return config;
}

std::filesystem::path fmu_path(const std::filesystem::path& configured, const std::filesystem::path& fmu_dir,
                               const char* name) {
  if (!configured.empty()) return configured;
  return fmu_dir / name;
}

// --- frames handed from the dynamics thread to the writer (the main thread) ---

class FramePipe {
 public:
  explicit FramePipe(std::size_t pool) {
    for (std::size_t k = 0; k < pool; ++k) m_free.push_back(std::make_unique<SurfaceFrame>());
  }
  /// Sizes every frame's arrays once, before the run, so that capturing allocates nothing.
  template <class Prepare>
  void prepare(Prepare&& prepare_frame) {
    for (auto& frame : m_free) prepare_frame(*frame);
  }
  std::unique_ptr<SurfaceFrame> take_free() {
    const std::lock_guard lock(m_mutex);
    if (m_free.empty()) return nullptr;
    auto frame = std::move(m_free.back());
    m_free.pop_back();
    return frame;
  }
  void push_filled(std::unique_ptr<SurfaceFrame> frame) {
    {
      const std::lock_guard lock(m_mutex);
      m_filled.push_back(std::move(frame));
    }
    m_ready.notify_one();
  }
  std::unique_ptr<SurfaceFrame> wait_filled(std::chrono::milliseconds timeout) {
    std::unique_lock lock(m_mutex);
    m_ready.wait_for(lock, timeout, [&] { return !m_filled.empty(); });
    if (m_filled.empty()) return nullptr;
    auto frame = std::move(m_filled.front());
    m_filled.pop_front();
    return frame;
  }
  void give_back(std::unique_ptr<SurfaceFrame> frame) {
    const std::lock_guard lock(m_mutex);
    m_free.push_back(std::move(frame));
  }

 private:
  std::mutex m_mutex;
  std::condition_variable m_ready;
  std::vector<std::unique_ptr<SurfaceFrame>> m_free;
  std::deque<std::unique_ptr<SurfaceFrame>> m_filled;
};

class FrameWriter {
 public:
  explicit FrameWriter(const std::filesystem::path& output_dir) : m_dir(output_dir) {
    std::filesystem::create_directories(m_dir / "frames");
  }
  void write(const SurfaceFrame& frame) {
    const std::string name = frame_file_name("frame", m_pvd.size());
    write_vtu(m_dir / "frames" / name, frame);
    m_pvd.add(frame.time_s, "frames/" + name);
  }
  void finish() const { m_pvd.write(m_dir / "surface.pvd"); }
  [[nodiscard]] std::size_t count() const { return m_pvd.size(); }

 private:
  std::filesystem::path m_dir;
  PvdWriter m_pvd;
};

// --- the session ---

class Session {
 public:
  Session(const Scenario& scenario, const SessionOptions& options)
      : m_scenario(scenario),
        m_options(options),
        m_tissue_fmu(fmu_path(scenario.tissue_fmu, options.fmu_dir, "Tissue.fmu")),
        m_haptic_fmu(fmu_path(scenario.haptic_fmu, options.fmu_dir, "HapticLoop.fmu")),
        m_tissue(m_tissue_fmu, with_overrides(scenario.tissue_parameters, options.tissue_parameter_overrides)),
        m_haptic(m_haptic_fmu, scenario.haptic_parameters),
        m_device(make_device(options.browser_device ? browser_config() : scenario.device, m_tissue)) {
    if (options.view && options.offline) throw ScenarioError("--view: the live view needs a real-time run, not --offline");
    if (!options.view && dynamic_cast<BrowserDevice*>(m_device.get()) != nullptr) {
      throw ScenarioError("device: the browser device needs the live view (run with --view or --mouse)");
    }
    if (options.view) {
      const SessionOptions::View& view = *options.view;
      if (!is_loopback_address(view.address) && view.token.empty()) {
        throw ScenarioError("--view-listen " + view.address + ": a non-loopback address needs an access token");
      }
      LiveViewSettings settings;
      settings.address = view.address;
      settings.port = view.port;
      settings.token = view.token;
      settings.static_dir = view.static_dir;
      settings.scenario = scenario.name;
      settings.rest_lower = m_tissue.rest_lower();
      settings.rest_upper = m_tissue.rest_upper();
      settings.device_max_force_n = m_haptic.max_force_n();
      settings.blade_length_m = m_tissue.blade_length_m();
      m_view = std::make_unique<LiveView>(settings, dynamic_cast<BrowserDevice*>(m_device.get()));
    }
    m_period_s = scenario.haptic_period_s;
    m_slot_s = scenario.tissue_step_s;
    m_ticks_per_slot = static_cast<std::uint64_t>(std::llround(m_slot_s / m_period_s));
    m_ticks = static_cast<std::uint64_t>(std::llround(std::ceil(scenario.duration_s / m_slot_s))) * m_ticks_per_slot;
    m_rows.resize(m_ticks);
    m_periods_s.reserve(m_ticks);
    m_step_s.reserve(m_ticks / m_ticks_per_slot + 8);
    m_step_cutting.reserve(m_ticks / m_ticks_per_slot + 8);
    m_summary.scenario = scenario.name;
    m_summary.offline = options.offline;
    m_summary.tissue_step_s = m_slot_s;
    m_summary.device_name = std::string(m_device->name());
    m_summary.device_max_force_n = m_haptic.max_force_n();
    m_summary.overrun_policy = scenario.overrun_policy == OverrunPolicy::catch_up ? "catch_up" : "skip";
    if (options.write_outputs) std::filesystem::create_directories(options.output_dir);
    // The first tool command: the haptic loop's output before any tick (the device at t = 0).
    m_haptic.set_device(m_device->read(0.0));
    HapticOutputs initial;
    m_haptic.read(initial);
    m_tool_command.reset(initial.tool);
  }

  SessionSummary run() {
    if (m_options.tissue_observer != nullptr) m_options.tissue_observer->started(m_tissue.instance());
    const Nanoseconds wall_start = now_ns();
    if (m_options.offline) {
      run_offline();
      m_summary.wall_time_s = static_cast<double>(now_ns() - wall_start) * 1e-9;
    } else {
      run_realtime();  // measures the session's wall time itself, from its first deadline
    }
    finish();
    return m_summary;
  }

 private:
  // One haptic tick n (session time n * period). Haptic thread: no allocation, no lock.
  void haptic_tick(std::uint64_t n) {
    const double t = static_cast<double>(n) * m_period_s;
    const DevicePose pose = m_device->read(t);
    if (m_tissue_sample.update()) {
      const TissueOutputs& sample = m_tissue_sample.read_buffer();
      if (sample.finite) {
        m_haptic.set_tissue(sample);
        m_last_tissue_time_s = sample.time_s;
        m_contact = sample.contact_active;
      } else {
        ++m_summary.samples_not_finite;
      }
    }
    m_haptic.set_device(pose);
    const DoStepResult result = m_haptic.step(t, m_period_s);
    if (result.status != fmi3OK && result.status != fmi3Warning) ++m_summary.haptic_errors;
    m_haptic.read(m_haptic_out);
    std::array<double, 3> force = m_haptic_out.device_force_n;
    if (!finite3(force)) {
      m_haptic_nan = true;
      force = {0.0, 0.0, 0.0};
    }
    const std::array<double, 3> sent = m_device->write_force(t, force);
    m_summary.max_device_force_n = std::max(m_summary.max_device_force_n, norm3(sent));
    ToolCommand& command = m_tool_command.write_buffer();
    command = m_haptic_out.tool;
    command.time_s = t + m_period_s;
    m_tool_command.publish();
    LogRow& row = m_rows[n];
    row.time_s = t;
    row.device = pose;
    row.tool_position_m = m_haptic_out.tool.position_m;
    row.tool_mode = m_haptic_out.tool.mode;
    row.force_n = sent;
    row.contact = m_contact;
    row.tissue_time_s = m_last_tissue_time_s;
    row.observed_energy_j = m_haptic_out.observed_energy_j;
  }

  // One tissue step from tissue time `time_s` over `slots` slots; returns the outputs to publish.
  void tissue_step(double time_s, int slots, TissueOutputs& out) {
    m_tool_command.update();
    m_tissue.set_tool(m_tool_command.read_buffer());
    const bool scalpel = m_tool_command.read_buffer().mode == static_cast<std::int64_t>(ToolMode::scalpel);
    const double step_s = slots * m_slot_s;
    TissueStepObserver* const observer = m_options.tissue_observer;
    const Nanoseconds cpu_start = observer != nullptr ? thread_cpu_ns() : 0;
    const Nanoseconds start = now_ns();
    const DoStepResult result = m_tissue.step(time_s, step_s);
    const double seconds = static_cast<double>(now_ns() - start) * 1e-9;
    const Nanoseconds cpu_end = observer != nullptr ? thread_cpu_ns() : 0;
    double reached_s = time_s + step_s;
    if (result.status == fmi3Discard) {
      ++m_summary.tissue_discards;
      reached_s = result.last_successful_time_s;
    } else if (result.status != fmi3OK) {
      ++m_summary.tissue_errors;
      if (m_summary.first_error.empty()) m_summary.first_error = "Tissue doStep: " + m_tissue.instance().log_text();
      m_tissue_failed = true;
    }
    m_tissue.read(out);
    out.time_s = reached_s;
    if (!out.finite) m_tissue_nan = true;
    m_summary.contact_seen = m_summary.contact_seen || out.contact_active;
    // Steps are "during cuts" from the first step with the scalpel in the tissue.
    m_cutting_seen = m_cutting_seen || (scalpel && out.blade_depth_m > 0.0) || out.cut_tets > 0;
    if (observer != nullptr) {
      TissueStepInfo info;
      info.index = m_step_s.size();
      info.start_s = time_s;
      info.reached_s = reached_s;
      info.cpu_s = static_cast<double>(cpu_end - cpu_start) * 1e-9;
      info.result = result;
      info.outputs = &out;
      observer->stepped(m_tissue.instance(), info);
    }
    m_step_s.push_back(seconds);
    m_step_cutting.push_back(m_cutting_seen ? 1 : 0);
    m_cut_tets.store(out.cut_tets, std::memory_order_relaxed);
    m_summary.cut_tets = out.cut_tets;
    m_summary.enriched_vertices = out.enriched_vertices;
  }

  bool frame_due(double time_s) const {
    return m_options.write_outputs && m_scenario.frame_rate_hz > 0.0 && time_s + 1e-9 >= m_next_frame_s;
  }
  void capture_frame(SurfaceFrame& frame, double time_s) {
    fill_frame(frame, time_s);
    m_next_frame_s += 1.0 / m_scenario.frame_rate_hz;
  }
  void fill_frame(SurfaceFrame& frame, double time_s) {
    m_tissue.read_surface(frame);
    frame.time_s = time_s;
    const ToolCommand& tool = m_tool_command.read_buffer();
    frame.has_tool = tool.mode != 0;
    frame.tool_mode = static_cast<int>(tool.mode);
    frame.tool_tip_m = tool.position_m;
    const auto& q = tool.orientation_wxyz;  // the tool axis: the quaternion's image of +z
    const std::array<double, 3> axis{2.0 * (q[1] * q[3] + q[0] * q[2]), 2.0 * (q[2] * q[3] - q[0] * q[1]),
                                     1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2])};
    const double length = tool.mode == static_cast<std::int64_t>(ToolMode::scalpel) ? m_tissue.blade_length_m() : 0.03;
    for (std::size_t a = 0; a < 3; ++a) frame.tool_handle_m[a] = tool.position_m[a] + length * axis[a];
    frame.contact_active = m_last_outputs.contact_active;
    frame.contact_point_m = m_last_outputs.contact_point_m;
    frame.force_n = m_last_outputs.contact_force_n;
    while (m_next_frame_s <= time_s + 1e-9) m_next_frame_s += 1.0 / m_scenario.frame_rate_hz;
  }

  void run_offline() {
    std::optional<FrameWriter> writer;
    if (m_options.write_outputs) writer.emplace(m_options.output_dir);
    SurfaceFrame frame;
    bool pending = false;
    TissueOutputs result;
    double tissue_time_s = 0.0;
    std::uint64_t next_progress = 0;
    for (std::uint64_t n = 0; n < m_ticks; ++n) {
      if (n % m_ticks_per_slot == 0) {
        // The result of the previous step arrives at the start of this slot, then the next starts.
        if (pending) {
          m_tissue_sample.write_buffer() = result;
          m_tissue_sample.publish();
          pending = false;
        }
        if (!m_tissue_failed) {
          tissue_step(tissue_time_s, 1, result);
          m_last_outputs = result;
          tissue_time_s = result.time_s;
          pending = true;
          if (frame_due(tissue_time_s)) {
            capture_frame(frame, tissue_time_s);
            writer->write(frame);
          }
        }
      }
      haptic_tick(n);
      if (m_options.progress != nullptr && n >= next_progress) {
        *m_options.progress << "offline: t = " << static_cast<double>(n) * m_period_s << " / " << m_scenario.duration_s
                            << " s, cut tets " << m_summary.cut_tets << "\n";
        next_progress += m_ticks / 10 + 1;
      }
    }
    m_summary.haptic_ticks = m_ticks;
    m_summary.tissue_steps = m_step_s.size();
    m_summary.sim_time_s = static_cast<double>(m_ticks) * m_period_s;
    if (writer) {
      m_summary.frames_written = writer->count();
      writer->finish();
    }
  }

  void run_realtime() {
    if (m_view) {
      m_view->start();
      if (m_options.view_started) m_options.view_started(m_view->port());
    }
    run_realtime_threads();
    if (m_view) {
      m_view->stop();
      const LiveViewCounters c = m_view->counters();
      m_summary.view = true;
      m_summary.view_connections = c.server.connections;
      m_summary.view_frames_sent = c.server.frames_sent;
      m_summary.view_frames_skipped = c.server.frames_skipped;
      m_summary.view_messages = c.server.messages;
      m_summary.view_malformed = c.device.malformed + c.server.binary;
      m_summary.view_oversized = c.server.oversized;
      m_summary.view_flood = c.server.flood;
      m_summary.view_out_of_order = c.device.out_of_order;
      m_summary.view_withdrawals = c.device.watchdog_trips;
    }
  }

  void run_realtime_threads() {
    FramePipe pipe(8);
    pipe.prepare([&](SurfaceFrame& frame) { m_tissue.reserve(frame); });
    std::atomic<int> ready{0};
    std::atomic<bool> go{false};
    std::atomic<bool> haptic_done{false};
    std::atomic<std::uint64_t> ticks_done{0};
    Nanoseconds start = 0;
    Nanoseconds haptic_end = 0;
    Priority haptic_priority, dynamics_priority;
    std::optional<std::uint64_t> stopped_at;  // haptic thread's, read after the join

    std::thread haptic([&] {
      if (m_options.realtime_priority) haptic_priority = try_fifo_priority(80);
      ready.fetch_add(1);
      while (!go.load(std::memory_order_acquire)) std::this_thread::yield();
      const Nanoseconds period = to_ns(m_period_s);
      Nanoseconds previous_wake = 0;
      if (m_options.haptic_thread_started) m_options.haptic_thread_started();
      for (std::uint64_t n = 0; n < m_ticks; ++n) {
        if (m_options.stop != nullptr && m_options.stop->load(std::memory_order_relaxed)) {
          stopped_at = n;  // asked to end early (Ctrl-C): the summary covers the ticks run
          break;
        }
        const Nanoseconds deadline = start + static_cast<Nanoseconds>(n) * period;
        sleep_until_ns(deadline);
        const Nanoseconds woke = now_ns();
        if (n == 0) m_summary.haptic_first_tick_late_us = static_cast<double>(woke - deadline) * 1e-3;
        if (n > 0) {
          const double period_s = static_cast<double>(woke - previous_wake) * 1e-9;
          m_periods_s.push_back(period_s);
          if (period_s > m_longest_period_s) {
            m_longest_period_s = period_s;
            m_summary.haptic_period_max_at_s = static_cast<double>(n) * m_period_s;
          }
        }
        previous_wake = woke;
        haptic_tick(n);
        if (now_ns() > deadline + period) ++m_summary.deadline_misses;  // the next tick starts late
        if (m_view) {
          m_view->record_tick(m_periods_s.empty() ? 0.0 : m_periods_s.back(), m_summary.deadline_misses,
                              m_rows[n].force_n);
        }
        ticks_done.store(n + 1, std::memory_order_relaxed);
      }
      haptic_end = now_ns();
      haptic_done.store(true, std::memory_order_release);
    });

    std::thread dynamics([&] {
      if (m_options.realtime_priority) dynamics_priority = try_fifo_priority(70);
      ready.fetch_add(1);
      while (!go.load(std::memory_order_acquire)) std::this_thread::yield();
      const Nanoseconds slot = to_ns(m_slot_s);
      const std::uint64_t slots_total = m_ticks / m_ticks_per_slot;
      std::uint64_t k = 0;  // the slot this step starts in
      int slots = 1;        // slots this step covers
      double tissue_time_s = 0.0;
      TissueOutputs result;
      while (k < slots_total && !haptic_done.load(std::memory_order_acquire) && !m_tissue_failed) {
        sleep_until_ns(start + static_cast<Nanoseconds>(k) * slot);
        slots = static_cast<int>(std::min<std::uint64_t>(static_cast<std::uint64_t>(slots), slots_total - k));
        tissue_step(tissue_time_s, slots, result);
        tissue_time_s = result.time_s;
        m_last_outputs = result;
        TissueOutputs& out = m_tissue_sample.write_buffer();
        out = result;
        m_tissue_sample.publish();
        if (m_view) {
          m_view->publish_tissue(TissueLive{tissue_time_s, m_step_s.empty() ? 0.0 : m_step_s.back(), result.cut_tets});
          if (m_view->frame_due()) {
            fill_frame(m_view->frame_buffer(), tissue_time_s);
            m_view->publish_frame();
          }
        }
        if (frame_due(tissue_time_s)) {
          if (auto frame = pipe.take_free()) {
            capture_frame(*frame, tissue_time_s);
            pipe.push_filled(std::move(frame));
          } else {
            ++m_summary.frames_dropped;
            m_next_frame_s += 1.0 / m_scenario.frame_rate_hz;
          }
        }
        k += static_cast<std::uint64_t>(slots);
        slots = 1;
        const Nanoseconds finished = now_ns();
        const Nanoseconds slot_end = start + static_cast<Nanoseconds>(k) * slot;
        if (finished > slot_end) {
          // Overrun: the step took longer than its slot(s). Never silent: counted, and handled by
          // the scenario's policy.
          ++m_summary.tissue_overruns;
          const auto missed = static_cast<std::uint64_t>((finished - slot_end) / slot) + 1;
          if (m_scenario.overrun_policy == OverrunPolicy::catch_up) {
            // The next step starts now (its slot began already) and covers the slots up to the
            // one the wall clock is in, at most max_catch_up_slots more than its own; tissue time
            // stays on wall time, with a longer (still whole-internal-step) communication step.
            const std::uint64_t cover =
                std::min<std::uint64_t>(missed, static_cast<std::uint64_t>(m_scenario.max_catch_up_slots) + 1);
            slots = static_cast<int>(cover);
            m_summary.catch_up_slots += cover - 1;
            if (missed > cover) {
              m_summary.skipped_slots += missed - cover;
              k += missed - cover;
            }
          } else {
            // The missed slots are skipped: the next step waits for the next slot boundary.
            m_summary.skipped_slots += missed;
            k += missed;
          }
        }
      }
      m_summary.sim_time_s = tissue_time_s;
    });

    while (ready.load() < 2) std::this_thread::yield();
    if (m_options.realtime_priority) {
      // Everything mapped now, the two threads' stacks and the frames included, is locked in
      // memory: no page fault in the loops. Not future mappings (MCL_FUTURE): then each large
      // allocation of the dynamics thread populated and locked its pages under the address-space
      // lock and stalled the haptic thread. May be refused like the priority.
      (void)mlockall(MCL_CURRENT);
    }
    start = now_ns() + 20'000'000;  // 20 ms from now: both threads are waiting
    go.store(true, std::memory_order_release);

    std::optional<FrameWriter> writer;
    if (m_options.write_outputs) writer.emplace(m_options.output_dir);
    Nanoseconds next_progress = start + 1'000'000'000;
    const auto drain = [&](std::chrono::milliseconds timeout) {
      while (auto frame = pipe.wait_filled(timeout)) {
        writer->write(*frame);
        pipe.give_back(std::move(frame));
        timeout = std::chrono::milliseconds(0);
      }
    };
    while (!haptic_done.load(std::memory_order_acquire)) {
      drain(std::chrono::milliseconds(50));
      if (m_options.progress != nullptr && now_ns() >= next_progress) {
        const double t = static_cast<double>(ticks_done.load(std::memory_order_relaxed)) * m_period_s;
        *m_options.progress << "real time: t = " << t << " / " << m_scenario.duration_s << " s, cut tets "
                            << m_cut_tets.load(std::memory_order_relaxed) << "\n";
        next_progress += 1'000'000'000;
      }
    }
    haptic.join();
    dynamics.join();
    if (stopped_at) {
      m_ticks = *stopped_at;
      m_rows.resize(m_ticks);
    }
    m_summary.wall_time_s = static_cast<double>(haptic_end - start) * 1e-9;
    drain(std::chrono::milliseconds(0));
    if (writer) {
      m_summary.frames_written = writer->count();
      writer->finish();
    }
    m_summary.haptic_ticks = m_ticks;
    m_summary.tissue_steps = m_step_s.size();
    m_summary.realtime_priority = haptic_priority.granted && dynamics_priority.granted;
    m_summary.realtime_priority_note =
        m_options.realtime_priority
            ? (m_summary.realtime_priority ? "SCHED_FIFO (haptic 80, dynamics 70)" : haptic_priority.note)
            : "not asked for";
  }

  void finish() {
    const double wall = m_summary.wall_time_s;
    if (m_options.offline) m_summary.sim_time_s = static_cast<double>(m_ticks) * m_period_s;
    m_summary.realtime_factor = wall > 0.0 ? m_summary.sim_time_s / wall : 0.0;
    m_summary.haptic_rate_hz = wall > 0.0 && !m_options.offline ? static_cast<double>(m_ticks) / wall : 0.0;
    m_summary.haptic_period_us = percentiles(m_periods_s, 1e6);
    m_summary.tissue_step_ms = percentiles(m_step_s, 1e3);
    std::vector<double> before, during;
    for (std::size_t k = 0; k < m_step_s.size(); ++k) (m_step_cutting[k] ? during : before).push_back(m_step_s[k]);
    m_summary.tissue_step_before_cut_ms = percentiles(before, 1e3);
    m_summary.tissue_step_during_cut_ms = percentiles(during, 1e3);
    HapticOutputs last;
    m_haptic.read(last);
    m_summary.passivity_dissipated_j = last.dissipated_energy_j;
    m_summary.passivity_observed_j = last.observed_energy_j;
    m_summary.device = m_device->counters();
    m_summary.nan_detected = m_haptic_nan || m_tissue_nan || !std::isfinite(m_summary.max_device_force_n);
    if (!m_options.write_outputs) return;

    const std::filesystem::path& dir = m_options.output_dir;
    {
      std::ofstream log(dir / "log.csv");
      log << "time_s,device_x_m,device_y_m,device_z_m,tool_x_m,tool_y_m,tool_z_m,tool_mode,force_x_n,force_y_n,"
             "force_z_n,contact,tissue_time_s,observed_energy_j\n";
      for (const LogRow& row : m_rows) log << log_line(row) << '\n';
      if (!log) throw std::runtime_error((dir / "log.csv").string() + ": cannot be written");
    }
    if (m_options.record) {
      std::ofstream record(*m_options.record);
      record << RECORDING_HEADER << '\n';
      for (const LogRow& row : m_rows) record << recording_line(row) << '\n';
      if (!record) throw std::runtime_error(m_options.record->string() + ": cannot be written");
    }
    if (m_scenario.write_png) {
      SurfaceFrame frame;
      m_next_frame_s = 0.0;
      capture_frame(frame, m_summary.sim_time_s);
      render_png(dir / "final.png", frame);
    }
    std::ofstream(dir / "summary.json") << m_summary.to_json();
  }

  const Scenario& m_scenario;
  const SessionOptions& m_options;
  Fmu3 m_tissue_fmu;
  Fmu3 m_haptic_fmu;
  TissueLink m_tissue;
  HapticLink m_haptic;
  std::unique_ptr<Device> m_device;
  std::unique_ptr<LiveView> m_view;          // --view
  double m_period_s = 0.001, m_slot_s = 0.01;
  std::uint64_t m_ticks_per_slot = 10, m_ticks = 0;
  // Exchanged between the threads (dissertation 5.1.3).
  LatestValue<ToolCommand> m_tool_command;
  LatestValue<TissueOutputs> m_tissue_sample;
  // Haptic thread's own.
  HapticOutputs m_haptic_out;
  std::vector<LogRow> m_rows;
  std::vector<double> m_periods_s;
  double m_last_tissue_time_s = 0.0;
  bool m_contact = false;
  bool m_haptic_nan = false;
  double m_longest_period_s = 0.0;
  // Dynamics thread's own.
  std::vector<double> m_step_s;
  std::vector<std::uint8_t> m_step_cutting;
  bool m_cutting_seen = false;
  bool m_tissue_nan = false;
  bool m_tissue_failed = false;
  double m_next_frame_s = 0.0;
  TissueOutputs m_last_outputs;
  std::atomic<std::uint64_t> m_cut_tets{0};  // for the progress line
  // Written by one thread each (each field by one thread only), read after both are joined.
  SessionSummary m_summary;
};

void json_percentiles(std::ostringstream& out, const char* name, const Percentiles& p) {
  out << "  \"" << name << "\": {\"p50\": " << p.p50 << ", \"p99\": " << p.p99 << ", \"max\": " << p.max << "},\n";
}

}  // namespace

std::string SessionSummary::to_json() const {
  std::ostringstream out;
  out.precision(9);
  out << "{\n";
  out << "  \"scenario\": " << json_string(scenario) << ",\n";
  out << "  \"mode\": \"" << (offline ? "offline" : "realtime") << "\",\n";
  out << "  \"sim_time_s\": " << sim_time_s << ",\n";
  out << "  \"wall_time_s\": " << wall_time_s << ",\n";
  out << "  \"realtime_factor\": " << realtime_factor << ",\n";
  out << "  \"haptic_rate_hz\": " << haptic_rate_hz << ",\n";
  out << "  \"haptic_ticks\": " << haptic_ticks << ",\n";
  json_percentiles(out, "haptic_period_us", haptic_period_us);
  out << "  \"haptic_period_max_at_s\": " << haptic_period_max_at_s << ",\n";
  out << "  \"haptic_first_tick_late_us\": " << haptic_first_tick_late_us << ",\n";
  out << "  \"deadline_misses\": " << deadline_misses << ",\n";
  out << "  \"tissue_communication_step_s\": " << tissue_step_s << ",\n";
  out << "  \"tissue_steps\": " << tissue_steps << ",\n";
  json_percentiles(out, "tissue_step_ms", tissue_step_ms);
  json_percentiles(out, "tissue_step_before_cut_ms", tissue_step_before_cut_ms);
  json_percentiles(out, "tissue_step_during_cut_ms", tissue_step_during_cut_ms);
  out << "  \"tissue_overruns\": " << tissue_overruns << ",\n";
  out << "  \"overrun_policy\": \"" << overrun_policy << "\",\n";
  out << "  \"catch_up_slots\": " << catch_up_slots << ",\n";
  out << "  \"skipped_slots\": " << skipped_slots << ",\n";
  out << "  \"tissue_discards\": " << tissue_discards << ",\n";
  out << "  \"tissue_errors\": " << tissue_errors << ",\n";
  out << "  \"haptic_errors\": " << haptic_errors << ",\n";
  out << "  \"samples_not_finite\": " << samples_not_finite << ",\n";
  out << "  \"cut_tets\": " << cut_tets << ",\n";
  out << "  \"enriched_vertices\": " << enriched_vertices << ",\n";
  out << "  \"contact_seen\": " << (contact_seen ? "true" : "false") << ",\n";
  out << "  \"max_device_force_N\": " << max_device_force_n << ",\n";
  out << "  \"device_max_force_N\": " << device_max_force_n << ",\n";
  out << "  \"passivity_dissipated_J\": " << passivity_dissipated_j << ",\n";
  out << "  \"passivity_observed_J\": " << passivity_observed_j << ",\n";
  out << "  \"nan_detected\": " << (nan_detected ? "true" : "false") << ",\n";
  out << "  \"device\": {\"name\": " << json_string(device_name) << ", \"received\": " << device.received
      << ", \"accepted\": " << device.accepted << ", \"malformed\": " << device.malformed
      << ", \"out_of_order\": " << device.out_of_order << ", \"duplicate\": " << device.duplicate
      << ", \"stale\": " << device.stale << ", \"watchdog_trips\": " << device.watchdog_trips << "},\n";
  out << "  \"frames_written\": " << frames_written << ",\n";
  out << "  \"frames_dropped\": " << frames_dropped << ",\n";
  if (view) {
    out << "  \"view\": {\"connections\": " << view_connections << ", \"frames_sent\": " << view_frames_sent
        << ", \"frames_skipped\": " << view_frames_skipped << ", \"messages\": " << view_messages
        << ", \"malformed\": " << view_malformed << ", \"oversized\": " << view_oversized << ", \"flood\": " << view_flood
        << ", \"out_of_order\": " << view_out_of_order << ", \"withdrawals\": " << view_withdrawals << "},\n";
  }
  out << "  \"realtime_priority\": " << (realtime_priority ? "true" : "false") << ",\n";
  out << "  \"realtime_priority_note\": " << json_string(realtime_priority_note) << ",\n";
  out << "  \"first_error\": " << json_string(first_error) << "\n";
  out << "}\n";
  return out.str();
}

// The Tissue FMU's sparse Cholesky (Debian's CHOLMOD) parallelizes some loops with OpenMP, whose
// worker pool outlives the call and spins while idle: on two cores it would compete with the
// haptic thread. Before the FMUs are loaded (libgomp reads its settings when it is loaded), the
// host limits OpenMP to the calling thread and lets idle workers sleep, unless the user set these.
// Once per process: setenv races with getenv in other threads (tissue-host compare runs sessions
// on several threads and calls this before starting them).
void keep_solver_libraries_on_the_calling_thread() {
  static std::once_flag once;
  std::call_once(once, [] {
    setenv("OMP_THREAD_LIMIT", "1", 0);
    setenv("OMP_WAIT_POLICY", "PASSIVE", 0);
    setenv("OPENBLAS_NUM_THREADS", "1", 0);
  });
}

std::vector<ParameterSetting> with_overrides(std::vector<ParameterSetting> parameters,
                                             const std::vector<ParameterSetting>& overrides) {
  for (const ParameterSetting& o : overrides) {
    const auto same =
        std::find_if(parameters.begin(), parameters.end(), [&](const ParameterSetting& p) { return p.name == o.name; });
    if (same != parameters.end()) {
      same->value = o.value;
    } else {
      parameters.push_back(o);
    }
  }
  return parameters;
}

SessionSummary run_session(const Scenario& scenario, const SessionOptions& options) {
  keep_solver_libraries_on_the_calling_thread();
  Session session(scenario, options);
  return session.run();
}

void print_summary(std::ostream& out, const SessionSummary& s, const std::filesystem::path& output_dir) {
  out << "scenario " << s.scenario << " (" << (s.offline ? "offline" : "real time") << "): " << s.sim_time_s
      << " s simulated in " << s.wall_time_s << " s, real-time factor " << s.realtime_factor << "\n";
  if (!s.offline) {
    out << "  haptic loop: " << s.haptic_rate_hz << " Hz, period p50/p99/max " << s.haptic_period_us.p50 << " / "
        << s.haptic_period_us.p99 << " / " << s.haptic_period_us.max << " us, deadline misses " << s.deadline_misses
        << "\n";
    out << "  priority: " << s.realtime_priority_note << "\n";
  }
  out << "  tissue step (" << s.tissue_step_s * 1e3 << " ms slots): p50/p99/max " << s.tissue_step_ms.p50 << " / "
      << s.tissue_step_ms.p99 << " / " << s.tissue_step_ms.max << " ms, overruns " << s.tissue_overruns << " ("
      << s.overrun_policy << ")\n";
  out << "  cut tets " << s.cut_tets << ", enriched vertices " << s.enriched_vertices << ", max device force "
      << s.max_device_force_n << " N (device maximum " << s.device_max_force_n << " N), passivity dissipated "
      << s.passivity_dissipated_j << " J, NaN " << (s.nan_detected ? "DETECTED" : "none") << "\n";
  if (!s.first_error.empty()) out << "  first error: " << s.first_error << "\n";
  out << "  outputs in " << output_dir.string() << ": summary.json, log.csv, ";
  if (s.frames_written > 0) {
    out << "surface.pvd (frames/, " << s.frames_written << " frames, open in ParaView), ";
  } else {
    out << "no frames (the scenario's frame_rate is 0), ";
  }
  out << "final.png\n";
}

}  // namespace tissue::host
