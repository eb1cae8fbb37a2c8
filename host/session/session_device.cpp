// The session's device (see session_device.hpp).
#include "session/session_device.hpp"

#include "device/hand_device.hpp"
#include "device/replay_device.hpp"
#include "device/scripted_device.hpp"
#include "device/udp_device.hpp"
#include "igtl/igtl_device.hpp"
#include "view/browser_device.hpp"

#include <vector>

namespace tissue::host {

std::unique_ptr<Device> make_device(const DeviceConfig& config, const TissueLink& tissue, double haptic_period_s,
                                    const std::shared_ptr<IgtlServer>& igtl) {
  switch (config.kind) {
    case DeviceKind::scripted:
      return std::make_unique<ScriptedDevice>(placed_waypoints(config, tissue.rest_lower(), tissue.rest_upper()));
    case DeviceKind::hand:
      return std::make_unique<HandDevice>(placed_waypoints(config, tissue.rest_lower(), tissue.rest_upper()),
                                          config.hand, haptic_period_s);
    case DeviceKind::replay:
      return std::make_unique<ReplayDevice>(config.replay_file);
    case DeviceKind::browser: {
      // Start put away, 2 cm above the middle of the body's top.
      DevicePose pose;
      for (std::size_t a = 0; a < 2; ++a) pose.position_m[a] = 0.5 * (tissue.rest_lower()[a] + tissue.rest_upper()[a]);
      pose.position_m[2] = tissue.rest_upper()[2] + 0.02;
      return std::make_unique<BrowserDevice>(pose);
    }
    case DeviceKind::udp: {
      UdpDeviceSettings settings;
      settings.bind_address = config.udp_address;
      settings.port = config.udp_port;
      settings.allow_remote = config.udp_allow_remote;
      return std::make_unique<UdpDevice>(settings);
    }
    case DeviceKind::openigtlink:
      if (igtl == nullptr) throw ScenarioError("device: kind \"openigtlink\" without an OpenIGTLink server");
      return std::make_unique<IgtlDevice>(igtl);
  }
  throw ScenarioError("device: unknown kind");
}

std::shared_ptr<IgtlServer> make_igtl_server(const Scenario& scenario) {
  if (!scenario.openigtlink) return nullptr;
  const OpenIgtlinkConfig& c = *scenario.openigtlink;
  IgtlServerSettings settings;
  settings.address = c.address;
  settings.port = c.port;
  settings.allow_remote = c.allow_remote;
  settings.codec.length_unit_m = c.length_unit_m;
  settings.codec.probe_transform = c.probe_transform;
  settings.codec.scalpel_transform = c.scalpel_transform;
  settings.surface_rate_hz = c.surface_rate_hz;
  try {
    return std::make_shared<IgtlServer>(settings);
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(scenario.file.string() + ": [openigtlink]: " + e.what());
  }
}

DeviceConfig browser_config() {
  DeviceConfig config;
  config.kind = DeviceKind::browser;
  return config;
}

}  // namespace tissue::host
