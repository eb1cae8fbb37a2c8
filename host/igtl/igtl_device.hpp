// igtl_device.hpp - the OpenIGTLink device: the hand's pose from an IgtlServer's client (TRANSFORM
// or POSITION messages), the force back to it as a SENSOR message, through a ForceWatchdog that
// ramps the force to zero when poses stop arriving (as the UDP device does).
#pragma once

#include "device/device.hpp"
#include "device/force_watchdog.hpp"
#include "igtl/igtl_server.hpp"

#include <memory>
#include <string>

namespace tissue::host {

class IgtlDevice final : public Device {
 public:
  /// Uses @p server (shared with the session's surface stream). Throws std::invalid_argument for bad watchdog settings.
  IgtlDevice(std::shared_ptr<IgtlServer> server, const ForceWatchdogSettings& watchdog = {});

  /// The newest accepted pose (held while none arrives; the default pose before the first). An
  /// accepted pose counts as arriving at @p time_s, the first read after the server took it.
  DevicePose read(double time_s) override;
  /// Scales @p force_n by the watchdog (a non-finite force becomes zero) and sends it; before the
  /// first pose nothing is sent and zero is returned.
  std::array<double, 3> write_force(double time_s, const std::array<double, 3>& force_n) override;
  /// The server's message counters (stale is always 0: TCP keeps order, the server keeps the newest)
  /// and the watchdog's trips.
  [[nodiscard]] DeviceCounters counters() const override;
  [[nodiscard]] std::string_view name() const override { return m_server->name(); }
  [[nodiscard]] double watchdog_scale() const { return m_watchdog.scale(); }

 private:
  std::shared_ptr<IgtlServer> m_server;
  ForceWatchdog m_watchdog;
  IgtlPoseSample m_sample;
  std::uint64_t m_accepted_seen = 0;
};

}  // namespace tissue::host
