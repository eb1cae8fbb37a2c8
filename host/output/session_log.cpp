// The session's log and recording (see session_log.hpp).
#include "output/session_log.hpp"

#include "device/replay_device.hpp"

#include <charconv>
#include <fstream>
#include <stdexcept>

namespace tissue::host {
namespace {

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

}  // namespace

// Shortest round-trip decimal: locale-independent, so equal runs write equal bytes.
void append_number(std::string& line, double value) {
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  line.append(buffer, error == std::errc() ? end : buffer);
}

void write_log(const std::filesystem::path& path, std::span<const LogRow> rows) {
  std::ofstream log(path);
  log << "time_s,device_x_m,device_y_m,device_z_m,tool_x_m,tool_y_m,tool_z_m,tool_mode,force_x_n,force_y_n,"
         "force_z_n,contact,tissue_time_s,observed_energy_j\n";
  for (const LogRow& row : rows) log << log_line(row) << '\n';
  if (!log) throw std::runtime_error(path.string() + ": cannot be written");
}

void write_recording(const std::filesystem::path& path, std::span<const LogRow> rows) {
  std::ofstream record(path);
  record << RECORDING_HEADER << '\n';
  for (const LogRow& row : rows) record << recording_line(row) << '\n';
  if (!record) throw std::runtime_error(path.string() + ": cannot be written");
}

}  // namespace tissue::host
