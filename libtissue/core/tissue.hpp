// Tissue: the facade of the core, one specimen in one scene. Owns the body, the integrator, the
// state and the tool interaction (DESIGN section 3): each step takes the tool pose, sweeps the
// scalpel through the volume cutter and enriches the completed tets, or updates the probe's
// god-object contact, then integrates, refits the surface BVH and reports the contact outputs.
// This is what the demo, tissue-bench and (issue 4) the FMU layer call.
#pragma once

#include "core/collide/surface_bvh.hpp"
#include "core/contact/background_contact_stiffness.hpp"
#include "core/contact/contact_stiffness.hpp"
#include "core/contact/point_contact.hpp"
#include "core/contact/point_spring.hpp"
#include "core/cut/cut_surface.hpp"
#include "core/render/cut_render_surface.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/integrate/integrator.hpp"
#include "core/integrate/integrator_factory.hpp"
#include "core/mesh/topology.hpp"
#include "core/solve/linear_solver.hpp"
#include "ports/tool.hpp"

#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace tissue {

/// Parses "none" / "probe" / "scalpel"; throws ParameterError otherwise.
ToolMode parse_tool_mode(std::string_view name);

/// The tool as the host drives it. The tool axis is the local +z axis, from the tip toward the
/// handle; the scalpel's cutting edge is the segment from the tip along that axis.
/// A ball-ended probe (InteractionSettings::probe_radius_m > 0) is posed by its ball's centre and
/// touches the tissue with the ball's pole along the axis, toward the tip (Tissue::touching_pose).
struct ToolPose {
  Eigen::Vector3d tip_position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  ToolMode mode = ToolMode::none;
};

/// Throws ParameterError for a non-finite position or a non-finite or zero quaternion.
void validate(const ToolPose& pose);

/// The tool axis (local +z, from the tip toward the handle) of a unit quaternion (ports/tool.hpp).
inline Eigen::Vector3d tool_axis(const Eigen::Quaterniond& orientation) {
  const auto axis = tissue::tool_axis(orientation.w(), orientation.x(), orientation.y(), orientation.z());
  return {axis[0], axis[1], axis[2]};
}

/// The pose a tool reaches from `previous` toward `target` when no point of its blade (blade_length_m
/// along the axis from the tip) may travel more than max_step_m: `target` itself when it is within
/// reach, when the mode changes or when the tool does nothing; otherwise the fraction of the way
/// (position linear, orientation along the shorter arc) whose path bound |tip move| + L angle is
/// max_step_m.
ToolPose reachable_pose(const ToolPose& previous, const ToolPose& target, double blade_length_m, double max_step_m);

