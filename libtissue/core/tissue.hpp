// Tissue: the facade of the core, one specimen in one scene, composed of its parts: the body and
// its integrator, the tool's kinematics (ToolKinematics), the scalpel's cut session (CutSession),
// the probe's contact model (ContactModel) and the surfaces at the current state (SurfaceViews).
// Each step takes the tool pose, sweeps the scalpel through the volume cutter and enriches the
// completed tets, or moves the probe's god-object, then integrates and reports the contact outputs
// (docs/DESIGN.md, "One Tissue step"). This is what the benches, the Python module and the Tissue FMU call.
#pragma once

#include "core/contact/contact_model.hpp"
#include "core/contact/point_spring.hpp"
#include "core/cut/cut_session.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/integrate/integrator.hpp"
#include "core/integrate/integrator_factory.hpp"
#include "core/mesh/topology.hpp"
#include "core/render/cut_render_surface.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/state_error.hpp"
#include "core/surface_views.hpp"
#include "core/tool/tool_kinematics.hpp"
#include "core/tool/tool_pose.hpp"

#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace tissue {

struct InteractionSettings {
  bool contact_enabled = true;
  bool cutting_enabled = true;
  double blade_length_m = 0.03;  ///< length of the scalpel's cutting edge, > 0
  CutterSettings cutter;
  ContactSettings contact;
  /// The fastest a hand moves the tool (tip or blade end) [m/s]: a pose farther than this times the
  /// step from the last pose the tissue applied is approached at this speed (docs/DESIGN.md, "One Tissue step").
  double max_tool_speed_m_per_s = 5.0;
  /// Radius of a ball-ended probe [m], >= 0: the probe's pose is its ball's centre, and it touches
  /// with the ball's pole (0: a point tip, the pose is the touching point).
  double probe_radius_m = 0.0;
};

struct TissueSettings {
  BodySettings body;
  IntegratorSettings integrator;  ///< which integrator, and IDA's settings
  SolverSettings solver;          ///< backward Euler's linear solver
  InteractionSettings interaction;
  double step_size_s = 1e-3;
  /// The operating field is the body's rest box grown by this fraction of its largest size on every side: a
  /// part cut free that falls wholly outside it leaves the dynamics (DeformableBody::park_parts_outside).
  double field_margin_fraction = 0.5;
  /// A finer surface of the same shape to draw (issue 22), riding on the tets and cut with them
  /// (Tissue::render_surface()); none: the tet skin only. Not part of the model fingerprint: it does
  /// not change the dynamics.
  std::shared_ptr<const TriangleSurface> render_surface;
};

/// Throws ParameterError for an invalid setting: first any setting outside its schema range
/// (tissue_settings_schema.hpp), then the parts' own checks (material, damping, integrator, solver,
/// cutter); fixed vertices and mesh-dependent settings are checked by DeformableBody.
void validate(const TissueSettings& settings);

/// A hash of the mesh and every setting that changes the dynamics (FNV-1a over the rest positions, the
/// tets, the schema's tissue settings in their order, the regions' materials, the fixed vertices and
/// the core's own settings): a snapshot restores only into a Tissue of the same value.
std::uint64_t model_fingerprint(const TetMesh& mesh, const TissueSettings& settings);

/// What one Tissue step did, with wall times [s].
struct TissueStepReport {
  StepReport dynamics;
  CutStepReport cut;            ///< default (not cutting) unless the scalpel swept
  EnrichmentResult enrichment;  ///< cut tets and enriched unknowns added by this step
  double cut_s = 0.0;           ///< volume cutter
  double enrich_s = 0.0;        ///< enrichment and in-place growth
  double contact_s = 0.0;       ///< god-object update and contact outputs
  double positions_s = 0.0;     ///< the surface's positions (written here while the tool is in use,
                                ///< else by their first read); the BVH's refit waits for the next query
  double total_s = 0.0;
  int parked_rows = 0;  ///< block rows this step took out of the dynamics (parts fallen out of the field)
};

/// Rows taken out of the dynamics (DeformableBody::park_parts_outside) after `after_batch` batches
/// of cuts: what a replay repeats at the same point.
struct ParkedRows {
  int after_batch = 0;
  std::vector<int> rows;
  bool operator==(const ParkedRows&) const = default;
};

