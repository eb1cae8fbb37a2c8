// device.hpp - what tissue-host asks of a haptic input device, in SI units.
//
// A device turns the user's hand into a pose and commands a force back to it. The host's haptic
// thread calls read() and write_force() once per 1 kHz tick, so both must be real-time safe: no
// allocation, no blocking, no exception. Devices: scripted (scenario waypoints), replay (CSV),
// udp (a bridge to a separate driver process, see device/UDP_PROTOCOL.md), openigtlink
// (igtl/OPENIGTLINK.md). Nothing here knows
// about FMI or the tissue core: the host maps a DevicePose onto the FMU inputs.
#pragma once

#include "ports/tool.hpp"

#include <array>
#include <cstdint>
#include <string_view>

namespace tissue::host {

/// What the hand does at one instant: tool tip position [m] and orientation (unit quaternion,
/// scalar first) in the scene frame, and the instrument selected.
struct DevicePose {
  std::array<double, 3> position_m{};
  std::array<double, 4> orientation_wxyz{1.0, 0.0, 0.0, 0.0};
  ToolMode mode = ToolMode::none;
};

/// Every packet or message the device saw, and those it dropped, by reason. For a device that
/// receives packets: received = accepted + malformed + oversized + out_of_order + duplicate + stale
/// + ignored (oversized and ignored: OpenIGTLink messages too large to read, of another type or
/// device name). watchdog_trips counts the times the input went silent and the force was ramped down.
struct DeviceCounters {
  std::uint64_t received = 0, accepted = 0, malformed = 0, oversized = 0, out_of_order = 0, duplicate = 0, stale = 0,
                ignored = 0, watchdog_trips = 0;
};

/// A haptic input device. read() and write_force() belong to the haptic thread; the time passed
/// to them is the session time [s] (the host's clock in real time, the simulated clock offline),
/// so a device's timing behaviour (e.g. a watchdog) is reproducible from the calls alone.
class Device {
 public:
  virtual ~Device() = default;
  /// The hand at session time t. Called by the haptic thread at 1 kHz: no allocation, never blocks.
  virtual DevicePose read(double time_s) = 0;
  /// The force the haptic loop commands for the hand at time t (haptic thread: no allocation, never blocks).
  /// Returns the force actually sent (after the device's own safety, e.g. the watchdog ramp).
  virtual std::array<double, 3> write_force(double time_s, const std::array<double, 3>& force_n) = 0;
  /// A snapshot of the counters; safe to call from any thread.
  [[nodiscard]] virtual DeviceCounters counters() const { return {}; }
  /// A short name for logs and summary.json (e.g. "udp 127.0.0.1:47001").
  [[nodiscard]] virtual std::string_view name() const = 0;
};

}  // namespace tissue::host
