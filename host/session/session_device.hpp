// The device a session is driven by: the scenario's (scripted waypoints, relative to the tissue's
// rest box or absolute; a replayed recording; the UDP bridge; an OpenIGTLink client) or the live
// view's browser device.
#pragma once

#include "device/device.hpp"
#include "igtl/igtl_server.hpp"
#include "links/fmu_links.hpp"
#include "scenario/scenario.hpp"

#include <memory>

namespace tissue::host {

/// The device `config` describes, placed by `tissue`'s rest box; a hand is advanced in ticks of
/// `haptic_period_s`; an OpenIGTLink device uses `igtl` (the session's server, null if it has
/// none). Throws ScenarioError / std::runtime_error.
std::unique_ptr<Device> make_device(const DeviceConfig& config, const TissueLink& tissue, double haptic_period_s,
                                    const std::shared_ptr<IgtlServer>& igtl);
/// The session's OpenIGTLink server, listening, when the scenario has one (else null).
std::shared_ptr<IgtlServer> make_igtl_server(const Scenario& scenario);
/// The browser device's configuration (--mouse).
DeviceConfig browser_config();

}  // namespace tissue::host
