// The closed-loop harness of issue 20: a simulated hand (host/device/hand_device.hpp) whose motion
// answers the force, on HapticLoop.fmu through the project's importer, while a synthetic tissue sends
// a sample every `sample_ticks` ticks computed for the tool position the loop output then, delivered
// one sample period later (as tissue-host does: 100 Hz samples, one step late). The tissues are flat
// walls at z = 0, so statics is known: a hand pushing p rests at depth p / K.
#pragma once

#include "device/hand_device.hpp"
#include "importer/fmu3.hpp"
#include "importer/fmu3_instance.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tissue::host::hand_test {

using Vec3 = std::array<double, 3>;
constexpr double TICK_S = 1e-3;
/// A tool this close above a wall is told the wall is near (the Tissue FMU's contact.nearMargin).
constexpr double NEAR_MARGIN_M = 0.01;

/// One sample as the host forwards it (the Tissue FMU's sample fields).
struct Sample {
  double time_s = 0.0;
  bool contact_active = false;
  bool contact_near = false;  ///< not in contact, the wall within NEAR_MARGIN_M of the tool
  Vec3 point_m{};
  Vec3 normal{0.0, 0.0, 1.0};
  Vec3 force_n{};
  std::array<double, 9> stiffness_n_per_m{};  // row-major
  std::array<double, 9> damping_n_s_per_m{};  // row-major
  Vec3 tool_position_m{};
  double blade_depth_m = 0.0;
};

/// A tissue played by the harness: the sample for a tool at `tool_m`.
class SyntheticTissue {
 public:
  virtual ~SyntheticTissue() = default;
  virtual Sample sample(const Vec3& tool_m, double time_s) = 0;
  [[nodiscard]] virtual std::string name() const = 0;
};

/// A wall z < 0 of stiffness K: force K (-z) e_z; K_c = K e_z e_z^T, or 0 (force-only, a tissue that
/// reports no stiffness). A tool less than NEAR_MARGIN_M above it is told the wall is near, unless
/// `reports_near` is false (a tissue that reports contact only).
class Wall final : public SyntheticTissue {
 public:
  Wall(double stiffness_n_per_m, bool reports_stiffness, bool reports_near = true)
      : m_stiffness_n_per_m(stiffness_n_per_m), m_reports_stiffness(reports_stiffness), m_reports_near(reports_near) {}
  Sample sample(const Vec3& tool_m, double time_s) override;
  [[nodiscard]] std::string name() const override;

 private:
  double m_stiffness_n_per_m;
  bool m_reports_stiffness;
  bool m_reports_near;
};

/// What a synthetic tissue reports besides its force.
struct Reports {
  bool stiffness = true;  ///< K_c (else 0)
  bool damping = true;    ///< D_c (else 0)
  bool near = true;       ///< the surface within NEAR_MARGIN_M of a tool not in contact
};

/// A Kelvin-Voigt wall whose force lags its depth: K d + c dd/dt (dd/dt from the last two samples),
/// K_c = K e_z e_z^T, D_c = c e_z e_z^T, each reported or 0 as `reports` says (all off: a tissue
/// from another tool that reports its force only).
class ViscoelasticWall final : public SyntheticTissue {
 public:
  ViscoelasticWall(double stiffness_n_per_m, double damping_n_s_per_m, Reports reports = {})
      : m_stiffness_n_per_m(stiffness_n_per_m), m_damping_n_s_per_m(damping_n_s_per_m), m_reports(reports) {}
  Sample sample(const Vec3& tool_m, double time_s) override;
  [[nodiscard]] std::string name() const override;

 private:
  double m_stiffness_n_per_m, m_damping_n_s_per_m;
  Reports m_reports;
  std::optional<std::pair<double, double>> m_last;  // (time, depth)
};

/// Another tissue's samples, every `period`-th one corrupted: a NaN force, then a normal of length 2.
class CorruptedSamples final : public SyntheticTissue {
 public:
  CorruptedSamples(std::unique_ptr<SyntheticTissue> tissue, int period) : m_tissue(std::move(tissue)), m_period(period) {}
  Sample sample(const Vec3& tool_m, double time_s) override;
  [[nodiscard]] std::string name() const override { return m_tissue->name() + ", corrupted samples"; }
  /// How many of the samples given a normal of length 2 were in contact or near the surface (the loop
  /// refuses those: their normal is used).
  [[nodiscard]] long long_normals_used() const { return m_long_normals_used; }

 private:
  std::unique_ptr<SyntheticTissue> m_tissue;
  int m_period;
  long m_count = 0;
  long m_long_normals_used = 0;
};

struct LoopSettings {
  HandSettings hand;                 ///< default: 0.2 kg, 2 N s/m; the harness pushes with push_n
  double start_height_m = 0.01;      ///< the hand starts at rest this far above the wall
  double max_force_n = 3.3;          ///< device.maxForce
  double max_force_rate_n_per_s = 1000.0;  ///< device.maxForceRate (the FMU's start value)
  bool passivity_control = true;
  double min_hand_mass_kg = 0.05;  ///< passivity.minHandMass (the FMU's start value)
  double contact_damping_n_s_per_m = 2.0;  ///< contact.damping (the FMU's start value)
  bool hold_damping = true;                ///< contact.holdDamping (the FMU's start value)
  int sample_ticks = 10;   ///< 100 Hz samples
  double duration_s = 3.0;
  /// If set, the hand's (z, dz/dt) after every tick.
  std::vector<std::array<double, 2>>* trace = nullptr;
};

struct LoopResult {
  HandFigures hand;
  /// The one-port's energy, -(work of the device on the hand), at its lowest over the run [J]:
  /// < 0 means the loop gave the hand energy it never took from it.
  double lowest_one_port_energy_j = 0.0;
  std::uint64_t samples_refused = 0;     ///< by the HapticLoop (tissue.samplesRefused)
  std::uint64_t samples_not_finite = 0;  ///< not forwarded (FMI refuses a non-finite Float64), as tissue-host
  bool completed = false;
  std::string failure;  ///< what stopped the run early
  [[nodiscard]] double penetration_m() const { return -hand.mean_position_m[2]; }
};

const Fmu3& haptic_loop_fmu();

/// Sets `sample` as the HapticLoop's tissue.* inputs (with tissue.time), as the host's relay does:
/// one set per type, the booleans first.
fmi3Status deliver(Fmu3Instance& fmu, const Sample& sample);

/// The hand dropped onto `tissue`, run for `settings.duration_s`.
LoopResult run_hand_on(SyntheticTissue& tissue, const LoopSettings& settings);

}  // namespace tissue::host::hand_test
