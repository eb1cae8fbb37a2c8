// tissue-host's sessions (host/session) on the built Tissue.fmu and HapticLoop.fmu:
// * every scenario in host/scenarios runs offline with the cut counts it expects, the device force
//   never above the device's maximum, no NaN, and two offline runs write byte-identical logs and
//   frames;
// * a recorded session replayed offline is the same session;
// * the threaded real-time path runs a short session with both threads (under the tsan preset this
//   is the data-race check);
// * scenario files with mistakes are refused naming the key.
#include "scenario/scenario.hpp"
#include "session/session.hpp"
#include "links/fmu_links.hpp"
#include "host/vtu_read.hpp"
#include "support/under_sanitizer.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <thread>
#include <variant>
#include <vector>

namespace tissue::host {
namespace {

const std::filesystem::path SCENARIOS = TISSUE_SCENARIO_DIR;
const std::filesystem::path FMUS = TISSUE_FMU_DIR;

std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("tissue_host_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

std::string contents(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

SessionSummary run_offline(const Scenario& scenario, const std::filesystem::path& dir,
                           std::optional<std::filesystem::path> record = std::nullopt) {
  SessionOptions options;
  options.offline = true;
  options.output_dir = dir;
  options.fmu_dir = FMUS;
  options.record = std::move(record);
  return run_session(scenario, options);
}

// The largest change of the device force from one tick to the next in log.csv [N].
double largest_force_step_n(const std::filesystem::path& log_file) {
  std::ifstream log(log_file);
  std::string line;
  std::getline(log, line);  // header
  std::array<double, 3> previous{};
  double largest = 0.0;
  while (std::getline(log, line)) {
    std::vector<double> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(std::stod(field));
    const std::array<double, 3> force{fields.at(8), fields.at(9), fields.at(10)};
    largest = std::max(largest, std::hypot(force[0] - previous[0], force[1] - previous[1], force[2] - previous[2]));
    previous = force;
  }
  return largest;
}

// Every frame file and the logs of two runs, byte for byte.
void expect_same_outputs(const std::filesystem::path& a, const std::filesystem::path& b) {
  EXPECT_EQ(contents(a / "log.csv"), contents(b / "log.csv"));
  EXPECT_EQ(contents(a / "surface.pvd"), contents(b / "surface.pvd"));
  std::vector<std::string> frames;
  for (const auto& entry : std::filesystem::directory_iterator(a / "frames")) {
    frames.push_back(entry.path().filename().string());
  }
  ASSERT_FALSE(frames.empty());
  for (const std::string& frame : frames) {
    EXPECT_EQ(contents(a / "frames" / frame), contents(b / "frames" / frame)) << frame;
  }
  EXPECT_EQ(contents(a / "final.png"), contents(b / "final.png"));
}

class EveryScenario : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryScenario, RunsOfflineAsExpectedAndReproducibly) {
  if (test::UNDER_SANITIZER && (GetParam() == "cut_organ" || GetParam() == "resect_lobe")) {
    GTEST_SKIP() << "the organ and its 82k-triangle surface take minutes under a sanitizer; the release run checks it";
  }
  const Scenario scenario = load_scenario(SCENARIOS / (GetParam() + ".toml"));
  const std::filesystem::path first = fresh_dir(GetParam() + "_1"), second = fresh_dir(GetParam() + "_2");
  const SessionSummary a = run_offline(scenario, first);
  EXPECT_FALSE(a.nan_detected);
  EXPECT_EQ(a.tissue_errors, 0u) << a.first_error;
  EXPECT_EQ(a.haptic_errors, 0u);
  EXPECT_LE(a.max_device_force_n, a.device_max_force_n + 1e-12);
  if (scenario.expect.min_cut_tets) {
    EXPECT_GE(a.cut_tets, *scenario.expect.min_cut_tets);
  }
  if (scenario.expect.max_cut_tets) {
    EXPECT_LE(a.cut_tets, *scenario.expect.max_cut_tets);
  }
  if (scenario.expect.contact) {
    EXPECT_EQ(a.contact_seen, *scenario.expect.contact);
  }
  EXPECT_GT(a.frames_written, 0u);
  // No kick, whatever the hand or the cuts do: the HapticLoop's rate limit (device.maxForceRate, as
  // the session read it back) over a 1 ms tick, plus rounding.
  EXPECT_GT(a.device_max_force_rate_n_per_s, 0.0);
  EXPECT_LE(largest_force_step_n(first / "log.csv"), a.device_max_force_rate_n_per_s * 1e-3 + 1e-9);
  EXPECT_TRUE(std::filesystem::exists(first / "summary.json"));
  // The second run checks reproducibility, which the release run does; under a sanitizer it would
  // run the same code again (a quarter of the sanitizer suite's host time).
  if (test::UNDER_SANITIZER) return;
  const SessionSummary b = run_offline(scenario, second);
  EXPECT_EQ(b.cut_tets, a.cut_tets);
  expect_same_outputs(first, second);
}

INSTANTIATE_TEST_SUITE_P(HostScenarios, EveryScenario,
                         ::testing::Values("poke_frog", "cut_frog_complete", "cut_frog_partial", "beam_two_cuts",
                                           "careless_hand", "cantilever_release", "hand_press_frog", "hand_cut_frog",
                                           "x_cut_frog", "flap_frog", "cut_organ", "resect_lobe"));

// The values of a VTU frame's DataArray `name` (binary or ASCII).
std::vector<double> vtu_array(const std::filesystem::path& file, const std::string& array_name) {
  const std::string text = contents(file);
  const std::size_t name = text.find("Name=\"" + array_name + "\"");
  const std::size_t open = text.rfind("<DataArray", name);
  const std::size_t body = text.find('>', name) + 1;
  const std::string tag = text.substr(open, body - open);
  const auto attribute = [&](const std::string& key) {
    const std::size_t at = tag.find(key + "=\"") + key.size() + 2;
    return tag.substr(at, tag.find('"', at) - at);
  };
  return vtu_read::data_array_values(attribute("type"), attribute("format"),
                                     std::string_view(text).substr(body, text.find("</DataArray>", body) - body));
}

// The triangles of a VTU frame (its connectivity).
std::vector<std::uint32_t> vtu_triangles(const std::filesystem::path& file) {
  const std::vector<double> values = vtu_array(file, "connectivity");
  return {values.begin(), values.end()};
}

// The volume a VTU frame's closed triangle surface encloses (divergence theorem). [m^3]
double vtu_enclosed_m3(const std::filesystem::path& file) {
  const std::vector<double> x = vtu_array(file, "Points");
  const std::vector<std::uint32_t> triangles = vtu_triangles(file);
  double volume_m3 = 0.0;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const double* a = &x[3 * triangles[t]];
    const double* b = &x[3 * triangles[t + 1]];
    const double* c = &x[3 * triangles[t + 2]];
    volume_m3 +=
        (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0])) /
        6.0;
  }
  return volume_m3;
}

