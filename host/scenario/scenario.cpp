// load_scenario (see scenario.hpp), on toml++ (Debian's libtomlplusplus-dev).
#include "scenario/scenario.hpp"

#include "scenario/parameter_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string_view>

namespace tissue::host {
namespace {

class Reader {
 public:
  explicit Reader(std::string origin) : m_origin(std::move(origin)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    throw ScenarioError(m_origin + ": " + key + ": " + why);
  }

  double number(const toml::node& node, const std::string& key) const {
    if (const auto* f = node.as_floating_point()) return check_finite(f->get(), key);
    if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
    fail(key, "must be a number");
  }
  double check_finite(double value, const std::string& key) const {
    if (!std::isfinite(value)) fail(key, "must be finite");
    return value;
  }
  double positive(const toml::node& node, const std::string& key) const {
    const double value = number(node, key);
    if (!(value > 0.0)) fail(key, "must be > 0, got " + std::to_string(value));
    return value;
  }
  template <std::size_t N>
  std::array<double, N> numbers(const toml::node& node, const std::string& key) const {
    const auto* array = node.as_array();
    if (array == nullptr || array->size() != N) fail(key, "must be an array of " + std::to_string(N) + " numbers");
    std::array<double, N> values{};
    for (std::size_t k = 0; k < N; ++k) values[k] = number(*array->get(k), key);
    return values;
  }
  std::string string(const toml::node& node, const std::string& key) const {
    if (const auto* s = node.as_string()) return s->get();
    fail(key, "must be a string");
  }
  bool boolean(const toml::node& node, const std::string& key) const {
    if (const auto* b = node.as_boolean()) return b->get();
    fail(key, "must be true or false");
  }
  // Refuses keys the scenario format does not have (a typo would otherwise be silently ignored).
  void only(const toml::table& table, const std::string& where, std::initializer_list<std::string_view> keys) const {
    for (const auto& [key, value] : table) {
      if (std::find(keys.begin(), keys.end(), key.str()) == keys.end()) {
        fail(where.empty() ? std::string(key.str()) : where + "." + std::string(key.str()), "unknown key");
      }
    }
  }

