// The renderer as the FMU layer sees it: settings refused by validate() with the setting's name,
// samples and device positions with NaN/Inf that never reach the output, K_c repaired to symmetric
// PSD, the tool put away, and a saved state that continues bitwise.
#include "haptic/haptic_renderer.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace tissue::haptic {
namespace {

constexpr double DT_S = 1e-3;
constexpr double NAN_VALUE = std::numeric_limits<double>::quiet_NaN();
constexpr double INF = std::numeric_limits<double>::infinity();

TissueSample pressing_contact() {
  TissueSample sample;
  sample.time_s = 0.5;
  sample.contact_active = true;
  sample.contact_normal = Eigen::Vector3d::UnitZ();
  sample.tool_position_m = {0.0, 0.0, -1e-3};
  sample.force_on_tool_n = {0.2, 0.0, 2.0};
  sample.contact_stiffness_n_per_m = Eigen::Vector3d(500.0, 500.0, 2000.0).asDiagonal();
  sample.blade_depth_m = 0.0;
  return sample;
}

TEST(RendererSettings, ValidateRefusesEachSettingOutOfRangeNamingIt) {
  EXPECT_NO_THROW(validate(RendererSettings{}));
  RendererSettings unlimited;
  unlimited.max_force_rate_n_per_s = INF;  // the documented way to turn the limiter off
  EXPECT_NO_THROW(validate(unlimited));
  RendererSettings free_cut;
  free_cut.cutting.fracture_toughness_j_per_m2 = 0.0;
  EXPECT_NO_THROW(validate(free_cut));

  const std::vector<std::pair<std::string, std::function<void(RendererSettings&)>>> bad = {
      {"max_force_n", [](RendererSettings& s) { s.max_force_n = -1.0; }},
      {"max_force_n", [](RendererSettings& s) { s.max_force_n = 0.0; }},
      {"max_force_n", [](RendererSettings& s) { s.max_force_n = INF; }},
      {"max_force_n", [](RendererSettings& s) { s.max_force_n = NAN_VALUE; }},
      {"max_force_rate_n_per_s", [](RendererSettings& s) { s.max_force_rate_n_per_s = 0.0; }},
      {"max_force_rate_n_per_s", [](RendererSettings& s) { s.max_force_rate_n_per_s = -300.0; }},
      {"max_force_rate_n_per_s", [](RendererSettings& s) { s.max_force_rate_n_per_s = NAN_VALUE; }},
      {"velocity_filter_cutoff_hz", [](RendererSettings& s) { s.velocity_filter_cutoff_hz = 0.0; }},
      {"velocity_filter_cutoff_hz", [](RendererSettings& s) { s.velocity_filter_cutoff_hz = INF; }},
      {"fracture_toughness_j_per_m2", [](RendererSettings& s) { s.cutting.fracture_toughness_j_per_m2 = -1.0; }},
      {"blade_friction_n_per_m", [](RendererSettings& s) { s.cutting.blade_friction_n_per_m = -0.1; }},
      {"smoothing_speed_m_per_s", [](RendererSettings& s) { s.cutting.smoothing_speed_m_per_s = 0.0; }},
  };
  for (const auto& [name, spoil] : bad) {
    RendererSettings settings;
    spoil(settings);
    try {
      validate(settings);
      ADD_FAILURE() << name << " accepted";
    } catch (const ParameterError& error) {
      EXPECT_NE(std::string(error.what()).find(name), std::string::npos) << error.what();
    }
    EXPECT_THROW(HapticRenderer{settings}, ParameterError) << name;
  }
}

// Each field of a sample set to NaN or Inf is refused with its name, and the renderer keeps
// rendering the previous sample exactly as before.
TEST(HapticRenderer, NonFiniteSamplesAreRefusedAndTheLastGoodOneKept) {
  const std::vector<std::pair<std::string, std::function<void(TissueSample&, double)>>> fields = {
      {"time_s", [](TissueSample& s, double bad) { s.time_s = bad; }},
      {"contact_point_m", [](TissueSample& s, double bad) { s.contact_point_m.y() = bad; }},
      {"contact_normal", [](TissueSample& s, double bad) { s.contact_normal.x() = bad; }},
      {"force_on_tool_n", [](TissueSample& s, double bad) { s.force_on_tool_n.z() = bad; }},
      {"contact_stiffness_n_per_m", [](TissueSample& s, double bad) { s.contact_stiffness_n_per_m(1, 2) = bad; }},
      {"tool_position_m", [](TissueSample& s, double bad) { s.tool_position_m.x() = bad; }},
      {"blade_depth_m", [](TissueSample& s, double bad) { s.blade_depth_m = bad; }},
  };
  const Eigen::Vector3d x(0.0, 0.0, -1.2e-3);
  for (const auto& [name, spoil] : fields) {
    for (double bad : {NAN_VALUE, INF, -INF}) {
      HapticRenderer renderer;
      renderer.set_sample(pressing_contact());
      for (int i = 0; i < 20; ++i) renderer.tick(x, ToolMode::probe, DT_S);
      const RendererState before = renderer.save_state();
      TissueSample sample = pressing_contact();
      spoil(sample, bad);
      try {
        renderer.set_sample(sample);
        ADD_FAILURE() << name << " = " << bad << " accepted";
      } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find(name), std::string::npos) << error.what();
      }
      const Eigen::Vector3d f = renderer.tick(x, ToolMode::probe, DT_S);
      EXPECT_TRUE(f.allFinite());
      HapticRenderer reference;
      reference.restore_state(before);
      EXPECT_EQ(f, reference.tick(x, ToolMode::probe, DT_S)) << name;
    }
  }
}