// Border edges (directed edges without their twin), directed edges used twice, and connected pieces
// of a triangle surface.
struct SurfaceShape {
  std::size_t border = 0, repeated = 0;
  long pieces = 0;
};

SurfaceShape shape_of(const std::vector<std::uint32_t>& triangles) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  std::vector<std::uint32_t> root(*std::max_element(triangles.begin(), triangles.end()) + 1);
  std::iota(root.begin(), root.end(), 0u);
  const auto find = [&](std::uint32_t v) {
    while (root[v] != v) v = root[v] = root[root[v]];
    return v;
  };
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      ++directed[{triangles[t + k], triangles[t + (k + 1) % 3]}];
      root[find(triangles[t + k])] = find(triangles[t + (k + 1) % 3]);
    }
  }
  SurfaceShape shape;
  for (const auto& [edge, count] : directed) {
    shape.border += directed.contains({edge.second, edge.first}) ? 0 : 1;
    shape.repeated += count > 1 ? 1 : 0;
  }
  std::vector<bool> is_root(root.size(), false);
  for (const std::uint32_t v : triangles) is_root[find(v)] = true;
  shape.pieces = std::count(is_root.begin(), is_root.end(), true);
  return shape;
}

// A session's frames (dir/frames, in time order), each checked drawn closed: no border edge and no
// directed edge used twice.
std::vector<std::filesystem::path> frames_drawn_closed(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> frames;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "frames")) frames.push_back(entry.path());
  std::sort(frames.begin(), frames.end());
  for (const std::filesystem::path& frame : frames) {
    const SurfaceShape shape = shape_of(vtu_triangles(frame));
    EXPECT_EQ(shape.border, 0u) << frame.filename();
    EXPECT_EQ(shape.repeated, 0u) << frame.filename();
  }
  return frames;
}

// The complete cut with the frog's render surface switched on (the scenario's surface.renderSurface):
// every frame, while the blade is in the body and after, is the fine surface closed and consistently
// oriented (every directed edge has its twin, none is used twice); the last (more than its 23240
// triangles: split and capped) is in two pieces. Two cap failures this test caught: a border vertex
// the split left on the opening with material on one side (a pass-through, not a crack tip) left
// the held half's opening uncapped (226 border edges in the last frame); and a crack tip smeared
// over split points on no piece's side (the front meeting the surface obliquely) left the slit's
// walls uncapped at 1.8 s (97).
// The recording keeps the scenario's frame rate: a frame every 1/rate of simulated time (it wrote
// one every two periods, 31 frames for 2 s at 30 Hz, before the fix).
TEST(Frames, TheRecordingKeepsTheScenariosFrameRate) {
  Scenario scenario = load_scenario(SCENARIOS / "poke_frog.toml");
  ASSERT_EQ(scenario.frame_rate_hz, 30.0);
  ASSERT_EQ(scenario.duration_s, 2.0);
  const SessionSummary s = run_offline(scenario, fresh_dir("frame_rate"));
  EXPECT_GE(s.frames_written, 60u);  // frames at 0, 1/30, ..., 2 s: 60 or 61 by where the run ends
  EXPECT_LE(s.frames_written, 61u);
}

TEST(ScenarioFile, TheSlicerScenarioListensForOpenIgtlinkInMillimetres) {
  const Scenario scenario = load_scenario(SCENARIOS / "slicer_frog.toml");
  EXPECT_EQ(scenario.device.kind, DeviceKind::openigtlink);
  ASSERT_TRUE(scenario.openigtlink.has_value());
  EXPECT_EQ(scenario.openigtlink->address, "127.0.0.1");
  EXPECT_EQ(scenario.openigtlink->port, 18944);
  EXPECT_EQ(scenario.openigtlink->length_unit_m, 0.001);
  EXPECT_EQ(scenario.openigtlink->probe_transform, "ProbeToTissue");
}