 private:
  std::string m_origin;
};

ToolMode tool_mode(const Reader& r, const toml::node& node, const std::string& key) {
  const std::string name = r.string(node, key);
  if (const auto mode = tool_mode_named(name)) return *mode;
  r.fail(key, "must be \"none\", \"probe\" or \"scalpel\", got \"" + name + "\"");
}

std::vector<ParameterSetting> parameters(const Reader& r, const toml::table* table, const std::string& where) {
  std::vector<ParameterSetting> settings;
  if (table == nullptr) return settings;
  for (const auto& [key, node] : *table) {
    const std::string name(key.str());
    const std::string full = where + "." + name;
    ParameterSetting setting{name, 0.0};
    if (const auto* f = node.as_floating_point()) {
      setting.value = r.check_finite(f->get(), full);
    } else if (const auto* i = node.as_integer()) {
      setting.value = i->get();
    } else if (const auto* b = node.as_boolean()) {
      setting.value = b->get();
    } else if (const auto* s = node.as_string()) {
      setting.value = s->get();
    } else if (const auto* a = node.as_array()) {
      std::vector<double> values;
      for (const toml::node& element : *a) values.push_back(r.number(element, full));
      setting.value = values;
    } else {
      r.fail(full, "must be a number, boolean, string or array of numbers");
    }
    settings.push_back(std::move(setting));
  }
  return settings;
}

Waypoint waypoint(const Reader& r, const toml::node& node, const std::string& key) {
  const auto* table = node.as_table();
  if (table == nullptr) r.fail(key, "must be a table { t = ..., position = [...] or at = [...], mode = ... }");
  r.only(*table, key, {"t", "position", "at", "orientation", "axis", "mode"});
  Waypoint w;
  const toml::node* t = table->get("t");
  if (t == nullptr) r.fail(key + ".t", "is missing");
  w.time_s = r.number(*t, key + ".t");
  const toml::node* position = table->get("position");
  const toml::node* at = table->get("at");
  if ((position == nullptr) == (at == nullptr)) r.fail(key, "needs exactly one of position (m) or at (box fractions)");
  w.box_relative = at != nullptr;
  w.position = r.numbers<3>(position != nullptr ? *position : *at, key + (position != nullptr ? ".position" : ".at"));
  const toml::node* orientation = table->get("orientation");
  const toml::node* axis = table->get("axis");
  if (orientation != nullptr && axis != nullptr) r.fail(key, "give orientation (quaternion) or axis, not both");
  if (orientation != nullptr) {
    w.orientation_wxyz = r.numbers<4>(*orientation, key + ".orientation");
    const double norm =
        std::sqrt(w.orientation_wxyz[0] * w.orientation_wxyz[0] + w.orientation_wxyz[1] * w.orientation_wxyz[1] +
                  w.orientation_wxyz[2] * w.orientation_wxyz[2] + w.orientation_wxyz[3] * w.orientation_wxyz[3]);
    if (!(norm > 1e-12)) r.fail(key + ".orientation", "must be a non-zero quaternion (w x y z)");
    for (double& c : w.orientation_wxyz) c /= norm;
  }
  if (axis != nullptr) {
    // The tool axis (tip toward handle) in the scene: the rotation taking +z onto it.
    const std::array<double, 3> a = r.numbers<3>(*axis, key + ".axis");
    const double norm = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(norm > 1e-12)) r.fail(key + ".axis", "must be a non-zero vector");
    const std::array<double, 3> d{a[0] / norm, a[1] / norm, a[2] / norm};
    if (d[2] < -1.0 + 1e-12) {
      w.orientation_wxyz = {0.0, 1.0, 0.0, 0.0};  // half turn about x
    } else {
      // q = (1 + z.d, z x d) normalized, z = (0, 0, 1): z x d = (-d_y, d_x, 0).
      std::array<double, 4> q{1.0 + d[2], -d[1], d[0], 0.0};
      const double qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
      for (double& c : q) c /= qn;
      w.orientation_wxyz = q;
    }
  }
  if (const toml::node* mode = table->get("mode")) w.mode = tool_mode(r, *mode, key + ".mode");
  return w;
}

toml::table parse_toml(const std::string& text, const std::filesystem::path& origin) {
  try {
    return toml::parse(text, origin.string());
  } catch (const toml::parse_error& error) {
    std::ostringstream message;
    message << origin.string() << ":" << error.source().begin.line << ": " << error.description();
    throw ScenarioError(message.str());
  }
}

// A path the scenario gives: absolute, or relative to the scenario file's folder `base`.
std::filesystem::path relative_to(const std::filesystem::path& base, const std::string& path) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? p : base / p;
}

// [scenario]: name (the file's stem unless given), description, duration.
void read_scenario_table(const Reader& r, const toml::table& root, const std::filesystem::path& origin, Scenario& s) {
  const toml::table* scenario = root["scenario"].as_table();
  if (scenario == nullptr) r.fail("scenario", "the [scenario] table is missing");
  r.only(*scenario, "scenario", {"name", "description", "duration"});
  if (const toml::node* n = scenario->get("name")) s.name = r.string(*n, "scenario.name");
  if (s.name.empty()) s.name = origin.stem().string();
  if (const toml::node* n = scenario->get("description")) s.description = r.string(*n, "scenario.description");
  const toml::node* duration = scenario->get("duration");
  if (duration == nullptr) r.fail("scenario.duration", "is missing (seconds)");
  s.duration_s = r.positive(*duration, "scenario.duration");
  if (s.duration_s > 24.0 * 3600.0) r.fail("scenario.duration", "longer than a day");
}

// A default the host gives an FMU: `setting` unless the scenario sets that parameter itself.
bool is_set(const std::vector<ParameterSetting>& parameters, std::string_view name) {
  return std::any_of(parameters.begin(), parameters.end(), [&](const ParameterSetting& p) { return p.name == name; });
}

void add_unless_set(std::vector<ParameterSetting>& parameters, ParameterSetting setting) {
  if (!is_set(parameters, setting.name)) parameters.push_back(std::move(setting));
}

// A file next to the scenario that [tissue] names (`key`: its mesh, its render surface): its
// absolute path, which is what the FMU is given; refused naming the key if there is no such file.
std::string scenario_file(const Reader& r, const toml::node& node, const std::filesystem::path& base,
                          const std::string& key) {
  const std::filesystem::path file = relative_to(base, r.string(node, key));
  if (!std::filesystem::exists(file)) r.fail(key, "no file " + file.string());
  return std::filesystem::absolute(file).lexically_normal().string();
}

