// The Tissue facade: its parts composed, one step as a short list of calls, and its saved state.
#include "core/tissue.hpp"

#include "core/mesh/mesh_io.hpp"
#include "core/tissue_settings_schema.hpp"
#include "core/wall_clock.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace tissue {

namespace {

TissueSettings checked(TissueSettings settings) {
  validate(settings);
  return settings;
}

}  // namespace

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
      // Only what the scene requires: the surface BVH only with contact or cutting, the edge
      // adjacency and the cutter only with cutting.
      m_surfaces(m_body, m_settings.interaction.cutting_enabled || m_settings.interaction.contact_enabled,
                 m_settings.render_surface.get()),
      m_tool(m_settings.interaction.probe_radius_m, m_settings.interaction.blade_length_m,
             m_settings.interaction.max_tool_speed_m_per_s * m_settings.step_size_s),
      m_cuts(m_settings.interaction.cutting_enabled, m_body.mesh(),
             m_body.adjacency(), m_surfaces.surface(),
             m_settings.interaction.cutter, m_settings.interaction.blade_length_m),
      m_contact(m_settings.interaction.contact, m_settings.interaction.contact_enabled, m_settings.step_size_s,
                m_settings.body.damping.stiffness_damping_s, m_body, *m_integrator, m_contact_spring,
                m_surfaces.surface()),
      m_model_fingerprint(tissue::model_fingerprint(m_body.mesh(), m_settings)) {
  m_state.displacement_m.setZero(m_body.dof_count());
  m_state.velocity_m_per_s.setZero(m_body.dof_count());
  m_body.attach(m_contact_spring);
}

void Tissue::set_tool(const ToolPose& pose) {
  m_tool.set(pose);
  if (!m_tool.stepped()) sample_near_surface();  // the sample before the first step is of the pose set
}

TissueStepReport Tissue::step() {
  const auto start = std::chrono::steady_clock::now();
  TissueStepReport report;
  const InteractionSettings& interaction = m_settings.interaction;
  const ToolKinematics::Move move = m_tool.next_move();
  const ToolPose& previous = move.previous;
  const ToolPose& current = move.current;

  // Cut: the blade's sweep since the last step, the tets it completed enriched; when the scalpel
  // stops cutting, the stroke ends where the blade is.
  const bool cutting = current.mode == ToolMode::scalpel && interaction.cutting_enabled && previous.mode == ToolMode::scalpel;
  const CutSweepReport sweep = cutting ? m_cuts.sweep(previous, current, m_surfaces.bvh(), cut_applier())
                                       : m_cuts.stop(m_surfaces.bvh(), cut_applier());
  report.cut = sweep.cut;
  report.enrichment = sweep.enrichment;
  report.cut_s = sweep.cut_s;
  report.enrich_s = sweep.enrich_s;

  // Touch: the probe's god-object and spring.
  const auto contact_start = std::chrono::steady_clock::now();
  if (current.mode == ToolMode::probe && interaction.contact_enabled) {
    const ToolPose& from = previous.mode == ToolMode::probe ? previous : current;
    m_contact.probe(from.tip_position_m, current.tip_position_m, m_surfaces.bvh(), tool_axis(current.orientation));
  } else {
    m_contact.withdraw();
  }
  report.contact_s = seconds_since(contact_start);

  // Integrate; the tool's move stands once the step did.
  try {
    report.dynamics = m_integrator->step(m_body, m_state, m_settings.step_size_s);
  } catch (...) {
    sample_near_surface();
    throw;
  }
  m_tool.apply(move);
  report.parked_rows = park_fallen_parts();

  // The surface's positions: written now while the tool works the tissue (a probe's outputs below
  // and the next sweep of a scalpel read them anyway; written later, they ran beside a Tissue FMU's
  // surface job that the host's next step then waited for), else when first read.
  const auto positions_start = std::chrono::steady_clock::now();
  m_surfaces.update_positions(m_body, m_state.displacement_m);
  m_surfaces.moved();
  if (m_tool.applied().mode != ToolMode::none) (void)m_surfaces.positions_m();
  report.positions_s = seconds_since(positions_start);

  // Report: the contact outputs at the new positions, and the surface near a probe not touching.
  const auto output_start = std::chrono::steady_clock::now();
  m_contact.update_output(m_surfaces.bvh(), m_tool.applied().tip_position_m);
  sample_near_surface();
  report.contact_s += seconds_since(output_start);
  report.total_s = seconds_since(start);
  return report;
}