struct InteractionSettings {
  bool contact_enabled = true;
  bool cutting_enabled = true;
  double blade_length_m = 0.03;  ///< length of the scalpel's cutting edge, > 0
  CutterSettings cutter;
  /// Stiffness of the implicit spring from the god-object's material point to the probe tip;
  /// 0 chooses recommended_contact_spring_stiffness_n_per_m() (100 x the body's contact scale).
  double contact_spring_stiffness_n_per_m = 0.0;
  ContactStiffnessModel contact_stiffness_model = ContactStiffnessModel::effective_static;
  /// The effective (reference) K_c costs a factorization: it is recomputed when a contact starts and
  /// then every this many steps (>= 1); the elementLocal model is recomputed every step.
  int contact_stiffness_refresh_steps = 10;
  /// The effective K_c's factorization runs in a worker thread beside the step
  /// (background_contact_stiffness.hpp) instead of in it: a refresh started at a step is rendered
  /// from the next step on, the previous K_c standing until then; at a new contact, the elementLocal
  /// estimate (the one the near-surface report gave) stands for that first step. The results are
  /// the same with or without a thread to be had. Off: no thread unless asked (the FMU's rule).
  bool contact_stiffness_in_background = false;
  /// The fastest a hand moves the tool (tip or blade end) [m/s]: a pose farther than this times the
  /// step from the last pose the tissue applied is approached at this speed (DESIGN section 7).
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

/// The contact outputs of the last step (the haptic loop's input).
struct ContactOutput {
  bool active = false;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< the god-object (proxy) position
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();   ///< unit outward surface normal there
  Eigen::Vector3d force_on_tool_n = Eigen::Vector3d::Zero();
  Eigen::Matrix3d stiffness_n_per_m = Eigen::Matrix3d::Zero();  ///< K_c (model from the settings)
  double penetration_depth_m = 0.0;                             ///< |tip - proxy|
};

/// What one Tissue step did, with wall times [s].
struct TissueStepReport {
  StepReport dynamics;
  CutStepReport cut;            ///< default (not cutting) unless the scalpel swept
  EnrichmentResult enrichment;  ///< cut tets and enriched unknowns added by this step
  double cut_s = 0.0;           ///< volume cutter
  double enrich_s = 0.0;        ///< enrichment and in-place growth
  double contact_s = 0.0;       ///< god-object update and contact outputs
  double positions_s = 0.0;     ///< positions after the step (the BVH refit waits for the next query)
  double total_s = 0.0;
};

/// A saved state that cannot be restored here (another model, a malformed or inconsistent state).
class StateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Everything a Tissue carries from one step to the next, so that a restored instance continues
/// bitwise as the saved one would have (FMI get/set/serialize FMU state). The cuts are kept as the
/// history of enrichments, batch by batch, so that a fresh instance replays the same growth.
struct TissueSnapshot {
  std::uint64_t model_fingerprint = 0;  ///< of the mesh and settings (Tissue::model_fingerprint())
  std::vector<TetCut> cuts;             ///< every enriched cut, in order
  std::vector<int> cut_batch_ends;      ///< after enrichment k, cuts [0, cut_batch_ends[k]) were applied
  std::vector<std::vector<TetPositions>> cut_offsets;  ///< per cut tet made: its pieces' CutPiece::offset_m
  DynamicState dynamics;
  DeformableBody::Rotations rotations;
  Eigen::VectorXd integrator_state;
  VolumeCutter::SessionState cutter;
  PointContact::State contact;
  std::optional<PointSpring> point_spring;
  ToolPose tool;
  ToolPose previous_tool;
  Eigen::Vector3d applied_tool_position_m = Eigen::Vector3d::Zero();
  ContactOutput contact_output;
  int steps_since_stiffness = 0;
  /// A K_c refresh started in the background and not yet rendered (Tissue::update_contact_output):
  /// none, done without a result (the fallbacks follow), or done with `pending_stiffness_n_per_m`.
  enum class PendingStiffness : std::uint8_t { none, failed, ready };
  PendingStiffness pending_stiffness = PendingStiffness::none;
  Eigen::Matrix3d pending_stiffness_n_per_m = Eigen::Matrix3d::Zero();
};

class Tissue {
 public:
  /// Throws ParameterError for invalid settings.
  Tissue(TetMesh mesh, TissueSettings settings);
  // The cutter and the BVH hold references into the body: not copyable, not movable.
  Tissue(const Tissue&) = delete;
  Tissue& operator=(const Tissue&) = delete;

  /// The tool pose for the next step, as the hand gives it (a ball probe by its centre): the one
  /// check of a pose (validate) and its one normalization. Throws ParameterError (pose kept) for a
  /// non-finite position or a non-finite or zero quaternion.
  void set_tool(const ToolPose& pose);
  /// The pose as set (normalized).
  [[nodiscard]] const ToolPose& tool() const { return m_tool; }
  /// The pose that touches the tissue: tool(), with a ball probe's pole for its centre.
  [[nodiscard]] ToolPose touching_pose() const;
  /// The touching pose the last step applied: touching_pose() or, after an impossible jump, the pose
  /// on the way to it that the hand's top speed reaches (InteractionSettings::max_tool_speed_m_per_s).
  [[nodiscard]] const ToolPose& applied_tool() const { return m_previous_tool; }
  /// The tool position the last step applied, in set_tool's terms (a ball probe's centre): the
  /// position set, bitwise, unless the hand's top speed held the tool back.
  [[nodiscard]] const Eigen::Vector3d& applied_tool_position_m() const { return m_applied_tool_position_m; }
  /// Length of the blade inside the tissue while the scalpel cuts [m] (0 otherwise): from the
  /// handle end of the edge, the first crossing of the mesh's own surface is where it enters.
  [[nodiscard]] double blade_depth_m() const;

  /// One step of step_size_s: tool interaction (cut or contact), backward Euler, BVH refit,
  /// contact outputs. Throws IntegrationError (state unchanged) when the dynamics step fails.
  TissueStepReport step();

