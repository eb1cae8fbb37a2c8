// The closed-loop harness (see hand_on_tissue.hpp).
#include "hand_on_tissue.hpp"

#include <algorithm>
#include <stdexcept>
#include <string_view>

namespace tissue::host::hand_test {
namespace {

constexpr std::int64_t TOOL_PROBE = 1;  // enumeration ToolMode

fmi3ValueReference vr(std::string_view name) {
  const ModelVariable* variable = haptic_loop_fmu().description().find_variable(name);
  if (variable == nullptr) throw std::logic_error("HapticLoop.fmu has no variable " + std::string(name));
  return variable->value_reference;
}

struct Refs {
  fmi3ValueReference device_position = vr("device.position"), device_tool_mode = vr("device.toolMode"),
                     tissue_time = vr("tissue.time"), contact_active = vr("tissue.contactActive"),
                     contact_near = vr("tissue.contactNear"),
                     contact_point = vr("tissue.contactPoint"), contact_normal = vr("tissue.contactNormal"),
                     contact_force = vr("tissue.contactForce"), contact_stiffness = vr("tissue.contactStiffness"),
                     contact_damping = vr("tissue.contactDamping"),
                     tool_position_in = vr("tissue.toolPosition"), blade_depth = vr("tissue.bladeDepth"),
                     tool_position = vr("tool.position"), device_force = vr("device.force"),
                     samples_refused = vr("tissue.samplesRefused");
};

const Refs& refs() {
  static const Refs r;
  return r;
}

std::string status_text(const char* call, fmi3Status status, Fmu3Instance& fmu) {
  return std::string(call) + ": " + status_name(status) + "\n" + fmu.log_text();
}

bool finite(const Sample& s) {
  bool all = std::isfinite(s.time_s) && std::isfinite(s.blade_depth_m);
  for (const Vec3* v : {&s.point_m, &s.normal, &s.force_n, &s.tool_position_m}) {
    for (const double x : *v) all = all && std::isfinite(x);
  }
  for (const double x : s.stiffness_n_per_m) all = all && std::isfinite(x);
  for (const double x : s.damping_n_s_per_m) all = all && std::isfinite(x);
  return all;
}

Vec3 get3(Fmu3Instance& fmu, fmi3ValueReference ref) {
  Vec3 v{};
  const std::array<fmi3ValueReference, 1> vrs{ref};
  if (fmu.get_float64(vrs, v) != fmi3OK) v.fill(std::numeric_limits<double>::quiet_NaN());
  return v;
}

}  // namespace

fmi3Status deliver(Fmu3Instance& fmu, const Sample& s) {
  const Refs& r = refs();
  const std::array<fmi3ValueReference, 8> float_vrs{r.tissue_time,       r.contact_point,   r.contact_normal,
                                                    r.contact_force,     r.contact_stiffness, r.contact_damping,
                                                    r.tool_position_in,  r.blade_depth};
  std::array<double, 32> values{};
  std::size_t at = 0;
  values[at++] = s.time_s;
  for (const double v : s.point_m) values[at++] = v;
  for (const double v : s.normal) values[at++] = v;
  for (const double v : s.force_n) values[at++] = v;
  for (const double v : s.stiffness_n_per_m) values[at++] = v;
  for (const double v : s.damping_n_s_per_m) values[at++] = v;
  for (const double v : s.tool_position_m) values[at++] = v;
  values[at++] = s.blade_depth_m;
  const std::array<fmi3ValueReference, 2> bool_vrs{r.contact_active, r.contact_near};
  const std::array<fmi3Boolean, 2> flags{s.contact_active, s.contact_near};
  const fmi3Status status = fmu.set_boolean(bool_vrs, flags);
  if (status != fmi3OK) return status;
  return fmu.set_float64(float_vrs, values);
}

const Fmu3& haptic_loop_fmu() {
  static const Fmu3 fmu(HAPTIC_LOOP_FMU_PATH);
  return fmu;
}

Sample Wall::sample(const Vec3& tool_m, double time_s) {
  Sample s;
  s.time_s = time_s;
  s.contact_active = tool_m[2] < 0.0;
  s.contact_near = m_reports_near && !s.contact_active && tool_m[2] < NEAR_MARGIN_M;
  s.point_m = {tool_m[0], tool_m[1], 0.0};
  if (s.contact_active) s.force_n = {0.0, 0.0, -m_stiffness_n_per_m * tool_m[2]};
  if (m_reports_stiffness) s.stiffness_n_per_m[8] = m_stiffness_n_per_m;
  s.tool_position_m = tool_m;
  return s;
}

std::string Wall::name() const {
  return std::to_string(static_cast<int>(m_stiffness_n_per_m)) + " N/m wall, " +
         (m_reports_stiffness ? "with K_c" : "force only") + (m_reports_near ? "" : ", contact only");
}

Sample ViscoelasticWall::sample(const Vec3& tool_m, double time_s) {
  Sample s;
  s.time_s = time_s;
  const double depth_m = std::max(0.0, -tool_m[2]);
  double rate_m_per_s = 0.0;
  if (m_last && time_s > m_last->first) rate_m_per_s = (depth_m - m_last->second) / (time_s - m_last->first);
  m_last = {time_s, depth_m};
  s.contact_active = depth_m > 0.0;
  s.contact_near = m_reports.near && !s.contact_active && tool_m[2] < NEAR_MARGIN_M;
  s.point_m = {tool_m[0], tool_m[1], 0.0};
  if (s.contact_active) {
    s.force_n = {0.0, 0.0, std::max(0.0, m_stiffness_n_per_m * depth_m + m_damping_n_s_per_m * rate_m_per_s)};
  }
  if (m_reports.stiffness) s.stiffness_n_per_m[8] = m_stiffness_n_per_m;
  if (m_reports.damping) s.damping_n_s_per_m[8] = m_damping_n_s_per_m;
  s.tool_position_m = tool_m;
  return s;
}

std::string ViscoelasticWall::name() const {
  std::string reported = m_reports.stiffness ? "K_c" : "";
  if (m_reports.damping) reported += reported.empty() ? "D_c" : ", D_c";
  if (m_reports.near) reported += reported.empty() ? "near" : ", near";
  return std::to_string(static_cast<int>(m_stiffness_n_per_m)) + " N/m viscoelastic wall (" +
         std::to_string(static_cast<int>(m_damping_n_s_per_m)) + " N s/m; " +
         (reported.empty() ? std::string("force only") : "reports " + reported) + ")";
}

Sample CorruptedSamples::sample(const Vec3& tool_m, double time_s) {
  Sample s = m_tissue->sample(tool_m, time_s);
  ++m_count;
  if (m_count % m_period == 0) s.force_n[2] = std::numeric_limits<double>::quiet_NaN();
  if (m_count % m_period == m_period / 2) {
    s.normal = {0.0, 0.0, 2.0};
    if (s.contact_active || s.contact_near) ++m_long_normals_used;
  }
  return s;
}

LoopResult run_hand_on(SyntheticTissue& tissue, const LoopSettings& settings) {
  LoopResult result;
  DeviceWaypoint start;
  start.pose.position_m = {0.0, 0.0, settings.start_height_m};
  start.pose.mode = ToolMode::probe;
  HandDevice hand({start}, settings.hand, TICK_S);
  Fmu3Instance fmu(haptic_loop_fmu(), "hand", false);
  const auto fail = [&](const char* call, fmi3Status status) {
    result.failure = status_text(call, status, fmu);
    return result;
  };
  fmi3Status status = fmu.set_float64("device.maxForce", {settings.max_force_n});
  if (status == fmi3OK) status = fmu.set_float64("device.maxForceRate", {settings.max_force_rate_n_per_s});
  if (status == fmi3OK) status = fmu.set_boolean("passivity.control", {settings.passivity_control});
  if (status == fmi3OK) status = fmu.set_float64("passivity.minHandMass", {settings.min_hand_mass_kg});
  if (status == fmi3OK) status = fmu.set_float64("contact.damping", {settings.contact_damping_n_s_per_m});
  if (status == fmi3OK) status = fmu.set_boolean("contact.holdDamping", {settings.hold_damping});
  if (status == fmi3OK) status = fmu.set_float64("device.position", {0.0, 0.0, settings.start_height_m});
  if (status == fmi3OK) status = fmu.enter_initialization_mode(std::nullopt, 0.0, std::nullopt);
  if (status == fmi3OK) status = fmu.exit_initialization_mode();
  if (status != fmi3OK) return fail("set-up", status);

  const Refs& r = refs();
  const auto ticks = static_cast<long>(std::llround(settings.duration_s / TICK_S));
  std::optional<Sample> pending;
  long samples = 0;
  double most_work_j = 0.0;
  for (long k = 0; k < ticks; ++k) {
    const double t = static_cast<double>(k) * TICK_S;
    if (k % settings.sample_ticks == 0) {
      // The sample computed at the last slot arrives now; the next one starts from the tool now.
      if (pending && !finite(*pending)) {
        ++result.samples_not_finite;  // tissue-host does not forward it either (SessionSummary)
      } else if (pending && (status = deliver(fmu, *pending)) != fmi3OK) {
        return fail("deliver", status);
      }
      ++samples;
      pending = tissue.sample(get3(fmu, r.tool_position), static_cast<double>(samples * settings.sample_ticks) * TICK_S);
    }
    const DevicePose pose = hand.read(t);
    const std::array<fmi3ValueReference, 1> position_vrs{r.device_position}, mode_vrs{r.device_tool_mode};
    const std::array<fmi3Int64, 1> mode{TOOL_PROBE};
    status = fmu.set_float64(position_vrs, pose.position_m);
    if (status == fmi3OK) status = fmu.set_int64(mode_vrs, mode);
    if (status != fmi3OK) return fail("set device", status);
    const DoStepResult stepped = fmu.do_step(t, TICK_S);
    if (stepped.status != fmi3OK && stepped.status != fmi3Warning) return fail("doStep", stepped.status);
    hand.write_force(t, get3(fmu, r.device_force));
    if (settings.trace != nullptr) {
      settings.trace->push_back({hand.hand().position_m()[2], hand.hand().velocity_m_per_s()[2]});
    }
    most_work_j = std::max(most_work_j, hand.hand().device_work_j());
  }
  const std::array<fmi3ValueReference, 1> refused_vrs{r.samples_refused};
  std::array<fmi3UInt64, 1> refused{};
  (void)fmu.get_uint64(refused_vrs, refused);
  result.samples_refused = refused[0];
  result.hand = hand.figures();
  result.lowest_one_port_energy_j = -most_work_j;
  result.completed = true;
  return result;
}

}  // namespace tissue::host::hand_test