// [tissue.regions.NAME] (optional): a region's material, as the Tissue FMU's material.regions text.
std::string region_materials_text(const Reader& r, const toml::table& regions) {
  std::string text;
  for (const auto& [name, node] : regions) {
    const std::string where = "tissue.regions." + std::string(name.str());
    const toml::table* region = node.as_table();
    if (region == nullptr) r.fail(where, "must be a table (youngModulus, poissonRatio, density, dampingAlpha)");
    r.only(*region, where, {"youngModulus", "poissonRatio", "density", "dampingAlpha"});
    if (!text.empty()) text += "; ";
    text += std::string(name.str()) + ":";
    bool first = true;
    for (const auto& [key, value] : *region) {
      char number[32];  // shortest round-trip text
      const auto end =
          std::to_chars(number, number + sizeof(number), r.number(value, where + "." + std::string(key.str())));
      text += (first ? " " : ", ") + std::string(key.str()) + "=" + std::string(number, end.ptr);
      first = false;
    }
  }
  return text;
}

// [tissue] (optional): the FMU, the communication step, the parameters, a mesh file and a render surface file.
void read_tissue(const Reader& r, const toml::table& root, const std::filesystem::path& base, Scenario& s) {
  if (const toml::table* tissue = root["tissue"].as_table()) {
    r.only(*tissue, "tissue", {"fmu", "communication_step", "mesh", "render_surface", "parameters", "regions"});
    if (const toml::node* n = tissue->get("fmu")) s.tissue_fmu = relative_to(base, r.string(*n, "tissue.fmu"));
    if (const toml::node* n = tissue->get("communication_step")) {
      s.tissue_step_s = r.positive(*n, "tissue.communication_step");
    }
    s.tissue_parameters = parameters(r, tissue->get_as<toml::table>("parameters"), "tissue.parameters");
    if (const toml::node* n = tissue->get("regions")) {
      const toml::table* regions = n->as_table();
      if (regions == nullptr) r.fail("tissue.regions", "must be a table of regions ([tissue.regions.NAME])");
      if (is_set(s.tissue_parameters, "material.regions")) {
        r.fail("tissue.regions", "given twice: also as tissue.parameters.\"material.regions\"");
      }
      s.tissue_parameters.push_back(ParameterSetting{"material.regions", region_materials_text(r, *regions)});
    }
    if (const toml::node* n = tissue->get("mesh")) {
      s.tissue_parameters.insert(s.tissue_parameters.begin(),
                                 ParameterSetting{"mesh", scenario_file(r, *n, base, "tissue.mesh")});
    }
    if (const toml::node* n = tissue->get("render_surface")) {
      if (is_set(s.tissue_parameters, "surface.renderSurface")) {
        r.fail("tissue.render_surface", "given twice: also as tissue.parameters.\"surface.renderSurface\"");
      }
      s.tissue_parameters.push_back(
          ParameterSetting{"surface.renderSurface", scenario_file(r, *n, base, "tissue.render_surface")});
    }
  }
  // Unless the scenario says otherwise, one internal step per communication step: the frog's
  // backward-Euler step at 10 ms is stable and takes a fraction of its slot (docs/BENCHMARKS.md).
  add_unless_set(s.tissue_parameters, ParameterSetting{"stepSize", s.tissue_step_s});
  // The host runs beside the tissue's threads anyway: our Tissue.fmu refreshes its contact stiffness
  // in a worker, off the step's 10 ms slot (a CHOLMOD factorization: ~7 ms on the frog), unless the
  // scenario says otherwise. Another tissue FMU is given only what the scenario says.
  // The same for the lagged factor of the default solver, pcgCholesky (a refactorization: ~5 ms on
  // the frog, issue 40).
  if (s.tissue_fmu.empty()) {
    add_unless_set(s.tissue_parameters, ParameterSetting{"contact.stiffnessInBackground", true});
    add_unless_set(s.tissue_parameters, ParameterSetting{"integrator.refactorInBackground", true});
  }
}

// [haptic] (optional): the FMU, the period, the parameters; the tissue step a whole number of periods.
void read_haptic(const Reader& r, const toml::table& root, const std::filesystem::path& base, Scenario& s) {
  if (const toml::table* haptic = root["haptic"].as_table()) {
    r.only(*haptic, "haptic", {"fmu", "period", "parameters"});
    if (const toml::node* n = haptic->get("fmu")) s.haptic_fmu = relative_to(base, r.string(*n, "haptic.fmu"));
    if (const toml::node* n = haptic->get("period")) s.haptic_period_s = r.positive(*n, "haptic.period");
    s.haptic_parameters = parameters(r, haptic->get_as<toml::table>("parameters"), "haptic.parameters");
  }
  // The tissue step is a whole number of haptic periods: the slots line up with the ticks.
  const double ticks = std::round(s.tissue_step_s / s.haptic_period_s);
  if (ticks < 1.0 || std::abs(ticks * s.haptic_period_s - s.tissue_step_s) > 1e-9 * s.tissue_step_s) {
    r.fail("tissue.communication_step",
           "must be a whole multiple of haptic.period (" + std::to_string(s.haptic_period_s) + " s)");
  }
}

