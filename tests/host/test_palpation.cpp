// Palpation (issue 25, part 2): host/scenarios/palpate_liver.toml's simulated hand presses a probe
// 2 mm into the organ (meshes/liver_palpation_tumour.veg, the 10 ms slot's mesh: issue 42) straight
// down beside the stiff inclusion and holds,
// then over it and holds, as a clinician palpates (the sweep that follows is for the figure). In each
// dwell the normal force the haptic loop renders to the hand (the mean of the dwell's last 0.4 s in
// log.csv) is compared with the full model's quasi-static poke (core/contact/quasi_static_poke.hpp)
// of the same body, built as the Tissue FMU builds it (gravity included), to the same point: the
// frictionless poke (the contact slides, issue 42: point_contact.hpp), from the material point
// straight below at rest, pushed to where the god-object holds it, the tool's position plus F / k
// (the contact spring's stretch). The hand sags on its grip (F / 3000 N/m, 0.5-0.8 mm), which is why
// the target is where the tool was and not where the script put it.
//
// What must hold: the normal force over the inclusion is larger than beside it by the ratio the
// pokes predict (1.49 here; 1.67 on the 52k-tet liver_tumour.veg the scenario stepped before), within
// 5 %, and each dwell's normal force is its poke's within 5 %; and the inclusion is felt: the ratio
// above 1.3, several times the ~7-10 % just-noticeable difference of a force held by the hand (Jones
// 1989, "Matching forces: constant errors and differential thresholds"). Measured: 0.01 % beside,
// 0.01 % over (the whole force vector too). The 5 %: the settled hand on the
// frog rests on the quasi-static force within 3.3 % (test_session.cpp's HandDevice test); the dwells
// are 0.8 s. The poke's slide stops at a tangential residual of 1e-3 (a few slides of ~10 s each).
// Before the contact slid, its isotropic spring held the point bonded part of the way, and the bonded
// poke was the reference (0.2 % and 2.4 %).
#include "core/contact/quasi_static_poke.hpp"
#include "core/tissue.hpp"
#include "fmi3/value_store.hpp"
#include "scenario/scenario.hpp"
#include "session/session.hpp"
#include "support/under_sanitizer.hpp"
#include "tissue_fmu/tissue_model.hpp"
#include "tissue_fmu/variables.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace tissue::host {
namespace {

const std::filesystem::path SCENARIOS = TISSUE_SCENARIO_DIR;
const std::filesystem::path FMUS = TISSUE_FMU_DIR;
constexpr double SETTLED_WINDOW_S = 0.4;  // the end of each dwell the forces are averaged over
constexpr double SHORTEST_DWELL_S = 0.6;

struct LogRow {
  double time_s = 0.0;
  Eigen::Vector3d tool_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  bool contact = false;
};

std::vector<LogRow> read_log(const std::filesystem::path& file) {
  std::ifstream log(file);
  std::string line;
  std::getline(log, line);  // header: time_s, device_xyz, tool_xyz, tool_mode, force_xyz, ...
  std::vector<LogRow> rows;
  while (std::getline(log, line)) {
    std::vector<double> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(std::stod(field));
    rows.push_back({fields.at(0), Eigen::Vector3d(fields.at(4), fields.at(5), fields.at(6)),
                    Eigen::Vector3d(fields.at(8), fields.at(9), fields.at(10)), fields.at(11) != 0.0});
  }
  return rows;
}

// Runs the scenario offline into a fresh temporary folder `name` and reads its log; empty (with a
// test failure) when the tissue reported an error or a NaN.
std::vector<LogRow> run_offline(const Scenario& scenario, const char* name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  SessionOptions options;
  options.offline = true;
  options.output_dir = dir;
  options.fmu_dir = FMUS;
  const SessionSummary summary = run_session(scenario, options);
  EXPECT_EQ(summary.tissue_errors, 0u) << summary.first_error;
  EXPECT_FALSE(summary.nan_detected);
  if (summary.tissue_errors != 0 || summary.nan_detected) return {};
  return read_log(dir / "log.csv");
}

// Where the scripted path holds still in probe mode for SHORTEST_DWELL_S or longer: the end times.
std::vector<double> dwell_ends_s(const DeviceConfig& device) {
  std::vector<double> ends;
  for (std::size_t k = 1; k < device.waypoints.size(); ++k) {
    const Waypoint& a = device.waypoints[k - 1];
    const Waypoint& b = device.waypoints[k];
    if (a.mode == ToolMode::probe && b.mode == ToolMode::probe && a.position == b.position &&
        b.time_s - a.time_s >= SHORTEST_DWELL_S) {
      ends.push_back(b.time_s);
    }
  }
  return ends;
}

struct Dwell {
  Eigen::Vector3d tool_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
};

Dwell settled(const std::vector<LogRow>& rows, double end_s) {
  Dwell mean;
  int count = 0;
  for (const LogRow& row : rows) {
    if (row.time_s < end_s - SETTLED_WINDOW_S || row.time_s >= end_s) continue;
    mean.tool_m += row.tool_m;
    mean.force_n += row.force_n;
    ++count;
  }
  EXPECT_GT(count, 0) << "no log rows before " << end_s << " s";
  mean.tool_m /= std::max(count, 1);
  mean.force_n /= std::max(count, 1);
  return mean;
}

// The scenario's tissue as the Tissue FMU builds it. Only the mesh is taken from the scenario's
// parameters: the test checks that the others cannot change the static equilibrium.
std::unique_ptr<Tissue> scenario_tissue(const Scenario& scenario) {
  const fmi3::ModelDescription& description = tissue_fmu::tissue_model_description();
  fmi3::ValueStore values(description);
  values.set_starts();
  for (const ParameterSetting& p : scenario.tissue_parameters) {
    if (p.name == "mesh") {
      const char* path = std::get<std::string>(p.value).c_str();
      values.write<const char*>(*description.find("mesh"), std::span<const char* const>(&path, 1));
    } else {
      // K_c's settings (contact.stiffness*) change what the haptic loop renders between samples,
      // not the tissue's equilibrium.
      // What is drawn (surface.renderSurface) is not part of the dynamics (TissueSettings::render_surface).
      EXPECT_TRUE(p.name == "stepSize" || p.name.starts_with("integrator.") || p.name.starts_with("contact.stiffness") ||
                  p.name == "surface.renderSurface")
          << p.name << " may change the statics";
    }
  }
  return tissue_fmu::make_tissue(values, scenario.file.parent_path().string());
}

// The material point of the top surface straight below `point_m` at rest (the vertical line through it
// meets the upward-facing triangle there): the point a probe pressed straight down holds.
SurfacePoint point_below(const Tissue& tissue, const Eigen::Vector3d& point_m) {
  const SurfacePoint below = surface_point_below(point_m, tissue.surface().triangles, tissue.current_positions_m());
  EXPECT_GE(below.triangle, 0) << "no surface above or below (" << point_m.transpose() << ")";
  return below;
}

TEST(Palpation, TheHandFeelsTheInclusionByTheRatioTheQuasiStaticPokesPredict) {
  if (test::UNDER_SANITIZER) GTEST_SKIP() << "the 52k-tet organ takes minutes under a sanitizer";
  Scenario scenario = load_scenario(SCENARIOS / "palpate_liver.toml");
  const std::vector<double> ends = dwell_ends_s(scenario.device);
  ASSERT_EQ(ends.size(), 2u) << "the scenario dwells beside the inclusion, then over it";
  scenario.duration_s = ends.back() + 0.1;  // the sweep that follows is the figure's, not this test's

  const std::vector<LogRow> rows = run_offline(scenario, "tissue_host_test_palpation");
  ASSERT_FALSE(rows.empty());

  const std::unique_ptr<Tissue> tissue = scenario_tissue(scenario);
  const double spring_n_per_m = tissue->contact_spring_stiffness_n_per_m();
  std::vector<double> rendered, predicted;  // normal forces [N]
  for (const double end_s : ends) {
    const Dwell dwell = settled(rows, end_s);
    const Eigen::Vector3d held_m = dwell.tool_m + dwell.force_n / spring_n_per_m;
    DeformableBody body(tissue->body().mesh(), tissue->settings().body);
    QuasiStaticPokeSettings poke_settings;
    poke_settings.force_tolerance = 1e-8;
    poke_settings.friction = PokeFriction::frictionless;  // the contact slides (point_contact.hpp)
    poke_settings.tangential_tolerance = 1e-3;
    const QuasiStaticPoke poke =
        quasi_static_poke(body, tissue->surface().triangles, point_below(*tissue, held_m), held_m, poke_settings);
    ASSERT_TRUE(poke.converged) << "the poke to (" << held_m.transpose() << ") m";
    rendered.push_back(dwell.force_n.dot(poke.normal));
    predicted.push_back(poke.force_on_tool_n.dot(poke.normal));
    std::printf(
        "  dwell ending %.2f s at (%.2f, %.2f, %.2f) mm: rendered (%.3f, %.3f, %.3f) N, poke (%.3f, %.3f, %.3f) N; "
        "normal %.4f N against %.4f N\n",
        end_s, 1e3 * held_m.x(), 1e3 * held_m.y(), 1e3 * held_m.z(), dwell.force_n.x(), dwell.force_n.y(),
        dwell.force_n.z(), poke.force_on_tool_n.x(), poke.force_on_tool_n.y(), poke.force_on_tool_n.z(),
        rendered.back(), predicted.back());
  }
  // [0] beside the inclusion, [1] over it.
  const double rendered_ratio = rendered[1] / rendered[0];
  const double predicted_ratio = predicted[1] / predicted[0];
  std::printf("  over / beside: rendered %.3f, quasi-static pokes %.3f\n", rendered_ratio, predicted_ratio);
  EXPECT_GT(predicted_ratio, 1.3) << "the inclusion is ten times stiffer: it must be felt";
  EXPECT_NEAR(rendered_ratio, predicted_ratio, 0.05 * predicted_ratio);
  for (std::size_t k = 0; k < rendered.size(); ++k) {
    EXPECT_NEAR(rendered[k], predicted[k], 0.05 * predicted[k]) << (k == 0 ? "beside" : "over");
  }
}

// The probe slides (issue 42, item 4), the loop closed: host/scenarios/slide_frog.toml's loosely held
// hand (0.2 kg, 1 N s/m) slides the probe 2 mm deep along the frog's back at 30 mm/s. Over the
// slide (from 0.1 s after it starts to its end) the contact must hold at every tick, and the force
// along the path must be what the back's slope explains: along the path's normal (-s, 0, 1) (s its
// dz/dx between waypoints), |f . t| <= 10 % of |f| at the 95th percentile of the ticks and 5 % at the
// median (measured 4.3 % and 2.1 %; the largest, 14 %, where the scripted path bends at a waypoint and
// the hand's does not). With the isotropic contact spring the tissue dragged 16-39 % of |f| on the frog
// (tests/physics/test_sliding_probe.cpp).
TEST(Palpation, AHandSlidingOverTheFrogFeelsTheSlopeAndKeepsTheContact) {
  const Scenario scenario = load_scenario(SCENARIOS / "slide_frog.toml");
  const std::vector<Waypoint>& path = scenario.device.waypoints;
  ASSERT_GE(path.size(), 5u);
  const double start_s = path[2].time_s + 0.1;  // pressed, held, then the slide
  const double end_s = path[path.size() - 2].time_s;

  const std::vector<LogRow> rows = run_offline(scenario, "tissue_host_test_slide_frog");
  const auto slope_at = [&](double x_m) {
    for (std::size_t k = 3; k + 1 < path.size(); ++k) {
      const Waypoint& a = path[k - 1];
      const Waypoint& b = path[k];
      if (std::min(a.position[0], b.position[0]) <= x_m && x_m <= std::max(a.position[0], b.position[0])) {
        return (b.position[2] - a.position[2]) / (b.position[0] - a.position[0]);
      }
    }
    return 0.0;
  };
  std::vector<double> off;
  int lost = 0;
  for (const LogRow& row : rows) {
    if (row.time_s < start_s || row.time_s > end_s) continue;
    if (!row.contact) ++lost;
    const double s = slope_at(row.tool_m.x());
    const Eigen::Vector3d along = Eigen::Vector3d(1.0, 0.0, s).normalized();
    if (row.force_n.norm() > 0.0) off.push_back(std::abs(row.force_n.dot(along)) / row.force_n.norm());
  }
  ASSERT_GT(off.size(), 800u);  // 0.9 s of 1 kHz ticks
  std::sort(off.begin(), off.end());
  const double median = off[off.size() / 2];
  const double p95 = off[off.size() * 95 / 100];
  std::printf("  %zu ticks: |f . t| / |f| median %.3f, p95 %.3f, max %.3f; contact lost at %d ticks\n", off.size(),
              median, p95, off.back(), lost);
  EXPECT_EQ(lost, 0);
  EXPECT_LT(median, 0.05);
  EXPECT_LT(p95, 0.10);
}

}  // namespace
}  // namespace tissue::host
