// The device a session is driven by: the scenario's (scripted waypoints, relative to the tissue's
// rest box or absolute; a replayed recording; the UDP bridge) or the live view's browser device.
#pragma once

#include "device/device.hpp"
#include "links/fmu_links.hpp"
#include "scenario/scenario.hpp"

#include <memory>

namespace tissue::host {

/// The device `config` describes, placed by `tissue`'s rest box; a hand is advanced in ticks of
/// `haptic_period_s`. Throws ScenarioError / std::runtime_error.
std::unique_ptr<Device> make_device(const DeviceConfig& config, const TissueLink& tissue, double haptic_period_s);
/// The browser device's configuration (--mouse).
DeviceConfig browser_config();

}  // namespace tissue::host
