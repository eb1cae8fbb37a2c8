#include "haptic/haptic_renderer.hpp"

#include "haptic/contact_force.hpp"
#include "haptic/force_limits.hpp"
#include "haptic/normal_model_estimate.hpp"
#include "haptic/velocity_filter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue::haptic {

namespace {

std::array<double, 3> to_array(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Vector3d to_vector(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

bool all_finite(const std::array<double, 3>& a) {
  return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]);
}

/// Relative slack on |f| <= max_force_n for a restored command: the clamp scales by max / |f|,
/// which can land an ulp or two above max.
constexpr double FORCE_BOUND_SLACK = 1e-12;
/// Below this motion along the normal between two samples the force's secant is noise: keep the
/// last stiffness estimate (1 um, about a desktop device's position resolution).
constexpr double MIN_SECANT_MOTION_M = 1e-6;
/// A force-only tissue's last contact plane stands in for the surface near report while the tool
/// stays this close to where it touched (the Tissue FMU's contact.nearMargin start value).
constexpr double REMEMBERED_PLANE_RADIUS_M = 0.01;

/// A contact's plane as a surface-near sample: its point, normal, K_c and D_c, no force.
TissueSample contact_plane(const Eigen::Vector3d& point_m, const Eigen::Vector3d& normal,
                           const Eigen::Matrix3d& stiffness_n_per_m, const Eigen::Matrix3d& damping_n_s_per_m) {
  TissueSample plane;
  plane.surface_near = true;
  plane.contact_point_m = point_m;
  plane.contact_normal = normal;
  plane.contact_stiffness_n_per_m = stiffness_n_per_m;
  plane.contact_damping_n_s_per_m = damping_n_s_per_m;
  return plane;
}

/// A saved sample was prepared already: checks it as prepare_sample() would (throws for non-finite
/// or non-unit values), and refuses it (`what` names it) where prepare_sample() would have had to
/// repair it, keeping its exact numbers so that a restored renderer continues bitwise.
void require_prepared(const TissueSample& sample, const std::string& what) {
  TissueSample check = sample;
  const SampleRepair repair = prepare_sample(check);
  if (repair.stiffness_repaired || repair.damping_repaired) {
    throw std::invalid_argument("RendererState: " + what + " is not symmetric positive semi-definite");
  }
}

}  // namespace

void validate(const RendererSettings& settings) {
  constexpr const char* WHO = "RendererSettings";
  require_finite_positive(WHO, "max_force_n", settings.max_force_n);
  require_setting(WHO, settings.max_force_rate_n_per_s > 0.0, "max_force_rate_n_per_s", settings.max_force_rate_n_per_s,
                  "> 0 (+infinity: no limit)");
  require_finite_positive(WHO, "passivity_min_hand_mass_kg", settings.passivity_min_hand_mass_kg);
  require_finite_non_negative(WHO, "max_estimated_stiffness_n_per_m", settings.max_estimated_stiffness_n_per_m);
  require_finite_non_negative(WHO, "contact_damping_n_s_per_m", settings.contact_damping_n_s_per_m);
  require_finite_positive(WHO, "velocity_filter_cutoff_hz", settings.velocity_filter_cutoff_hz);
  validate(settings.cutting);
}

HapticRenderer::HapticRenderer(RendererSettings settings) : m_settings(settings) { validate(m_settings); }

void HapticRenderer::set_sample(const TissueSample& sample) {
  TissueSample prepared = sample;
  const SampleRepair repair = prepare_sample(prepared);  // throws before anything changes
  const bool touching = prepared.contact_active || prepared.surface_near;
  const bool followed = m_has_sample && (m_sample.contact_active || m_sample.surface_near);
  const double interval_s = prepared.time_s - m_sample.time_s;
  // The tool's motion over the sample interval whatever the contact (the estimate's depth rate), and
  // v0, the same while the tool touches or nears the surface in both samples (0 otherwise).
  const Eigen::Vector3d motion_m_per_s = m_has_sample && interval_s > 0.0
                                             ? ((prepared.tool_position_m - m_sample.tool_position_m) / interval_s).eval()
                                             : Eigen::Vector3d::Zero();
  const Eigen::Vector3d tool_velocity_m_per_s = touching && followed ? motion_m_per_s : Eigen::Vector3d::Zero();
  if (prepared.contact_active && prepared.contact_stiffness_n_per_m.isZero(0.0)) {
    estimate_contact_model(prepared, motion_m_per_s);
    remember_contact_plane(prepared);
  } else {
    m_estimate_pair.reset();
    // The tissue reports its surface itself, or says the tool touched nothing where the plane has it
    // inside: the tissue moved away (sagged, fell, was cut), and the plane would be a phantom wall.
    const bool inside_plane =
        m_last_contact && (prepared.tool_position_m - m_last_contact->contact_point_m).dot(m_last_contact->contact_normal) < 0.0;
    if (prepared.contact_active || prepared.surface_near || inside_plane) m_last_contact.reset();
  }
  m_sample_tool_velocity_m_per_s = tool_velocity_m_per_s;
  m_sample_motion_m_per_s = motion_m_per_s;
  m_sample = prepared;
  m_has_sample = true;
  m_last_sample_repaired = repair.stiffness_repaired || repair.damping_repaired;
}