  [[nodiscard]] const DeformableBody& body() const { return m_body; }
  [[nodiscard]] const DynamicState& state() const { return m_state; }
  [[nodiscard]] const TissueSettings& settings() const { return m_settings; }
  [[nodiscard]] double time_s() const { return m_state.time_s; }
  [[nodiscard]] double kinetic_energy_j() const { return m_body.kinetic_energy_j(m_state.velocity_m_per_s); }
  [[nodiscard]] double elastic_energy_j() { return m_body.elastic_energy_j(m_state.displacement_m); }
  /// Positions of all vertices, 3 per vertex [m].
  void vertex_positions(Eigen::VectorXd& positions_m) const { m_body.positions(m_state.displacement_m, positions_m); }
  /// The positions after the last step, as the BVH is refitted to: the mesh vertices (3 each), then
  /// the corners of the cut faces (cut_surface()).
  [[nodiscard]] const Eigen::VectorXd& current_positions_m() const { return m_positions_m; }
  /// The faces the cuts opened; they are in the surface BVH after the mesh's surface triangles.
  [[nodiscard]] const CutSurface& cut_surface() const { return m_cut_surface; }
  /// The surface to draw, with corners indexing current_positions_m(): the mesh's surface without
  /// the triangles of cut tets, their pieces either side of the cut (the skin), then the cut faces.
  template <class Visit>
  void for_each_drawn_triangle(Visit&& visit) const;
  /// How many triangles for_each_drawn_triangle() visits.
  [[nodiscard]] std::size_t drawn_triangle_count() const {
    return m_surface.triangles.size() - m_cut_surface.replaced_triangles().size() +
           m_cut_surface.skin_triangles().size() + m_cut_surface.drawn_triangles().size();
  }

  [[nodiscard]] const SurfaceMesh& surface() const { return m_surface; }
  /// The render surface (TissueSettings::render_surface) at the current state, re-meshed for the
  /// cuts made since it was last asked for and mapped onto the current positions (both on demand:
  /// a step does not pay for them); nullptr when the scene has none.
  [[nodiscard]] const CutRenderSurface* render_surface() const;
  /// Over the surface and the cut faces; empty (no tree) when neither contact nor cutting is on.
  /// Fitted to the current positions (a step leaves the refit to the first query after it).
  [[nodiscard]] const SurfaceBvh& surface_bvh() const { return fitted_bvh(); }
  /// Throws std::logic_error when cutting is off (no cutter is built then).
  [[nodiscard]] const VolumeCutter& cutter() const;
  [[nodiscard]] bool has_cutter() const { return m_cutter.has_value(); }
  [[nodiscard]] const PointContact& point_contact() const { return m_contact; }
  /// The contact's spring, a force term of the body while the probe touches.
  [[nodiscard]] const PointSpringTerm& contact_spring() const { return m_contact_spring; }
  [[nodiscard]] const ContactOutput& contact() const { return m_contact_output; }
  /// A hash of the mesh and every setting: a snapshot restores only into a Tissue of the same value.
  [[nodiscard]] std::uint64_t model_fingerprint() const { return m_model_fingerprint; }
  void save(TissueSnapshot& snapshot) const;
  /// True when the snapshot's cuts are exactly the cuts made here, so restore() works in place.
  [[nodiscard]] bool has_cuts_of(const TissueSnapshot& snapshot) const;
  /// True when restore() can take the snapshot here: it has the same cuts, or nothing was cut here
  /// yet (the snapshot's cuts are replayed). Cuts cannot be undone: otherwise use a fresh Tissue.
  [[nodiscard]] bool can_restore(const TissueSnapshot& snapshot) const {
    return m_cut_batch_ends.empty() || has_cuts_of(snapshot);
  }
  /// Restores a snapshot of this model: in place when has_cuts_of(snapshot), by replaying the cuts
  /// when nothing was cut here yet (a fresh instance). Throws StateError unless can_restore(), or
  /// when the snapshot is of another model or inconsistent; the instance is then unchanged, except
  /// when the replay of cuts into a fresh instance fails (discard it).
  void restore(const TissueSnapshot& snapshot);

  /// How many times K_c fell back to the spring alone (no matrix could be condensed).
  [[nodiscard]] int contact_stiffness_fallbacks() const { return m_contact_stiffness_fallbacks; }
  /// The integrator of the settings (backward Euler or IDA).
  [[nodiscard]] const Integrator& integrator() const { return *m_integrator; }

  /// The spring stiffness the contact uses (resolved from the settings) [N/m].
  [[nodiscard]] double contact_spring_stiffness_n_per_m() const {
    return m_contact.settings().spring_stiffness_n_per_m;
  }

