// ContactModel: the probe's contact as the tissue renders it and reports it. Each step the probe's
// god-object follows the tool over the surface and its spring acts on the body (probe, withdraw);
// after the dynamics step the model reports the complete contact output a haptic loop reads
// (update_output, tool_contact): the proxy, the normal, the force on the tool, the contact stiffness
// K_c (elementLocal, or the effective K_c refreshed every few steps, in the step or in a worker
// thread, with its fallbacks), the damping D_c = beta K_c, and, for a probe not yet touching, the
// surface within a margin of it (surface_near.hpp).
#pragma once

#include "core/collide/lazy_surface_bvh.hpp"
#include "core/contact/background_contact_stiffness.hpp"
#include "core/contact/contact_stiffness.hpp"
#include "core/contact/point_contact.hpp"
#include "core/contact/point_spring.hpp"
#include "core/contact/surface_near.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/integrate/integrator.hpp"
#include "core/mesh/topology.hpp"
#include "core/tool/tool_pose.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

namespace tissue {

struct ContactSettings {
  /// Stiffness of the implicit spring from the god-object's material point to the probe tip;
  /// 0 chooses recommended_contact_spring_stiffness_n_per_m() (100 x the body's contact scale).
  double spring_stiffness_n_per_m = 0.0;
  ContactStiffnessModel stiffness_model = ContactStiffnessModel::effective_static;
  /// The effective (reference) K_c costs a factorization: it is recomputed when a contact starts and
  /// then every this many steps (>= 1); the elementLocal model is recomputed every step.
  int stiffness_refresh_steps = 10;
  /// The effective K_c's factorization runs in a worker thread beside the step
  /// (background_contact_stiffness.hpp) instead of in it: a refresh started at a step is rendered
  /// from the next step on, the previous K_c standing until then; at a new contact, the elementLocal
  /// estimate (the one the near-surface report gave) stands for that first step. The results are
  /// the same with or without a thread to be had. Off: no thread unless asked (the FMU's rule).
  bool stiffness_in_background = false;
  /// In the background: a refresh started at a step is rendered this many steps later (>= 1), the
  /// step waiting for the worker only if it is later still; the next refresh starts then, so K_c is
  /// refreshed every max(stiffness_refresh_steps, this) steps. A fixed step, not "when ready": a run
  /// gives the same K_c whatever the machine.
  int stiffness_latency_steps = 1;
  /// The effective K_c's matrix is factorized at every this many refreshes (>= 1; and after a cut
  /// changed its pattern, or a save point or a restore); the refreshes between condense the contact's
  /// current point from the last factor (EffectiveContactStiffness keeps it): forward solves instead
  /// of a factorization, the body's stiffness as it was when factorized. In the background such a
  /// refresh lands at the next step, a factorization stiffness_latency_steps later. Above 1, a save
  /// point lets the refresh under way land at the next step (as a restored run does).
  int stiffness_refactor_refreshes = 1;
  /// A probe not in contact but this close to the surface reports it (ToolContact::near) [m];
  /// 0: never.
  double near_surface_margin_m = 0.01;
  /// Coulomb friction coefficient of the probe on the tissue, >= 0; 0: frictionless (the contact
  /// slides; point_contact.hpp).
  double friction_coefficient = 0.0;
  /// The probe's pad radius, >= 0 [m]; 0: a point (point_contact.hpp, "A pad"). A pad is
  /// frictionless and its K_c effectiveStatic (the pad's along its normal: pad_stiffness_n_per_m).
  double pad_radius_m = 0.0;
};

/// The contact outputs of the last step, as the contact point is (the haptic loop's input).
struct ContactOutput {
  bool active = false;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< the god-object (proxy) position
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();   ///< unit outward surface normal there
  Eigen::Vector3d force_on_tool_n = Eigen::Vector3d::Zero();
  Eigen::Matrix3d stiffness_n_per_m = Eigen::Matrix3d::Zero();  ///< K_c bonded (model from the settings)
  double penetration_depth_m = 0.0;                             ///< |tip - proxy|
};

/// The complete contact output a haptic loop renders, in the tool position's terms (a ball probe's
/// centre): in contact, ContactOutput's; near the surface, the nearest surface point's.
struct ToolContact {
  bool active = false;  ///< in contact
  bool near = false;    ///< not in contact, the surface within the margin: point, normal and K_c are its
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< the proxy (or near point), offset as the tool's position
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_on_tool_n = Eigen::Vector3d::Zero();
  /// K_c as the tool meets it: the bonded K_c while a contact with friction sticks, its sliding part
  /// (sliding_contact_stiffness_n_per_m) while it slides; near the surface, the nearest point's.
  Eigen::Matrix3d stiffness_n_per_m = Eigen::Matrix3d::Zero();
  /// D_c = beta K_c: pressed at a speed v, the tool feels the quasi-static force plus beta K_n v
  /// (point_contact.hpp; tests/physics/test_contact_press.cpp).
  Eigen::Matrix3d damping_n_s_per_m = Eigen::Matrix3d::Zero();
  double penetration_depth_m = 0.0;
};

class ContactModel {
 public:
  /// What a saved state holds of the contact (the spring is the body's term: saved with it).
  struct State {
    PointContact::State contact;
    ContactOutput output;
    int steps_since_stiffness = 0;
    /// A K_c refresh started in the background and not yet rendered: none, done without a result
    /// (the fallbacks follow), or done with `pending_stiffness_n_per_m`.
    enum class PendingStiffness : std::uint8_t { none, failed, ready };
    PendingStiffness pending_stiffness = PendingStiffness::none;
    Eigen::Matrix3d pending_stiffness_n_per_m = Eigen::Matrix3d::Zero();
  };

