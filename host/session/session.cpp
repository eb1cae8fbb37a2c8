// run_session (see session.hpp): the Session builds the parts (the two FMU links and the sample's
// relay, the device, the recording, the live view), says what a tick, a step and a frame do
// (schedule/session_steps.hpp), and hands itself to a scheduler (schedule/): offline or real time.
#include "session/session.hpp"

#include "device/hand_device.hpp"
#include "importer/fmu3.hpp"
#include "links/fmu_links.hpp"
#include "links/sample_relay.hpp"
#include "output/frame_writer.hpp"
#include "output/png_renderer.hpp"
#include "output/session_log.hpp"
#include "output/slot_timing.hpp"
#include "schedule/offline_schedule.hpp"
#include "schedule/realtime_schedule.hpp"
#include "schedule/schedule.hpp"
#include "schedule/session_steps.hpp"
#include "session/session_device.hpp"
#include "sync/latest_value.hpp"
#include "sync/realtime_clock.hpp"
#include "view/browser_device.hpp"
#include "view/live_view.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

namespace tissue::host {
namespace {

bool finite3(const std::array<double, 3>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

double norm3(const std::array<double, 3>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

std::filesystem::path fmu_path(const std::filesystem::path& configured, const std::filesystem::path& fmu_dir,
                               const char* name) {
  if (!configured.empty()) return configured;
  return fmu_dir / name;
}

RealtimeOptions realtime_options(const SessionOptions& options) {
  RealtimeOptions realtime;
  realtime.realtime_priority = options.realtime_priority;
  realtime.haptic_thread_started = options.haptic_thread_started;
  realtime.stop = options.stop;
  realtime.progress = options.progress;
  return realtime;
}

// --- the session ---

class Session final : public SessionSteps {
 public:
  Session(const Scenario& scenario, const SessionOptions& options)
      : m_scenario(scenario),
        m_options(options),
        m_tissue_fmu(fmu_path(scenario.tissue_fmu, options.fmu_dir, "Tissue.fmu")),
        m_haptic_fmu(fmu_path(scenario.haptic_fmu, options.fmu_dir, "HapticLoop.fmu")),
        m_tissue(m_tissue_fmu, with_overrides(scenario.tissue_parameters, options.tissue_parameter_overrides)),
        m_haptic(m_haptic_fmu, scenario.haptic_parameters),
        m_relay(SampleLayout(ports::TISSUE_SAMPLE, m_tissue.instance().description(), m_haptic.instance().description())),
        m_contact_slot(m_relay.layout().slot("contact.active")),
        m_point_slot(m_relay.layout().slot("contact.point")),
        m_force_slot(m_relay.layout().slot("contact.force")),
        m_blade_depth_slot(m_relay.layout().slot("cut.bladeDepth")),
        m_step_sample(m_relay.make_sample()),
        m_last_outputs(m_relay.make_sample()),
        m_igtl(make_igtl_server(scenario)),
        m_device(make_device(options.browser_device ? browser_config() : scenario.device, m_tissue,
                             scenario.haptic_period_s, m_igtl)),
        m_schedule(make_schedule(scenario)) {
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
    m_rows.resize(m_schedule.ticks);
    m_step_s.reserve(m_schedule.slots() + 8);
    m_step_cutting.reserve(m_schedule.slots() + 8);
    m_summary.scenario = scenario.name;
    m_summary.tissue_fmu = std::filesystem::absolute(fmu_path(scenario.tissue_fmu, options.fmu_dir, "Tissue.fmu")).string();
    m_summary.haptic_fmu =
        std::filesystem::absolute(fmu_path(scenario.haptic_fmu, options.fmu_dir, "HapticLoop.fmu")).string();
    m_summary.offline = options.offline;
    m_summary.tissue_step_s = m_schedule.slot_s;
    m_summary.device_name = std::string(m_device->name());
    m_summary.device_max_force_n = m_haptic.max_force_n();
    m_summary.device_max_force_rate_n_per_s = m_haptic.max_force_rate_n_per_s();
    m_summary.overrun_policy = scenario.overrun_policy == OverrunPolicy::catch_up ? "catch_up" : "skip";
    if (options.write_outputs) std::filesystem::create_directories(options.output_dir);
    // The first tool command: the haptic loop's output before any tick (the device at t = 0).
    m_haptic.set_device(m_device->read(0.0));
    HapticOutputs initial;
    m_haptic.read(initial);
    m_tool_command.reset(initial.tool);
    m_tissue_sample.reset(m_relay.make_sample());
  }

  SessionSummary run() {
    if (m_options.tissue_observer != nullptr) m_options.tissue_observer->started(m_tissue.instance());
    start_view();
    std::optional<FrameWriter> writer;
    if (m_options.write_outputs) writer.emplace(m_options.output_dir);
    FrameWriter* const frames = writer ? &*writer : nullptr;
    if (m_options.offline) {
      run_offline(*this, m_schedule, frames, m_options.progress, m_summary);
    } else {
      RealtimeOptions realtime = realtime_options(m_options);
      if (m_options.write_outputs) realtime.slot_timings = &m_slot_timings;
      run_realtime(*this, m_schedule, realtime, frames, m_summary);
    }
    m_rows.resize(m_summary.haptic_ticks);  // fewer when a real-time run was stopped early
    stop_view();
    finish();
    return m_summary;
  }

 private:
  // --- SessionSteps: what the scheduler drives ---

  // One haptic tick n (session time n * period). Haptic thread: no allocation, no lock.
  void haptic_tick(std::uint64_t n) override {
    const double t = static_cast<double>(n) * m_schedule.haptic_period_s;
    const DevicePose pose = m_device->read(t);
    if (m_tissue_sample.update()) {
      const RelaySample& sample = m_tissue_sample.read_buffer();
      if (sample.finite) {
        (void)m_relay.write(sample, m_haptic.instance());
        m_last_tissue_time_s = sample.time_s;
        m_contact = sample.flag(m_contact_slot);
      } else {
        ++m_summary.samples_not_finite;
      }
    }
    m_haptic.set_device(pose);
    const DoStepResult result = m_haptic.step(t, m_schedule.haptic_period_s);
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
    command.time_s = t + m_schedule.haptic_period_s;
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

  void haptic_tick_timed(std::uint64_t n, double period_s, std::uint64_t deadline_misses) override {
    if (m_view) m_view->record_tick(period_s, deadline_misses, m_rows[n].force_n);
  }

  bool tissue_failed() const override { return m_tissue_failed; }

  // One tissue step from tissue time `time_s` over `slots` slots, into m_step_sample. Dynamics thread.
  double tissue_step(double time_s, int slots) override {
    RelaySample& out = m_step_sample;
    m_tool_command.update();
    m_tissue.set_tool(m_tool_command.read_buffer());
    const bool scalpel = m_tool_command.read_buffer().mode == static_cast<std::int64_t>(ToolMode::scalpel);
    const double step_s = slots * m_schedule.slot_s;
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
    m_relay.read(m_tissue.instance(), out);
    m_tissue.read_counters(out);
    out.time_s = reached_s;
    if (!out.finite) m_tissue_nan = true;
    m_summary.contact_seen = m_summary.contact_seen || out.flag(m_contact_slot);
    // Steps are "during cuts" from the first step with the scalpel in the tissue.
    m_cutting_seen = m_cutting_seen || (scalpel && out.values(m_blade_depth_slot)[0] > 0.0) || out.cut_tets > 0;
    if (observer != nullptr) {
      TissueStepInfo info;
      info.index = m_step_s.size();
      info.start_s = time_s;
      info.reached_s = reached_s;
      info.cpu_s = static_cast<double>(cpu_end - cpu_start) * 1e-9;
      info.result = result;
      info.contact_force_n = out.vector3(m_force_slot);
      observer->stepped(m_tissue.instance(), info);
    }
    m_step_s.push_back(seconds);
    m_step_cutting.push_back(m_cutting_seen ? 1 : 0);
    m_cut_tets.store(out.cut_tets, std::memory_order_relaxed);
    m_summary.cut_tets = out.cut_tets;
    m_summary.enriched_vertices = out.enriched_vertices;
    m_last_outputs = out;
    return out.time_s;
  }

  void prepare_surface_after_step(bool prepare) override { m_tissue.prepare_surface_after_step(prepare); }

  void publish_tissue_sample() override {
    m_tissue_sample.write_buffer() = m_step_sample;
    m_tissue_sample.publish();
  }

  void tissue_sample_published(double time_s) override {
    if (m_igtl && m_igtl->surface_due(time_s)) {
      fill_frame(m_igtl->surface_buffer(), time_s);
      m_igtl->publish_surface(time_s);
    }
    if (!m_view) return;
    m_view->publish_tissue(TissueLive{time_s, m_step_s.empty() ? 0.0 : m_step_s.back(), m_step_sample.cut_tets});
    if (m_view->frame_due()) {
      fill_frame(m_view->frame_buffer(), time_s);
      m_view->publish_frame();
    }
  }

  bool frame_due(double time_s) const override {
    return m_options.write_outputs && m_scenario.frame_rate_hz > 0.0 && time_s + 1e-9 >= m_next_frame_s;
  }
  bool frame_remeshed() override { return m_tissue.surface_remeshed(); }
  bool frame_preparing() override { return m_tissue.surface_preparing(); }
  void capture_frame(SurfaceFrame& frame, double time_s) override {
    fill_frame(frame, time_s, Mapping::deferred);
    // The next recorded frame is the first one due after this one (not a period past it).
    while (m_next_frame_s <= time_s + 1e-9) m_next_frame_s += 1.0 / m_scenario.frame_rate_hz;
  }
  void complete_frame(SurfaceFrame& frame) override { m_recording_mapping.complete(frame); }
  void frame_dropped() override { m_next_frame_s += 1.0 / m_scenario.frame_rate_hz; }
  void reserve_frame(SurfaceFrame& frame) override { m_tissue.reserve(frame); }
  // The surface, the tool and the contact at `time_s` (the recording's frames, the live view's and
  // the OpenIGTLink surfaces; each keeps its own rate).
  enum class Mapping { now, deferred };
  void fill_frame(SurfaceFrame& frame, double time_s, Mapping mapping = Mapping::now) {
    if (mapping == Mapping::now) {
      m_tissue.read_surface(frame);
    } else {
      m_tissue.read_surface_unmapped(frame);
    }
    frame.time_s = time_s;
    const ToolCommand& tool = m_tool_command.read_buffer();
    frame.has_tool = tool.mode != 0;
    frame.tool_mode = static_cast<int>(tool.mode);
    frame.tool_tip_m = tool.position_m;
    const auto& q = tool.orientation_wxyz;
    const std::array<double, 3> axis = tool_axis(q[0], q[1], q[2], q[3]);
    const double length = tool.mode == static_cast<std::int64_t>(ToolMode::scalpel) ? m_tissue.blade_length_m() : 0.03;
    for (std::size_t a = 0; a < 3; ++a) frame.tool_handle_m[a] = tool.position_m[a] + length * axis[a];
    frame.contact_active = m_last_outputs.flag(m_contact_slot);
    frame.contact_point_m = m_last_outputs.vector3(m_point_slot);
    frame.force_n = m_last_outputs.vector3(m_force_slot);
  }

  std::uint64_t cut_tets() const override { return m_cut_tets.load(std::memory_order_relaxed); }

  // --- around the run ---

  // The live view listens before the run and stops after it; its counters go into the summary.
  void start_view() {
    if (!m_view) return;
    m_view->start();
    if (m_options.view_started) m_options.view_started(m_view->port());
  }
  void stop_view() {
    if (!m_view) return;
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

  void finish() {
    const double wall = m_summary.wall_time_s;
    m_summary.realtime_factor = wall > 0.0 ? m_summary.sim_time_s / wall : 0.0;
    m_summary.haptic_rate_hz =
        wall > 0.0 && !m_options.offline ? static_cast<double>(m_summary.haptic_ticks) / wall : 0.0;
    m_summary.tissue_steps = m_step_s.size();
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
    if (m_igtl) m_summary.openigtlink = m_igtl->counters();
    if (const auto* hand = dynamic_cast<const HandDevice*>(m_device.get())) m_summary.hand = hand->figures();
    m_summary.nan_detected = m_haptic_nan || m_tissue_nan || !std::isfinite(m_summary.max_device_force_n);
    if (!m_options.write_outputs) return;

    const std::filesystem::path& dir = m_options.output_dir;
    write_log(dir / "log.csv", m_rows);
    if (!m_options.offline) write_slot_timings(dir / "slots.csv", m_slot_timings);
    if (m_options.record) write_recording(*m_options.record, m_rows);
    if (m_scenario.write_png) {
      SurfaceFrame frame;
      m_next_frame_s = 0.0;
      capture_frame(frame, m_summary.sim_time_s);
      complete_frame(frame);
      render_png(dir / "final.png", frame, operating_field());
    }
    std::ofstream(dir / "summary.json") << m_summary.to_json();
  }

  // The picture's camera frames the body's rest box grown by half its size on every side (the
  // operating field), not all of the surface: a piece cut free falls out of the picture, as out of
  // a fixed camera's, instead of shrinking the body to a speck (issue 40: freed pieces now fall).
  [[nodiscard]] RenderSettings operating_field() const {
    RenderSettings settings;
    std::array<double, 6> box{};
    for (size_t axis = 0; axis < 3; ++axis) {
      const double half = 0.5 * (m_tissue.rest_upper()[axis] - m_tissue.rest_lower()[axis]);
      box[axis] = m_tissue.rest_lower()[axis] - half;
      box[3 + axis] = m_tissue.rest_upper()[axis] + half;
    }
    settings.fit_box_m = box;
    return settings;
  }

  const Scenario& m_scenario;
  const SessionOptions& m_options;
  Fmu3 m_tissue_fmu;
  Fmu3 m_haptic_fmu;
  TissueLink m_tissue;
  SurfaceMapping m_recording_mapping;  // complete_frame()'s: the recording's frames, in the writer's thread
  HapticLink m_haptic;
  SampleRelay m_relay;  // the tissue sample from m_tissue to m_haptic, and its fields' slots
  SampleSlot m_contact_slot, m_point_slot, m_force_slot, m_blade_depth_slot;
  RelaySample m_step_sample;   // dynamics thread's: the step's sample, until published
  RelaySample m_last_outputs;  // dynamics thread's: the last step's sample
  std::vector<SlotTiming> m_slot_timings;  // real time: each step's, written as slots.csv
  std::shared_ptr<IgtlServer> m_igtl;  // [openigtlink]: the device's and the surface stream's
  std::unique_ptr<Device> m_device;
  std::unique_ptr<LiveView> m_view;          // --view
  Schedule m_schedule;
  // Exchanged between the threads (dissertation 5.1.3).
  LatestValue<ToolCommand> m_tool_command;
  LatestValue<RelaySample> m_tissue_sample;
  // Haptic thread's own.
  HapticOutputs m_haptic_out;
  std::vector<LogRow> m_rows;
  double m_last_tissue_time_s = 0.0;
  bool m_contact = false;
  bool m_haptic_nan = false;
  // Dynamics thread's own.
  std::vector<double> m_step_s;
  std::vector<std::uint8_t> m_step_cutting;
  bool m_cutting_seen = false;
  bool m_tissue_nan = false;
  bool m_tissue_failed = false;
  double m_next_frame_s = 0.0;
  std::atomic<std::uint64_t> m_cut_tets{0};  // for the progress line
  // Written by one thread each (each field by one thread only), read after both are joined.
  SessionSummary m_summary;
};

}  // namespace

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

}  // namespace tissue::host