void HapticRenderer::remember_contact_plane(const TissueSample& sample) {
  m_last_contact = contact_plane(sample.contact_point_m, sample.contact_normal, sample.contact_stiffness_n_per_m,
                                 sample.contact_damping_n_s_per_m);
}

void HapticRenderer::estimate_contact_model(TissueSample& sample, const Eigen::Vector3d& motion_m_per_s) {
  const Eigen::Vector3d& n = sample.contact_normal;
  const Eigen::Matrix3d normal_projector = (n * n.transpose()).eval();  // exactly symmetric
  const bool damping_reported = !sample.contact_damping_n_s_per_m.isZero(0.0);
  NormalModel model = m_normal_model;  // the last estimate, of this contact or the one before
  if (damping_reported) model.damping_n_s_per_m = n.dot(sample.contact_damping_n_s_per_m * n);
  if (m_has_sample && m_sample.contact_active) {
    const NormalPair pair{-(sample.tool_position_m - m_sample.tool_position_m).dot(n),
                          -(motion_m_per_s - m_sample_motion_m_per_s).dot(n),
                          (sample.force_on_tool_n - m_sample.force_on_tool_n).dot(n)};
    NormalModelLimits limits;
    limits.max_stiffness_n_per_m = m_settings.max_estimated_stiffness_n_per_m;
    limits.min_depth_change_m = MIN_SECANT_MOTION_M;
    model = estimate_normal_model(model, pair, m_estimate_pair, damping_reported, limits);
    m_estimate_pair = pair;
  } else {
    m_estimate_pair.reset();  // the contact's first sample: the last contact's model stands
  }
  m_normal_model = model;
  sample.contact_stiffness_n_per_m = model.stiffness_n_per_m * normal_projector;
  if (!damping_reported) sample.contact_damping_n_s_per_m = model.damping_n_s_per_m * normal_projector;
}

