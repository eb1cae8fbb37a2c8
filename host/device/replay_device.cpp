// ReplayDevice (see replay_device.hpp).
#include "device/replay_device.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace tissue::host {

ReplayDevice::ReplayDevice(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": the recording cannot be read");
  std::string line;
  std::size_t number = 0;
  const auto fail = [&](const std::string& why) {
    throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": " + why);
  };
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1) {
      if (line != RECORDING_HEADER) fail(std::string("the header must be \"") + RECORDING_HEADER + "\"");
      continue;
    }
    if (line.empty()) continue;
    std::array<double, 9> v{};
    const char* p = line.data();
    const char* end = line.data() + line.size();
    for (std::size_t k = 0; k < v.size(); ++k) {
      const auto [next, error] = std::from_chars(p, end, v[k]);
      if (error != std::errc() || !std::isfinite(v[k]))
        fail("field " + std::to_string(k + 1) + " is not a finite number");
      p = next;
      if (k + 1 < v.size()) {
        if (p == end || *p != ',') fail("expected 9 comma-separated fields");
        ++p;
      }
    }
    if (p != end) fail("more than 9 fields");
    if (!m_times.empty() && !(v[0] > m_times.back())) fail("times must increase");
    const double mode = v[8];
    if (mode != 0.0 && mode != 1.0 && mode != 2.0) fail("mode must be 0, 1 or 2");
    const double norm = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
    if (!(norm > 1e-12)) fail("the orientation is not a quaternion");
    DevicePose pose;
    pose.position_m = {v[1], v[2], v[3]};
    pose.orientation_wxyz = {v[4] / norm, v[5] / norm, v[6] / norm, v[7] / norm};
    pose.mode = static_cast<ToolMode>(static_cast<int>(mode));
    m_times.push_back(v[0]);
    m_poses.push_back(pose);
  }
  if (m_times.empty()) throw std::runtime_error(file.string() + ": the recording has no rows");
}

DevicePose ReplayDevice::read(double time_s) {
  m_reads.fetch_add(1, std::memory_order_relaxed);
  // The last row at or before t (with a tolerance of a nanosecond for times written in decimal).
  const auto after = std::upper_bound(m_times.begin(), m_times.end(), time_s + 1e-9);
  if (after == m_times.begin()) return m_poses.front();
  return m_poses[static_cast<std::size_t>(after - m_times.begin()) - 1];
}

std::array<double, 3> ReplayDevice::write_force(double, const std::array<double, 3>& force_n) { return force_n; }

DeviceCounters ReplayDevice::counters() const {
  DeviceCounters c;
  c.received = c.accepted = m_reads.load(std::memory_order_relaxed);
  return c;
}

}  // namespace tissue::host