Eigen::AlignedBox3d Tissue::operating_field() const {
  Eigen::AlignedBox3d rest;
  for (const Eigen::Vector3d& x : m_body.mesh().rest_positions_m) rest.extend(x);
  // The same margin on every side (of the largest size): a thin body's field is not thin.
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(m_settings.field_margin_fraction * rest.sizes().maxCoeff());
  return {rest.min() - margin, rest.max() + margin};
}

int Tissue::park_fallen_parts() {
  if (m_body.cut_tet_count() == 0 || ++m_steps_since_park_check < PARK_CHECK_STEPS) return 0;
  m_steps_since_park_check = 0;
  std::vector<int> rows = m_body.park_parts_outside(operating_field(), m_state);
  if (rows.empty()) return 0;
  m_integrator->restart(Restart::system_grown);  // velocities set, blocks dropped
  m_surfaces.take_out_parked(m_body);
  const int count = static_cast<int>(rows.size());
  m_parked.push_back({static_cast<int>(m_cuts.batch_ends().size()), std::move(rows)});
  return count;
}

EnrichmentResult Tissue::apply_cuts(std::span<const TetCut> cuts,
                                    std::span<const std::vector<TetPositions>> offsets_m) {
  const int first_new = static_cast<int>(m_body.cut_tets().size());
  EnrichmentResult result;
  if (offsets_m.empty()) {
    result = m_body.enrich(cuts, m_state);
  } else {
    result = m_body.enrich(cuts, offsets_m);
    m_body.grow_state(m_state);  // the snapshot's state replaces it after the replay
  }
  m_integrator->restart(Restart::system_grown);
  m_surfaces.add_cut_tets(m_body, m_state.displacement_m, first_new);
  return result;
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

void Tissue::save(TissueSnapshot& snapshot) {
  // A save point is a restart point: the integrator's solver forgets its lagged factor here as the
  // restore does, so that the run after the save and the run after a restore continue alike.
  m_integrator->restart(Restart::state_saved);
  snapshot.model_fingerprint = m_model_fingerprint;
  snapshot.cuts = m_cuts.history();
  snapshot.cut_batch_ends = m_cuts.batch_ends();
  snapshot.cut_offsets = cut_offsets();
  snapshot.parked = m_parked;
  snapshot.steps_since_park_check = m_steps_since_park_check;
  snapshot.dynamics = m_state;
  m_body.save_rotations(snapshot.rotations);
  snapshot.integrator_state = m_integrator->internal_state();
  m_cuts.save(snapshot.cutter);
  snapshot.point_spring = m_contact_spring.spring();
  snapshot.pad_springs = m_contact_spring.pad();
  const ToolKinematics::State tool = m_tool.state();
  snapshot.tool = tool.tool;
  snapshot.previous_tool = tool.applied;
  snapshot.applied_tool_position_m = tool.applied_position_m;
  const ContactModel::State contact = m_contact.state();
  snapshot.contact = contact.contact;
  snapshot.contact_output = contact.output;
  snapshot.steps_since_stiffness = contact.steps_since_stiffness;
  snapshot.pending_stiffness = contact.pending_stiffness;
  snapshot.pending_stiffness_n_per_m = contact.pending_stiffness_n_per_m;
}

bool Tissue::has_cuts_of(const TissueSnapshot& snapshot) const {
  return m_cuts.has_history(snapshot.cuts, snapshot.cut_batch_ends) && snapshot.cut_offsets == cut_offsets() &&
         snapshot.parked == m_parked;
}

void Tissue::replay(const TissueSnapshot& snapshot) {
  const std::vector<ParkedRows>& parked = snapshot.parked;
  for (size_t k = 0; k < parked.size(); ++k) {
    if (parked[k].after_batch < 1 || parked[k].after_batch > static_cast<int>(snapshot.cut_batch_ends.size()) ||
        (k > 0 && parked[k].after_batch < parked[k - 1].after_batch)) {
      throw StateError("the state's parked parts do not follow its cuts");
    }
  }
  size_t next = 0;
  const ApplyCuts apply = [&](std::span<const TetCut> cuts, std::span<const std::vector<TetPositions>> offsets_m) {
    const EnrichmentResult made = apply_cuts(cuts, offsets_m);
    const int batches = static_cast<int>(m_cuts.batch_ends().size()) + 1;  // this one is recorded after
    for (; next < parked.size() && parked[next].after_batch == batches; ++next) {
      m_body.park_rows(parked[next].rows);  // std::invalid_argument: the replay's StateError
      m_surfaces.take_out_parked(m_body);
      m_parked.push_back(parked[next]);
    }
    return made;
  };
  m_cuts.replay(snapshot.cuts, snapshot.cut_batch_ends, snapshot.cut_offsets, apply);
}

void Tissue::restore(const TissueSnapshot& snapshot) {
  if (snapshot.model_fingerprint != m_model_fingerprint) {
    throw StateError("the state was saved from another model (the mesh or a parameter differs)");
  }
  CutSession::check_history(snapshot.cuts, snapshot.cut_batch_ends);
  if (!can_restore(snapshot)) {
    throw StateError("the state has other cuts than this instance; restore it into a fresh instance");
  }
  if (snapshot.steps_since_park_check < 0 || snapshot.steps_since_park_check >= PARK_CHECK_STEPS) {
    throw StateError("the state's steps since the last look for fallen parts are out of range");
  }
  if (!has_cuts_of(snapshot)) replay(snapshot);
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
  // Bounded as mesh coordinates are: beyond, the elements' deformation overflows (found by fuzzing).
  if (dynamics.displacement_m.cwiseAbs().maxCoeff() > MAX_ABS_COORDINATE ||
      dynamics.velocity_m_per_s.cwiseAbs().maxCoeff() > MAX_ABS_COORDINATE) {
    throw StateError("the state holds a displacement beyond +-1e6 m or a velocity beyond +-1e6 m/s "
                     "(MAX_ABS_COORDINATE)");
  }
  const ToolKinematics::State tool{snapshot.tool, snapshot.previous_tool, snapshot.applied_tool_position_m};
  ToolKinematics::check(tool);
  const DeformableBody::Rotations& rotations = snapshot.rotations;
  try {
    m_body.check_rotations(rotations);
  } catch (const std::invalid_argument& error) {
    throw StateError(std::string("the state's rotations do not fit: ") + error.what());
  }
  const ContactModel::State contact{snapshot.contact, snapshot.contact_output, snapshot.steps_since_stiffness,
                                    snapshot.pending_stiffness, snapshot.pending_stiffness_n_per_m};
  m_contact.check(contact);
  const std::optional<PointSpring> old_spring = m_contact_spring.spring();
  const std::vector<PointSpring> old_pad = m_contact_spring.pad();
  try {
    m_contact_spring.set(snapshot.point_spring, m_body.term_layout(), snapshot.pad_springs);
    m_cuts.restore(snapshot.cutter);
  } catch (const std::invalid_argument& error) {
    m_contact_spring.set(old_spring, m_body.term_layout(), old_pad);
    throw StateError(std::string("the state is inconsistent: ") + error.what());
  }
  m_body.restore_rotations(rotations);
  m_state = dynamics;
  m_steps_since_park_check = snapshot.steps_since_park_check;
  m_integrator->restore_internal_state(snapshot.integrator_state);
  m_integrator->restart(Restart::state_restored);
  m_tool.restore(tool);
  m_contact.restore(contact);
  m_surfaces.update_positions(m_body, m_state.displacement_m);
  m_surfaces.moved();  // refitted by the first query
  sample_near_surface();
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
