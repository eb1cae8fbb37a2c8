// ContactModel (see contact_model.hpp).
#include "core/contact/contact_model.hpp"

#include "core/contact/surface_point.hpp"
#include "core/parameter_error.hpp"
#include "core/state_error.hpp"

#include <algorithm>
#include <string>

namespace tissue {

namespace {

// CHOLMOD may factorize a singular K through rounding; the point of a free piece then comes out with
// a K_c at rounding level. Held points of the frog measure 0.0017 to 14 times the contact scale
// (contact_stiffness.hpp): below 1e-6 of it, a static K_c belongs to a piece nothing holds.
constexpr double FREE_PIECE_STIFFNESS_FRACTION = 1e-6;

PointContactSettings point_contact_settings(const ContactSettings& settings, double step_size_s,
                                            double stiffness_damping_s, const DeformableBody& body,
                                            const SurfaceMesh& surface, const Integrator& integrator) {
  PointContactSettings contact;
  const double stiffness = settings.spring_stiffness_n_per_m;
  contact.spring_stiffness_n_per_m =
      stiffness > 0.0 ? stiffness : recommended_contact_spring_stiffness_n_per_m(body, surface);
  // A surface that sags or swings onto a probe held still touches it (issue 10), up to half a mean
  // surface edge deep: deeper, the tool was put inside, and snapping it out would kick the tissue.
  contact.passed_over_depth_m = 0.5 * mean_surface_edge_m(body, surface);
  // The spring stands for the rigid tool: the step must not damp it (issue 9).
  contact.spring_tangent_fraction = integrator.undamped_tangent_share(step_size_s, stiffness_damping_s);
  contact.friction_coefficient = settings.friction_coefficient;
  contact.pad_radius_m = settings.pad_radius_m;
  if (settings.pad_radius_m > 0.0 && settings.stiffness_model == ContactStiffnessModel::element_local) {
    throw ParameterError("a probe with a pad (contact pad radius " + std::to_string(settings.pad_radius_m) +
                         " m) needs the effectiveStatic contact stiffness: elementLocal is a point's");
  }
  return contact;
}

}  // namespace

ContactModel::ContactModel(const ContactSettings& settings, bool enabled, double step_size_s,
                           double stiffness_damping_s, DeformableBody& body, Integrator& integrator,
                           PointSpringTerm& spring, const SurfaceMesh& surface)
    : m_settings(settings),
      m_enabled(enabled),
      m_step_size_s(step_size_s),
      m_stiffness_damping_s(stiffness_damping_s),
      m_body(body),
      m_integrator(integrator),
      m_spring(spring),
      m_surface(surface),
      m_contact(point_contact_settings(settings, step_size_s, stiffness_damping_s, body, surface, integrator)),
      m_stiffness_scale_n_per_m(contact_stiffness_scale_n_per_m(body, surface)),
      m_pending_latency_steps(settings.stiffness_latency_steps) {
  m_contact.set_touchable_triangles(static_cast<int>(m_surface.triangles.size()));
}

void ContactModel::probe(const Eigen::Vector3d& previous_m, const Eigen::Vector3d& current_m,
                         const LazySurfaceBvh& bvh, const Eigen::Vector3d& tool_axis) {
  m_contact.set_pad_axis(tool_axis);
  const bool was_in_contact = m_contact.in_contact();
  // How far the pressed surface rises to a tool drawn back (PointContact::update): the last step's
  // normal force over its normal contact stiffness.
  const ContactOutput& last = m_output;
  const double pressed_n = last.active ? last.force_on_tool_n.dot(last.normal) : 0.0;
  const double normal_stiffness_n_per_m = last.normal.dot(rendered_stiffness_n_per_m() * last.normal);
  const double follow_distance_m =
      pressed_n > 0.0 && normal_stiffness_n_per_m > 0.0 ? pressed_n / normal_stiffness_n_per_m : 0.0;
  m_contact.update(previous_m, current_m, bvh.positions_m(), bvh.fitted(), follow_distance_m, normal_stiffness_n_per_m);
  m_contact.apply(bvh.fitted(), m_spring, m_body.term_layout());
  if (m_contact.in_contact() && !was_in_contact) m_steps_since_stiffness = -1;  // a new contact: refresh K_c
  if (m_contact.in_contact() != was_in_contact) m_integrator.restart(Restart::contact_changed);
}

void ContactModel::withdraw() {
  if (!m_contact.in_contact() && !m_spring.spring()) return;
  m_contact.release();
  m_spring.set(std::nullopt, m_body.term_layout());
  m_integrator.restart(Restart::contact_changed);
}

void ContactModel::update_output(const LazySurfaceBvh& bvh, const Eigen::Vector3d& applied_tip_m) {
  ContactOutput& out = m_output;
  if (!m_contact.in_contact()) {
    m_stiffness_refresh.cancel();
    out = ContactOutput{};
    return;
  }
  out.active = true;
  const SurfaceBvh& fitted = bvh.fitted();
  out.point_m = surface_point_position_m(m_contact.proxy(), fitted.triangles(), bvh.positions_m());
  out.normal = m_contact.normal();
  out.force_on_tool_n = m_contact.force_on_tool_n(fitted, bvh.positions_m());
  out.penetration_depth_m = (applied_tip_m - out.point_m).norm();
  refresh_stiffness(m_contact.proxy().triangle);
}

void ContactModel::refresh_stiffness(int triangle) {
  ContactOutput& out = m_output;
  if (m_settings.stiffness_model == ContactStiffnessModel::element_local) {
    out.stiffness_n_per_m = element_local_contact_stiffness(m_body.elasticity(), m_surface, triangle);
    return;
  }
  // A refresh started in the background stiffness_latency_steps ago is rendered from this step on;
  // until then the one before stands, and no other starts.
  const bool new_contact = m_steps_since_stiffness < 0;
  if (m_stiffness_refresh.state() != BackgroundContactStiffness::State::idle) {
    if (!new_contact && m_steps_since_stiffness < m_pending_latency_steps) {
      ++m_steps_since_stiffness;
      return;
    }
    out.stiffness_n_per_m = landed_stiffness(m_stiffness_refresh.take(), triangle);
  }
  const int period = m_settings.stiffness_in_background
                         ? std::max(m_settings.stiffness_refresh_steps, m_pending_latency_steps)
                         : m_settings.stiffness_refresh_steps;
  if (!new_contact && m_steps_since_stiffness < period) {
    ++m_steps_since_stiffness;
    return;
  }
  m_steps_since_stiffness = 1;
  // K_c from the static K where the body is held, from the step's Newton matrix (asked of the
  // integrator) where nothing holds it; the contact spring taken out of either
  // (contact_stiffness.hpp); a point on fixed vertices only is a rigid support: the spring alone.
  const bool held = !m_body.settings().fixed_vertices.empty();
  const ShiftedSystem system = held ? static_contact_system(m_body.tangent(), m_system_diagonal)
                                    : m_integrator.newton_stiffness(m_body, m_step_size_s, m_system_diagonal);
  const ContactStiffnessRequest request = stiffness_request_at(
      system, triangle, held ? FREE_PIECE_STIFFNESS_FRACTION * m_stiffness_scale_n_per_m : 0.0);
  // Between factorizations (stiffness_refactor_refreshes), the current point from the last factor:
  // the spring taken out is the one its matrix holds.
  const bool background = m_settings.stiffness_in_background;
  const bool condense_only =
      m_last_factor.usable && m_last_factor.refreshes_since < m_settings.stiffness_refactor_refreshes &&
      m_last_factor.pattern == system.stiffness->pattern_revision() && m_last_factor.rows == system.rows() &&
      (background ? m_stiffness_refresh.factored() : m_effective_stiffness.rows() > 0);
  ContactStiffnessRequest from_factor = request;
  if (condense_only) {
    from_factor.spring_point = m_last_factor.request.spring_point;
    from_factor.spring_in_matrix_n_per_m = m_last_factor.request.spring_in_matrix_n_per_m;
    from_factor.spring_direction = m_last_factor.request.spring_direction;
    from_factor.pad_in_matrix = m_last_factor.request.pad_in_matrix;
    ++m_last_factor.refreshes_since;
  } else {
    m_last_factor.usable = true;
    m_last_factor.request = request;
    m_last_factor.pattern = system.stiffness->pattern_revision();
    m_last_factor.rows = system.rows();
    m_last_factor.refreshes_since = 1;
    ++m_stiffness_factorizations;
  }
  if (background) {
    if (new_contact) out.stiffness_n_per_m = element_local_contact_stiffness(m_body.elasticity(), m_surface, triangle);
    // A factorization lands stiffness_latency_steps later; forward solves from the factor, the next step.
    m_pending_latency_steps = condense_only ? 1 : m_settings.stiffness_latency_steps;
    if (condense_only) {
      m_stiffness_refresh.start_condense(from_factor);
    } else {
      m_stiffness_refresh.start(system, request);
    }
    return;
  }
  try {
    out.stiffness_n_per_m = landed_stiffness(condense_only ? condense_factored(m_effective_stiffness, from_factor)
                                                           : condensed_contact_stiffness(m_effective_stiffness, system, request),
                                             triangle);
  } catch (const std::exception&) {
    // Neither matrix could be factorized (non-finite values): render the spring alone, counted.
    ++m_stiffness_fallbacks;
    out.stiffness_n_per_m = Eigen::Matrix3d::Identity() * spring_stiffness_n_per_m();
  }
}

ContactStiffnessRequest ContactModel::stiffness_request_at(const ShiftedSystem& system, int triangle,
                                                           double floor_n_per_m) const {
  const std::array<int, 3>& corners = m_surface.triangles[static_cast<std::size_t>(triangle)];
  const ContactInterpolation point = contact_interpolation(m_body.dofs(), corners, m_contact.proxy().barycentric);
  return contact_stiffness_request(system, m_body.dofs(), point, m_spring.spring(), spring_stiffness_n_per_m(),
                                   floor_n_per_m, m_settings.pad_radius_m > 0.0 ? &m_spring.pad() : nullptr);
}

Eigen::Matrix3d ContactModel::landed_stiffness(const std::optional<Eigen::Matrix3d>& landed, int triangle) {
  if (landed) return *landed;
  m_last_factor.usable = false;  // the next refresh factorizes (and the fallback below loads another matrix)
  // The static K failed where a cut set the contacted piece free (K singular there; issue 10): the
  // step's Newton matrix, now.
  if (!m_body.settings().fixed_vertices.empty()) {
    const ShiftedSystem step = m_integrator.newton_stiffness(m_body, m_step_size_s, m_system_diagonal);
    if (const auto stiffness =
            condensed_contact_stiffness(m_effective_stiffness, step, stiffness_request_at(step, triangle, 0.0))) {
      return *stiffness;
    }
  }
  ++m_stiffness_fallbacks;
  return Eigen::Matrix3d::Identity() * spring_stiffness_n_per_m();
}

void ContactModel::sample_near_surface(const ToolPose& touching, const LazySurfaceBvh& bvh) {
  m_near.reset();
  const double margin_m = m_settings.near_surface_margin_m;
  if (touching.mode != ToolMode::probe || !m_enabled || m_output.active || !(margin_m > 0.0)) return;
  m_near = near_surface(touching.tip_position_m, margin_m, bvh.fitted(), bvh.positions_m(), m_surface,
                        m_body.elasticity(), m_near_hits);
}

Eigen::Matrix3d ContactModel::rendered_stiffness_n_per_m() const {
  const ContactOutput& contact = m_output;
  if (!contact.active) return Eigen::Matrix3d::Zero();
  if (m_contact.sticking()) return contact.stiffness_n_per_m;
  return sliding_contact_stiffness_n_per_m(contact.stiffness_n_per_m, contact.normal);
}

ToolContact ContactModel::tool_contact(const Eigen::Vector3d& ball_offset_m) const {
  const ContactOutput& contact = m_output;
  const bool near = !contact.active && m_near.has_value();
  ToolContact out;
  out.active = contact.active;
  out.near = near;
  out.point_m = (near ? m_near->point_m : contact.point_m) + ball_offset_m;
  out.normal = near ? m_near->normal : contact.normal;
  out.force_on_tool_n = contact.force_on_tool_n;
  out.stiffness_n_per_m = near ? m_near->stiffness_n_per_m : rendered_stiffness_n_per_m();
  out.damping_n_s_per_m = m_stiffness_damping_s * out.stiffness_n_per_m;
  out.penetration_depth_m = contact.penetration_depth_m;
  return out;
}

ContactModel::State ContactModel::state() const {
  State state;
  state.contact = m_contact.state();
  state.output = m_output;
  state.steps_since_stiffness = m_steps_since_stiffness;
  forget_factor();  // a save point, as in a run restored to it
  m_stiffness_refresh.wait();
  if (m_stiffness_refresh.state() == BackgroundContactStiffness::State::done) {
    const std::optional<Eigen::Matrix3d>& result = m_stiffness_refresh.result();
    state.pending_stiffness = result ? State::PendingStiffness::ready : State::PendingStiffness::failed;
    if (result) state.pending_stiffness_n_per_m = *result;
  }
  return state;
}

void ContactModel::check(const State& state) const {
  // A contact is on the mesh's own surface only (probe() releases one on a cut face).
  const PointContact::State& contact = state.contact;
  const auto triangles = static_cast<int>(m_surface.triangles.size());
  if (contact.in_contact && (contact.proxy.triangle < 0 || contact.proxy.triangle >= triangles)) {
    throw StateError("the state's contact is on a triangle the surface does not have");
  }
}

void ContactModel::forget_factor() const {
  m_last_factor.usable = false;
  if (m_settings.stiffness_refactor_refreshes > 1) m_pending_latency_steps = 1;
}

void ContactModel::restore(const State& state) {
  m_contact.restore(state.contact);
  m_output = state.output;
  m_steps_since_stiffness = state.steps_since_stiffness;
  forget_factor();
  switch (state.pending_stiffness) {
    case State::PendingStiffness::none: m_stiffness_refresh.cancel(); break;
    case State::PendingStiffness::failed: m_stiffness_refresh.set_done(std::nullopt); break;
    case State::PendingStiffness::ready: m_stiffness_refresh.set_done(state.pending_stiffness_n_per_m); break;
  }
}

}  // namespace tissue