// The waypoints of a scripted device, in increasing time.
std::vector<Waypoint> waypoints(const Reader& r, const toml::table& device) {
  const toml::array* list = device.get_as<toml::array>("waypoints");
  if (list == nullptr || list->empty()) r.fail("device.waypoints", "a scripted device needs waypoints");
  std::vector<Waypoint> result;
  for (std::size_t k = 0; k < list->size(); ++k) {
    result.push_back(waypoint(r, *list->get(k), "device.waypoints[" + std::to_string(k) + "]"));
  }
  for (std::size_t k = 1; k < result.size(); ++k) {
    if (!(result[k].time_s > result[k - 1].time_s)) {
      r.fail("device.waypoints[" + std::to_string(k) + "].t", "waypoint times must increase");
    }
  }
  return result;
}

// A hand device's mass, damping, grip and push, each refused outside its range (HandLimits).
HandSettings read_hand(const Reader& r, const toml::table& device) {
  HandSettings hand;
  const auto in_range = [&](const char* key, double low, double high, const char* unit, double& value) {
    const toml::node* n = device.get(key);
    if (n == nullptr) return;
    const std::string name = std::string("device.") + key;
    value = r.number(*n, name);
    if (!(value >= low && value <= high)) {
      r.fail(name, "must be in [" + std::to_string(low) + ", " + std::to_string(high) + "] " + unit + ", got " +
                       std::to_string(value));
    }
  };
  in_range("mass", HandLimits::min_mass_kg, HandLimits::max_mass_kg, "kg", hand.mass_kg);
  in_range("damping", 0.0, HandLimits::max_damping_n_s_per_m, "N s/m", hand.damping_n_s_per_m);
  in_range("grip_stiffness", 0.0, HandLimits::max_grip_stiffness_n_per_m, "N/m", hand.grip_stiffness_n_per_m);
  if (const toml::node* n = device.get("push")) {
    hand.push_n = r.numbers<3>(*n, "device.push");
    for (const double p : hand.push_n) {
      if (!(std::abs(p) <= HandLimits::max_push_n)) {
        r.fail("device.push", "each component must be in [-" + std::to_string(HandLimits::max_push_n) + ", " +
                                  std::to_string(HandLimits::max_push_n) + "] N, got " + std::to_string(p));
      }
    }
  }
  return hand;
}

std::uint16_t port_number(const Reader& r, const toml::node& node, const std::string& key) {
  const double port = r.number(node, key);
  if (port < 1 || port > 65535 || port != std::floor(port)) r.fail(key, "must be in 1..65535");
  return static_cast<std::uint16_t>(port);
}

