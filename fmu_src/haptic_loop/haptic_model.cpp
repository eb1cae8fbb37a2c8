// HapticModel (see haptic_model.hpp).
#include "haptic_loop/haptic_model.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <string>

namespace tissue::haptic_fmu {
namespace {

using fmi3::ValueStore;
using fmi3::VariableError;
using fmi3::VariableInfo;

fmi3::ValueReference vr(Vr v) { return static_cast<fmi3::ValueReference>(v); }

Eigen::Vector3d vector3(const ValueStore& values, Vr v) {
  const std::span<const double> a = values.float64_array(vr(v));
  return {a[0], a[1], a[2]};
}

void put3(std::span<double> out, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(k)] = v(k);
}

struct HapticState final : fmi3::ModelState {
  haptic::RendererState renderer;
  double time_s = 0.0;
  bool has_sample_time = false;
  double sample_time_s = 0.0;
  std::uint64_t samples_received = 0;
  std::uint64_t samples_refused = 0;
};

template <std::size_t N>
void put_array(serial::ByteWriter& w, const std::array<double, N>& a) {
  for (const double v : a) w.put(v);
}
template <std::size_t N>
void get_array(serial::ByteReader& r, std::array<double, N>& a) {
  for (double& v : a) r.get(v);
}

}  // namespace

haptic::RendererSettings renderer_settings(const ValueStore& values) {
  haptic::RendererSettings s;
  s.max_force_n = values.float64(vr(Vr::max_force));
  s.max_force_rate_n_per_s = values.float64(vr(Vr::max_force_rate));
  s.passivity_control = values.boolean(vr(Vr::passivity_control));
  s.passivity_min_hand_mass_kg = values.float64(vr(Vr::passivity_min_hand_mass));
  s.contact_damping_n_s_per_m = values.float64(vr(Vr::contact_damping));
  s.hold_damping = values.boolean(vr(Vr::contact_hold_damping));
  s.velocity_filter_cutoff_hz = values.float64(vr(Vr::velocity_cutoff));
  s.cutting.fracture_toughness_j_per_m2 = values.float64(vr(Vr::fracture_toughness));
  s.cutting.blade_friction_n_per_m = values.float64(vr(Vr::blade_friction));
  s.cutting.smoothing_speed_m_per_s = values.float64(vr(Vr::cutting_smoothing_speed));
  haptic::validate(s);
  return s;
}

HapticModel::HapticModel(const fmi3::ModelContext& context, const ValueStore& values)
    : m_context(context), m_values(values), m_renderer(renderer_settings(values)) {}

// The inputs are not checked here: the schema's rules hold at every set (device.orientation's
// min_norm), and the tissue sample is checked where it is used (take_tissue_sample: a bad one is
// refused and counted, the hand's loop goes on).
void check_parameters(const ValueStore& values) {
  (void)renderer_settings(values);
  const double step_s = values.float64(vr(Vr::step_size));
  if (!(step_s > 0.0)) throw VariableError("stepSize must be > 0 s, got " + std::to_string(step_s));
  const double scale = values.float64(vr(Vr::workspace_scale));
  if (!(scale > 0.0)) throw VariableError("workspace.scale must be > 0, got " + std::to_string(scale));
}

Eigen::Vector3d tool_position(const ValueStore& values, const Eigen::Vector3d& device_position_m) {
  return vector3(values, Vr::workspace_offset) + values.float64(vr(Vr::workspace_scale)) * device_position_m;
}

void HapticModel::validate_parameters(const ValueStore& values) const { check_parameters(values); }

void HapticModel::parameters_changed() { m_renderer = haptic::HapticRenderer(renderer_settings(m_values)); }

void HapticModel::enter_initialization_mode(double start_time_s) { m_time_s = start_time_s; }

void HapticModel::exit_initialization_mode() {}

Eigen::Vector3d HapticModel::tool_position() const {
  return haptic_fmu::tool_position(m_values, vector3(m_values, Vr::device_position));
}