Eigen::Vector3d HapticRenderer::tick(const Eigen::Vector3d& device_position_m, ToolMode mode, double dt_s) {
  if (!(std::isfinite(dt_s) && dt_s > 0.0)) {
    throw std::invalid_argument("HapticRenderer::tick: dt_s = " + std::to_string(dt_s) + ", must be finite and > 0");
  }
  TickReport report;
  const double max_change_n = m_settings.max_force_rate_n_per_s * dt_s;  // +inf stays +inf

  if (!device_position_m.allFinite()) {
    // Where the hand is is unknown: render nothing, release the force at the rate limit, book
    // nothing (the motion over this tick is unknown) and restart the velocity afterwards.
    report.position_rejected = true;
    m_has_previous_position = false;
    m_filtered_velocity_m_per_s.setZero();
    const LimitedForce released = limit_rate(m_commanded_force_n, Eigen::Vector3d::Zero(), max_change_n);
    m_commanded_force_n = released.force_n;
    m_commanded_damping_n.setZero();
    report.rate_limited = released.acted;
    report.commanded_force_n = m_commanded_force_n;
    report.observed_energy_j = report.predicted_energy_j = m_observer.energy_j();
    m_report = report;
    return m_commanded_force_n;
  }

  // Motion over the tick that just ended; the observer books the force held over it.
  Eigen::Vector3d motion_m_per_s = Eigen::Vector3d::Zero();  // backward difference
  if (m_has_previous_position) {
    const Eigen::Vector3d displacement_m = device_position_m - m_previous_position_m;
    m_observer.book(m_commanded_force_n, m_commanded_damping_n, displacement_m);
    motion_m_per_s = displacement_m / dt_s;
  }
  m_previous_position_m = device_position_m;
  m_has_previous_position = true;
  m_filtered_velocity_m_per_s +=
      low_pass_gain(dt_s, m_settings.velocity_filter_cutoff_hz) * (motion_m_per_s - m_filtered_velocity_m_per_s);

  // The environment: contact (probe or scalpel, as the sample says) and cutting (scalpel).
  if (m_has_sample && mode != ToolMode::none) {
    const bool near_plane = !m_sample.contact_active && m_sample.surface_near && mode == ToolMode::probe;
    if (!m_sample.contact_active && !m_sample.surface_near && m_last_contact &&
        (device_position_m - m_last_contact->contact_point_m).norm() > REMEMBERED_PLANE_RADIUS_M) {
      m_last_contact.reset();  // the tool left the place: the plane says nothing of elsewhere
    }
    const bool remembered_plane =
        !m_sample.contact_active && !m_sample.surface_near && m_last_contact && mode == ToolMode::probe;
    if (m_sample.contact_active || near_plane || remembered_plane) {
      const TissueSample& plane = remembered_plane ? *m_last_contact : m_sample;
      const Eigen::Vector3d spring_n = m_sample.contact_active ? intermediate_force(m_sample, device_position_m)
                                                               : near_surface_force(plane, device_position_m);
      const Eigen::Vector3d sample_velocity_m_per_s =
          remembered_plane ? Eigen::Vector3d::Zero() : m_sample_tool_velocity_m_per_s;
      const Eigen::Vector3d damping_n =
          contact_damping_force(plane, motion_m_per_s, sample_velocity_m_per_s, m_settings.contact_damping_n_s_per_m,
                                m_settings.hold_damping ? dt_s : 0.0);
      report.contact_force_n = unilateral_force(spring_n + damping_n, plane, device_position_m);
    }
    if (mode == ToolMode::scalpel) {
      report.cutting_force_n =
          cutting_force(m_settings.cutting, m_sample.blade_depth_m, m_filtered_velocity_m_per_s, motion_m_per_s);
    }
  }
  const Eigen::Vector3d environment_n = report.contact_force_n + report.cutting_force_n;
  if (environment_n.isZero(0.0) && m_commanded_force_n.isZero(0.0)) m_observer.drop_credit();

  // Limits, then the controller on what the limits let through, then the limits on its sum.
  LimitedForce clamped = clamp_magnitude(environment_n, m_settings.max_force_n);
  LimitedForce limited = limit_rate(m_commanded_force_n, clamped.force_n, max_change_n);
  Eigen::Vector3d command_n = limited.force_n;
  Eigen::Vector3d damping_n = Eigen::Vector3d::Zero();
  if (m_settings.passivity_control) {
    const double max_damping_n_s_per_m = m_settings.passivity_min_hand_mass_kg / (2.0 * dt_s);
    const PassivityAction action =
        passivity_damping(m_observer.energy_j(), command_n, motion_m_per_s, dt_s, max_damping_n_s_per_m);
    if (action.damping_n_s_per_m > 0.0) {
      clamped = clamp_magnitude(command_n + action.damping_force_n, m_settings.max_force_n);
      limited = limit_rate(m_commanded_force_n, clamped.force_n, max_change_n);
      damping_n = limited.force_n - command_n;
      command_n = limited.force_n;
      report.passivity_acted = true;
      report.damping_n_s_per_m = action.damping_n_s_per_m;
    }
  }

  m_commanded_force_n = command_n;
  m_commanded_damping_n = damping_n;
  report.passivity_force_n = damping_n;
  report.commanded_force_n = command_n;
  report.velocity_m_per_s = m_filtered_velocity_m_per_s;
  report.observed_energy_j = m_observer.energy_j();
  report.predicted_energy_j = m_observer.energy_j() - command_n.dot(motion_m_per_s) * dt_s;
  report.clamped = clamped.acted;
  report.rate_limited = limited.acted;
  m_report = report;
  return command_n;
}

void HapticRenderer::reset() { *this = HapticRenderer(m_settings); }

RendererState HapticRenderer::save_state() const {
  RendererState state;
  state.has_sample = m_has_sample;
  state.contact_active = m_sample.contact_active;
  state.surface_near = m_sample.surface_near;
  state.sample_time_s = m_sample.time_s;
  state.contact_point_m = to_array(m_sample.contact_point_m);
  state.contact_normal = to_array(m_sample.contact_normal);
  state.force_on_tool_n = to_array(m_sample.force_on_tool_n);
  Eigen::Map<Eigen::Matrix3d>(state.contact_stiffness_n_per_m.data()) = m_sample.contact_stiffness_n_per_m;
  Eigen::Map<Eigen::Matrix3d>(state.contact_damping_n_s_per_m.data()) = m_sample.contact_damping_n_s_per_m;
  state.sample_tool_velocity_m_per_s = to_array(m_sample_tool_velocity_m_per_s);
  state.sample_motion_m_per_s = to_array(m_sample_motion_m_per_s);
  state.has_last_contact = m_last_contact.has_value();
  if (m_last_contact) {
    state.last_contact_point_m = to_array(m_last_contact->contact_point_m);
    state.last_contact_normal = to_array(m_last_contact->contact_normal);
    Eigen::Map<Eigen::Matrix3d>(state.last_contact_stiffness_n_per_m.data()) = m_last_contact->contact_stiffness_n_per_m;
    Eigen::Map<Eigen::Matrix3d>(state.last_contact_damping_n_s_per_m.data()) = m_last_contact->contact_damping_n_s_per_m;
  }
  state.normal_model = {m_normal_model.stiffness_n_per_m, m_normal_model.damping_n_s_per_m};
  state.has_estimate_pair = m_estimate_pair.has_value();
  if (m_estimate_pair) {
    state.estimate_pair = {m_estimate_pair->depth_change_m, m_estimate_pair->rate_change_m_per_s,
                           m_estimate_pair->force_change_n};
  }
  state.tool_position_m = to_array(m_sample.tool_position_m);
  state.blade_depth_m = m_sample.blade_depth_m;
  state.has_previous_position = m_has_previous_position;
  state.previous_position_m = to_array(m_previous_position_m);
  state.filtered_velocity_m_per_s = to_array(m_filtered_velocity_m_per_s);
  state.commanded_force_n = to_array(m_commanded_force_n);
  state.commanded_damping_n = to_array(m_commanded_damping_n);
  state.observed_energy_j = m_observer.energy_j();
  state.dissipated_energy_j = m_observer.dissipated_j();
  return state;
}

