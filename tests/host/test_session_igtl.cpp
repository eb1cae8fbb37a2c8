// OpenIGTLink end to end through tissue-host in real time (issue 24): a client built on Debian's
// libopenigtlink (tests/host/igtl_client.*), as 3D Slicer or PLUS would be, sends a press of the
// frog's back as TRANSFORM messages in millimetres at 1 kHz over loopback, with bad messages mixed
// in, then goes silent; the session runs both FMUs on their threads. Checked: the poses arrive on
// the client's path; the force the client reads back is the force of those poses replayed offline
// from the session's recording, within the host's timing (one tissue slot); the surface arrives as
// POLYDATA; every bad message is dropped, counted and changes nothing; silence zeroes the force.
// What depends on the machine keeping time (how many poses and forces pass, a single watchdog trip,
// the surfaces' rate, the path and the force comparison) is asserted only when the client and the
// haptic thread kept their 1 ms periods and the tissue its pace: beside CPU-bound processes either
// may be held off for longer than the watchdog's 50 ms (a trip mid-stream is then the protection
// working). The protocol's facts and the watchdog's zero after the last pose hold whatever the load.
#include "igtl_client.hpp"
#include "scenario/scenario.hpp"
#include "session/session.hpp"
#include "support/under_sanitizer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace tissue::host {
namespace {

constexpr int PORT = 47393;
constexpr double PRESS_S = 0.5, HOLD_UNTIL_S = 1.0;

// The press: from 1 cm above the frog's back (near z = 0.036 m, meshes/frog.veg) to 3 mm into it
// in PRESS_S, held until HOLD_UNTIL_S.
DevicePose press_pose(double time_s) {
  DevicePose pose;
  pose.mode = ToolMode::probe;
  pose.position_m = {-0.007, 0.0, 0.046 - 0.013 * std::min(1.0, time_s / PRESS_S)};
  return pose;
}

struct LogRow {
  double time_s = 0.0;
  double device_z_m = 0.0;
  std::array<double, 3> force_n{};
  double tissue_time_s = 0.0;  ///< the time of the tissue sample the haptic loop rendered from
};

std::vector<LogRow> read_log(const std::filesystem::path& file) {
  std::ifstream log(file);
  std::string line;
  std::getline(log, line);
  std::vector<LogRow> rows;
  while (std::getline(log, line)) {
    std::vector<double> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(std::stod(field));
    rows.push_back({fields.at(0), fields.at(3), {fields.at(8), fields.at(9), fields.at(10)}, fields.at(12)});
  }
  return rows;
}

std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("tissue_host_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

// The poses the session received, as its recording (`--record`) kept them, replayed offline: the
// same pose at every tick, so the two runs differ only in when the tissue's results reached the
// haptic loop.
std::vector<LogRow> replayed_run(const std::filesystem::path& recording) {
  const std::string text = "[scenario]\nduration = 1.6\n[device]\nkind = \"replay\"\nfile = \"" + recording.string() +
                           "\"\n[output]\nframe_rate = 0\npng = false\n";
  const Scenario scenario = parse_scenario(text, std::filesystem::path(TISSUE_SCENARIO_DIR) / "igtl_replay.toml");
  SessionOptions options;
  options.offline = true;
  options.output_dir = fresh_dir("igtl_replay");
  options.fmu_dir = TISSUE_FMU_DIR;
  run_session(scenario, options);
  return read_log(options.output_dir / "log.csv");
}

TEST(IgtlSession, APressFromAnOpenIgtlinkClientFeelsLikeTheScriptedPressAndShowsTheSurface) {
  const std::string text =
      "[scenario]\nduration = 1.6\n[device]\nkind = \"openigtlink\"\n[openigtlink]\nport = " + std::to_string(PORT) +
      "\nsurface_rate = 20\n[output]\nframe_rate = 0\npng = false\n";
  const Scenario scenario = parse_scenario(text, std::filesystem::path(TISSUE_SCENARIO_DIR) / "igtl_test.toml");
  SessionOptions options;
  options.output_dir = fresh_dir("igtl");
  options.fmu_dir = TISSUE_FMU_DIR;
  options.record = options.output_dir / "poses.csv";
  // Where allowed, and not under a sanitizer (its slowed threads at SCHED_FIFO would starve the rest):
  // fewer overruns, so the timing is compared more often.
  options.realtime_priority = !tissue::test::UNDER_SANITIZER;
  std::atomic<bool> session_started{false};
  std::chrono::steady_clock::time_point session_start;
  options.haptic_thread_started = [&] {
    session_start = std::chrono::steady_clock::now();
    session_started.store(true);
  };

  std::vector<test::ReceivedForce> forces;
  std::optional<test::ReceivedSurface> surface;
  std::size_t surfaces = 0;
  double largest_send_gap_s = 0.0;  // the client's longest time between two poses
  double last_pose_s = 0.0;         // when the client sent its last pose, from the session's start
  std::thread client_thread([&] {
    test::IgtlClient client("127.0.0.1", PORT);  // the server listens from the session's start
    while (!session_started.load()) std::this_thread::sleep_for(std::chrono::microseconds(200));
    const auto start = std::chrono::steady_clock::now();
    std::uint64_t timestamp = 1ULL << 32U;
    auto last_send = start;
    for (int n = 0; n < 1000; ++n) {
      const DevicePose pose = press_pose(n * 1e-3);
      const auto now = std::chrono::steady_clock::now();
      if (n > 0) largest_send_gap_s = std::max(largest_send_gap_s, std::chrono::duration<double>(now - last_send).count());
      last_send = now;
      client.send_transform("ProbeToTissue", pose, 1e-3, ++timestamp);
      if (n == 300) {
        DevicePose far = pose;
        far.position_m = {0.5, 0.5, 0.5};
        std::vector<std::uint8_t> corrupted = test::pack_transform("ProbeToTissue", far, 1e-3, timestamp + 1);
        corrupted[70] ^= 0x10U;  // a body byte: the CRC fails
        client.send_raw(corrupted);
        client.send_transform("ProbeToTissue", far, 1e-3, timestamp - 5);    // out of order
        client.send_transform("ProbeToTissue", far, 1e-3, timestamp);        // duplicate
        client.send_transform("NeedleToTracker", far, 1e-3, timestamp + 1);  // another tool: ignored
      }
      std::this_thread::sleep_until(start + std::chrono::microseconds(1000 * (n + 1)));
    }
    last_pose_s = std::chrono::duration<double>(last_send - session_start).count();
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // silence
    forces = client.forces();
    surface = client.last_surface();
    surfaces = client.surface_count();
  });
  const SessionSummary s = run_session(scenario, options);
  client_thread.join();

  EXPECT_FALSE(s.nan_detected);
  EXPECT_EQ(s.tissue_errors, 0u) << s.first_error;
  EXPECT_EQ(s.device_name, "openigtlink 127.0.0.1:" + std::to_string(PORT));
  // Whatever the load: every bad message is dropped and counted by its reason, the final silence
  // trips the watchdog, one client connected, forces and the surface come back.
  EXPECT_EQ(s.device.malformed, 1u);
  EXPECT_EQ(s.device.out_of_order, 1u);
  EXPECT_EQ(s.device.duplicate, 1u);
  EXPECT_EQ(s.device.ignored, 1u);
  EXPECT_GE(s.device.watchdog_trips, 1u);
  ASSERT_TRUE(s.openigtlink.has_value());
  EXPECT_EQ(s.openigtlink->connections, 1u);
  EXPECT_GT(forces.size(), 100u);
  EXPECT_TRUE(std::all_of(forces.begin(), forces.end(), [](const test::ReceivedForce& f) { return f.unit_is_newton; }));
  EXPECT_GE(surfaces, 1u);
  // When the machine kept time (the client never paused for half the watchdog's timeout and the
  // tissue kept pace; a sanitizer build's steps overrun their slots many times over): nearly every
  // pose is accepted (a few may share a millisecond's read), only the final silence trips the
  // watchdog, the forces come back at the haptic rate, and the surface at 20 Hz over ~1.5 s (one
  // per tissue step at most: when steps overrun, at least one).
  const bool kept_time =
      largest_send_gap_s < 0.025 && s.sim_time_s > 0.9 * scenario.duration_s && !tissue::test::UNDER_SANITIZER;
  std::cout << "client's largest gap " << largest_send_gap_s * 1e3 << " ms, " << s.deadline_misses
            << " haptic misses, " << s.tissue_overruns << " tissue overruns: "
            << (kept_time ? "kept time" : "did not keep time (timing facts not asserted)") << "\n";
  if (kept_time) {
    EXPECT_GE(s.device.accepted, 900u);  // of 1000
    EXPECT_EQ(s.device.watchdog_trips, 1u);
    EXPECT_GT(forces.size(), 800u);
    EXPECT_GE(surfaces, s.tissue_overruns == 0 ? 10u : 1u);
  }
  ASSERT_TRUE(surface.has_value());
  EXPECT_EQ(surface->name, "TissueSurface");
  EXPECT_GT(surface->polygons, 1000u);
  // In millimetres: the frog is ~126 mm long.
  float x_min = 1e9F, x_max = -1e9F;
  for (const auto& p : surface->point_list) {
    x_min = std::min(x_min, p[0]);
    x_max = std::max(x_max, p[0]);
  }
  EXPECT_NEAR(x_max - x_min, 126.0F, 10.0F);

  const std::vector<LogRow> rows = read_log(options.output_dir / "log.csv");
  // Silence: the force sent is exactly zero from 150 ms (timeout 50 + ramp 100; + a tick, and the
  // 50 ms the session's clock may start after the haptic thread's first tick) after the last pose,
  // whenever the client sent it.
  double last_nonzero_s = 0.0;
  for (const LogRow& r : rows) {
    if (r.force_n != std::array<double, 3>{0.0, 0.0, 0.0}) last_nonzero_s = r.time_s;
  }
  EXPECT_LT(last_nonzero_s, last_pose_s + 0.150 + 0.050) << "the watchdog did not zero the force in time";
  if (!kept_time) GTEST_SKIP() << "not a run on its deadlines: the path and the force comparison need one";

  // The forces the client read are the forces the session rendered and logged (float64 on the wire,
  // the log's shortest round-trip text), in the order it rendered them; the server sends the latest
  // one, so some ticks may be passed over.
  std::size_t logged = 0, matched = 0;
  for (const test::ReceivedForce& f : forces) {
    while (logged < rows.size() && rows[logged].force_n != f.force_n) ++logged;
    if (logged < rows.size()) ++matched;
  }
  EXPECT_EQ(matched, forces.size()) << "a force the client read is not in the session's log, or out of its order";

  // The path arrived: the client's clock starts when the haptic thread does, some ms from session
  // time 0, so the lead is read off the delivered poses (the median over the press) and, with it,
  // nearly every pose of the press lies on the client's path. A late wake-up of the client's
  // thread on a busy machine puts a pose a few ms behind: 3 ms of travel (78 um) are allowed.
  std::vector<double> offsets;
  for (const LogRow& r : rows) {
    if (r.time_s >= 0.05 && r.time_s <= PRESS_S - 0.05) offsets.push_back((0.046 - r.device_z_m) / 0.026 - r.time_s);
  }
  ASSERT_GT(offsets.size(), 300u);
  std::vector<double> sorted = offsets;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double offset_s = sorted[sorted.size() / 2];
  std::cout << "the client's path runs " << offset_s * 1e3 << " ms ahead of session time\n";
  ASSERT_LT(std::abs(offset_s), 0.1);
  // Off the path: a pose more than 3 ms of travel from where the client's path was at that tick
  // (the client's thread stalled).
  std::size_t off_path_count = 0, press_ticks = 0;
  for (std::size_t n = 0; n < rows.size(); ++n) {
    if (rows[n].time_s > HOLD_UNTIL_S) break;
    if (rows[n].time_s < 0.05) continue;  // before the client's first poses arrive
    const double from_path_m = std::abs(rows[n].device_z_m - press_pose(rows[n].time_s + offset_s).position_m[2]);
    off_path_count += from_path_m > 0.003 * 0.026 ? 1 : 0;
    ++press_ticks;
  }
  std::cout << off_path_count << " of " << press_ticks << " poses off the client's path\n";

  // The force matches an offline replay of the poses received, within the host's timing. The
  // real-time tissue takes the tool's pose when its step starts and publishes the result when it is
  // done, the offline one at the slot's boundaries: the two render each tick from samples a slot
  // (10 ms) apart at most, plus the difference of the two samples' ages. At each tick of the press
  // and hold the OpenIGTLink force lies within the replayed force's range over that window either
  // side, give or take 5% of the held force: the frog rings after the press (the replay's force
  // swings by ~12% of the held force after the press), and the pose a step starts from, up to a slot
  // later in real time, shifts the ringing's phase. An overrun feeds the tissue a pose from further
  // along the path, and the frog's response differs by more than that: a run with more than one
  // overrun is not compared (one is allowed: where CHOLMOD's factorization is slower than a slot,
  // the first contact step's synchronous K_c refresh overruns in every run). Nor is a run in which
  // the client's thread stalled (a pose off its path): the pose then holds and jumps back, and
  // whether a step starts before or after the jump decides the frog's response for a while.
  if (tissue::test::UNDER_SANITIZER || s.tissue_overruns > 1 || off_path_count > 0) {
    GTEST_SKIP() << "not a run on its deadlines (" << s.tissue_overruns << " overruns, " << off_path_count
                 << " poses off the client's path): the timing comparison needs one";
  }
  const std::vector<LogRow> replayed = replayed_run(*options.record);
  ASSERT_EQ(replayed.size(), rows.size());
  std::vector<double> held_n;
  for (const LogRow& r : replayed) {
    if (r.time_s >= PRESS_S + 0.1 && r.time_s <= HOLD_UNTIL_S - 0.05) held_n.push_back(r.force_n[2]);
  }
  ASSERT_FALSE(held_n.empty());
  std::nth_element(held_n.begin(), held_n.begin() + held_n.size() / 2, held_n.end());
  const double held_force_n = held_n[held_n.size() / 2];
  ASSERT_GT(held_force_n, 0.5) << "the replayed press did not touch the frog";
  const double slack_n = 0.05 * held_force_n;
  std::size_t compared = 0, outside = 0;
  double widest_s = 0.0;
  for (std::size_t n = 0; n < rows.size(); ++n) {
    const LogRow& r = rows[n];
    if (r.time_s < 0.05 || r.time_s > HOLD_UNTIL_S - 0.05) continue;
    const double window_s = 0.010 + std::abs(r.tissue_time_s - replayed[n].tissue_time_s);
    widest_s = std::max(widest_s, window_s);
    double lo = 1e9, hi = -1e9;
    for (const LogRow& q : replayed) {
      if (std::abs(q.time_s - r.time_s) <= window_s + 1e-9) {
        lo = std::min(lo, q.force_n[2]);
        hi = std::max(hi, q.force_n[2]);
      }
    }
    ++compared;
    if (r.force_n[2] < lo - slack_n || r.force_n[2] > hi + slack_n) ++outside;
  }
  std::cout << "widest window: " << widest_s * 1e3 << " ms\n";
  EXPECT_GT(compared, 850u);
  EXPECT_LE(outside, compared / 100) << outside << " of " << compared << " ticks outside the replayed band";
}

}  // namespace
}  // namespace tissue::host