// Whether the stroke separates the sagging frog is issue 41's: under the converged defaults (issue
// 40) the front sags as the blade passes and hangs by the last uncut tets at the back, as it does
// with exact solves; the Jacobi step of before left the body nearly still, so it fell in two.
TEST(RenderSurface, TheCompleteCutDrawsTheFrogClosedInEveryFrame) {
  const Scenario scenario = load_scenario(SCENARIOS / "cut_frog_complete.toml");
  const std::filesystem::path dir = fresh_dir("render_complete");
  const SessionSummary s = run_offline(scenario, dir);
  ASSERT_GT(s.cut_tets, 50u);
  const std::vector<std::filesystem::path> frames = frames_drawn_closed(dir);
  ASSERT_GT(frames.size(), 40u);
  const std::vector<std::uint32_t> triangles = vtu_triangles(frames.back());
  EXPECT_GT(triangles.size(), 3u * 23240u);  // the uncut frog's triangles and the cut faces'

  // What is drawn changes nothing else: with the tet skin the session's log (tool, forces, tissue
  // state per tick) is the same bytes. (The scripted path once followed the drawn surface's box.)
  Scenario skin = scenario;
  const auto render = std::find_if(skin.tissue_parameters.begin(), skin.tissue_parameters.end(),
                                   [](const ParameterSetting& p) { return p.name == "surface.renderSurface"; });
  ASSERT_NE(render, skin.tissue_parameters.end());
  render->value = std::string("none");
  const std::filesystem::path skin_dir = fresh_dir("render_complete_skin");
  const SessionSummary t = run_offline(skin, skin_dir);
  EXPECT_EQ(t.cut_tets, s.cut_tets);
  EXPECT_TRUE(contents(skin_dir / "log.csv") == contents(dir / "log.csv")) << "the logs differ";
}

// The X and the flap (partial cuts crossing and ending inside, on the sagging frog) draw the render
// surface closed in every frame (issue 41: before, their loops stayed open and they drew the tet skin).
class CrossingCutsScenario : public ::testing::TestWithParam<const char*> {};
TEST_P(CrossingCutsScenario, DrawsTheRenderSurfaceClosedInEveryFrame) {
  const Scenario scenario = load_scenario(SCENARIOS / (std::string(GetParam()) + ".toml"));
  const std::filesystem::path dir = fresh_dir(std::string("render_") + GetParam());
  const SessionSummary s = run_offline(scenario, dir);
  ASSERT_GT(s.cut_tets, 50u);
  const std::vector<std::filesystem::path> frames = frames_drawn_closed(dir);
  ASSERT_GT(frames.size(), 40u);
  EXPECT_GT(vtu_triangles(frames.back()).size(), 3u * 23240u);  // the render surface, not the skin
}
INSTANTIATE_TEST_SUITE_P(HostScenarios, CrossingCutsScenario, ::testing::Values("x_cut_frog", "flap_frog"));

// The careless hand's 10 + 10 hatched strokes through the frog sagging on its tray (docs/hatched_frog.toml,
// the picture in docs/BENCHMARKS.md): the render surface closed in every frame (issue 41, item 4;
// once 7 of its 96 frames had border or repeated edges where strokes passed closer than a tet).
TEST(HatchedFrogScenario, DrawsTheRenderSurfaceClosedInEveryFrame) {
  const Scenario scenario = load_scenario(SCENARIOS.parent_path().parent_path() / "docs" / "hatched_frog.toml");
  const std::filesystem::path dir = fresh_dir("render_hatched_frog");
  const SessionSummary s = run_offline(scenario, dir);
  ASSERT_GT(s.cut_tets, 1000u);
  const std::vector<std::filesystem::path> frames = frames_drawn_closed(dir);
  ASSERT_GT(frames.size(), 90u);
}

// The same strokes on neighbouring trajectories (Young's modulus 3% and 5% higher: other tets cut,
// pieces free at other steps; tests/bench/hatched_closure.py): where a later stroke crosses an
// earlier one within tets at rest, the chain walk leaves holes (through `import tissue` 518 and 554
// border edges at the end, and open from step 563 and 297 on). They are now filled by their cuts'
// faces where the part then encloses its simulated volume (or the faces bound the solid they close
// as drawn: python/tests/test_scenario.py, x 1.08). Closed in every frame, and the last frame
// encloses the first's volume to 10%: the blade takes no material (the sagging body's strain and the
// surface's bulge over the tets move it by ~4%), while a sheet through a piece took 20-90% of its
// part where the 30 + 30 hatching's holes were filled unchecked.
class HatchedFrogNeighbours : public ::testing::TestWithParam<double> {};
TEST_P(HatchedFrogNeighbours, DrawTheRenderSurfaceClosedInEveryFrame) {
  Scenario scenario = load_scenario(SCENARIOS.parent_path().parent_path() / "docs" / "hatched_frog.toml");
  const auto young = std::find_if(scenario.tissue_parameters.begin(), scenario.tissue_parameters.end(),
                                  [](const ParameterSetting& p) { return p.name == "material.youngModulus"; });
  ASSERT_NE(young, scenario.tissue_parameters.end());
  young->value = std::get<double>(young->value) * GetParam();
  const std::filesystem::path dir = fresh_dir("render_hatched_frog_" + std::to_string(std::lround(100 * GetParam())));
  const SessionSummary s = run_offline(scenario, dir);
  ASSERT_GT(s.cut_tets, 1000u);
  const std::vector<std::filesystem::path> frames = frames_drawn_closed(dir);
  ASSERT_GT(frames.size(), 90u);
  EXPECT_NEAR(vtu_enclosed_m3(frames.back()) / vtu_enclosed_m3(frames.front()), 1.0, 0.1);
}
// x 0.93 and x 1.02 drew one edge with four triangles (a cut's loop passing a surface vertex twice,
// clipped whole); x 1.06 ended at 1.32 times the first frame's volume (a parked piece swelling as it
// fell: its rows solved only to the real-time cap), and with that fixed 13 of 21 trajectories drew
// the four-triangle edge. All 21 (x 0.93 ... 1.13) pass; these five run in the suite.
INSTANTIATE_TEST_SUITE_P(YoungModulusScaled, HatchedFrogNeighbours, ::testing::Values(0.93, 1.02, 1.03, 1.05, 1.06));