/// How many steps apart a Tissue looks for parts that fell out of the operating field.
inline constexpr int PARK_CHECK_STEPS = 10;

/// Everything a Tissue carries from one step to the next, so that a restored instance continues
/// bitwise as the saved one would have (FMI get/set/serialize FMU state). The cuts are kept as the
/// history of enrichments, batch by batch, so that a fresh instance replays the same growth.
struct TissueSnapshot {
  std::uint64_t model_fingerprint = 0;  ///< of the mesh and settings (Tissue::model_fingerprint())
  std::vector<TetCut> cuts;             ///< every enriched cut, in order
  std::vector<int> cut_batch_ends;      ///< after enrichment k, cuts [0, cut_batch_ends[k]) were applied
  std::vector<std::vector<TetPositions>> cut_offsets;  ///< per cut tet made: its pieces' CutPiece::offset_m
  std::vector<ParkedRows> parked;       ///< in order
  int steps_since_park_check = 0;
  DynamicState dynamics;
  DeformableBody::Rotations rotations;
  Eigen::VectorXd integrator_state;
  VolumeCutter::SessionState cutter;
  PointContact::State contact;
  std::optional<PointSpring> point_spring;
  std::vector<PointSpring> pad_springs;  ///< a pad probe's, beside point_spring
  ToolPose tool;
  ToolPose previous_tool;
  Eigen::Vector3d applied_tool_position_m = Eigen::Vector3d::Zero();
  ContactOutput contact_output;
  int steps_since_stiffness = 0;
  /// A K_c refresh started in the background and not yet rendered (ContactModel::State).
  using PendingStiffness = ContactModel::State::PendingStiffness;
  PendingStiffness pending_stiffness = PendingStiffness::none;
  Eigen::Matrix3d pending_stiffness_n_per_m = Eigen::Matrix3d::Zero();
};

class Tissue {
 public:
  /// Throws ParameterError for invalid settings.
  Tissue(TetMesh mesh, TissueSettings settings);
  // The parts hold references into the body and each other: not copyable, not movable.
  Tissue(const Tissue&) = delete;
  Tissue& operator=(const Tissue&) = delete;

  /// The tool pose for the next step, as the hand gives it (a ball probe by its centre): the one
  /// check of a pose (validate) and its one normalization. Throws ParameterError (pose kept) for a
  /// non-finite position or a non-finite or zero quaternion.
  void set_tool(const ToolPose& pose);
  /// The pose as set (normalized).
  [[nodiscard]] const ToolPose& tool() const { return m_tool.pose(); }
  /// The pose that touches the tissue: tool(), with a ball probe's pole for its centre.
  [[nodiscard]] ToolPose touching_pose() const { return m_tool.touching(); }
  /// The touching pose the last step applied: touching_pose() or, after an impossible jump, the pose
  /// on the way to it that the hand's top speed reaches (InteractionSettings::max_tool_speed_m_per_s).
  [[nodiscard]] const ToolPose& applied_tool() const { return m_tool.applied(); }
  /// The tool position the last step applied, in set_tool's terms (a ball probe's centre): the
  /// position set, bitwise, unless the hand's top speed held the tool back.
  [[nodiscard]] const Eigen::Vector3d& applied_tool_position_m() const { return m_tool.applied_position_m(); }
  /// Length of the blade inside the tissue while the scalpel cuts [m] (0 otherwise): from the
  /// handle end of the edge, the first crossing of the mesh's own surface is where it enters.
  [[nodiscard]] double blade_depth_m() const {
    return m_cuts.blade_depth_m(m_tool.pose(), m_surfaces.bvh(), m_surfaces.mesh_triangle_count());
  }

  /// One step of step_size_s: tool interaction (cut or contact), the dynamics step, the contact
  /// outputs. Throws IntegrationError (state unchanged) when the dynamics step fails.
  TissueStepReport step();