 private:
  void interact_with_scalpel(const ToolPose& previous, const ToolPose& current, TissueStepReport& report);
  void interact_with_probe(const ToolPose& previous, const ToolPose& current);
  void update_contact_output();
  /// What K_c at the proxy on `triangle` needs besides `system`'s factor (the point, the spring).
  [[nodiscard]] ContactStiffnessRequest contact_stiffness_request_at(const ShiftedSystem& system, int triangle,
                                                                     double floor_n_per_m) const;
  /// The K_c a condensation gave (in this step or in the background), or its fallbacks computed now:
  /// the step's Newton matrix where the static K failed, else the spring alone (counted).
  Eigen::Matrix3d landed_contact_stiffness(const std::optional<Eigen::Matrix3d>& landed, int triangle);
  void update_positions();
  /// Enriches `cuts` (one batch), grows the state, adds the opened faces to the surface and the BVH.
  // Live (offsets empty: taken from the state) or replayed from a snapshot (its recorded offsets).
  EnrichmentResult apply_cuts(std::span<const TetCut> cuts,
                              std::span<const std::vector<TetPositions>> recorded_offsets_m = {});
  // Per cut tet, its pieces' offsets (what a replay needs besides the cuts).
  [[nodiscard]] std::vector<std::vector<TetPositions>> cut_offsets() const;
  [[nodiscard]] Blade blade(const ToolPose& pose) const;

  TissueSettings m_settings;
  PointSpringTerm m_contact_spring;  // attached to m_body for its lifetime
  DeformableBody m_body;
  std::unique_ptr<Integrator> m_integrator;
  DynamicState m_state;
  SurfaceMesh m_surface;
  Eigen::VectorXd m_vertex_positions_m;
  Eigen::VectorXd m_positions_m;
  CutSurface m_cut_surface;
  // The tree's boxes are refitted when a query needs them, not after every step: a step with no
  // tool near the tissue leaves them stale (the bridge: ~0.15 ms of a 2.8 ms step).
  [[nodiscard]] const SurfaceBvh& fitted_bvh() const {
    if (m_bvh_stale) {
      m_bvh.refit(m_positions_m);
      m_bvh_stale = false;
    }
    return m_bvh;
  }
  mutable SurfaceBvh m_bvh;
  mutable bool m_bvh_stale = false;
  std::optional<VolumeCutter> m_cutter;  // only with cutting enabled
  PointContact m_contact;
  double m_contact_stiffness_scale_n_per_m = 0.0;  ///< contact_stiffness_scale_n_per_m of the body
  EffectiveContactStiffness m_effective_stiffness;
  Eigen::VectorXd m_contact_system_diagonal;
  int m_steps_since_stiffness = 0;
  mutable BackgroundContactStiffness m_stiffness_refresh;  // save() waits for a running one
  int m_contact_stiffness_fallbacks = 0;
  ContactOutput m_contact_output;
  ToolPose m_tool;
  ToolPose m_previous_tool;
  Eigen::Vector3d m_applied_tool_position_m = Eigen::Vector3d::Zero();
  bool m_stepped = false;  // a step (or a restore) has set m_applied_tool_position_m
  mutable std::vector<SurfaceBvh::SegmentHit> m_blade_hits;  // scratch of blade_depth_m()
  std::uint64_t m_model_fingerprint = 0;
  std::vector<TetCut> m_cut_history;
  std::vector<int> m_cut_batch_ends;
  // The render surface, brought up to date by render_surface() (re-meshed when the cut tets changed,
  // mapped when the state changed).
  mutable std::unique_ptr<CutRenderSurface> m_render;
  mutable std::optional<std::size_t> m_render_cut_tets;  // the cut tets it was meshed for (none: not yet)
  mutable bool m_render_mapped = false;
};

/// Restores `snapshot` into `tissue`: in place when it can (Tissue::can_restore), else into a fresh
/// Tissue of the same mesh and settings that replays the snapshot's cuts (cuts are not undone in
/// place), which replaces `tissue` once it holds the snapshot. Throws StateError, `tissue` unchanged.
void restore_or_replay(std::unique_ptr<Tissue>& tissue, const TissueSnapshot& snapshot);

template <class Visit>
void Tissue::for_each_drawn_triangle(Visit&& visit) const {
  const std::vector<int>& replaced = m_cut_surface.replaced_triangles();  // ascending
  auto next_replaced = replaced.begin();
  for (std::size_t t = 0; t < m_surface.triangles.size(); ++t) {
    if (next_replaced != replaced.end() && *next_replaced == static_cast<int>(t)) {
      ++next_replaced;
      continue;
    }
    visit(m_surface.triangles[t]);
  }
  for (const auto& triangle : m_cut_surface.skin_triangles()) visit(triangle);
  for (const auto& triangle : m_cut_surface.drawn_triangles()) visit(triangle);
}

}  // namespace tissue
