// The haptic rendering core of the HapticLoop FMU (docs/DESIGN.md, "Haptic loop"): every 1 ms tick it turns the
// device position, the tool mode and the tissue's latest sample into the force to command on the
// device. The pieces, each in its own file with one job, in the order a tick applies them:
//   1. contact_force.hpp: intermediate representation f0 - K_c (x - x0), then the unilateral
//      constraint against the contact plane;
//   2. cutting_force.hpp: fracture-mechanics cutting resistance (scalpel mode), from the filtered
//      velocity (velocity_filter.hpp);
//   3. force_limits.hpp: clamp to max_force_n, then rate limit against the previous command;
//   4. passivity.hpp: the passivity controller adds damping if the one-port would turn active, and
//      its sum goes through the same clamp and rate limit; the observer books the force finally
//      commanded, at the next tick, with the displacement it acted over.
// The observer must see what the device really applied, so it comes after every piece that changes
// the force; the controller must come after the limits so that what it plans is what is commanded
// (its own output is limited too, and whatever that withholds stays in the observed deficit).
// Sign convention: forces on the tool; see tissue_sample.hpp. SI units.
//
// Real-time: tick() and set_sample() allocate nothing (except on the throwing paths) and do no I/O.
#pragma once

#include "core/parameter_error.hpp"
#include "haptic/cutting_force.hpp"
#include "haptic/normal_model_estimate.hpp"
#include "haptic/passivity.hpp"
#include "haptic/tissue_sample.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <type_traits>