// The hand's figures reach the summary (device kind "hand"): a hand pressing the frog was in contact,
// and the device's force did work on it.
// A scalpel drawn by a hand through the frog (E = 1 MPa): the stroke cuts through although the
// cutting force holds the blade back, and that force only resists: it takes work from the hand
// (the device's work on the hand is negative), never gives it.
TEST(HandDevice, AHandDrawnScalpelCutsThroughAndTheBladeTakesWorkFromTheHand) {
  const Scenario scenario = load_scenario(SCENARIOS / "hand_cut_frog.toml");
  const SessionSummary s = run_offline(scenario, fresh_dir("hand_cut"));
  ASSERT_TRUE(s.hand.has_value());
  EXPECT_GE(s.cut_tets, 50u);
  EXPECT_LT(s.hand->device_work_j, 0.0);
  EXPECT_FALSE(s.nan_detected);
}

TEST(HandDevice, TheSummarySaysHowTheHandMoved) {
  const Scenario scenario = load_scenario(SCENARIOS / "hand_press_frog.toml");
  EXPECT_EQ(scenario.device.kind, DeviceKind::hand);
  EXPECT_EQ(scenario.device.hand.grip_stiffness_n_per_m, 300.0);
  const std::filesystem::path dir = fresh_dir("hand_press");
  const SessionSummary s = run_offline(scenario, dir);
  ASSERT_TRUE(s.hand.has_value());
  EXPECT_TRUE(s.contact_seen);
  EXPECT_NE(s.hand->device_work_j, 0.0);
  EXPECT_NEAR(s.hand->window_s, 1.0, 1e-9);
  const nlohmann::json summary = nlohmann::json::parse(contents(dir / "summary.json"));
  ASSERT_TRUE(summary.contains("hand"));
  EXPECT_EQ(summary["hand"]["device_work_J"].get<double>(), s.hand->device_work_j);
}

// The mean device force over the last `window_s` of log.csv [N].
std::array<double, 3> mean_force_n(const std::filesystem::path& log_file, double window_s) {
  std::ifstream log(log_file);
  std::string line;
  std::getline(log, line);                  // header
  std::vector<std::array<double, 4>> rows;  // time, force
  while (std::getline(log, line)) {
    std::vector<double> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(std::stod(field));
    rows.push_back({fields.at(0), fields.at(8), fields.at(9), fields.at(10)});
  }
  std::array<double, 3> sum{};
  int count = 0;
  for (const auto& r : rows) {
    if (r[0] < rows.back()[0] - window_s) continue;
    for (std::size_t a = 0; a < 3; ++a) sum[a] += r[a + 1];
    ++count;
  }
  for (double& x : sum) x /= count;
  return sum;
}

