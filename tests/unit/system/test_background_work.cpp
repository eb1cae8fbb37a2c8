// BackgroundWork (core/system/background_work.hpp): one job at a time on a thread of its own. A job
// runs once, wait() returns after it, and a job handed over from a real-time (SCHED_FIFO) thread
// runs at the normal policy, so that it only takes what the real-time threads leave idle
// (inherited, it would take a core from the dynamics team).
#include "core/system/background_work.hpp"

#include "fifo_thread.hpp"

#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace tissue {
namespace {

TEST(BackgroundWork, EachJobRunsOnceOnItsThreadAndWaitReturnsAfterIt) {
  BackgroundWork work;
  EXPECT_FALSE(work.pending());
  work.wait();  // nothing started: returns at once
  std::vector<int> done;
  std::thread::id ran_on;
  for (int k = 0; k < 20; ++k) {
    work.start([&, k] {
      done.push_back(k);  // the owner reads it only after wait(): no lock needed
      ran_on = std::this_thread::get_id();
    });
    EXPECT_TRUE(work.pending());
    if (k % 2 == 0) work.wait();  // start() waits for a running job itself
  }
  work.wait();
  EXPECT_FALSE(work.pending());
  ASSERT_EQ(done.size(), 20u);
  for (int k = 0; k < 20; ++k) EXPECT_EQ(done[static_cast<std::size_t>(k)], k);
  EXPECT_NE(ran_on, std::this_thread::get_id());
}

TEST(BackgroundWork, AJobHandedOverFromARealTimeThreadRunsAtTheNormalPolicy) {
  int policy_in_job = -1;
  const bool fifo = test::run_on_a_fifo_thread([&] {
    BackgroundWork work;  // its thread is made by this (real-time) thread at the first job
    work.start([&] { policy_in_job = sched_getscheduler(0); });
    work.wait();
  });
  if (!fifo) GTEST_SKIP() << "SCHED_FIFO not permitted here (not root, no CAP_SYS_NICE)";
  EXPECT_EQ(policy_in_job, SCHED_OTHER);
}

TEST(BackgroundWork, DestructionWaitsForARunningJob) {
  std::atomic<bool> finished{false};
  {
    BackgroundWork work;
    work.start([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      finished = true;
    });
  }
  EXPECT_TRUE(finished);
}

// busy(): true from start() while the job runs, false once it has finished (without a wait()), and
// false with no job; it never blocks on the job (the job here cannot finish until the test lets it).
TEST(BackgroundWork, BusyWhileAJobRuns) {
  BackgroundWork work;
  EXPECT_FALSE(work.busy());
  std::atomic<bool> release{false}, finished{false};
  work.start([&] {
    while (!release) std::this_thread::yield();
    finished = true;
  });
  EXPECT_TRUE(work.busy());  // the job waits for `release`: it cannot have finished
  EXPECT_TRUE(work.busy());
  release = true;
  while (work.busy()) std::this_thread::yield();
  EXPECT_TRUE(finished);
  work.wait();
  EXPECT_FALSE(work.busy());
}

}  // namespace
}  // namespace tissue