// [device]: scripted (waypoints), hand (waypoints held by a simulated hand), replay (a --record
// file), udp (address, port) or browser.
DeviceConfig read_device(const Reader& r, const toml::table& root, const std::filesystem::path& base) {
  const toml::table* device = root["device"].as_table();
  if (device == nullptr) r.fail("device", "the [device] table is missing");
  r.only(*device, "device",
         {"kind", "waypoints", "file", "address", "port", "allow_remote", "mass", "damping", "grip_stiffness", "push"});
  const toml::node* kind = device->get("kind");
  const std::string kind_name = kind != nullptr ? r.string(*kind, "device.kind") : "scripted";
  DeviceConfig config;
  if (kind_name != "hand") {
    for (const char* key : {"mass", "damping", "grip_stiffness", "push"}) {
      if (device->contains(key)) r.fail(std::string("device.") + key, "is for kind = \"hand\" only");
    }
  }
  if (kind_name == "scripted") {
    config.kind = DeviceKind::scripted;
    config.waypoints = waypoints(r, *device);
  } else if (kind_name == "hand") {
    config.kind = DeviceKind::hand;
    config.waypoints = waypoints(r, *device);
    config.hand = read_hand(r, *device);
  } else if (kind_name == "replay") {
    config.kind = DeviceKind::replay;
    const toml::node* file = device->get("file");
    if (file == nullptr) r.fail("device.file", "a replay device needs the CSV file --record wrote");
    config.replay_file = relative_to(base, r.string(*file, "device.file"));
  } else if (kind_name == "udp") {
    config.kind = DeviceKind::udp;
    if (const toml::node* n = device->get("address")) config.udp_address = r.string(*n, "device.address");
    if (const toml::node* n = device->get("port")) config.udp_port = port_number(r, *n, "device.port");
    if (const toml::node* n = device->get("allow_remote"))
      config.udp_allow_remote = r.boolean(*n, "device.allow_remote");
  } else if (kind_name == "browser") {
    config.kind = DeviceKind::browser;  // the live view's mouse and keyboard (--view)
  } else if (kind_name == "openigtlink") {
    config.kind = DeviceKind::openigtlink;  // the [openigtlink] server's client
  } else {
    r.fail("device.kind",
           "must be \"scripted\", \"hand\", \"replay\", \"udp\", \"browser\" or \"openigtlink\", got \"" + kind_name +
               "\"");
  }
  if (kind_name != "udp") {
    for (const char* key : {"address", "port", "allow_remote"}) {
      if (device->contains(key)) {
        r.fail(std::string("device.") + key,
               kind_name == "openigtlink" ? "goes in the [openigtlink] table" : "is for kind = \"udp\" only");
      }
    }
  }
  return config;
}

// [openigtlink] (optional; the device kind "openigtlink" takes its defaults without it): the server.
OpenIgtlinkConfig read_openigtlink(const Reader& r, const toml::table& table) {
  r.only(table, "openigtlink",
         {"address", "port", "allow_remote", "length_unit", "probe_transform", "scalpel_transform", "surface_rate"});
  OpenIgtlinkConfig config;
  if (const toml::node* n = table.get("address")) config.address = r.string(*n, "openigtlink.address");
  if (const toml::node* n = table.get("port")) config.port = port_number(r, *n, "openigtlink.port");
  if (const toml::node* n = table.get("allow_remote")) config.allow_remote = r.boolean(*n, "openigtlink.allow_remote");
  if (const toml::node* n = table.get("length_unit")) {
    config.length_unit_m = r.number(*n, "openigtlink.length_unit");
    if (!(config.length_unit_m > 0.0 && config.length_unit_m <= 1.0)) {
      r.fail("openigtlink.length_unit", "must be in (0, 1] m (metres per unit on the wire: 0.001 for mm)");
    }
  }
  for (auto [key, name] : {std::pair{"probe_transform", &config.probe_transform},
                           std::pair{"scalpel_transform", &config.scalpel_transform}}) {
    if (const toml::node* n = table.get(key)) {
      *name = r.string(*n, std::string("openigtlink.") + key);  // checked by the server (igtl_codec.cpp)
    }
  }
  if (const toml::node* n = table.get("surface_rate")) {
    config.surface_rate_hz = r.number(*n, "openigtlink.surface_rate");
    if (config.surface_rate_hz < 0.0 || config.surface_rate_hz > 1000.0) {
      r.fail("openigtlink.surface_rate", "must be in [0, 1000] Hz");
    }
  }
  return config;
}

// [realtime] (optional): the overrun policy and how many slots a step may catch up.
void read_realtime(const Reader& r, const toml::table& realtime, Scenario& s) {
  r.only(realtime, "realtime", {"overrun_policy", "max_catch_up_slots"});
  if (const toml::node* n = realtime.get("overrun_policy")) {
    const std::string policy = r.string(*n, "realtime.overrun_policy");
    if (policy == "catch_up") {
      s.overrun_policy = OverrunPolicy::catch_up;
    } else if (policy == "skip") {
      s.overrun_policy = OverrunPolicy::skip;
    } else {
      r.fail("realtime.overrun_policy", "must be \"catch_up\" or \"skip\"");
    }
  }
  if (const toml::node* n = realtime.get("max_catch_up_slots")) {
    const double slots = r.number(*n, "realtime.max_catch_up_slots");
    if (slots < 1 || slots > 100 || slots != std::floor(slots))
      r.fail("realtime.max_catch_up_slots", "must be in 1..100");
    s.max_catch_up_slots = static_cast<int>(slots);
  }
}