void HapticModel::take_tissue_sample() {
  const double time_s = m_values.float64(vr(Vr::tissue_time));
  if (m_has_sample_time && time_s == m_sample_time_s) return;
  m_has_sample_time = true;
  m_sample_time_s = time_s;
  haptic::TissueSample sample;
  sample.time_s = time_s;
  sample.contact_active = m_values.boolean(vr(Vr::tissue_contact_active));
  sample.surface_near = m_values.boolean(vr(Vr::tissue_contact_near));
  sample.contact_point_m = vector3(m_values, Vr::tissue_contact_point);
  sample.contact_normal = vector3(m_values, Vr::tissue_contact_normal);
  sample.force_on_tool_n = vector3(m_values, Vr::tissue_contact_force);
  const std::span<const double> k = m_values.float64_array(vr(Vr::tissue_contact_stiffness));
  const std::span<const double> d = m_values.float64_array(vr(Vr::tissue_contact_damping));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      sample.contact_stiffness_n_per_m(r, c) = k[static_cast<std::size_t>(3 * r + c)];
      sample.contact_damping_n_s_per_m(r, c) = d[static_cast<std::size_t>(3 * r + c)];
    }
  }
  sample.tool_position_m = vector3(m_values, Vr::tissue_tool_position);
  sample.blade_depth_m = m_values.float64(vr(Vr::tissue_blade_depth));
  try {
    m_renderer.set_sample(sample);
    ++m_samples_received;
  } catch (const std::invalid_argument& error) {
    // A bad sample must not stop the hand's loop: the previous one stays, and it is counted.
    ++m_samples_refused;
    if (m_samples_refused == 1) {
      m_context.log(fmi3::LogLevel::warning,
                    std::string("tissue sample refused, the previous one kept: ") + error.what());
    }
  }
}

fmi3::StepOutcome HapticModel::do_step(double current_time_s, double step_s) {
  const double tick_s = m_values.float64(vr(Vr::step_size));
  const long ticks = fmi3::whole_internal_steps(m_time_s, current_time_s, step_s, tick_s);
  const std::uint64_t refused_before = m_samples_refused;
  take_tissue_sample();
  const auto mode = static_cast<ToolMode>(m_values.int64(vr(Vr::device_tool_mode)));
  const Eigen::Vector3d position_m = tool_position();
  for (long n = 0; n < ticks; ++n) m_renderer.tick(position_m, mode, tick_s);
  // Whole ticks from the communication point: no drift from adding step_s.
  m_time_s = current_time_s + static_cast<double>(ticks) * tick_s;
  // A refused sample does not stop the hand's loop, but the importer hears of it (fmi3Warning).
  return {true, m_time_s, m_samples_refused != refused_before};
}

void HapticModel::reset() {
  m_renderer = haptic::HapticRenderer(renderer_settings(m_values));
  m_time_s = 0.0;
  m_has_sample_time = false;
  m_sample_time_s = 0.0;
  m_samples_received = 0;
  m_samples_refused = 0;
}

// --- outputs ---

void HapticModel::get_float64(const VariableInfo& info, std::span<double> out) {
  const haptic::TickReport& report = m_renderer.last_tick();
  switch (static_cast<Vr>(info.vr)) {
    case Vr::time:
      out[0] = m_time_s;
      return;
    case Vr::tool_position:
      put3(out, tool_position());
      return;
    case Vr::tool_orientation: {
      const std::span<const double> q = m_values.float64_array(vr(Vr::device_orientation));
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      for (std::size_t k = 0; k < 4; ++k) out[k] = q[k] / norm;
      return;
    }
    case Vr::device_force:
      put3(out, report.commanded_force_n);
      return;
    case Vr::contact_force:
      put3(out, report.contact_force_n);
      return;
    case Vr::cutting_force:
      put3(out, report.cutting_force_n);
      return;
    case Vr::passivity_force:
      put3(out, report.passivity_force_n);
      return;
    case Vr::observed_energy:
      out[0] = m_renderer.observed_energy_j();
      return;
    case Vr::dissipated_energy:
      out[0] = m_renderer.dissipated_energy_j();
      return;
    default:
      Model::get_float64(info, out);
  }
}

void HapticModel::get_int64(const VariableInfo& info, std::span<std::int64_t> out) {
  if (static_cast<Vr>(info.vr) != Vr::tool_mode) Model::get_int64(info, out);
  out[0] = m_values.int64(vr(Vr::device_tool_mode));
}

void HapticModel::get_uint64(const VariableInfo& info, std::span<std::uint64_t> out) {
  switch (static_cast<Vr>(info.vr)) {
    case Vr::samples_received:
      out[0] = m_samples_received;
      return;
    case Vr::samples_refused:
      out[0] = m_samples_refused;
      return;
    default:
      Model::get_uint64(info, out);
  }
}

void HapticModel::get_boolean(const VariableInfo& info, std::span<bool> out) {
  const haptic::TickReport& report = m_renderer.last_tick();
  switch (static_cast<Vr>(info.vr)) {
    case Vr::force_clamped:
      out[0] = report.clamped;
      return;
    case Vr::force_rate_limited:
      out[0] = report.rate_limited;
      return;
    case Vr::passivity_acted:
      out[0] = report.passivity_acted;
      return;
    default:
      Model::get_boolean(info, out);
  }
}

// --- FMU states ---

