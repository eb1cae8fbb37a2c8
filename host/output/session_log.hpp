// The session's log: one row per haptic tick (the device, the tool, the force sent, contact, the
// tissue time and the observed energy), written as log.csv, and the device poses alone as a CSV the
// replay device reads back (--record). Numbers are written shortest round-trip and locale
// independent, so equal runs write equal bytes.
#pragma once

#include "device/device.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace tissue::host {

struct LogRow {
  double time_s = 0.0;
  DevicePose device;
  std::array<double, 3> tool_position_m{};
  std::int64_t tool_mode = 0;
  std::array<double, 3> force_n{};  ///< sent to the device
  bool contact = false;
  double tissue_time_s = 0.0;
  double observed_energy_j = 0.0;
};

/// Shortest round-trip decimal of `value` appended to `line`.
void append_number(std::string& line, double value);
/// The rows as log.csv (with its header). Throws std::runtime_error if the file cannot be written.
void write_log(const std::filesystem::path& path, std::span<const LogRow> rows);
/// The rows' device poses as a replayable recording (replay_device.hpp). Throws std::runtime_error.
void write_recording(const std::filesystem::path& path, std::span<const LogRow> rows);

}  // namespace tissue::host