  /// `spring` is attached to `body`; `body`, `integrator`, `spring` and `surface` (the body's mesh
  /// surface) outlive the model. `stiffness_damping_s` is the body's Rayleigh beta (the spring is
  /// not tissue: the step does not damp it, issue 9). Throws ParameterError for invalid settings.
  ContactModel(const ContactSettings& settings, bool enabled, double step_size_s, double stiffness_damping_s,
               DeformableBody& body, Integrator& integrator, PointSpringTerm& spring, const SurfaceMesh& surface);
  ContactModel(const ContactModel&) = delete;
  ContactModel& operator=(const ContactModel&) = delete;

  /// The probe's touching point moved from `previous_m` to `current_m`: the god-object follows it
  /// over the surface in `bvh` and the spring acts on the body. `tool_axis`: the tool's axis (a
  /// pad's face is across it).
  void probe(const Eigen::Vector3d& previous_m, const Eigen::Vector3d& current_m, const LazySurfaceBvh& bvh,
             const Eigen::Vector3d& tool_axis = Eigen::Vector3d::UnitZ());
  /// No probe this step: a contact ends and the spring is taken away.
  void withdraw();
  /// After the dynamics step, at the new positions: the contact outputs (K_c refreshed as the
  /// settings say); `applied_tip_m` is the touching point the step applied.
  void update_output(const LazySurfaceBvh& bvh, const Eigen::Vector3d& applied_tip_m);
  /// The near-surface report of the tissue's sample: of the touching pose set when a step ends (or
  /// fails), a state is restored, or a pose is set before the first step, at the current positions.
  void sample_near_surface(const ToolPose& touching, const LazySurfaceBvh& bvh);

  [[nodiscard]] const ContactOutput& output() const { return m_output; }
  /// K_c as the tool meets it (ToolContact::stiffness_n_per_m) in contact; zero out of contact.
  [[nodiscard]] Eigen::Matrix3d rendered_stiffness_n_per_m() const;
  /// The complete output, `ball_offset_m` (the tool position minus its touching point) added to the
  /// point.
  [[nodiscard]] ToolContact tool_contact(const Eigen::Vector3d& ball_offset_m) const;
  [[nodiscard]] const PointContact& point_contact() const { return m_contact; }
  /// The spring stiffness the contact uses (resolved from the settings) [N/m].
  [[nodiscard]] double spring_stiffness_n_per_m() const { return m_contact.settings().spring_stiffness_n_per_m; }
  /// How many times K_c fell back to the spring alone (no matrix could be condensed).
  [[nodiscard]] int stiffness_fallbacks() const { return m_stiffness_fallbacks; }

  /// How many times K_c's matrix was factorized (a refresh that condensed from the last factor does
  /// not count; ContactSettings::stiffness_refactor_refreshes).
  [[nodiscard]] int stiffness_factorizations() const { return m_stiffness_factorizations; }

  /// Waits for a running K_c refresh (its result is part of the state). A save point, like a restore,
  /// lets the next refresh factorize (the factor is not saved), so that a run continuing from it and a
  /// run restored to it render the same K_c.
  [[nodiscard]] State state() const;
  /// Throws StateError for a state restore() refuses: a contact on a triangle the mesh's surface
  /// does not have.
  void check(const State& state) const;
  void restore(const State& state);

 private:
  [[nodiscard]] ContactStiffnessRequest stiffness_request_at(const ShiftedSystem& system, int triangle,
                                                             double floor_n_per_m) const;
  /// The K_c a condensation gave (in this step or in the background), or its fallbacks computed now:
  /// the step's Newton matrix where the static K failed, else the spring alone (counted).
  Eigen::Matrix3d landed_stiffness(const std::optional<Eigen::Matrix3d>& landed, int triangle);
  void refresh_stiffness(int triangle);
  /// At a save point and a restore (the factor and the kind of the refresh under way are not saved):
  /// the next refresh factorizes, and with stiffness_refactor_refreshes above 1 the refresh under way
  /// lands at the next step, so that a run continuing from a save point and one restored to it agree.
  void forget_factor() const;

  ContactSettings m_settings;
  bool m_enabled;
  double m_step_size_s;
  double m_stiffness_damping_s;
  DeformableBody& m_body;
  Integrator& m_integrator;
  PointSpringTerm& m_spring;
  const SurfaceMesh& m_surface;
  PointContact m_contact;
  double m_stiffness_scale_n_per_m;  ///< contact_stiffness_scale_n_per_m of the body
  EffectiveContactStiffness m_effective_stiffness;
  Eigen::VectorXd m_system_diagonal;
  int m_steps_since_stiffness = 0;
  mutable BackgroundContactStiffness m_stiffness_refresh;  // state() waits for a running one
  int m_stiffness_fallbacks = 0;
  // The last factorization K_c's refreshes may condense from (stiffness_refactor_refreshes).
  struct LastFactor {
    bool usable = false;              // false: the next refresh factorizes (state() clears it)
    ContactStiffnessRequest request;  // of the factorization: the spring its matrix holds
    std::uint64_t pattern = 0;        // the matrix's pattern revision and rows
    int rows = 0;
    int refreshes_since = 0;
  };
  mutable LastFactor m_last_factor;
  mutable int m_pending_latency_steps;  // when the refresh under way lands (forget_factor() may shorten it)
  int m_stiffness_factorizations = 0;
  ContactOutput m_output;
  std::optional<NearSurface> m_near;
  std::vector<SurfaceBvh::SphereHit> m_near_hits;  // scratch of sample_near_surface()
};

}  // namespace tissue