// Issue 20: a hand (0.2 kg, 2 N s/m, gripping its path at 300 N/m) presses the frog's back 5 mm and
// holds, on the frog as shipped (E = 100 kPa) and ten times stiffer and more viscous (1 MPa,
// damping.beta 10 ms: the contact ~10x stiffer, its viscous force ~100x larger). It settles within
// 0.5 s of the end of its path, and the force it rests on (the last of 4 s) is the tissue's
// quasi-static force there: a scripted tool taken to where the hand rests and held for 8 s feels the
// same force, to the tolerance of the contact tests for the default contact spring, 1.5 k_n / k <=
// 1.5 x 2.2 / 100 = 3.3% (ContactDynamics, test_contact_dynamics.cpp, which also shows that the
// settled dynamic contact is the full model's frictionless quasi-static poke). Measured 0.07% and
// 0.9%; the held tool needs the 8 s at 1 MPa because a tangential load relaxes slowly under the
// isotropic contact spring (point_contact.hpp).
TEST(HandDevice, AHandPressingTheFrogSettlesOnTheQuasiStaticForce) {
  for (const bool stiff : {false, true}) {
    Scenario scenario = load_scenario(SCENARIOS / "hand_press_frog.toml");
    scenario.duration_s = 4.0;
    if (stiff) {
      scenario.tissue_parameters.push_back({"material.youngModulus", 1e6});
      scenario.tissue_parameters.push_back({"damping.beta", 0.01});
    }
    const std::filesystem::path dir = fresh_dir(stiff ? "hand_press_stiff" : "hand_press_soft");
    const SessionSummary s = run_offline(scenario, dir);
    ASSERT_TRUE(s.hand.has_value());
    const double path_end_s = scenario.device.waypoints.back().time_s;
    EXPECT_LE(s.hand->settle_time_s - path_end_s, 0.5) << (stiff ? "1 MPa" : "100 kPa");
    EXPECT_LT(s.hand->residual_speed_m_per_s, 1e-3);

    Scenario held = scenario;
    held.device.kind = DeviceKind::scripted;
    held.duration_s = 8.0;
    const std::array<double, 3> rest = s.hand->mean_position_m;
    Waypoint above;
    above.position = {rest[0], rest[1], rest[2] + 0.01};
    above.mode = ToolMode::probe;
    Waypoint there = above;
    there.time_s = 0.5;
    there.position = rest;
    Waypoint hold = there;
    hold.time_s = held.duration_s;
    held.device.waypoints = {above, there, hold};
    const std::filesystem::path held_dir = fresh_dir(stiff ? "held_stiff" : "held_soft");
    (void)run_offline(held, held_dir);
    const std::array<double, 3> quasi_static = mean_force_n(held_dir / "log.csv", 0.5);
    const std::array<double, 3>& hand = s.hand->mean_force_n;
    const double difference =
        std::hypot(hand[0] - quasi_static[0], hand[1] - quasi_static[1], hand[2] - quasi_static[2]);
    const double magnitude = std::hypot(quasi_static[0], quasi_static[1], quasi_static[2]);
    std::printf("  %s: settled %.3f s after the path, residual %.3g mm/s; hand %.4f N, held %.4f N: %.2f%%\n",
                stiff ? "1 MPa" : "100 kPa", s.hand->settle_time_s - path_end_s, 1e3 * s.hand->residual_speed_m_per_s,
                std::hypot(hand[0], hand[1], hand[2]), magnitude, 100.0 * difference / magnitude);
    EXPECT_LE(difference, 0.033 * magnitude);
  }
}

TEST(Replay, ARecordedSessionReplayedIsTheSameSession) {
  const Scenario scripted = load_scenario(SCENARIOS / "cut_frog_partial.toml");
  const std::filesystem::path recorded = fresh_dir("recorded"), replayed = fresh_dir("replayed");
  std::filesystem::create_directories(recorded);
  const std::filesystem::path recording = recorded / "hand.csv";
  const SessionSummary original = run_offline(scripted, recorded, recording);
  Scenario replay = scripted;
  replay.device = DeviceConfig{};
  replay.device.kind = DeviceKind::replay;
  replay.device.replay_file = recording;
  const SessionSummary again = run_offline(replay, replayed);
  EXPECT_EQ(again.cut_tets, original.cut_tets);
  EXPECT_GT(original.cut_tets, 0u);
  EXPECT_EQ(contents(recorded / "log.csv"), contents(replayed / "log.csv"));
}

TEST(RealTime, BothThreadsRunAShortSessionOnTheirDeadlines) {
  Scenario scenario = load_scenario(SCENARIOS / "poke_frog.toml");
  scenario.duration_s = 0.6;
  scenario.write_png = false;
  SessionOptions options;
  options.output_dir = fresh_dir("realtime");
  options.fmu_dir = FMUS;
  options.realtime_priority = false;
  const SessionSummary s = run_session(scenario, options);
  EXPECT_EQ(s.haptic_ticks, 600u);
  EXPECT_FALSE(s.nan_detected);
  EXPECT_EQ(s.haptic_errors, 0u);
  EXPECT_EQ(s.tissue_errors, 0u) << s.first_error;
  EXPECT_GT(s.tissue_steps, 0u);
  EXPECT_GT(s.wall_time_s, 0.59);  // it kept wall time (no sleeping would finish far sooner)
  EXPECT_LE(s.max_device_force_n, s.device_max_force_n + 1e-12);
  // Every tick was logged with its session time.
  std::ifstream log(options.output_dir / "log.csv");
  std::string line;
  std::size_t rows = 0;
  while (std::getline(log, line)) ++rows;
  EXPECT_EQ(rows, 601u);
  // slots.csv: a row per tissue step, saying slot by slot what the summary counts (whatever the
  // machine's load: the same run's two accounts of its overruns and frames agree).
  std::ifstream slots(options.output_dir / "slots.csv");
  ASSERT_TRUE(std::getline(slots, line));
  EXPECT_EQ(line, "slot,slots,start_late_ms,step_ms,sample_ms,frame,capture_ms,end_after_slot_ms");
  std::uint64_t steps = 0, overruns = 0, captured = 0, deferred = 0, last_slot = 0;
  while (std::getline(slots, line)) {
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    if (line.back() == ',') fields.emplace_back();
    ASSERT_EQ(fields.size(), 8u) << line;
    const std::uint64_t slot = std::stoull(fields[0]);
    if (steps > 0) {
      EXPECT_GT(slot, last_slot) << line;
    }
    last_slot = slot;
    ++steps;
    EXPECT_GE(std::stod(fields[3]), 0.0) << line;
    overruns += std::stod(fields[7]) > 0.0 ? 1 : 0;
    captured += fields[5].rfind("captured", 0) == 0 ? 1 : 0;
    deferred += fields[5].rfind("deferred", 0) == 0 ? 1 : 0;
  }
  EXPECT_EQ(steps, s.tissue_steps);
  EXPECT_EQ(overruns, s.tissue_overruns);
  EXPECT_EQ(captured, s.frames_written);
  EXPECT_EQ(deferred, s.frames_deferred);
}

