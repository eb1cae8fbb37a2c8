// The Tissue facade.
#include "core/tissue.hpp"

#include "core/tissue_settings_schema.hpp"

#include <algorithm>
#include <array>
#include <Eigen/Eigenvalues>

#include <chrono>
#include <cmath>
#include <string>

namespace tissue {

namespace {

TissueSettings checked(TissueSettings settings) {
  validate(settings);
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

// CHOLMOD may factorize a singular K through rounding; the point of a free piece then comes out with
// a K_c at rounding level. Held points of the frog measure 0.0017 to 14 times the contact scale
// (contact_stiffness.hpp): below 1e-6 of it, a static K_c belongs to a piece nothing holds.
constexpr double FREE_PIECE_STIFFNESS_FRACTION = 1e-6;

double free_piece_floor_n_per_m(double contact_stiffness_scale_n_per_m) {
  return FREE_PIECE_STIFFNESS_FRACTION * contact_stiffness_scale_n_per_m;
}

// The largest turn of the blade one cutter sweep covers (its two triangles span the ruled surface
// of a turning segment to within ~ L (1 - cos(angle / 2)), 0.1 mm for a 3 cm blade at 5 degrees).
constexpr double MAX_SWEEP_ANGLE_RAD = 5.0 * 3.14159265358979323846 / 180.0;

bool same_cut(const TetCut& a, const TetCut& b) {
  return a.tet == b.tet && a.cut_id == b.cut_id && a.side == b.side &&
         a.volume_fraction_above == b.volume_fraction_above && a.edge_ratio == b.edge_ratio &&
         a.min_volume_fraction == b.min_volume_fraction;
}

PointContactSettings contact_settings(const TissueSettings& settings, const DeformableBody& body,
                                      const SurfaceMesh& surface, const Integrator& integrator) {
  PointContactSettings contact;
  const double stiffness = settings.interaction.contact_spring_stiffness_n_per_m;
  contact.spring_stiffness_n_per_m =
      stiffness > 0.0 ? stiffness : recommended_contact_spring_stiffness_n_per_m(body, surface);
  // A surface that sags or swings onto a probe held still touches it (issue 10), up to half a mean
  // surface edge deep: deeper, the tool was put inside, and snapping it out would kick the tissue.
  contact.passed_over_depth_m = 0.5 * mean_surface_edge_m(body, surface);
  // The spring stands for the rigid tool: the step must not damp it (issue 9).
  contact.spring_tangent_fraction =
      integrator.undamped_tangent_share(settings.step_size_s, settings.body.damping.stiffness_damping_s);
  return contact;
}

}  // namespace

ToolMode parse_tool_mode(std::string_view name) {
  if (const auto mode = tool_mode_named(name)) return *mode;
  throw ParameterError("unknown tool mode '" + std::string(name) + "' (expected none, probe or scalpel)");
}

void validate(const TissueSettings& settings) {
  check_setting_ranges(settings);  // the schema's ranges (tissue_settings_schema.hpp), named as users set them
  validate(settings.body.material);
  validate(settings.body.damping);
  validate(settings.integrator);
  validate(settings.solver);
  validate(settings.interaction.cutter);
}

Tissue::Tissue(TetMesh mesh, TissueSettings settings)
    : m_settings(checked(std::move(settings))),
      m_body(std::move(mesh), m_settings.body),
      m_integrator(make_integrator(m_settings.integrator, m_settings.solver)),
      m_surface(extract_surface(m_body.mesh())),
      // Only what the scene requires (DESIGN section 1): the edge adjacency and the cutter only with
      // cutting, the surface BVH only with contact or cutting.
      m_vertex_positions_m(rest_positions(m_body)),
      m_positions_m(m_vertex_positions_m),
      m_cut_surface(m_body.mesh().vertex_count()),
      m_bvh(m_settings.interaction.cutting_enabled || m_settings.interaction.contact_enabled
                ? m_surface.triangles
                : std::vector<std::array<int, 3>>{},
            m_positions_m),
      m_contact(contact_settings(m_settings, m_body, m_surface, *m_integrator)),
      m_contact_stiffness_scale_n_per_m(contact_stiffness_scale_n_per_m(m_body, m_surface)),
      m_model_fingerprint(tissue::model_fingerprint(m_body.mesh(), m_settings)) {
  m_state.displacement_m.setZero(m_body.dof_count());
  m_state.velocity_m_per_s.setZero(m_body.dof_count());
  m_body.attach(m_contact_spring);
  if (m_settings.interaction.cutting_enabled) {
    m_cutter.emplace(m_body.mesh(), m_body.adjacency(), m_surface, m_settings.interaction.cutter);
  }
  if (m_settings.render_surface) {
    try {
      m_render = std::make_unique<CutRenderSurface>(m_body.mesh(), *m_settings.render_surface,
                                                    default_max_outside_m(m_body.mesh()),
                                                    m_settings.render_surface->source_name);
    } catch (const MeshError& error) {
      throw ParameterError(error.what());
    }
  }
}

const CutRenderSurface* Tissue::render_surface() const {
  if (!m_render) return nullptr;
  if (m_render_cut_tets != m_body.cut_tets().size()) {
    m_render->rebuild(m_body);
    m_render_cut_tets = m_body.cut_tets().size();
    m_render_mapped = false;
  }
  if (!m_render_mapped) {
    m_render->update(m_body, m_state.displacement_m);
    m_render_mapped = true;
  }
  return m_render.get();
}

const VolumeCutter& Tissue::cutter() const {
  if (!m_cutter) throw std::logic_error("Tissue::cutter: cutting is off in this scene (no cutter was built)");
  return *m_cutter;
}

void validate(const ToolPose& pose) {
  if (!pose.tip_position_m.allFinite()) throw ParameterError("tool position must be finite");
  const double norm = pose.orientation.coeffs().norm();
  if (!std::isfinite(norm) || !(norm > MIN_ORIENTATION_NORM)) {
    throw ParameterError("tool orientation must be a finite, non-zero quaternion");
  }
}

void Tissue::set_tool(const ToolPose& pose) {
  validate(pose);
  m_tool = pose;
  m_tool.orientation.normalize();
  if (!m_stepped) m_applied_tool_position_m = m_tool.tip_position_m;  // nothing held it back yet
}

ToolPose Tissue::touching_pose() const {
  ToolPose touching = m_tool;
  const double radius_m = m_settings.interaction.probe_radius_m;
  if (touching.mode == ToolMode::probe && radius_m > 0.0) {
    touching.tip_position_m -= radius_m * tool_axis(touching.orientation);
  }
  return touching;
}

double Tissue::blade_depth_m() const {
  if (m_tool.mode != ToolMode::scalpel || !m_cutter || !m_cutter->cutting()) return 0.0;
  // The edge runs from the tip along the tool axis; from the handle end (outside while a cut
  // starts), the first crossing of the mesh's own surface is where the blade enters the tissue.
  const double length_m = m_settings.interaction.blade_length_m;
  const Eigen::Vector3d handle_m = m_tool.tip_position_m + length_m * tool_axis(m_tool.orientation);
  fitted_bvh().intersect_segment(handle_m, m_tool.tip_position_m, m_positions_m, m_blade_hits);
  const auto mesh_triangles = static_cast<int>(m_surface.triangles.size());
  for (const SurfaceBvh::SegmentHit& hit : m_blade_hits) {
    if (hit.triangle < mesh_triangles) return (1.0 - hit.segment_parameter) * length_m;
  }
  return length_m;  // no crossing while cutting: the whole edge is inside
}

Blade Tissue::blade(const ToolPose& pose) const {
  return Blade{pose.tip_position_m, pose.tip_position_m + m_settings.interaction.blade_length_m * tool_axis(pose.orientation)};
}

ToolPose reachable_pose(const ToolPose& previous, const ToolPose& target, double blade_length_m, double max_step_m) {
  // Only a tool that interacts in both poses is held to the hand's speed; a mode switch or a tool
  // that does nothing goes where it is put.
  if (target.mode != previous.mode || target.mode == ToolMode::none || !(max_step_m > 0.0)) return target;
  // With the position moved linearly and the orientation along the shorter arc, no point of the
  // blade travels farther than |tip move| + L * turn angle: the fraction f of the way keeps every
  // point's path, and so its chord, within f times that.
  const double path_m = (target.tip_position_m - previous.tip_position_m).norm() +
                        blade_length_m * previous.orientation.angularDistance(target.orientation);
  if (!(path_m > max_step_m)) return target;
  const double fraction = max_step_m / path_m;
  ToolPose reached = target;
  reached.tip_position_m = previous.tip_position_m + fraction * (target.tip_position_m - previous.tip_position_m);
  reached.orientation = previous.orientation.slerp(fraction, target.orientation).normalized();
  return reached;
}

int sweep_substeps(const ToolPose& from, const ToolPose& to) {
  const double angle_rad = from.orientation.angularDistance(to.orientation);
  return std::max(1, static_cast<int>(std::ceil(angle_rad / MAX_SWEEP_ANGLE_RAD)));
}

void Tissue::interact_with_scalpel(const ToolPose& previous, const ToolPose& current, TissueStepReport& report) {
  // The blade sweeps two triangles per cutter step; a turning blade's surface is curved, so the
  // step is cut in sub-sweeps of at most MAX_SWEEP_ANGLE_RAD, along the path the tool took.
  const int substeps = sweep_substeps(previous, current);
  ToolPose from = previous;
  for (int k = 1; k <= substeps; ++k) {
    const double fraction = static_cast<double>(k) / substeps;
    ToolPose to = current;
    if (k < substeps) {
      to.tip_position_m = previous.tip_position_m + fraction * (current.tip_position_m - previous.tip_position_m);
      to.orientation = previous.orientation.slerp(fraction, current.orientation).normalized();
    }
    const auto cut_start = std::chrono::steady_clock::now();
    const CutStepReport cut = m_cutter->step(blade(from), blade(to), m_positions_m, fitted_bvh());
    const int newly_cut = report.cut.newly_cut_tets + cut.newly_cut_tets;
    report.cut = cut;
    report.cut.newly_cut_tets = newly_cut;
    report.cut_s += seconds_since(cut_start);
    from = to;
    if (m_cutter->new_cuts().empty()) continue;
    const auto enrich_start = std::chrono::steady_clock::now();
    const EnrichmentResult enriched = apply_cuts(m_cutter->new_cuts());
    report.enrichment.new_cut_tets += enriched.new_cut_tets;
    report.enrichment.new_enriched_dofs += enriched.new_enriched_dofs;
    report.enrichment.matrix_relayout = report.enrichment.matrix_relayout || enriched.matrix_relayout;
    report.enrich_s += seconds_since(enrich_start);
  }
}

EnrichmentResult Tissue::apply_cuts(std::span<const TetCut> cuts,
                                    std::span<const std::vector<TetPositions>> recorded_offsets_m) {
  const int first_new = static_cast<int>(m_body.cut_tets().size());
  EnrichmentResult result;
  if (recorded_offsets_m.empty()) {
    result = m_body.enrich(cuts, m_state);
  } else {
    result = m_body.enrich(cuts, recorded_offsets_m);
    m_body.grow_state(m_state);  // the snapshot's state replaces it after the replay
  }
  m_integrator->restart(Restart::system_grown);
  m_cut_history.insert(m_cut_history.end(), cuts.begin(), cuts.end());
  m_cut_batch_ends.push_back(static_cast<int>(m_cut_history.size()));
  // The opened faces join the surface (at the current state: both parts still coincide).
  const int new_faces = m_cut_surface.add_cut_tets(m_body, first_new, m_surface);
  update_positions();
  const auto& faces = m_cut_surface.triangles();
  m_bvh.add_triangles(std::span(faces).last(static_cast<size_t>(new_faces)), m_positions_m);
  return result;
}

void Tissue::save(TissueSnapshot& snapshot) const {
  snapshot.model_fingerprint = m_model_fingerprint;
  snapshot.cuts = m_cut_history;
  snapshot.cut_batch_ends = m_cut_batch_ends;
  snapshot.cut_offsets = cut_offsets();
  snapshot.dynamics = m_state;
  m_body.save_rotations(snapshot.rotations);
  snapshot.integrator_state = m_integrator->internal_state();
  if (m_cutter) m_cutter->save(snapshot.cutter);
  snapshot.contact = m_contact.state();
  snapshot.point_spring = m_contact_spring.spring();
  snapshot.tool = m_tool;
  snapshot.previous_tool = m_previous_tool;
  snapshot.applied_tool_position_m = m_applied_tool_position_m;
  snapshot.contact_output = m_contact_output;
  snapshot.steps_since_stiffness = m_steps_since_stiffness;
  m_stiffness_refresh.wait();
  using Pending = TissueSnapshot::PendingStiffness;
  snapshot.pending_stiffness = Pending::none;
  snapshot.pending_stiffness_n_per_m.setZero();
  if (m_stiffness_refresh.state() == BackgroundContactStiffness::State::done) {
    const std::optional<Eigen::Matrix3d>& result = m_stiffness_refresh.result();
    snapshot.pending_stiffness = result ? Pending::ready : Pending::failed;
    if (result) snapshot.pending_stiffness_n_per_m = *result;
  }
}

std::vector<std::vector<TetPositions>> Tissue::cut_offsets() const {
  std::vector<std::vector<TetPositions>> offsets(m_body.cut_tets().size());
  for (size_t k = 0; k < offsets.size(); ++k) {
    for (size_t p = 0; p < m_body.xfem().piece_count(static_cast<int>(k)); ++p) {
      offsets[k].push_back(m_body.xfem().piece(static_cast<int>(k), static_cast<int>(p)).offset_m);
    }
  }
  return offsets;
}

bool Tissue::has_cuts_of(const TissueSnapshot& snapshot) const {
  return snapshot.cut_batch_ends == m_cut_batch_ends && snapshot.cuts.size() == m_cut_history.size() &&
         std::equal(snapshot.cuts.begin(), snapshot.cuts.end(), m_cut_history.begin(), same_cut) &&
         snapshot.cut_offsets == cut_offsets();
}

void Tissue::restore(const TissueSnapshot& snapshot) {
  if (snapshot.model_fingerprint != m_model_fingerprint) {
    throw StateError("the state was saved from another model (the mesh or a parameter differs)");
  }
  int previous_end = 0;
  for (const int end : snapshot.cut_batch_ends) {
    if (end <= previous_end) throw StateError("the state's cut batches are not increasing");
    previous_end = end;
  }
  if (static_cast<size_t>(previous_end) != snapshot.cuts.size()) {
    throw StateError("the state's cut batches do not add up to its cuts");
  }
  if (!can_restore(snapshot)) {
    throw StateError("the state has other cuts than this instance; restore it into a fresh instance");
  }
  if (!has_cuts_of(snapshot)) {
    try {
      // A batch makes a cut tet per cut and may remake others (their pieces' ghosts regrouped): it
      // takes the offsets of as many cut tets as it made.
      int begin = 0;
      size_t offsets_used = 0;
      const std::span<const std::vector<TetPositions>> offsets(snapshot.cut_offsets);
      for (const int end : snapshot.cut_batch_ends) {
        const auto first = static_cast<size_t>(begin);
        const auto count = static_cast<size_t>(end - begin);
        if (offsets_used + count > offsets.size()) throw StateError("the state has too few enrichment offsets");
        const EnrichmentResult made = apply_cuts(std::span(snapshot.cuts).subspan(first, count), offsets.subspan(offsets_used));
        offsets_used += static_cast<size_t>(made.new_cut_tets);
        begin = end;
      }
      if (offsets_used != offsets.size()) throw StateError("the state has more enrichment offsets than cut tets");
    } catch (const std::invalid_argument& error) {
      throw StateError(std::string("the state's cuts cannot be replayed: ") + error.what());
    }
  }
  // Check everything before changing anything.
  const Eigen::Index dofs = m_body.dof_count();
  const DynamicState& dynamics = snapshot.dynamics;
  if (dynamics.displacement_m.size() != dofs || dynamics.velocity_m_per_s.size() != dofs) {
    throw StateError("the state has " + std::to_string(dynamics.displacement_m.size()) + " unknowns, the model " +
                     std::to_string(dofs));
  }
  if (!dynamics.displacement_m.allFinite() || !dynamics.velocity_m_per_s.allFinite() ||
      !std::isfinite(dynamics.time_s)) {
    throw StateError("the state holds a non-finite displacement, velocity or time");
  }
  if (!snapshot.applied_tool_position_m.allFinite()) throw StateError("the state's applied tool position is not finite");
  const DeformableBody::Rotations& rotations = snapshot.rotations;
  const size_t tets = static_cast<size_t>(m_body.mesh().tet_count());
  if (rotations.tets.size() != tets || rotations.tet_warm_starts.size() != tets ||
      rotations.pieces.size() != m_body.xfem().piece_rotations().size() ||
      rotations.piece_warm_starts.size() != m_body.xfem().piece_warm_starts().size()) {
    throw StateError("the state's rotations do not match the mesh and its cuts");
  }
  const PointContact::State& contact = snapshot.contact;
  if (contact.in_contact && (contact.proxy.triangle < 0 || contact.proxy.triangle >= m_bvh.triangle_count())) {
    throw StateError("the state's contact is on a triangle the surface does not have");
  }
  const std::optional<PointSpring> old_spring = m_contact_spring.spring();
  try {
    m_contact_spring.set(snapshot.point_spring, m_body.term_layout());
    if (m_cutter) m_cutter->restore(snapshot.cutter);
  } catch (const std::invalid_argument& error) {
    m_contact_spring.set(old_spring, m_body.term_layout());
    throw StateError(std::string("the state is inconsistent: ") + error.what());
  }
  m_body.restore_rotations(rotations);
  m_state = dynamics;
  m_integrator->restore_internal_state(snapshot.integrator_state);
  m_integrator->restart(Restart::state_restored);
  m_contact.restore(contact);
  m_tool = snapshot.tool;
  m_previous_tool = snapshot.previous_tool;
  m_applied_tool_position_m = snapshot.applied_tool_position_m;
  m_stepped = true;  // the snapshot's applied position stands until the next step
  m_contact_output = snapshot.contact_output;
  m_steps_since_stiffness = snapshot.steps_since_stiffness;
  switch (snapshot.pending_stiffness) {
    case TissueSnapshot::PendingStiffness::none: m_stiffness_refresh.cancel(); break;
    case TissueSnapshot::PendingStiffness::failed: m_stiffness_refresh.set_done(std::nullopt); break;
    case TissueSnapshot::PendingStiffness::ready: m_stiffness_refresh.set_done(snapshot.pending_stiffness_n_per_m); break;
  }
  update_positions();
  m_bvh_stale = true;  // refitted by the first query (fitted_bvh)
}

void Tissue::interact_with_probe(const ToolPose& previous, const ToolPose& current) {
  const bool was_in_contact = m_contact.in_contact();
  // How far the pressed surface rises to a tool drawn back (PointContact::update): the last step's
  // normal force over its normal contact stiffness.
  const ContactOutput& last = m_contact_output;
  const double pressed_n = last.active ? last.force_on_tool_n.dot(last.normal) : 0.0;
  const double normal_stiffness_n_per_m = last.normal.dot(last.stiffness_n_per_m * last.normal);
  const double follow_distance_m =
      pressed_n > 0.0 && normal_stiffness_n_per_m > 0.0 ? pressed_n / normal_stiffness_n_per_m : 0.0;
  m_contact.update(previous.tip_position_m, current.tip_position_m, m_positions_m, fitted_bvh(), follow_distance_m);
  // The probe touches the mesh's surface only: a cut face's corners are not vertices the spring can
  // act on (they move with the enriched unknowns), so a probe reaching into a crack feels nothing.
  if (m_contact.in_contact() && m_contact.proxy().triangle >= static_cast<int>(m_surface.triangles.size())) {
    m_contact.release();
  }
  m_contact.apply(m_bvh, m_contact_spring, m_body.term_layout());
  if (m_contact.in_contact() && !was_in_contact) m_steps_since_stiffness = -1;  // a new contact: refresh K_c
  if (m_contact.in_contact() != was_in_contact) m_integrator->restart(Restart::contact_changed);
}

void Tissue::update_contact_output() {
  ContactOutput& out = m_contact_output;
  if (!m_contact.in_contact()) {
    m_stiffness_refresh.cancel();
    out = ContactOutput{};
    return;
  }
  out.active = true;
  const SurfaceBvh& bvh = fitted_bvh();
  out.point_m = surface_point_position_m(m_contact.proxy(), bvh.triangles(), m_positions_m);
  out.normal = m_contact.normal();
  out.force_on_tool_n = m_contact.force_on_tool_n(bvh, m_positions_m);
  out.penetration_depth_m = (m_previous_tool.tip_position_m - out.point_m).norm();

  const int triangle = m_contact.proxy().triangle;
  const InteractionSettings& interaction = m_settings.interaction;
  if (interaction.contact_stiffness_model == ContactStiffnessModel::element_local) {
    out.stiffness_n_per_m = element_local_contact_stiffness(m_body.elasticity(), m_surface, triangle);
    return;
  }
  // A refresh started in the background at the last step is rendered from this step on.
  if (m_stiffness_refresh.state() != BackgroundContactStiffness::State::idle) {
    out.stiffness_n_per_m = landed_contact_stiffness(m_stiffness_refresh.take(), triangle);
  }
  const bool new_contact = m_steps_since_stiffness < 0;
  if (!new_contact && m_steps_since_stiffness < interaction.contact_stiffness_refresh_steps) {
    ++m_steps_since_stiffness;
    return;
  }
  m_steps_since_stiffness = 1;
  // DESIGN section 4: K_c from the static K where the body is held, from the step's Newton matrix
  // (asked of the integrator) where nothing holds it; the contact spring taken out of either
  // (contact_stiffness.hpp); a point on fixed vertices only is a rigid support: the spring alone.
  const bool held = !m_body.settings().fixed_vertices.empty();
  const ShiftedSystem system = held ? static_contact_system(m_body.tangent(), m_contact_system_diagonal)
                                    : m_integrator->newton_stiffness(m_body, m_settings.step_size_s,
                                                                     m_contact_system_diagonal);
  const ContactStiffnessRequest request = contact_stiffness_request_at(
      system, triangle, held ? free_piece_floor_n_per_m(m_contact_stiffness_scale_n_per_m) : 0.0);
  if (interaction.contact_stiffness_in_background) {
    if (new_contact) out.stiffness_n_per_m = element_local_contact_stiffness(m_body.elasticity(), m_surface, triangle);
    m_stiffness_refresh.start(system, request);
    return;
  }
  try {
    out.stiffness_n_per_m =
        landed_contact_stiffness(condensed_contact_stiffness(m_effective_stiffness, system, request), triangle);
  } catch (const std::exception&) {
    // Neither matrix could be factorized (non-finite values): render the spring alone, counted.
    ++m_contact_stiffness_fallbacks;
    out.stiffness_n_per_m = Eigen::Matrix3d::Identity() * contact_spring_stiffness_n_per_m();
  }
}

ContactStiffnessRequest Tissue::contact_stiffness_request_at(const ShiftedSystem& system, int triangle,
                                                              double floor_n_per_m) const {
  const ContactInterpolation point =
      contact_interpolation(m_body.dofs(), m_bvh.triangle(triangle), m_contact.proxy().barycentric);
  return contact_stiffness_request(system, m_body.dofs(), point, m_contact_spring.spring(),
                                   contact_spring_stiffness_n_per_m(), floor_n_per_m);
}

Eigen::Matrix3d Tissue::landed_contact_stiffness(const std::optional<Eigen::Matrix3d>& landed, int triangle) {
  if (landed) return *landed;
  // The static K failed where a cut set the contacted piece free (K singular there; issue 10): the
  // step's Newton matrix, now.
  if (!m_body.settings().fixed_vertices.empty()) {
    const ShiftedSystem step =
        m_integrator->newton_stiffness(m_body, m_settings.step_size_s, m_contact_system_diagonal);
    if (const auto stiffness = condensed_contact_stiffness(m_effective_stiffness, step,
                                                           contact_stiffness_request_at(step, triangle, 0.0))) {
      return *stiffness;
    }
  }
  ++m_contact_stiffness_fallbacks;
  return Eigen::Matrix3d::Identity() * contact_spring_stiffness_n_per_m();
}

void Tissue::update_positions() {
  m_render_mapped = false;
  m_body.positions(m_state.displacement_m, m_vertex_positions_m);
  m_positions_m.head(m_vertex_positions_m.size()) = m_vertex_positions_m;
  m_cut_surface.update_points(m_body, m_state.displacement_m, m_positions_m);
}

TissueStepReport Tissue::step() {
  const auto start = std::chrono::steady_clock::now();
  TissueStepReport report;
  const ToolPose previous = m_previous_tool;
  const InteractionSettings& interaction = m_settings.interaction;
  // DESIGN section 7: a pose farther than a hand can move in one step is approached at the hand's
  // top speed; the tool catches up with it over the next steps.
  const ToolPose target = touching_pose();
  const ToolPose current = reachable_pose(previous, target, interaction.blade_length_m,
                                          interaction.max_tool_speed_m_per_s * m_settings.step_size_s);

  // Collide and cut (DESIGN section 3): the blade's sweep since the last step.
  const bool scalpel = current.mode == ToolMode::scalpel && interaction.cutting_enabled;
  if (scalpel && previous.mode == ToolMode::scalpel) {
    interact_with_scalpel(previous, current, report);
  } else if (m_cutter && m_cutter->cutting()) {
    m_cutter->end_cut();
  }

  const auto contact_start = std::chrono::steady_clock::now();
  const bool probe = current.mode == ToolMode::probe && interaction.contact_enabled;
  if (probe) {
    interact_with_probe(previous.mode == ToolMode::probe ? previous : current, current);
  } else if (m_contact.in_contact() || m_contact_spring.spring()) {
    m_contact.release();
    m_contact_spring.set(std::nullopt, m_body.term_layout());
    m_integrator->restart(Restart::contact_changed);
  }
  report.contact_s = seconds_since(contact_start);

  report.dynamics = m_integrator->step(m_body, m_state, m_settings.step_size_s);
  m_previous_tool = current;
  m_stepped = true;
  // Only a tool that keeps its mode and does something is ever held back (reachable_pose); then the
  // applied pose differs from the target, else the position is the one set, bitwise.
  const bool held_back = target.mode != ToolMode::none && current.mode == target.mode &&
                         (current.tip_position_m != target.tip_position_m ||
                          current.orientation.coeffs() != target.orientation.coeffs());
  m_applied_tool_position_m = m_tool.tip_position_m;
  if (held_back) {
    m_applied_tool_position_m = current.tip_position_m;
    const double radius_m = interaction.probe_radius_m;
    if (current.mode == ToolMode::probe && radius_m > 0.0) {
      m_applied_tool_position_m += radius_m * tool_axis(current.orientation);
    }
  }

  const auto positions_start = std::chrono::steady_clock::now();
  update_positions();
  m_bvh_stale = true;  // refitted by the first query that needs it (fitted_bvh)
  report.positions_s = seconds_since(positions_start);

  const auto output_start = std::chrono::steady_clock::now();
  update_contact_output();
  report.contact_s += seconds_since(output_start);
  report.total_s = seconds_since(start);
  return report;
}

void restore_or_replay(std::unique_ptr<Tissue>& tissue, const TissueSnapshot& snapshot) {
  if (tissue->can_restore(snapshot)) {
    tissue->restore(snapshot);
    return;
  }
  // Cuts cannot be undone in place: a fresh Tissue replays the snapshot's.
  auto fresh = std::make_unique<Tissue>(tissue->body().mesh(), tissue->settings());
  fresh->restore(snapshot);
  tissue = std::move(fresh);
}

}  // namespace tissue