TEST(HapticRenderer, SamplesWithANonUnitNormalOrNegativeDepthAreRefused) {
  HapticRenderer renderer;
  TissueSample sample = pressing_contact();
  sample.contact_normal = {0.0, 0.0, 1.01};
  EXPECT_THROW(renderer.set_sample(sample), std::invalid_argument);
  sample.contact_active = false;  // no contact: the normal is not used and may be anything finite
  sample.contact_normal.setZero();
  EXPECT_NO_THROW(renderer.set_sample(sample));
  sample.blade_depth_m = -1e-3;
  EXPECT_THROW(renderer.set_sample(sample), std::invalid_argument);
}

// An antisymmetric K_c (a curl field) or a negative eigenvalue would make the contact an energy
// source on a closed path; the renderer keeps the nearest symmetric PSD matrix: the symmetric part
// with negative eigenvalues set to zero. Tolerance 1e-9 N/m on ~2000 N/m (eigen-solver rounding).
TEST(HapticRenderer, AStiffnessThatIsNotSymmetricPsdIsProjected) {
  HapticRenderer renderer;
  TissueSample sample = pressing_contact();
  renderer.set_sample(sample);
  EXPECT_FALSE(renderer.last_sample_repaired());
  EXPECT_EQ(renderer.sample().contact_stiffness_n_per_m, sample.contact_stiffness_n_per_m);

  Eigen::Matrix3d k;
  k << 1000.0, 300.0, 0.0,  //
      -100.0, -50.0, 0.0,   // symmetric part [[1000, 100], [100, -50]]: one negative eigenvalue
      0.0, 0.0, 2000.0;
  sample.contact_stiffness_n_per_m = k;
  renderer.set_sample(sample);
  EXPECT_TRUE(renderer.last_sample_repaired());
  const Eigen::Matrix3d repaired = renderer.sample().contact_stiffness_n_per_m;
  EXPECT_LT((repaired - repaired.transpose()).norm(), 1e-9);
  const Eigen::Matrix3d symmetric = 0.5 * (k + k.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> expected(symmetric);
  const Eigen::Matrix3d projected =
      expected.eigenvectors() * expected.eigenvalues().cwiseMax(0.0).asDiagonal() * expected.eigenvectors().transpose();
  EXPECT_LT((repaired - projected).norm(), 1e-9);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(repaired).eigenvalues().minCoeff(), -1e-9);
}

// A device position with NaN or Inf: the output stays finite, contact is not rendered, and the
// force is released toward zero at the rate limit (0.3 N per tick), not dropped at once. When the
// positions come back the velocity restarts: the jump across the gap is not differentiated (here
// 5 cm in one tick would be 50 m/s, a 0.8 N cutting force at once).
TEST(HapticRenderer, NonFiniteDevicePositionsReleaseTheForceAtTheRateLimit) {
  HapticRenderer renderer;
  TissueSample sample = pressing_contact();
  sample.blade_depth_m = 5e-3;
  renderer.set_sample(sample);
  const Eigen::Vector3d x(0.0, 0.0, -1e-3);
  Eigen::Vector3d previous;
  for (int i = 0; i < 30; ++i) previous = renderer.tick(x, ToolMode::scalpel, DT_S);
  ASSERT_NEAR(previous.norm(), sample.force_on_tool_n.norm(), 1e-12);

  const double step_n = renderer.settings().max_force_rate_n_per_s * DT_S;
  const Eigen::Vector3d bad_positions[] = {{NAN_VALUE, 0.0, 0.0}, {0.0, INF, 0.0}, {0.0, 0.0, -INF}};
  for (int i = 0; i < 12; ++i) {
    const Eigen::Vector3d f = renderer.tick(bad_positions[i % 3], ToolMode::scalpel, DT_S);
    EXPECT_TRUE(f.allFinite());
    EXPECT_TRUE(renderer.last_tick().position_rejected);
    EXPECT_LE((f - previous).norm(), step_n + 1e-12);
    EXPECT_LE(f.norm(), std::max(0.0, previous.norm() - step_n) + 1e-12);  // only ever decreasing
    previous = f;
  }
  EXPECT_EQ(previous, Eigen::Vector3d::Zero());  // 2.01 N gone after 7 ticks

  const Eigen::Vector3d back = x + Eigen::Vector3d(0.05, 0.0, 0.0);
  renderer.tick(back, ToolMode::scalpel, DT_S);
  EXPECT_FALSE(renderer.last_tick().position_rejected);
  EXPECT_EQ(renderer.last_tick().velocity_m_per_s, Eigen::Vector3d::Zero());
  EXPECT_EQ(renderer.last_tick().cutting_force_n, Eigen::Vector3d::Zero());
}

