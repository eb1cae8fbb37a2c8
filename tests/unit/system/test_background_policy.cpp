// leave_realtime_policy (core/system/background_policy.hpp): a background thread made by a
// real-time (SCHED_FIFO) thread inherits its policy; after the call it runs at SCHED_OTHER, so that
// it takes only what the real-time threads leave idle. A thread at the normal policy keeps it.
#include "core/system/background_policy.hpp"

#include "fifo_thread.hpp"

#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>

#include <thread>

namespace tissue {
namespace {

TEST(BackgroundPolicy, AThreadMadeByARealTimeThreadLeavesItsPolicy) {
  int inherited = -1, after = -1;
  const bool fifo = test::run_on_a_fifo_thread([&] {
    std::thread background([&] {
      inherited = sched_getscheduler(0);
      leave_realtime_policy();
      after = sched_getscheduler(0);
    });
    background.join();
  });
  if (!fifo) GTEST_SKIP() << "SCHED_FIFO not permitted here (not root, no CAP_SYS_NICE)";
  EXPECT_EQ(inherited, SCHED_FIFO);
  EXPECT_EQ(after, SCHED_OTHER);
}

TEST(BackgroundPolicy, AThreadAtTheNormalPolicyKeepsIt) {
  int after = -1;
  std::thread background([&] {
    leave_realtime_policy();
    after = sched_getscheduler(0);
  });
  background.join();
  EXPECT_EQ(after, SCHED_OTHER);
}

}  // namespace
}  // namespace tissue