void HapticRenderer::restore_state(const RendererState& state) {
  TissueSample sample;
  sample.time_s = state.sample_time_s;
  sample.contact_active = state.contact_active;
  sample.surface_near = state.surface_near;
  sample.contact_point_m = to_vector(state.contact_point_m);
  sample.contact_normal = to_vector(state.contact_normal);
  sample.force_on_tool_n = to_vector(state.force_on_tool_n);
  sample.contact_stiffness_n_per_m = Eigen::Map<const Eigen::Matrix3d>(state.contact_stiffness_n_per_m.data());
  sample.contact_damping_n_s_per_m = Eigen::Map<const Eigen::Matrix3d>(state.contact_damping_n_s_per_m.data());
  sample.tool_position_m = to_vector(state.tool_position_m);
  sample.blade_depth_m = state.blade_depth_m;
  require_prepared(sample, "the contact stiffness or damping");
  const bool motion_finite = all_finite(state.previous_position_m) && all_finite(state.filtered_velocity_m_per_s) &&
                             all_finite(state.sample_tool_velocity_m_per_s) && all_finite(state.estimate_pair) &&
                             all_finite(state.sample_motion_m_per_s);
  const bool model_valid = state.normal_model[0] >= 0.0 && state.normal_model[1] >= 0.0 &&
                           std::isfinite(state.normal_model[0]) && std::isfinite(state.normal_model[1]);
  if (!model_valid) throw std::invalid_argument("RendererState: the estimated contact model is not finite and >= 0");
  std::optional<TissueSample> last_contact;
  if (state.has_last_contact) {
    last_contact = contact_plane(to_vector(state.last_contact_point_m), to_vector(state.last_contact_normal),
                                 Eigen::Map<const Eigen::Matrix3d>(state.last_contact_stiffness_n_per_m.data()),
                                 Eigen::Map<const Eigen::Matrix3d>(state.last_contact_damping_n_s_per_m.data()));
    require_prepared(*last_contact, "the remembered plane's stiffness or damping");
  }
  const bool command_finite = all_finite(state.commanded_force_n) && all_finite(state.commanded_damping_n);
  if (!motion_finite || !command_finite || !std::isfinite(state.observed_energy_j) ||
      !std::isfinite(state.dissipated_energy_j)) {
    throw std::invalid_argument("RendererState: a motion, force or energy value is not finite");
  }
  if (to_vector(state.commanded_force_n).norm() > m_settings.max_force_n * (1.0 + FORCE_BOUND_SLACK)) {
    throw std::invalid_argument("RendererState: commanded_force_n exceeds max_force_n");
  }

  m_sample = sample;
  m_sample_tool_velocity_m_per_s = to_vector(state.sample_tool_velocity_m_per_s);
  m_sample_motion_m_per_s = to_vector(state.sample_motion_m_per_s);
  m_last_contact = last_contact;
  m_normal_model = NormalModel{state.normal_model[0], state.normal_model[1]};
  m_estimate_pair.reset();
  if (state.has_estimate_pair) {
    m_estimate_pair = NormalPair{state.estimate_pair[0], state.estimate_pair[1], state.estimate_pair[2]};
  }
  m_has_sample = state.has_sample;
  m_last_sample_repaired = false;
  m_has_previous_position = state.has_previous_position;
  m_previous_position_m = to_vector(state.previous_position_m);
  m_filtered_velocity_m_per_s = to_vector(state.filtered_velocity_m_per_s);
  m_commanded_force_n = to_vector(state.commanded_force_n);
  m_commanded_damping_n = to_vector(state.commanded_damping_n);
  m_observer.set(state.observed_energy_j, state.dissipated_energy_j);
  m_report = TickReport{};
}

}  // namespace tissue::haptic
