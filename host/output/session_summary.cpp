// SessionSummary as JSON and as text (see session_summary.hpp).
#include "output/session_summary.hpp"

#include "output/json_text.hpp"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <sstream>

namespace tissue::host {
namespace {

void json_percentiles(std::ostringstream& out, const char* name, const Percentiles& p) {
  out << "  \"" << name << "\": {\"p50\": " << p.p50 << ", \"p99\": " << p.p99 << ", \"max\": " << p.max << "},\n";
}

}  // namespace

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
  out << "  \"device_max_force_rate_N_per_s\": " << device_max_force_rate_n_per_s << ",\n";
  out << "  \"passivity_dissipated_J\": " << passivity_dissipated_j << ",\n";
  out << "  \"passivity_observed_J\": " << passivity_observed_j << ",\n";
  out << "  \"nan_detected\": " << (nan_detected ? "true" : "false") << ",\n";
  out << "  \"device\": {\"name\": " << json_string(device_name) << ", \"received\": " << device.received
      << ", \"accepted\": " << device.accepted << ", \"malformed\": " << device.malformed
      << ", \"out_of_order\": " << device.out_of_order << ", \"duplicate\": " << device.duplicate
      << ", \"stale\": " << device.stale << ", \"watchdog_trips\": " << device.watchdog_trips << "},\n";
  if (hand) {
    const auto number = [](double x) { return json_number(x); };
    out << "  \"hand\": {\"settle_time_s\": " << number(hand->settle_time_s)
        << ", \"settle_speed_m_per_s\": " << number(hand->settle_speed_m_per_s)
        << ", \"residual_speed_m_per_s\": " << number(hand->residual_speed_m_per_s)
        << ", \"device_work_J\": " << number(hand->device_work_j)
        << ", \"chatter_frequency_Hz\": " << number(hand->chatter_frequency_hz)
        << ", \"chatter_amplitude_m\": " << number(hand->chatter_amplitude_m) << ", \"mean_force_N\": ["
        << number(hand->mean_force_n[0]) << ", " << number(hand->mean_force_n[1]) << ", "
        << number(hand->mean_force_n[2]) << "], \"mean_position_m\": [" << number(hand->mean_position_m[0]) << ", "
        << number(hand->mean_position_m[1]) << ", " << number(hand->mean_position_m[2])
        << "], \"window_s\": " << number(hand->window_s) << "},\n";
  }
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
