// ReplayDevice: the hand as tissue-host recorded it (`run --record FILE.csv`): one row per haptic
// tick, "time_s,x_m,y_m,z_m,qw,qx,qy,qz,mode". Read whole at construction (refused with the line
// and the reason if malformed); read() returns the last row at or before t: an offline replay of a
// recording at the same haptic period reproduces the recorded session. No allocation in read().
#pragma once

#include "device/device.hpp"

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

namespace tissue::host {

class ReplayDevice final : public Device {
 public:
  /// Throws std::runtime_error naming the file and line for a missing or malformed recording.
  explicit ReplayDevice(const std::filesystem::path& file);

  DevicePose read(double time_s) override;
  std::array<double, 3> write_force(double time_s, const std::array<double, 3>& force_n) override;
  [[nodiscard]] DeviceCounters counters() const override;
  [[nodiscard]] std::string_view name() const override { return "replay"; }
  [[nodiscard]] std::size_t row_count() const { return m_times.size(); }

 private:
  std::vector<double> m_times;
  std::vector<DevicePose> m_poses;
  std::atomic<std::uint64_t> m_reads{0};
};

/// The header line of a recording.
inline constexpr const char* RECORDING_HEADER = "time_s,x_m,y_m,z_m,qw,qx,qy,qz,mode";

}  // namespace tissue::host
