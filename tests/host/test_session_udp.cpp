// The UDP device end to end through tissue-host in real time (issue 9): a driver thread (the test
// sender, tests/host/udp_sender.*) sends a poke of the frog's back as pose packets at 1 kHz over
// loopback, with a few malformed, replayed and out-of-order packets mixed in, then goes silent;
// the session runs both FMUs on its two threads. Checked: the poses arrive and drive the probe into
// contact, forces come back to the driver, every bad packet is dropped and counted by reason, and
// after the driver goes silent the watchdog brings the force sent to zero within its timeout and
// ramp (50 + 100 ms).
#include "device/udp_packet.hpp"
#include "scenario/scenario.hpp"
#include "session/session.hpp"
#include "udp_sender.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace tissue::host {
namespace {

constexpr std::uint16_t PORT = 47391;

TEST(UdpSession, PosesDriveTheProbeForcesComeBackBadPacketsAreCountedSilenceZeroesTheForce) {
  const std::string text = std::string("[scenario]\nduration = 1.6\n[device]\nkind = \"udp\"\nport = ") +
                           std::to_string(PORT) + "\n[output]\nframe_rate = 0\npng = false\n";
  const Scenario scenario = parse_scenario(text, std::filesystem::path(TISSUE_SCENARIO_DIR) / "udp_test.toml");
  SessionOptions options;
  options.output_dir = std::filesystem::temp_directory_path() / "tissue_host_test_udp";
  options.fmu_dir = TISSUE_FMU_DIR;
  options.realtime_priority = false;
  std::atomic<bool> session_started{false};
  options.haptic_thread_started = [&] { session_started.store(true); };

  std::vector<udp::ForcePacket> forces;
  std::thread driver([&] {
    test::UdpSender sender("127.0.0.1", PORT);
    while (!session_started.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    // The frog's back is near (0, 0, 0.036) m (rest box of meshes/frog.veg): down from 1 cm above
    // to 3 mm inside in 0.5 s, held until 1.0 s; then silence.
    const auto start = std::chrono::steady_clock::now();
    for (int n = 0; n < 1000; ++n) {
      const double t = n * 1e-3;
      DevicePose pose;
      pose.mode = ToolMode::probe;
      pose.position_m = {-0.007, 0.0, 0.046 - 0.013 * std::min(1.0, t / 0.5)};
      sender.send_pose(pose);
      if (n == 300) {
        std::vector<std::uint8_t> bad(20, 0xAB);  // malformed: too short, no magic
        sender.send_raw(bad);
        udp::PosePacket replay;
        replay.sequence = sender.next_sequence() - 1;  // a replay of the last one
        replay.send_time_s = test::monotonic_time_s();
        replay.pose = pose;
        sender.send_packet(replay);
        replay.sequence = 5;  // out of order
        sender.send_packet(replay);
      }
      sender.drain_forces(forces);
      std::this_thread::sleep_until(start + std::chrono::microseconds(1000 * (n + 1)));
    }
    const auto quiet_until = std::chrono::steady_clock::now() + std::chrono::milliseconds(700);
    while (std::chrono::steady_clock::now() < quiet_until) {
      sender.drain_forces(forces);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  const SessionSummary s = run_session(scenario, options);
  driver.join();

  EXPECT_FALSE(s.nan_detected);
  EXPECT_EQ(s.tissue_errors, 0u) << s.first_error;
  // The poses reach the tissue and the probe touches the back (when the tissue keeps pace: a
  // sanitizer build's steps overrun their slots many times over).
  const bool kept_pace = s.sim_time_s > 0.9 * scenario.duration_s;
  if (kept_pace) {
    EXPECT_TRUE(s.contact_seen) << "the poses did not reach the tissue";
  }
  EXPECT_GE(s.device.accepted, 800u);  // of 1000 sent (a loaded machine may see some as stale)
  EXPECT_EQ(s.device.malformed, 1u);
  EXPECT_EQ(s.device.duplicate, 1u);
  EXPECT_EQ(s.device.out_of_order, 1u);
  EXPECT_EQ(s.device.watchdog_trips, 1u);
  // Forces came back to the driver, some of them pushing the probe out (+z).
  double largest_up = 0.0;
  for (const udp::ForcePacket& f : forces) largest_up = std::max(largest_up, f.force_n[2]);
  EXPECT_GT(forces.size(), 500u);
  if (kept_pace) {
    EXPECT_GT(largest_up, 0.1);
  }
  // The force sent to the device is exactly zero from 150 ms (+ a tick) after the last pose.
  std::ifstream log(options.output_dir / "log.csv");
  std::string line;
  std::getline(log, line);
  double last_nonzero_s = 0.0;
  while (std::getline(log, line)) {
    std::vector<double> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(std::stod(field));
    if (fields.at(8) != 0.0 || fields.at(9) != 0.0 || fields.at(10) != 0.0) last_nonzero_s = fields.at(0);
  }
  EXPECT_LT(last_nonzero_s, 1.0 + 0.05 + 0.1 + 0.05) << "the watchdog did not zero the force in time";
}

}  // namespace
}  // namespace tissue::host
