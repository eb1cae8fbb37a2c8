// What a session reports: timing (haptic periods, tissue steps, overruns), what happened (cuts,
// contact, forces, passivity, NaN, errors), the device's and the view's counters; as summary.json and
// as a few printed lines.
#pragma once

#include "device/device.hpp"
#include "device/hand_device.hpp"
#include "device/igtl_counters.hpp"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace tissue::host {

struct Percentiles {
  double p50 = 0.0, p99 = 0.0, max = 0.0;
};

struct SessionSummary {
  std::string scenario;
  std::string tissue_fmu, haptic_fmu;  ///< the FMU files the session loaded
  bool offline = false;
  double sim_time_s = 0.0, wall_time_s = 0.0, realtime_factor = 0.0;
  double haptic_rate_hz = 0.0;
  Percentiles haptic_period_us;
  double haptic_period_max_at_s = 0.0;     ///< session time of the longest period (where to look)
  double haptic_first_tick_late_us = 0.0;  ///< how late the first tick woke
  std::uint64_t haptic_ticks = 0, deadline_misses = 0;
  Percentiles tissue_step_ms, tissue_step_before_cut_ms, tissue_step_during_cut_ms;
  double tissue_step_s = 0.0;
  std::uint64_t tissue_steps = 0, tissue_overruns = 0, skipped_slots = 0, catch_up_slots = 0;
  std::uint64_t tissue_discards = 0, tissue_errors = 0, haptic_errors = 0, samples_not_finite = 0;
  std::uint64_t cut_tets = 0, enriched_vertices = 0;
  bool contact_seen = false;
  double max_device_force_n = 0.0, device_max_force_n = 0.0, device_max_force_rate_n_per_s = 0.0;
  double passivity_dissipated_j = 0.0, passivity_observed_j = 0.0;
  bool nan_detected = false;
  std::string device_name;
  DeviceCounters device;
  std::optional<HandFigures> hand;  ///< a simulated hand's motion (device kind "hand")
  std::uint64_t frames_written = 0, frames_dropped = 0;
  /// Real time: due frames left to a later slot because the step left too little of its own (FrameBudget).
  std::uint64_t frames_deferred = 0;
  bool view = false;
  std::uint64_t view_connections = 0, view_frames_sent = 0, view_frames_skipped = 0, view_messages = 0,
                view_malformed = 0, view_oversized = 0, view_flood = 0, view_out_of_order = 0, view_withdrawals = 0;
  std::optional<IgtlCounters> openigtlink;  ///< the OpenIGTLink server's, when the session had one
  bool realtime_priority = false;
  std::string realtime_priority_note;
  std::string first_error;
  std::string overrun_policy;

  [[nodiscard]] std::string to_json() const;
};

/// p50, p99 and max of `values` times `scale` (zeros for none).
Percentiles percentiles(std::vector<double> values, double scale);
/// {"p50": .., "p99": .., "max": ..}.
nlohmann::ordered_json percentiles_json(const Percentiles& p);

/// The summary in a few lines, and where the outputs are.
void print_summary(std::ostream& out, const SessionSummary& summary, const std::filesystem::path& output_dir);

}  // namespace tissue::host
