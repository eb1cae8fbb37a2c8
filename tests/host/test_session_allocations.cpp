// The haptic thread of a real-time tissue-host session allocates nothing (STYLE "real-time
// discipline"; issue 9): operator new is replaced by one that counts the calls made on a thread
// that asked to be counted, and the session's haptic_thread_started hook asks for its haptic
// thread, right before the first tick. A short poke session (device read, HapticLoop doStep
// through the importer, tissue samples taken, force written, log rows) at 1 kHz.
#include "igtl_client.hpp"
#include "scenario/scenario.hpp"
#include "session/session.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <thread>
#include <filesystem>
#include <new>

namespace {

thread_local bool t_counted = false;
std::atomic<long> g_counted_allocations{0};

}  // namespace

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  if (t_counted) g_counted_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace tissue::host {
namespace {

// One real-time session of `scenario` (1 s), counting the haptic thread's allocations.
long haptic_thread_allocations(Scenario scenario, const char* scenario_file, const char* output,
                               std::atomic<bool>* started = nullptr) {
  scenario.duration_s = 1.0;  // the probe reaches the back at 0.3 s: contact samples are taken
  scenario.write_png = false;
  SessionOptions options;
  options.output_dir = std::filesystem::temp_directory_path() / output;
  options.fmu_dir = TISSUE_FMU_DIR;
  options.realtime_priority = false;
  options.haptic_thread_started = [started] {
    t_counted = true;
    if (started != nullptr) started->store(true);
  };
  g_counted_allocations = 0;
  const SessionSummary summary = run_session(scenario, options);
  // Contact samples reach the haptic thread when the tissue keeps pace (a sanitizer build's tissue
  // steps overrun their slots many times over, and the probe may never reach the back).
  if (summary.sim_time_s > 0.9 * scenario.duration_s) {
    EXPECT_TRUE(summary.contact_seen) << scenario_file;
  }
  EXPECT_EQ(summary.haptic_ticks, 1000u) << scenario_file;
  return g_counted_allocations.load();
}

TEST(HapticThread, AllocatesNothingAfterStart) {
  // The counter works: an allocation on a counted thread is seen.
  t_counted = true;
  void* probe = ::operator new(16);  // a direct call: the compiler may not elide it
  t_counted = false;
  ::operator delete(probe);
  ASSERT_EQ(g_counted_allocations.exchange(0), 1);

  const auto load = [](const char* file) { return load_scenario(std::filesystem::path(TISSUE_SCENARIO_DIR) / file); };
  EXPECT_EQ(haptic_thread_allocations(load("poke_frog.toml"), "poke_frog.toml", "tissue_host_test_allocations"), 0);
  // A simulated hand as the device (issue 20): its tick and its window of figures allocate nothing.
  EXPECT_EQ(haptic_thread_allocations(load("hand_press_frog.toml"), "hand_press_frog.toml",
                                      "tissue_host_test_allocations_hand"),
            0);
}

// The OpenIGTLink device (issue 24): taking the client's pose and handing the force to the server's
// thread allocate nothing on the haptic thread (the surfaces go out from the dynamics thread).
TEST(HapticThread, AllocatesNothingWithAnOpenIgtlinkClientPressing) {
  Scenario scenario = load_scenario(std::filesystem::path(TISSUE_SCENARIO_DIR) / "slicer_frog.toml");
  scenario.openigtlink->port = 47395;
  std::atomic<bool> started{false};
  std::thread client_thread([&] {
    test::IgtlClient client("127.0.0.1", scenario.openigtlink->port);
    while (!started.load()) std::this_thread::sleep_for(std::chrono::microseconds(200));
    const auto start = std::chrono::steady_clock::now();
    for (int n = 0; n < 900; ++n) {  // down onto the back and 3 mm in within 0.3 s, held
      DevicePose pose;
      pose.mode = ToolMode::probe;
      pose.position_m = {-0.007, 0.0, 0.046 - 0.013 * std::min(1.0, n / 300.0)};
      client.send_transform("ProbeToTissue", pose);
      std::this_thread::sleep_until(start + std::chrono::microseconds(1000 * (n + 1)));
    }
  });
  const long allocations = haptic_thread_allocations(scenario, "slicer_frog.toml", "tissue_host_test_allocations_igtl",
                                                     &started);
  client_thread.join();
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace tissue::host
