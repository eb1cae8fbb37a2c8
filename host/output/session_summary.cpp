// SessionSummary as JSON and as text (see session_summary.hpp).
#include "output/session_summary.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <ostream>

namespace tissue::host {

nlohmann::ordered_json percentiles_json(const Percentiles& p) {
  return {{"p50", p.p50}, {"p99", p.p99}, {"max", p.max}};
}

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

// nlohmann::json writes non-finite numbers (a hand that never settled) as null.
std::string SessionSummary::to_json() const {
  nlohmann::ordered_json j;
  j["scenario"] = scenario;
  j["mode"] = offline ? "offline" : "realtime";
  j["fmus"] = {{"tissue", tissue_fmu}, {"haptic_loop", haptic_fmu}};
  j["sim_time_s"] = sim_time_s;
  j["wall_time_s"] = wall_time_s;
  j["realtime_factor"] = realtime_factor;
  j["haptic_rate_hz"] = haptic_rate_hz;
  j["haptic_ticks"] = haptic_ticks;
  j["haptic_period_us"] = percentiles_json(haptic_period_us);
  j["haptic_period_max_at_s"] = haptic_period_max_at_s;
  j["haptic_first_tick_late_us"] = haptic_first_tick_late_us;
  j["deadline_misses"] = deadline_misses;
  j["tissue_communication_step_s"] = tissue_step_s;
  j["tissue_steps"] = tissue_steps;
  j["tissue_step_ms"] = percentiles_json(tissue_step_ms);
  j["tissue_step_before_cut_ms"] = percentiles_json(tissue_step_before_cut_ms);
  j["tissue_step_during_cut_ms"] = percentiles_json(tissue_step_during_cut_ms);
  j["tissue_overruns"] = tissue_overruns;
  j["overrun_policy"] = overrun_policy;
  j["catch_up_slots"] = catch_up_slots;
  j["skipped_slots"] = skipped_slots;
  j["tissue_discards"] = tissue_discards;
  j["tissue_errors"] = tissue_errors;
  j["haptic_errors"] = haptic_errors;
  j["samples_not_finite"] = samples_not_finite;
  j["cut_tets"] = cut_tets;
  j["enriched_vertices"] = enriched_vertices;
  j["contact_seen"] = contact_seen;
  j["max_device_force_N"] = max_device_force_n;
  j["device_max_force_N"] = device_max_force_n;
  j["device_max_force_rate_N_per_s"] = device_max_force_rate_n_per_s;
  j["passivity_dissipated_J"] = passivity_dissipated_j;
  j["passivity_observed_J"] = passivity_observed_j;
  j["nan_detected"] = nan_detected;
  j["device"] = {{"name", device_name},         {"received", device.received},
                 {"accepted", device.accepted}, {"malformed", device.malformed},
                 {"oversized", device.oversized}, {"out_of_order", device.out_of_order},
                 {"duplicate", device.duplicate}, {"stale", device.stale},
                 {"ignored", device.ignored},   {"watchdog_trips", device.watchdog_trips}};
  if (hand) {
    j["hand"] = {{"settle_time_s", hand->settle_time_s},
                 {"settle_speed_m_per_s", hand->settle_speed_m_per_s},
                 {"residual_speed_m_per_s", hand->residual_speed_m_per_s},
                 {"device_work_J", hand->device_work_j},
                 {"chatter_frequency_Hz", hand->chatter_frequency_hz},
                 {"chatter_amplitude_m", hand->chatter_amplitude_m},
                 {"mean_force_N", hand->mean_force_n},
                 {"mean_position_m", hand->mean_position_m},
                 {"window_s", hand->window_s}};
  }
  j["frames_written"] = frames_written;
  j["frames_dropped"] = frames_dropped;
  j["frames_deferred"] = frames_deferred;
  if (view) {
    j["view"] = {{"connections", view_connections}, {"frames_sent", view_frames_sent},
                 {"frames_skipped", view_frames_skipped}, {"messages", view_messages},
                 {"malformed", view_malformed}, {"oversized", view_oversized},
                 {"flood", view_flood}, {"out_of_order", view_out_of_order},
                 {"withdrawals", view_withdrawals}};
  }
  if (openigtlink) {
    const IgtlCounters& c = *openigtlink;
    j["openigtlink"] = {{"connections", c.connections}, {"refused_connections", c.refused_connections},
                        {"received", c.received},       {"accepted", c.accepted},
                        {"malformed", c.malformed},     {"oversized", c.oversized},
                        {"out_of_order", c.out_of_order}, {"duplicate", c.duplicate},
                        {"ignored", c.ignored},         {"forces_sent", c.forces_sent},
                        {"forces_dropped", c.forces_dropped}, {"surfaces_sent", c.surfaces_sent},
                        {"surfaces_skipped", c.surfaces_skipped}};
  }
  j["realtime_priority"] = realtime_priority;
  j["realtime_priority_note"] = realtime_priority_note;
  j["first_error"] = first_error;
  // Text that is not UTF-8 (a device name, an error message) is replaced, not refused.
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
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
  if (s.hand) {
    out << "  hand: " << (std::isnan(s.hand->settle_time_s) ? std::string("never settled")
                                                             : "settled at " + std::to_string(s.hand->settle_time_s) + " s")
        << ", residual speed " << s.hand->residual_speed_m_per_s * 1e3 << " mm/s, chatter "
        << s.hand->chatter_frequency_hz << " Hz x " << s.hand->chatter_amplitude_m * 1e3
        << " mm, device work on the hand " << s.hand->device_work_j << " J\n";
  }
  if (s.openigtlink) {
    const IgtlCounters& c = *s.openigtlink;
    out << "  openigtlink: " << c.connections << " connection(s), " << c.accepted << " of " << c.received
        << " messages accepted (malformed " << c.malformed << ", oversized " << c.oversized << ", out of order "
        << c.out_of_order << ", duplicate " << c.duplicate << ", ignored " << c.ignored << "), forces sent "
        << c.forces_sent << ", surfaces sent " << c.surfaces_sent << "\n";
  }
  if (!s.first_error.empty()) out << "  first error: " << s.first_error << "\n";
  out << "  outputs in " << output_dir.string() << ": summary.json, log.csv, " << (s.offline ? "" : "slots.csv, ");
  if (s.frames_written > 0) {
    out << "surface.pvd (frames/, " << s.frames_written << " frames, open in ParaView), ";
  } else {
    out << "no frames (the scenario's frame_rate is 0), ";
  }
  out << "final.png\n";
}

}  // namespace tissue::host
