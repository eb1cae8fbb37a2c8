// A session as a TOML file (host/scenarios/*.toml): how long, the two FMUs and their parameters,
// the tissue's communication step, the device (scripted waypoints, a replay CSV or the UDP bridge),
// what to write, what to expect. load_scenario() reads and checks it; every refusal names the file,
// the key and the reason. Positions may be given in metres or as fractions of the tissue's rest
// bounding box (`at = [fx, fy, fz]`), resolved once the Tissue FMU is loaded, so a scenario can
// describe "across the body" without knowing the mesh's coordinates.
#pragma once

#include "device/scripted_device.hpp"

#include "device/device.hpp"
#include "device/simulated_hand.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace tissue::host {

/// A scenario file that cannot be run (what, where).
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One FMU parameter by name, as TOML gave it; the host converts it to the variable's type.
struct ParameterSetting {
  std::string name;
  std::variant<double, std::int64_t, bool, std::string, std::vector<double>> value;
};

/// A point of the scripted hand: where it is at time_s; motion is linear between waypoints, the
/// orientation is interpolated along the shorter arc, the mode switches at the waypoint's time.
struct Waypoint {
  double time_s = 0.0;
  std::array<double, 3> position{};  ///< metres, or fractions of the rest box if box_relative
  bool box_relative = false;
  std::array<double, 4> orientation_wxyz{1.0, 0.0, 0.0, 0.0};
  ToolMode mode = ToolMode::none;
};

enum class DeviceKind { scripted, hand, replay, udp, browser, openigtlink };

struct DeviceConfig {
  DeviceKind kind = DeviceKind::scripted;
  std::vector<Waypoint> waypoints;    ///< scripted, hand (the path its grip follows)
  HandSettings hand;                  ///< hand: mass, damping, grip, push
  std::filesystem::path replay_file;  ///< replay (relative to the scenario file)
  std::string udp_address = "127.0.0.1";
  std::uint16_t udp_port = 47001;
  bool udp_allow_remote = false;
};

/// The OpenIGTLink server ([openigtlink]; host/igtl/OPENIGTLINK.md): the pose in (device kind
/// "openigtlink"), the force back, the surface out as POLYDATA.
struct OpenIgtlinkConfig {
  std::string address = "127.0.0.1";
  std::uint16_t port = 18944;
  bool allow_remote = false;
  double length_unit_m = 1e-3;  ///< metres per length unit on the wire (3D Slicer and PLUS: mm)
  std::string probe_transform = "ProbeToTissue";
  std::string scalpel_transform = "ScalpelToTissue";
  double surface_rate_hz = 30.0;  ///< POLYDATA per second (0: none)
};

/// What a tissue step that overran its slot leads to (never silent: overruns are counted).
enum class OverrunPolicy {
  /// The next step covers the slots missed (a longer communication step, whole internal steps),
  /// so that tissue time stays on wall time; at most max_catch_up_slots at once.
  catch_up,
  /// The missed slots are skipped: tissue time falls behind wall time (real-time factor < 1).
  skip,
};

/// What a test of the scenario expects (optional; tissue-host reports, tests check).
struct Expectations {
  std::optional<std::uint64_t> min_cut_tets, max_cut_tets;
  std::optional<bool> contact;  ///< a contact happens at some point
};

struct Scenario {
  std::filesystem::path file;  ///< where it was read from
  std::string name;
  std::string description;
  double duration_s = 1.0;
  // The tissue.
  std::filesystem::path tissue_fmu;  ///< "" = the Tissue.fmu built next to tissue-host
  double tissue_step_s = 0.01;       ///< communication step (one slot of the dynamics thread)
  /// By name (tissue.parameters); `tissue.mesh = "file"` adds "mesh" with the file's absolute path
  /// (`tissue.render_surface = "file"` the same for "surface.renderSurface"),
  /// and "stepSize" is the communication step unless given.
  std::vector<ParameterSetting> tissue_parameters;
  // The haptic loop.
  std::filesystem::path haptic_fmu;  ///< "" = the HapticLoop.fmu built next to tissue-host
  double haptic_period_s = 0.001;
  std::vector<ParameterSetting> haptic_parameters;
  DeviceConfig device;
  /// Set when the scenario has an [openigtlink] table or the device kind "openigtlink".
  std::optional<OpenIgtlinkConfig> openigtlink;
  // Real time.
  OverrunPolicy overrun_policy = OverrunPolicy::catch_up;
  int max_catch_up_slots = 4;
  // Outputs.
  double frame_rate_hz = 30.0;  ///< VTU frames of the surface, in simulated time; 0 = none
  bool write_png = true;
  Expectations expect;
};

/// The device's waypoints in the scene frame: box-relative ones (`at`) placed in the tissue's rest
/// box [rest_lower, rest_upper] [m], the others as they are (the session's scripted device and
/// simulated hand, and the Python module's Scenario.tool_at, follow them).
std::vector<DeviceWaypoint> placed_waypoints(const DeviceConfig& config, const std::array<double, 3>& rest_lower,
                                             const std::array<double, 3>& rest_upper);

/// The largest scenario file load_scenario reads [bytes] (the shipped ones are under 4 KiB).
inline constexpr std::size_t MAX_SCENARIO_FILE_BYTES = std::size_t{1} << 20;

/// Reads and checks a scenario. Throws ScenarioError naming the file, the key and the reason.
Scenario load_scenario(const std::filesystem::path& file);
/// The same from text (for tests); `origin` names it in messages and anchors relative paths.
Scenario parse_scenario(const std::string& text, const std::filesystem::path& origin);

}  // namespace tissue::host