TEST(RealTime, AStopRequestEndsTheRunWithItsOutputs) {
  // Ctrl-C in tissue-host sets SessionOptions::stop: the run ends at the next tick, and the
  // summary, the log and the picture cover the ticks run.
  Scenario scenario = load_scenario(SCENARIOS / "poke_frog.toml");
  scenario.duration_s = 30.0;
  SessionOptions options;
  options.output_dir = fresh_dir("stopped");
  options.fmu_dir = FMUS;
  options.realtime_priority = false;
  std::atomic<bool> stop{false};
  options.stop = &stop;
  // The 0.7 s count from the first tick, not from the call: under a sanitizer on a loaded machine
  // loading the FMUs took most of 0.7 s, and only 65 ticks had run when the stop came.
  std::atomic<bool> ticking{false};
  std::atomic<bool> returned{false};  // so that the stopper never waits for a run that did not tick
  options.haptic_thread_started = [&ticking] { ticking.store(true); };
  std::thread stopper([&stop, &ticking, &returned] {
    while (!ticking.load() && !returned.load()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
    stop.store(true);
  });
  SessionSummary s;
  try {
    s = run_session(scenario, options);
  } catch (...) {
    returned.store(true);
    stopper.join();
    throw;
  }
  returned.store(true);
  stopper.join();
  EXPECT_GT(s.haptic_ticks, 100u);
  EXPECT_LT(s.haptic_ticks, 10000u);  // not the 30000 of the scenario
  EXPECT_LT(s.wall_time_s, 10.0);
  EXPECT_EQ(s.tissue_errors, 0u);
  std::ifstream log(options.output_dir / "log.csv");
  std::string line;
  std::size_t rows = 0;
  while (std::getline(log, line)) ++rows;
  EXPECT_EQ(rows, s.haptic_ticks + 1);
  EXPECT_TRUE(std::filesystem::exists(options.output_dir / "summary.json"));
  EXPECT_TRUE(std::filesystem::exists(options.output_dir / "final.png"));
}

// Issue 44: a file that never ends (a device, a pipe) or is larger than MAX_SCENARIO_FILE_BYTES is
// refused after reading at most one byte more than the limit (before: read until memory ran out).
TEST(ScenarioFile, AFileBeyondTheLimitIsRefusedUnreadPastIt) {
  try {
    (void)load_scenario("/dev/zero");
    ADD_FAILURE() << "/dev/zero was accepted";
  } catch (const ScenarioError& error) {
    EXPECT_NE(std::string(error.what()).find("MAX_SCENARIO_FILE_BYTES"), std::string::npos) << error.what();
  }
}

TEST(ScenarioFile, MistakesAreRefusedNamingTheKey) {
  const auto refused = [](const std::string& text, const std::string& key) {
    try {
      (void)parse_scenario(text, "test.toml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const ScenarioError& error) {
      EXPECT_NE(std::string(error.what()).find(key), std::string::npos) << error.what();
    }
  };
  const std::string device = "\n[device]\nwaypoints = [ { t = 0.0, position = [0, 0, 0] } ]\n";
  refused("[scenario]\nduration = 1.0\n[device]\nkind = \"scripted\"\n", "device.waypoints");
  refused("[scenario]\nduration = -1.0\n" + device, "scenario.duration");
  // Found by fuzzing (issue 44): a count beyond what a double counts by one was cast (undefined).
  refused("[scenario]\nduration = 1.0\n[expect]\nmin_cut_tets = 1e300\n" + device, "expect.min_cut_tets");
  refused("[scenario]\nduration = 1.0\ncolour = 3\n" + device, "scenario.colour");
  refused("[scenario]\nduration = 1.0\n[tissue]\ncommunication_step = 0.0105\n" + device, "tissue.communication_step");
  refused(
      "[scenario]\nduration = 1.0\n[device]\nwaypoints = [ { t = 1.0, position = [0, 0, 0] }, "
      "{ t = 0.5, position = [0, 0, 0] } ]\n",
      "device.waypoints[1].t");
  refused("[scenario]\nduration = 1.0\n[device]\nwaypoints = [ { t = 0.0, position = [0, 0, 0], mode = \"knife\" } ]\n",
          "mode");
  refused("[scenario]\nduration = 1.0\n[device]\nkind = \"joystick\"\n", "device.kind");
  const std::string igtl = "[scenario]\nduration = 1.0\n[device]\nkind = \"openigtlink\"\n";
  refused(igtl + "[openigtlink]\nport = 70000\n", "openigtlink.port");
  refused(igtl + "[openigtlink]\nlength_unit = 0\n", "openigtlink.length_unit");
  refused(igtl + "[openigtlink]\nsurface_rate = -1\n", "openigtlink.surface_rate");
  refused(igtl + "[openigtlink]\nprobe = \"X\"\n", "openigtlink.probe");
  refused(igtl + "port = 18944\n", "device.port");
  refused("[scenario\nduration = 1.0\n", "test.toml:1");
  refused("[scenario]\nduration = 1.0\n[device]\nkind = \"udp\"\nport = 70000\n", "device.port");
  // A simulated hand's settings: refused with the key and the allowed range; only for a hand.
  const std::string hand =
      "[scenario]\nduration = 1.0\n[device]\nkind = \"hand\"\n"
      "waypoints = [ { t = 0.0, position = [0, 0, 0] } ]\n";
  refused(hand + "mass = 0.0\n", "test.toml: device.mass: must be in [0.010000, 10.000000] kg, got 0");
  refused(hand + "mass = nan\n", "device.mass: must be finite");
  refused(hand + "damping = -1\n", "device.damping: must be in [0.000000, 100.000000] N s/m");
  refused(hand + "grip_stiffness = 1e12\n", "device.grip_stiffness: must be in");
  refused(hand + "push = [0, 0, 1e3]\n", "device.push: each component must be in [-50.000000, 50.000000] N");
  refused(hand + "push = [0, 1]\n", "device.push: must be an array of 3 numbers");
  refused("[scenario]\nduration = 1.0\n[device]\nwaypoints = [ { t = 0.0, position = [0, 0, 0] } ]\nmass = 0.2\n",
          "device.mass: is for kind = \"hand\" only");
}

TEST(ScenarioFile, AParameterTheFmuRefusesStopsTheSessionBeforeItStarts) {
  Scenario scenario = load_scenario(SCENARIOS / "poke_frog.toml");
  scenario.tissue_parameters.push_back(ParameterSetting{"material.poissonRatio", 0.5});
  EXPECT_THROW((void)run_offline(scenario, fresh_dir("refused")), ScenarioError);
  scenario.tissue_parameters.back() = ParameterSetting{"material.colour", 1.0};
  EXPECT_THROW((void)run_offline(scenario, fresh_dir("refused")), ScenarioError);
}

// Our Tissue.fmu refreshes its contact stiffness in the background unless the scenario says
// otherwise; a tissue FMU of the user's is given only what the scenario says.
TEST(ScenarioFile, OurTissueRefreshesItsContactStiffnessInTheBackground) {
  const auto background = [](const Scenario& scenario) -> std::optional<decltype(ParameterSetting::value)> {
    for (const ParameterSetting& p : scenario.tissue_parameters) {
      if (p.name == "contact.stiffnessInBackground") return p.value;
    }
    return std::nullopt;
  };
  const std::string device = "\n[device]\nwaypoints = [ { t = 0.0, position = [0, 0, 0] } ]\n";
  const Scenario ours = parse_scenario("[scenario]\nduration = 1.0\n" + device, "test.toml");
  ASSERT_TRUE(background(ours).has_value());
  EXPECT_EQ(std::get<bool>(*background(ours)), true);
  const Scenario asked = parse_scenario(
      "[scenario]\nduration = 1.0\n[tissue.parameters]\n\"contact.stiffnessInBackground\" = false\n" + device,
      "test.toml");
  ASSERT_TRUE(background(asked).has_value());
  EXPECT_EQ(std::get<bool>(*background(asked)), false);
  const Scenario theirs = parse_scenario("[scenario]\nduration = 1.0\n[tissue]\nfmu = \"Other.fmu\"\n" + device,
                                         std::filesystem::temp_directory_path() / "test.toml");
  EXPECT_FALSE(background(theirs).has_value());
}

TEST(ScenarioFile, TheMouseNeedsTheLiveViewInRealTime) {
  // frog_mouse.toml's device is the browser: offline, or without --view, nothing could drive it.
  const Scenario scenario = load_scenario(SCENARIOS / "frog_mouse.toml");
  EXPECT_EQ(scenario.device.kind, DeviceKind::browser);
  EXPECT_THROW((void)run_offline(scenario, fresh_dir("mouse_offline")), ScenarioError);
  SessionOptions options;
  options.output_dir = fresh_dir("mouse_viewless");
  options.fmu_dir = FMUS;
  options.realtime_priority = false;
  EXPECT_THROW((void)run_session(scenario, options), ScenarioError);
  options.view = SessionOptions::View{"0.0.0.0", 0, "", ""};  // beyond loopback without a token
  EXPECT_THROW((void)run_session(scenario, options), ScenarioError);
}

}  // namespace
}  // namespace tissue::host