  [[nodiscard]] const DeformableBody& body() const { return m_body; }
  /// The body's rest box grown on every side by TissueSettings::field_margin_fraction of its largest size.
  [[nodiscard]] Eigen::AlignedBox3d operating_field() const;
  [[nodiscard]] const DynamicState& state() const { return m_state; }
  [[nodiscard]] const TissueSettings& settings() const { return m_settings; }
  [[nodiscard]] double time_s() const { return m_state.time_s; }
  [[nodiscard]] double kinetic_energy_j() const { return m_body.kinetic_energy_j(m_state.velocity_m_per_s); }
  [[nodiscard]] double elastic_energy_j() { return m_body.elastic_energy_j(m_state.displacement_m); }
  /// Positions of all vertices, 3 per vertex [m].
  void vertex_positions(Eigen::VectorXd& positions_m) const { m_body.positions(m_state.displacement_m, positions_m); }
  /// The positions after the last step, as the BVH is refitted to: the mesh vertices (3 each), then
  /// the corners of the cut faces (cut_surface()).
  [[nodiscard]] const Eigen::VectorXd& current_positions_m() const { return m_surfaces.positions_m(); }
  /// The faces the cuts opened; they are in the surface BVH after the mesh's surface triangles. Its
  /// drawn lists are those of the last read of the drawn surface (for_each_drawn_triangle and its kin).
  [[nodiscard]] const CutSurface& cut_surface() const { return m_surfaces.cut_surface(); }
  /// The surface to draw, with corners indexing current_positions_m(): the mesh's surface without
  /// the triangles of cut tets, their pieces either side of the cut (the skin), then the cut faces.
  /// Made when read (SurfaceViews::for_each_drawn_triangle).
  template <class Visit>
  void for_each_drawn_triangle(Visit&& visit) const {
    m_surfaces.for_each_drawn_triangle(m_body, m_state.displacement_m, std::forward<Visit>(visit));
  }
  /// How many triangles for_each_drawn_triangle() visits.
  [[nodiscard]] std::size_t drawn_triangle_count() const {
    return m_surfaces.drawn_triangle_count(m_body, m_state.displacement_m);
  }
  /// The cut faces for_each_drawn_triangle() visits last.
  [[nodiscard]] const std::vector<std::array<int, 3>>& drawn_cut_triangles() const {
    return m_surfaces.drawn_cut_triangles(m_body, m_state.displacement_m);
  }
  /// Whether the scene draws a render surface (TissueSettings::render_surface) instead of the tet skin.
  [[nodiscard]] bool has_render_surface() const { return m_surfaces.has_render_surface(); }

  [[nodiscard]] const SurfaceMesh& surface() const { return m_surfaces.surface(); }
  /// The render surface (TissueSettings::render_surface) at the current state, re-meshed for the
  /// cuts made since it was last asked for and mapped onto the current positions (both on demand:
  /// a step does not pay for them); nullptr when the scene has none.
  [[nodiscard]] const CutRenderSurface* render_surface() const {
    return m_surfaces.render_surface(m_body, m_state.displacement_m);
  }
  /// Over the surface and the cut faces; empty (no tree) when neither contact nor cutting is on.
  /// Fitted to the current positions (a step leaves the refit to the first query after it).
  [[nodiscard]] const SurfaceBvh& surface_bvh() const { return m_surfaces.bvh().fitted(); }
  /// Throws std::logic_error when cutting is off (no cutter is built then).
  [[nodiscard]] const VolumeCutter& cutter() const { return m_cuts.cutter(); }
  [[nodiscard]] bool has_cutter() const { return m_cuts.enabled(); }
  [[nodiscard]] const PointContact& point_contact() const { return m_contact.point_contact(); }
  /// The contact's spring, a force term of the body while the probe touches.
  [[nodiscard]] const PointSpringTerm& contact_spring() const { return m_contact_spring; }
  /// The contact outputs of the last step, at the contact point.
  [[nodiscard]] const ContactOutput& contact() const { return m_contact.output(); }
  /// The complete contact output a haptic loop renders, in set_tool's terms (a ball probe's centre):
  /// in contact or near the surface (InteractionSettings::contact.near_surface_margin_m), with the
  /// damping D_c = beta K_c.
  [[nodiscard]] ToolContact tool_contact() const {
    return m_contact.tool_contact(m_tool.touching_offset_m());
  }
  /// A hash of the mesh and every setting: a snapshot restores only into a Tissue of the same value.
  [[nodiscard]] std::uint64_t model_fingerprint() const { return m_model_fingerprint; }
  /// Saves the state. A save point is a restart point of the linear solver (its lagged factor is
  /// dropped, as at a restore), so that the run after it and a run restored to it continue alike.
  void save(TissueSnapshot& snapshot);
  /// True when the snapshot's cuts are exactly the cuts made here, so restore() works in place.
  [[nodiscard]] bool has_cuts_of(const TissueSnapshot& snapshot) const;
  /// True when restore() can take the snapshot here: it has the same cuts, or nothing was cut here
  /// yet (the snapshot's cuts are replayed). Cuts cannot be undone: otherwise use a fresh Tissue.
  [[nodiscard]] bool can_restore(const TissueSnapshot& snapshot) const {
    return (m_cuts.batch_ends().empty() && m_parked.empty()) || has_cuts_of(snapshot);
  }
  /// Restores a snapshot of this model: in place when has_cuts_of(snapshot), by replaying the cuts
  /// when nothing was cut here yet (a fresh instance). Throws StateError unless can_restore(), or
  /// when the snapshot is of another model or inconsistent (a displacement or velocity beyond
  /// +-MAX_ABS_COORDINATE [m, m/s] included); the instance is then unchanged, except
  /// when the replay of cuts into a fresh instance fails (discard it).
  void restore(const TissueSnapshot& snapshot);