namespace tissue::haptic {

struct RendererSettings {
  /// Largest force magnitude ever commanded [N], finite and > 0. 3.3 N: the peak force of the
  /// 3D Systems Touch (formerly Phantom Omni) at its nominal position, from the maker's data sheet
  /// (its continuous force is 0.88 N; holding more for long is the device driver's concern).
  double max_force_n = 3.3;
  /// Largest change of the commanded force per second [N/s], > 0; +infinity turns the limiter off.
  /// 1000 N/s: a 2000 N/m contact (about the stiffest a desktop device renders) met at 0.5 m/s asks
  /// for this much, so contacts are not softened, while a full-scale step (3.3 N: a cut releasing
  /// tension) is spread over 3.3 ticks. 300 N/s (the value before issue 20) lagged the contact at the
  /// 10-20 Hz a hand rings at: it narrowed the Z-width of the lightest hands (0.05 kg, 0.5 N s/m: 717
  /// against 24396 N/m with K_c; docs/BENCHMARKS.md). An engineering choice, not a published figure.
  double max_force_rate_n_per_s = 1000.0;
  /// Time-domain passivity controller on (passivity.hpp). The observer always runs.
  bool passivity_control = true;
  /// The lightest hand the controller must not throw back [kg], finite and > 0: its damping is
  /// bounded by min_hand_mass / (2 dt), so that over one tick it slows such a hand by at most half
  /// and never reverses it (passivity.hpp). 0.05 kg: a light grip on a stylus.
  double passivity_min_hand_mass_kg = 0.05;
  /// A sample without stiffness (K_c = 0: a tissue that reports its force only) is given the
  /// stiffness its force changed by along the normal since the last sample in contact, per metre the
  /// tool moved (the secant; HapticRenderer::set_sample), at most this [N/m], finite and >= 0 (0:
  /// no estimate, the force is held). 5000 N/m: above what a desktop device renders (a 3D Systems
  /// Touch ~1-2.3 N/mm).
  double max_estimated_stiffness_n_per_m = 5000.0;
  /// Viscous damping of a contact along its normal [N s/m], finite and >= 0, on top of the tissue's
  /// own (contact_force.hpp, contact_damping_force). 2 N s/m: a floor for a tissue that reports its
  /// force only (no K_c, no D_c): its contacts start a sample late and the stiffness is estimated, and
  /// 2 N s/m keeps what the one-port gives the hands of issue 20 to 2.9 mJ (11 mJ without); at the
  /// 0.1 m/s of a brisk poke it adds 0.2 N.
  double contact_damping_n_s_per_m = 2.0;
  /// Damp a contact by T K_c (T the tick): gives back twice what holding the contact's spring over a
  /// tick gives the hand, so that any hand is stable on any contact (contact_damping_force). Off only
  /// to measure what it does.
  bool hold_damping = true;
  /// Cut-off of the velocity low-pass [Hz], finite and > 0 (velocity_filter.hpp). 30 Hz: above the
  /// bandwidth of voluntary hand motion (below about 10 Hz), with a lag of 5.3 ms.
  double velocity_filter_cutoff_hz = 30.0;
  CuttingSettings cutting;
};

/// Throws ParameterError naming the first setting out of range (with its value and the range).
void validate(const RendererSettings& settings);

/// What one tick did, for logging and tests.
struct TickReport {
  Eigen::Vector3d contact_force_n = Eigen::Vector3d::Zero();    ///< intermediate representation, unilateral
  Eigen::Vector3d cutting_force_n = Eigen::Vector3d::Zero();    ///< cutting resistance
  Eigen::Vector3d passivity_force_n = Eigen::Vector3d::Zero();  ///< the controller's share of the command
  Eigen::Vector3d commanded_force_n = Eigen::Vector3d::Zero();  ///< what tick() returned
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();   ///< filtered hand velocity
  double observed_energy_j = 0.0;                               ///< E through the previous tick (passivity.hpp)
  double predicted_energy_j = 0.0;                              ///< E - f . v dt with the force commanded now
  double damping_n_s_per_m = 0.0;                               ///< alpha the controller asked for (0: it did not act)
  bool clamped = false;                                         ///< the clamp changed the commanded force
  bool rate_limited = false;                                    ///< the rate limiter changed the commanded force
  bool passivity_acted = false;                                 ///< the controller added damping
  bool position_rejected = false;                               ///< the device position was not finite
};

/// Everything a tick carries forward, as plain numbers (for the FMU's get/set FMU state; memcpy-able).
struct RendererState {
  // The current tissue sample (after prepare_sample), matrices column-major.
  bool has_sample = false;
  bool contact_active = false;
  bool surface_near = false;
  double sample_time_s = 0.0;
  std::array<double, 3> contact_point_m{};
  std::array<double, 3> contact_normal{};
  std::array<double, 3> force_on_tool_n{};
  std::array<double, 9> contact_stiffness_n_per_m{};
  std::array<double, 9> contact_damping_n_s_per_m{};
  std::array<double, 3> sample_tool_velocity_m_per_s{};  ///< v0 (HapticRenderer::sample_tool_velocity_m_per_s)
  /// The force-only estimate's last pair of samples in contact (normal_model_estimate.hpp): depth,
  /// rate and force changes.
  bool has_estimate_pair = false;
  std::array<double, 3> estimate_pair{};
  std::array<double, 2> normal_model{};               ///< the last estimate: K [N/m], c [N s/m]
  std::array<double, 3> sample_motion_m_per_s{};      ///< the tool's velocity over the last sample interval
  /// A force-only contact's remembered plane (HapticRenderer::remember_contact_plane).
  bool has_last_contact = false;
  std::array<double, 3> last_contact_point_m{};
  std::array<double, 3> last_contact_normal{};
  std::array<double, 9> last_contact_stiffness_n_per_m{};  ///< column-major
  std::array<double, 9> last_contact_damping_n_s_per_m{};
  std::array<double, 3> tool_position_m{};
  double blade_depth_m = 0.0;
  // Motion.
  bool has_previous_position = false;
  std::array<double, 3> previous_position_m{};
  std::array<double, 3> filtered_velocity_m_per_s{};
  // The command held on the device now, its controller share, and the observer.
  std::array<double, 3> commanded_force_n{};
  std::array<double, 3> commanded_damping_n{};
  double observed_energy_j = 0.0;
  double dissipated_energy_j = 0.0;

  bool operator==(const RendererState&) const = default;  ///< member-wise (padding is not compared)
};
static_assert(std::is_trivially_copyable_v<RendererState>);

class HapticRenderer {
 public:
  /// Throws ParameterError for invalid settings.
  explicit HapticRenderer(RendererSettings settings = {});