namespace tissue::host {
namespace {

// [tissue] render_surface = "file" (issue 42): an OBJ next to the scenario, given to the Tissue FMU as
// surface.renderSurface with its absolute path (the FMU would read a relative one in its resources).
TEST(ScenarioRenderSurface, AFileNextToTheScenarioIsGivenByItsAbsolutePath) {
  const std::string head =
      "[scenario]\nduration = 1\n[device]\nkind = \"scripted\"\n"
      "waypoints = [{ t = 0.0, position = [0, 0, 0.1], mode = \"none\" }]\n";
  const std::string scenario_file = (SCENARIOS / "render.toml").string();
  const Scenario scenario =
      parse_scenario(head + "[tissue]\nrender_surface = \"../../meshes/liver_surface.obj\"\n", scenario_file);
  const auto surface = std::find_if(scenario.tissue_parameters.begin(), scenario.tissue_parameters.end(),
                                    [](const ParameterSetting& p) { return p.name == "surface.renderSurface"; });
  ASSERT_NE(surface, scenario.tissue_parameters.end());
  const std::filesystem::path path = std::get<std::string>(surface->value);
  EXPECT_TRUE(path.is_absolute()) << path;
  EXPECT_TRUE(std::filesystem::equivalent(path, SCENARIOS / ".." / ".." / "meshes" / "liver_surface.obj")) << path;
  // No such file, or given twice: refused, naming the key.
  for (const std::string& bad :
       {std::string("[tissue]\nrender_surface = \"no_such_surface.obj\"\n"),
        std::string("[tissue]\nrender_surface = \"../../meshes/liver_surface.obj\"\n[tissue.parameters]\n"
                    "\"surface.renderSurface\" = \"frog\"\n")}) {
    try {
      (void)parse_scenario(head + bad, scenario_file);
      ADD_FAILURE() << "taken: " << bad;
    } catch (const ScenarioError& error) {
      EXPECT_NE(std::string(error.what()).find("tissue.render_surface"), std::string::npos) << error.what();
    }
  }
}

// [tissue.regions.NAME] (issue 25) becomes the Tissue FMU's material.regions, in its own grammar.
TEST(ScenarioRegions, ARegionsTableBecomesTheTissuesMaterialRegions) {
  const std::string head =
      "[scenario]\nduration = 1\n[device]\nkind = \"scripted\"\n"
      "waypoints = [{ t = 0.0, position = [0, 0, 0.1], mode = \"none\" }]\n";
  const Scenario scenario = parse_scenario(
      head +
          "[tissue.regions.tumour]\nyoungModulus = 1e6\ndensity = 1100\n[tissue.regions.skin]\npoissonRatio = 0.45\n"
          "dampingAlpha = 4\n",
      "regions.toml");
  const auto regions = std::find_if(scenario.tissue_parameters.begin(), scenario.tissue_parameters.end(),
                                    [](const ParameterSetting& p) { return p.name == "material.regions"; });
  ASSERT_NE(regions, scenario.tissue_parameters.end());
  // The FMU's grammar (parse_region_materials; BadUse.RegionMaterialsAreSetByName... reads it there),
  // tables and keys in TOML's (sorted) order.
  EXPECT_EQ(std::get<std::string>(regions->value),
            "skin: dampingAlpha=4, poissonRatio=0.45; tumour: density=1100, youngModulus=1e+06");
  try {
    parse_scenario(head + "[tissue.regions.tumour]\nstiffness = 1e6\n", "regions.toml");
    ADD_FAILURE() << "an unknown key was taken";
  } catch (const ScenarioError& error) {
    EXPECT_NE(std::string(error.what()).find("tissue.regions.tumour"), std::string::npos) << error.what();
  }
  EXPECT_THROW(parse_scenario(head + "[tissue.parameters]\n\"material.regions\" = \"a: density=1\"\n"
                                     "[tissue.regions.a]\ndensity = 2\n",
                              "regions.toml"),
               ScenarioError);
}

// Issue 42: the recording's frames are captured without their mapping (the embedding's bytes and the
// nodes, in the dynamics thread's slot) and mapped in the writer's thread. Completed, such a frame is
// the frame read and mapped at once, while the frog is cut (the embedding changes, its bytes are
// taken anew) and between (the bytes are shared, not copied again).
TEST(SurfaceMapping, AnUnmappedFrameCompletedIsTheFrameMappedAtOnce) {
  const Fmu3 fmu(FMUS / "Tissue.fmu");
  TissueLink link(fmu, {});
  const std::array<double, 3> lower = link.rest_lower(), upper = link.rest_upper();
  SurfaceMapping mapping;
  std::shared_ptr<const std::vector<std::uint8_t>> last_bytes;
  int new_bytes = 0, shared_bytes = 0;
  for (int n = 0; n <= 30; ++n) {
    ToolCommand scalpel;  // a vertical blade drawn across the frog's middle, its tip below it
    const double along = -0.1 + 1.2 * n / 25.0;
    scalpel.position_m = {lower[0] + along * (upper[0] - lower[0]), 0.5 * (lower[1] + upper[1]), lower[2] - 0.005};
    scalpel.mode = n <= 25 ? 2 : 0;
    link.set_tool(scalpel);
    ASSERT_EQ(link.step(0.01 * n, 0.01).status, fmi3OK);
    SurfaceFrame mapped, unmapped;
    link.read_surface(mapped);
    link.read_surface_unmapped(unmapped);
    ASSERT_TRUE(unmapped.embedding_bytes);
    EXPECT_TRUE(unmapped.positions_m.empty());
    (unmapped.embedding_bytes == last_bytes ? shared_bytes : new_bytes) += 1;
    last_bytes = unmapped.embedding_bytes;
    mapping.complete(unmapped);
    EXPECT_FALSE(unmapped.embedding_bytes);
    EXPECT_EQ(unmapped.positions_m, mapped.positions_m) << "step " << n;
    EXPECT_EQ(unmapped.triangles, mapped.triangles) << "step " << n;
    EXPECT_EQ(unmapped.mesh_triangle_count, mapped.mesh_triangle_count) << "step " << n;
    EXPECT_EQ(unmapped.embedding->revision, mapped.embedding->revision) << "step " << n;
  }
  std::printf("  embedding bytes taken anew %d times, shared %d times\n", new_bytes, shared_bytes);
  EXPECT_GT(new_bytes, 2) << "the cut changed the embedding";
  EXPECT_GT(shared_bytes, 2) << "between changes the bytes are shared";
}

}  // namespace
}  // namespace tissue::host