  /// How many times K_c fell back to the spring alone (no matrix could be condensed).
  [[nodiscard]] int contact_stiffness_fallbacks() const { return m_contact.stiffness_fallbacks(); }
  /// How many times K_c's matrix was factorized (InteractionSettings::contact.stiffness_refactor_refreshes).
  [[nodiscard]] int contact_stiffness_factorizations() const { return m_contact.stiffness_factorizations(); }
  /// The integrator of the settings (backward Euler or IDA).
  [[nodiscard]] const Integrator& integrator() const { return *m_integrator; }
  /// The spring stiffness the contact uses (resolved from the settings) [N/m].
  [[nodiscard]] double contact_spring_stiffness_n_per_m() const { return m_contact.spring_stiffness_n_per_m(); }

 private:
  /// Enriches one batch of cuts, grows the state, adds the opened faces to the surfaces: live
  /// (offsets empty: taken from the state) or replayed from a snapshot (its recorded offsets).
  EnrichmentResult apply_cuts(std::span<const TetCut> cuts, std::span<const std::vector<TetPositions>> offsets_m);
  /// apply_cuts as the cut session calls it (a live sweep or a replay).
  [[nodiscard]] ApplyCuts cut_applier() {
    return [this](std::span<const TetCut> cuts, std::span<const std::vector<TetPositions>> offsets_m) {
      return apply_cuts(cuts, offsets_m);
    };
  }
  /// Replays a snapshot's cuts batch by batch, and its parked rows where they were parked.
  void replay(const TissueSnapshot& snapshot);
  /// Per cut tet, its pieces' offsets (what a replay needs besides the cuts).
  [[nodiscard]] std::vector<std::vector<TetPositions>> cut_offsets() const;
  /// Every PARK_CHECK_STEPS steps of a cut body: parts fallen out of the operating field leave the
  /// dynamics (recorded for a replay). Returns the rows parked.
  int park_fallen_parts();
  /// The near-surface report of the pose set, at the current positions (the tissue's sample).
  void sample_near_surface() { m_contact.sample_near_surface(m_tool.touching(), m_surfaces.bvh()); }

  TissueSettings m_settings;
  PointSpringTerm m_contact_spring;  // attached to m_body for its lifetime
  DeformableBody m_body;
  std::unique_ptr<Integrator> m_integrator;
  DynamicState m_state;
  SurfaceViews m_surfaces;
  ToolKinematics m_tool;
  CutSession m_cuts;
  ContactModel m_contact;
  std::vector<ParkedRows> m_parked;
  int m_steps_since_park_check = 0;
  std::uint64_t m_model_fingerprint = 0;
};

/// Restores `snapshot` into `tissue`: in place when it can (Tissue::can_restore), else into a fresh
/// Tissue of the same mesh and settings that replays the snapshot's cuts (cuts are not undone in
/// place), which replaces `tissue` once it holds the snapshot. Throws StateError, `tissue` unchanged.
void restore_or_replay(std::unique_ptr<Tissue>& tissue, const TissueSnapshot& snapshot);

}  // namespace tissue
