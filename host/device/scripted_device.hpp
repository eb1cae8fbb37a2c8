// ScriptedDevice: the hand as a list of waypoints (time, pose, tool mode), from a scenario. The
// position moves linearly between waypoints, the orientation along the shorter arc (slerp), and the
// mode switches at a waypoint's time; before the first and after the last the hand holds still.
// read() is a binary search and a blend: no allocation, no blocking. The force is only recorded.
#pragma once

#include "device/device.hpp"

#include <atomic>
#include <vector>

namespace tissue::host {

struct DeviceWaypoint {
  double time_s = 0.0;
  DevicePose pose;
};

class ScriptedDevice final : public Device {
 public:
  /// Throws std::invalid_argument unless the times increase strictly and every number is finite
  /// (and every quaternion non-zero).
  explicit ScriptedDevice(std::vector<DeviceWaypoint> waypoints);

  DevicePose read(double time_s) override;
  std::array<double, 3> write_force(double time_s, const std::array<double, 3>& force_n) override;
  [[nodiscard]] DeviceCounters counters() const override;
  [[nodiscard]] std::string_view name() const override { return "scripted"; }

  /// The pose at time t (what read() returns).
  [[nodiscard]] DevicePose pose_at(double time_s) const;

 private:
  std::vector<DeviceWaypoint> m_waypoints;
  std::atomic<std::uint64_t> m_reads{0};
};

/// Spherical linear interpolation of unit quaternions (w x y z) along the shorter arc.
std::array<double, 4> slerp(const std::array<double, 4>& a, const std::array<double, 4>& b, double s);

}  // namespace tissue::host