  /// A new tissue sample arrived; it replaces the previous one (zero-order hold until the next).
  /// Throws std::invalid_argument (naming the field; the renderer unchanged) for a sample that
  /// prepare_sample() refuses: non-finite numbers, negative blade depth, a non-unit normal.
  /// The tool's velocity over the tissue step (sample_tool_velocity_m_per_s) is estimated here.
  /// A sample in contact without stiffness (K_c = 0: a tissue that reports its force only) gets
  /// K n n^T and, without damping either, c n n^T: the normal model its force's changes over the last
  /// two sample pairs give (normal_model_estimate.hpp; K at most max_estimated_stiffness_n_per_m):
  /// held force alone renders a delayed, active spring and damper (issues 20, 42; docs/DESIGN.md,
  /// "Haptic loop").
  void set_sample(const TissueSample& sample);

  /// One haptic tick: the device (hand) position now, the tool mode, the tick length. Returns the
  /// force to command on the device [N], finite, |f| <= max_force_n, and |f - f_previous| <=
  /// max_force_rate_n_per_s dt_s. A non-finite device position renders no contact and releases the
  /// force toward zero at the rate limit (no kick); the observer books nothing over ticks whose
  /// motion is unknown, and the velocity restarts from the next finite position.
  /// Throws std::invalid_argument unless dt_s is finite and > 0 (a caller's error; state unchanged).
  Eigen::Vector3d tick(const Eigen::Vector3d& device_position_m, ToolMode mode, double dt_s);

  /// Back to the state after construction (no sample, no motion, no force, zero energy).
  void reset();

  RendererState save_state() const;
  /// Throws std::invalid_argument (renderer unchanged) for a state this renderer could not have
  /// saved: non-finite numbers, a commanded force above max_force_n, an invalid sample.
  void restore_state(const RendererState& state);

  const RendererSettings& settings() const { return m_settings; }
  const TickReport& last_tick() const { return m_report; }
  bool has_sample() const { return m_has_sample; }
  /// The sample being rendered, as prepare_sample() left it.
  const TissueSample& sample() const { return m_sample; }
  /// v0: the tool's velocity over the tissue step the sample ends, (x0 - x0_previous) / (t - t_previous)
  /// from the last two samples (both in contact or near the surface, in increasing time); 0 otherwise.
  /// The viscous part of f0 is D_c v0; the renderer replaces it by D_c v, the hand's velocity now.
  const Eigen::Vector3d& sample_tool_velocity_m_per_s() const { return m_sample_tool_velocity_m_per_s; }
  /// Whether prepare_sample() had to project the last sample's K_c to symmetric PSD.
  bool last_sample_repaired() const { return m_last_sample_repaired; }
  /// Energy the renderer (the one-port behind the device) has absorbed [J]; see passivity.hpp.
  double observed_energy_j() const { return m_observer.energy_j(); }
  /// Energy the passivity controller's damping has taken from the hand since construction [J].
  double dissipated_energy_j() const { return m_observer.dissipated_j(); }

 private:
  /// K_c = K n n^T (and D_c = c n n^T unless the sample reports it) for a sample in contact without
  /// stiffness, from the normal force's changes over the last two sample pairs (set_sample;
  /// normal_model_estimate.hpp).
  /// Keeps a force-only contact's plane (point, normal, K and c) to render, as a surface near, while
  /// the next samples say neither contact nor near and the tool stays close: a hand that bounces off
  /// re-enters the wall at the crossing tick, not a sample or two later.
  void remember_contact_plane(const TissueSample& sample);
  /// `motion_m_per_s`: the tool's velocity over the interval since the previous sample, in contact or not.
  void estimate_contact_model(TissueSample& sample, const Eigen::Vector3d& motion_m_per_s);
  RendererSettings m_settings;
  TissueSample m_sample;
  Eigen::Vector3d m_sample_tool_velocity_m_per_s = Eigen::Vector3d::Zero();
  std::optional<NormalPair> m_estimate_pair;  // the last pair of samples in contact, for the estimate
  NormalModel m_normal_model;                 // the last estimate (kept from one contact to the next)
  std::optional<TissueSample> m_last_contact;  // a force-only contact's plane (remember_contact_plane)
  Eigen::Vector3d m_sample_motion_m_per_s = Eigen::Vector3d::Zero();  // the tool's, over the last interval
  bool m_has_sample = false;
  bool m_last_sample_repaired = false;
  bool m_has_previous_position = false;
  Eigen::Vector3d m_previous_position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d m_filtered_velocity_m_per_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d m_commanded_force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d m_commanded_damping_n = Eigen::Vector3d::Zero();
  PassivityObserver m_observer;
  TickReport m_report;
};

}  // namespace tissue::haptic