TEST(HapticRenderer, ATickLengthThatIsNotPositiveAndFiniteIsRefusedStateUnchanged) {
  HapticRenderer renderer;
  renderer.set_sample(pressing_contact());
  for (int i = 0; i < 5; ++i) renderer.tick({0.0, 0.0, -1e-3}, ToolMode::probe, DT_S);
  const RendererState before = renderer.save_state();
  for (double dt : {0.0, -1e-3, NAN_VALUE, INF}) {
    EXPECT_THROW(renderer.tick({0.0, 0.0, -1e-3}, ToolMode::probe, dt), std::invalid_argument) << dt;
  }
  const RendererState after = renderer.save_state();
  EXPECT_EQ(before, after);
}

TEST(HapticRenderer, TheToolPutAwayFeelsNothingAfterTheRamp) {
  RendererSettings settings;
  settings.max_force_rate_n_per_s = 300.0;  // not the default: seven ticks to watch
  HapticRenderer renderer(settings);
  renderer.set_sample(pressing_contact());
  const Eigen::Vector3d x(0.0, 0.0, -1e-3);
  for (int i = 0; i < 30; ++i) renderer.tick(x, ToolMode::probe, DT_S);
  Eigen::Vector3d f;
  for (int i = 0; i < 7; ++i) {
    f = renderer.tick(x, ToolMode::none, DT_S);
    EXPECT_TRUE(i == 6 || f.norm() > 0.0);  // released at the rate limit, not dropped
  }
  EXPECT_EQ(f, Eigen::Vector3d::Zero());
  renderer.reset();
  EXPECT_FALSE(renderer.has_sample());
  EXPECT_EQ(renderer.observed_energy_j(), 0.0);
  EXPECT_EQ(renderer.tick(x, ToolMode::probe, DT_S), Eigen::Vector3d::Zero());
}

/// A busy script: contact samples at 30 Hz, a moving hand, scalpel mode with the blade in.
Eigen::Vector3d busy_tick(HapticRenderer& renderer, int k) {
  const double t = k * DT_S;
  if (k % 33 == 0) {
    TissueSample sample = pressing_contact();
    sample.force_on_tool_n.z() = 1.0 + 0.5 * std::sin(3.0 * t);
    sample.tool_position_m.z() = -1e-3 + 3e-4 * std::cos(5.0 * t);
    sample.blade_depth_m = 2e-3;
    renderer.set_sample(sample);
  }
  const Eigen::Vector3d x(0.01 * std::sin(7.0 * t), 0.0, -1e-3 + 1e-3 * std::sin(11.0 * t));
  return renderer.tick(x, ToolMode::scalpel, DT_S);
}

// The FMU's get/set FMU state: a restored renderer (another instance) continues bitwise as the
// saved one, over samples, contact, cutting and the controller.
TEST(HapticRenderer, ARestoredStateContinuesBitwise) {
  HapticRenderer original;
  for (int k = 0; k < 500; ++k) busy_tick(original, k);
  const RendererState saved = original.save_state();
  std::vector<Eigen::Vector3d> expected;
  for (int k = 500; k < 1500; ++k) expected.push_back(busy_tick(original, k));

  HapticRenderer restored;
  for (int k = 0; k < 77; ++k) busy_tick(restored, 3 * k + 1);  // some other history
  restored.restore_state(saved);
  for (int k = 500; k < 1500; ++k) ASSERT_EQ(busy_tick(restored, k), expected[static_cast<std::size_t>(k - 500)]) << k;
  EXPECT_EQ(restored.observed_energy_j(), original.observed_energy_j());
  EXPECT_EQ(restored.dissipated_energy_j(), original.dissipated_energy_j());
}

TEST(HapticRenderer, AStateItCouldNotHaveSavedIsRefusedRendererUnchanged) {
  HapticRenderer renderer;
  for (int k = 0; k < 100; ++k) busy_tick(renderer, k);
  const RendererState good = renderer.save_state();
  const std::vector<std::function<void(RendererState&)>> spoil = {
      [](RendererState& s) { s.commanded_force_n[0] = NAN_VALUE; },
      [](RendererState& s) {
        s.commanded_force_n = {3.0, 3.0, 0.0};
      },  // 4.2 N > 3.3 N
      [](RendererState& s) { s.observed_energy_j = INF; },
      [](RendererState& s) { s.previous_position_m[2] = NAN_VALUE; },
      [](RendererState& s) { s.contact_stiffness_n_per_m[0] = -1000.0; },  // not PSD
      [](RendererState& s) {
        s.contact_normal = {0.0, 0.0, 2.0};
      },
      [](RendererState& s) { s.blade_depth_m = -1.0; },
  };
  for (std::size_t i = 0; i < spoil.size(); ++i) {
    RendererState bad = good;
    spoil[i](bad);
    EXPECT_THROW(renderer.restore_state(bad), std::invalid_argument) << i;
    const RendererState now = renderer.save_state();
    EXPECT_EQ(now, good) << i;
  }
}

}  // namespace
}  // namespace tissue::haptic