std::unique_ptr<fmi3::ModelState> HapticModel::save() const {
  auto state = std::make_unique<HapticState>();
  state->renderer = m_renderer.save_state();
  state->time_s = m_time_s;
  state->has_sample_time = m_has_sample_time;
  state->sample_time_s = m_sample_time_s;
  state->samples_received = m_samples_received;
  state->samples_refused = m_samples_refused;
  return state;
}

void HapticModel::restore(const fmi3::ModelState& model_state) {
  const auto* state = dynamic_cast<const HapticState*>(&model_state);
  if (state == nullptr) throw VariableError("set FMU state: not a HapticLoop FMU state");
  haptic::HapticRenderer renderer(renderer_settings(m_values));
  renderer.restore_state(state->renderer);
  m_renderer = renderer;
  m_time_s = state->time_s;
  m_has_sample_time = state->has_sample_time;
  m_sample_time_s = state->sample_time_s;
  m_samples_received = state->samples_received;
  m_samples_refused = state->samples_refused;
}

void HapticModel::serialize(const fmi3::ModelState& model_state, serial::ByteWriter& w) const {
  const auto& state = dynamic_cast<const HapticState&>(model_state);
  const haptic::RendererState& r = state.renderer;
  w.put_bool(r.has_sample);
  w.put_bool(r.contact_active);
  w.put_bool(r.surface_near);
  w.put(r.sample_time_s);
  put_array(w, r.contact_point_m);
  put_array(w, r.contact_normal);
  put_array(w, r.force_on_tool_n);
  put_array(w, r.contact_stiffness_n_per_m);
  put_array(w, r.contact_damping_n_s_per_m);
  put_array(w, r.sample_tool_velocity_m_per_s);
  w.put_bool(r.has_estimate_pair);
  put_array(w, r.estimate_pair);
  put_array(w, r.normal_model);
  put_array(w, r.sample_motion_m_per_s);
  w.put_bool(r.has_last_contact);
  put_array(w, r.last_contact_point_m);
  put_array(w, r.last_contact_normal);
  put_array(w, r.last_contact_stiffness_n_per_m);
  put_array(w, r.last_contact_damping_n_s_per_m);
  put_array(w, r.tool_position_m);
  w.put(r.blade_depth_m);
  w.put_bool(r.has_previous_position);
  put_array(w, r.previous_position_m);
  put_array(w, r.filtered_velocity_m_per_s);
  put_array(w, r.commanded_force_n);
  put_array(w, r.commanded_damping_n);
  w.put(r.observed_energy_j);
  w.put(r.dissipated_energy_j);
  w.put(state.time_s);
  w.put_bool(state.has_sample_time);
  w.put(state.sample_time_s);
  w.put(state.samples_received);
  w.put(state.samples_refused);
}

std::unique_ptr<fmi3::ModelState> HapticModel::deserialize(serial::ByteReader& r) const {
  auto state = std::make_unique<HapticState>();
  haptic::RendererState& s = state->renderer;
  s.has_sample = r.get_bool();
  s.contact_active = r.get_bool();
  s.surface_near = r.get_bool();
  r.get(s.sample_time_s);
  get_array(r, s.contact_point_m);
  get_array(r, s.contact_normal);
  get_array(r, s.force_on_tool_n);
  get_array(r, s.contact_stiffness_n_per_m);
  get_array(r, s.contact_damping_n_s_per_m);
  get_array(r, s.sample_tool_velocity_m_per_s);
  s.has_estimate_pair = r.get_bool();
  get_array(r, s.estimate_pair);
  get_array(r, s.normal_model);
  get_array(r, s.sample_motion_m_per_s);
  s.has_last_contact = r.get_bool();
  get_array(r, s.last_contact_point_m);
  get_array(r, s.last_contact_normal);
  get_array(r, s.last_contact_stiffness_n_per_m);
  get_array(r, s.last_contact_damping_n_s_per_m);
  get_array(r, s.tool_position_m);
  r.get(s.blade_depth_m);
  s.has_previous_position = r.get_bool();
  get_array(r, s.previous_position_m);
  get_array(r, s.filtered_velocity_m_per_s);
  get_array(r, s.commanded_force_n);
  get_array(r, s.commanded_damping_n);
  r.get(s.observed_energy_j);
  r.get(s.dissipated_energy_j);
  r.get(state->time_s);
  state->has_sample_time = r.get_bool();
  r.get(state->sample_time_s);
  r.get(state->samples_received);
  r.get(state->samples_refused);
  // The renderer checks what it could not have saved (non-finite numbers, a force above the limit).
  haptic::HapticRenderer check(renderer_settings(m_values));
  check.restore_state(s);
  return state;
}

}  // namespace tissue::haptic_fmu