// [output] (optional): the frame rate of the VTU frames and whether to render final.png.
void read_output(const Reader& r, const toml::table& output, Scenario& s) {
  r.only(output, "output", {"frame_rate", "png"});
  if (const toml::node* n = output.get("frame_rate")) {
    s.frame_rate_hz = r.number(*n, "output.frame_rate");
    if (s.frame_rate_hz < 0.0 || s.frame_rate_hz > 1000.0) r.fail("output.frame_rate", "must be in [0, 1000] Hz");
  }
  if (const toml::node* n = output.get("png")) s.write_png = r.boolean(*n, "output.png");
}

// [expect] (optional): what the tests check.
Expectations read_expect(const Reader& r, const toml::table& expect) {
  r.only(expect, "expect", {"min_cut_tets", "max_cut_tets", "contact"});
  const auto count = [&](const char* key) -> std::optional<std::uint64_t> {
    const toml::node* n = expect.get(key);
    if (n == nullptr) return std::nullopt;
    const double value = r.number(*n, std::string("expect.") + key);
    // Up to 2^53, where doubles still count by one (found by fuzzing, issue 44: 1e300 was cast).
    constexpr double LARGEST_COUNT = 9007199254740992.0;
    if (!(value >= 0 && value <= LARGEST_COUNT) || value != std::floor(value))
      r.fail(std::string("expect.") + key, "must be a count up to 2^53");
    return static_cast<std::uint64_t>(value);
  };
  Expectations expectations;
  expectations.min_cut_tets = count("min_cut_tets");
  expectations.max_cut_tets = count("max_cut_tets");
  if (const toml::node* n = expect.get("contact")) expectations.contact = r.boolean(*n, "expect.contact");
  return expectations;
}

}  // namespace

std::vector<ParameterSetting> read_parameter_table(const toml::table& table, const std::string& where,
                                                   const std::string& origin) {
  return parameters(Reader(origin), &table, where);
}

Scenario parse_scenario(const std::string& text, const std::filesystem::path& origin) {
  const Reader r(origin.string());
  const toml::table root = parse_toml(text, origin);
  // [compare] belongs to tissue-host compare (host/compare/compare_settings.*), which reads it itself.
  r.only(root, "",
         {"scenario", "tissue", "haptic", "device", "openigtlink", "realtime", "output", "expect", "compare"});
  Scenario s;
  s.file = origin;
  const std::filesystem::path base = origin.has_parent_path() ? origin.parent_path() : std::filesystem::path(".");
  read_scenario_table(r, root, origin, s);
  read_tissue(r, root, base, s);
  read_haptic(r, root, base, s);
  s.device = read_device(r, root, base);
  if (const toml::table* igtl = root["openigtlink"].as_table()) {
    s.openigtlink = read_openigtlink(r, *igtl);
  } else if (s.device.kind == DeviceKind::openigtlink) {
    s.openigtlink = OpenIgtlinkConfig{};
  }
  if (const toml::table* realtime = root["realtime"].as_table()) read_realtime(r, *realtime, s);
  if (const toml::table* output = root["output"].as_table()) read_output(r, *output, s);
  if (const toml::table* expect = root["expect"].as_table()) s.expect = read_expect(r, *expect);
  return s;
}

std::vector<DeviceWaypoint> placed_waypoints(const DeviceConfig& config, const std::array<double, 3>& rest_lower,
                                             const std::array<double, 3>& rest_upper) {
  std::vector<DeviceWaypoint> waypoints;
  for (const Waypoint& w : config.waypoints) {
    DeviceWaypoint d;
    d.time_s = w.time_s;
    for (std::size_t a = 0; a < 3; ++a) {
      d.pose.position_m[a] =
          w.box_relative ? rest_lower[a] + w.position[a] * (rest_upper[a] - rest_lower[a]) : w.position[a];
    }
    d.pose.orientation_wxyz = w.orientation_wxyz;
    d.pose.mode = w.mode;
    waypoints.push_back(d);
  }
  return waypoints;
}

Scenario load_scenario(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ScenarioError(file.string() + ": cannot be read");
  std::string text(MAX_SCENARIO_FILE_BYTES + 1, '\0');  // one more: a longer file is refused, not cut
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw ScenarioError(file.string() + ": cannot be read");
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > MAX_SCENARIO_FILE_BYTES) {
    throw ScenarioError(file.string() + ": larger than MAX_SCENARIO_FILE_BYTES (" +
                        std::to_string(MAX_SCENARIO_FILE_BYTES) + " bytes)");
  }
  return parse_scenario(text, file);
}

}  // namespace tissue::host
