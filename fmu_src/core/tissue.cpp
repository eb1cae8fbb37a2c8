// The Tissue facade.
#include "core/tissue.hpp"

#include "core/integrate/backward_euler.hpp"

#include <chrono>
#include <cmath>
#include <string>

namespace tissue {

LinearSolverKind parse_linear_solver_kind(std::string_view name) {
  if (name == "pcg") return LinearSolverKind::pcg;
  if (name == "cholmod") return LinearSolverKind::cholmod;
  throw ParameterError("unknown linear solver '" + std::string(name) + "' (expected pcg or cholmod)");
}

void validate(const SolverSettings& settings) {
  if (!(settings.pcg.tolerance > 0.0) || !std::isfinite(settings.pcg.tolerance)) {
    throw ParameterError("PCG tolerance must be finite and > 0, got " + std::to_string(settings.pcg.tolerance));
  }
  if (settings.pcg.max_iterations < 1) {
    throw ParameterError("PCG max iterations must be >= 1, got " + std::to_string(settings.pcg.max_iterations));
  }
}

std::unique_ptr<LinearSolver> make_linear_solver(const SolverSettings& settings) {
  validate(settings);
  switch (settings.kind) {
    case LinearSolverKind::pcg:
      return std::make_unique<PcgSolver>(settings.pcg);
    case LinearSolverKind::cholmod:
      return std::make_unique<CholmodSolver>();
  }
  throw ParameterError("unknown linear solver kind");
}

namespace {

TissueSettings checked(TissueSettings settings) {
  if (!(settings.step_size_s > 0.0) || !std::isfinite(settings.step_size_s)) {
    throw ParameterError("step size must be finite and > 0 s, got " + std::to_string(settings.step_size_s));
  }
  validate(settings.solver);
  validate(settings.interaction);
  return settings;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Eigen::VectorXd rest_positions(const DeformableBody& body) {
  Eigen::VectorXd positions_m;
  body.positions(Eigen::VectorXd::Zero(body.dof_count()), positions_m);
  return positions_m;
}

PointContactSettings contact_settings(const InteractionSettings& settings, const DeformableBody& body,
                                      const SurfaceMesh& surface) {
  PointContactSettings contact;
  contact.spring_stiffness_n_per_m = settings.contact_spring_stiffness_n_per_m > 0.0
                                         ? settings.contact_spring_stiffness_n_per_m
                                         : recommended_contact_spring_stiffness_n_per_m(body, surface);
  return contact;
}

}  // namespace

ToolMode parse_tool_mode(std::string_view name) {
  if (name == "none") return ToolMode::none;
  if (name == "probe") return ToolMode::probe;
  if (name == "scalpel") return ToolMode::scalpel;
  throw ParameterError("unknown tool mode '" + std::string(name) + "' (expected none, probe or scalpel)");
}

void validate(const InteractionSettings& settings) {
  if (!(settings.blade_length_m > 0.0) || !std::isfinite(settings.blade_length_m)) {
    throw ParameterError("blade length must be finite and > 0 m, got " + std::to_string(settings.blade_length_m));
  }
  if (!(settings.contact_spring_stiffness_n_per_m >= 0.0) ||
      !std::isfinite(settings.contact_spring_stiffness_n_per_m)) {
    throw ParameterError("contact spring stiffness must be finite and >= 0 N/m (0: automatic), got " +
                         std::to_string(settings.contact_spring_stiffness_n_per_m));
  }
  if (settings.contact_stiffness_refresh_steps < 1) {
    throw ParameterError("contact stiffness refresh must be >= 1 step, got " +
                         std::to_string(settings.contact_stiffness_refresh_steps));
  }
  const CutterSettings& cutter = settings.cutter;
  if (!(cutter.min_volume_fraction > 0.0 && cutter.min_volume_fraction < 0.5)) {
    throw ParameterError("minimum volume fraction must be in (0, 0.5), got " +
                         std::to_string(cutter.min_volume_fraction));
  }
  if (!(cutter.vertex_snap_fraction >= 0.0 && cutter.vertex_snap_fraction < 0.5)) {
    throw ParameterError("vertex snap fraction must be in [0, 0.5), got " +
                         std::to_string(cutter.vertex_snap_fraction));
  }
}

Tissue::Tissue(TetMesh mesh, TissueSettings settings)
    : m_settings(checked(std::move(settings))),
      m_body(std::move(mesh), m_settings.body),
      m_integrator(std::make_unique<BackwardEuler>(make_linear_solver(m_settings.solver),
                                                   BackwardEuler::Settings{m_settings.solver.warm_start})),
      m_surface(extract_surface(m_body.mesh())),
      m_adjacency(build_adjacency(m_body.mesh())),
      m_vertex_positions_m(rest_positions(m_body)),
      m_positions_m(m_vertex_positions_m),
      m_cut_surface(m_body.mesh().vertex_count()),
      m_bvh(m_surface.triangles, m_positions_m),
      m_cutter(m_body.mesh(), m_adjacency, m_surface, m_settings.interaction.cutter),
      m_contact(contact_settings(m_settings.interaction, m_body, m_surface)) {
  m_state.displacement_m.setZero(m_body.dof_count());
  m_state.velocity_m_per_s.setZero(m_body.dof_count());
}

void Tissue::set_tool(const ToolPose& pose) {
  if (!pose.tip_position_m.allFinite()) throw ParameterError("tool position must be finite");
  const double norm = pose.orientation.coeffs().norm();
  if (!std::isfinite(norm) || !(norm > 1e-12))
    throw ParameterError("tool orientation must be a finite, non-zero quaternion");
  m_tool = pose;
  m_tool.orientation.normalize();
}

Blade Tissue::blade(const ToolPose& pose) const {
  return Blade{pose.tip_position_m, pose.tip_position_m + m_settings.interaction.blade_length_m *
                                                              (pose.orientation * Eigen::Vector3d::UnitZ())};
}

void Tissue::interact_with_scalpel(const ToolPose& previous, TissueStepReport& report) {
  const auto cut_start = std::chrono::steady_clock::now();
  report.cut = m_cutter.step(blade(previous), blade(m_tool), m_positions_m, m_bvh);
  report.cut_s = seconds_since(cut_start);
  if (m_cutter.new_cuts().empty()) return;
  const auto enrich_start = std::chrono::steady_clock::now();
  const int first_new = static_cast<int>(m_body.cut_tets().size());
  report.enrichment = m_body.enrich(m_cutter.new_cuts());
  m_body.grow_state(m_state);
  // The opened faces join the surface (at the current state: both parts still coincide).
  const int new_faces = m_cut_surface.add_cut_tets(m_body, first_new);
  update_positions();
  const auto& faces = m_cut_surface.triangles();
  m_bvh.add_triangles(std::span(faces).last(static_cast<size_t>(new_faces)), m_positions_m);
  report.enrich_s = seconds_since(enrich_start);
}

void Tissue::interact_with_probe(const ToolPose& previous) {
  const bool was_in_contact = m_contact.in_contact();
  m_contact.update(previous.tip_position_m, m_tool.tip_position_m, m_positions_m, m_bvh);
  // The probe touches the mesh's surface only: a cut face's corners are not vertices the spring can
  // act on (they move with the enriched unknowns), so a probe reaching into a crack feels nothing.
  if (m_contact.in_contact() && m_contact.proxy().triangle >= static_cast<int>(m_surface.triangles.size())) {
    m_contact.release();
  }
  m_contact.apply(m_bvh, m_body);
  if (m_contact.in_contact() && !was_in_contact) m_steps_since_stiffness = -1;  // a new contact: refresh K_c
}

void Tissue::update_contact_output() {
  ContactOutput& out = m_contact_output;
  if (!m_contact.in_contact()) {
    out = ContactOutput{};
    return;
  }
  out.active = true;
  out.point_m = surface_point_position_m(m_contact.proxy(), m_bvh.triangles(), m_positions_m);
  out.normal = m_contact.normal();
  out.force_on_tool_n = m_contact.force_on_tool_n(m_bvh, m_positions_m);
  out.penetration_depth_m = (m_tool.tip_position_m - out.point_m).norm();

  const int triangle = m_contact.proxy().triangle;
  if (m_settings.interaction.contact_stiffness_model == ContactStiffnessModel::element_local) {
    out.stiffness_n_per_m = element_local_contact_stiffness(m_body.elasticity(), m_surface, triangle);
    return;
  }
  if (m_steps_since_stiffness >= 0 &&
      m_steps_since_stiffness < m_settings.interaction.contact_stiffness_refresh_steps) {
    ++m_steps_since_stiffness;
    return;
  }
  m_steps_since_stiffness = 1;
  // The tangent of this step holds the contact spring; take it out exactly (Sherman-Morrison).
  const bool has_fixed = !m_body.settings().fixed_vertices.empty();
  const ShiftedSystem system = has_fixed
                                   ? static_contact_system(m_body.tangent(), m_contact_system_diagonal)
                                   : step_contact_system(m_body, m_settings.step_size_s, m_contact_system_diagonal);
  m_effective_stiffness.factorize(system);
  const std::array<int, 3>& vertices = m_bvh.triangle(triangle);
  const ContactInterpolation point = contact_interpolation(m_body.dofs(), vertices, m_contact.proxy().barycentric);
  const std::optional<PointSpring>& spring = m_body.point_spring();
  std::optional<Eigen::Matrix3d> stiffness;
  if (spring) {
    stiffness = m_effective_stiffness.stiffness_n_per_m(
        point, contact_interpolation(m_body.dofs(), spring->vertices, spring->weights), spring->stiffness_n_per_m);
  } else {
    stiffness = m_effective_stiffness.stiffness_n_per_m(point);
  }
  // A point on fixed vertices only is a rigid support: report the spring alone.
  out.stiffness_n_per_m = stiffness ? *stiffness : Eigen::Matrix3d::Identity() * contact_spring_stiffness_n_per_m();
}

void Tissue::update_positions() {
  m_body.positions(m_state.displacement_m, m_vertex_positions_m);
  m_positions_m.head(m_vertex_positions_m.size()) = m_vertex_positions_m;
  m_cut_surface.update_points(m_body, m_state.displacement_m, m_positions_m);
}

TissueStepReport Tissue::step() {
  const auto start = std::chrono::steady_clock::now();
  TissueStepReport report;
  const ToolPose previous = m_previous_tool;
  const InteractionSettings& interaction = m_settings.interaction;

  // Collide and cut (DESIGN section 3): the blade's sweep since the last step.
  const bool scalpel = m_tool.mode == ToolMode::scalpel && interaction.cutting_enabled;
  if (scalpel && previous.mode == ToolMode::scalpel) {
    interact_with_scalpel(previous, report);
  } else if (m_cutter.cutting()) {
    m_cutter.end_cut();
  }

  const auto contact_start = std::chrono::steady_clock::now();
  const bool probe = m_tool.mode == ToolMode::probe && interaction.contact_enabled;
  if (probe) {
    interact_with_probe(previous.mode == ToolMode::probe ? previous : m_tool);
  } else if (m_contact.in_contact() || m_body.point_spring()) {
    m_contact.release();
    m_body.set_point_spring(std::nullopt);
  }
  report.contact_s = seconds_since(contact_start);

  report.dynamics = m_integrator->step(m_body, m_state, m_settings.step_size_s);
  m_previous_tool = m_tool;

  const auto refit_start = std::chrono::steady_clock::now();
  update_positions();
  m_bvh.refit(m_positions_m);
  report.refit_s = seconds_since(refit_start);

  const auto output_start = std::chrono::steady_clock::now();
  update_contact_output();
  report.contact_s += seconds_since(output_start);
  report.total_s = seconds_since(start);
  return report;
}

}  // namespace tissue
