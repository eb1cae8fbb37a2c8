// BackgroundWork (core/system/background_work.hpp): one job at a time on a thread of its own. A job
// runs once, wait() returns after it, and a job handed over from a real-time (SCHED_FIFO) thread
// runs at the normal policy, so that it only takes what the real-time threads leave idle
// (inherited, it would take a core from the dynamics team), but at the owner's while the owner
// waits for it.
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

// Finished without a wait() (busy() polled): the owner lends it nothing.
TEST(BackgroundWork, AJobHandedOverFromARealTimeThreadRunsAtTheNormalPolicy) {
  int policy_in_job = -1;
  const bool fifo = test::run_on_a_fifo_thread([&] {
    BackgroundWork work;  // its thread is made by this (real-time) thread at the first job
    work.start([&] { policy_in_job = sched_getscheduler(0); });
    while (work.busy()) std::this_thread::sleep_for(std::chrono::microseconds(100));  // a FIFO spin starves it
    work.wait();
  });
  if (!fifo) GTEST_SKIP() << "SCHED_FIFO not permitted here (not root, no CAP_SYS_NICE)";
  EXPECT_EQ(policy_in_job, SCHED_OTHER);
}

// Priority inheritance: while a real-time owner waits for a job, the job runs at the owner's
// policy and priority (else normal threads hold back what the owner waits for: the organ's first
// cut); the next job starts at the normal policy again. The job watches its own policy for up to
// 10 s: without the lending it never sees SCHED_FIFO.
TEST(BackgroundWork, AJobARealTimeOwnerWaitsForRunsAtTheOwnersPriority) {
  int policy_waited_for = -1, priority_waited_for = -1, policy_next = -1;
  const bool fifo = test::run_on_a_fifo_thread([&] {
    BackgroundWork work;
    work.start([] {});  // the thread made (it inherits SCHED_FIFO and leaves it), not waited for
    while (work.busy()) std::this_thread::sleep_for(std::chrono::microseconds(100));
    work.start([&] {
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      sched_param parameters{};
      do {
        (void)pthread_getschedparam(pthread_self(), &policy_waited_for, &parameters);
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      } while (policy_waited_for != SCHED_FIFO && std::chrono::steady_clock::now() < give_up);
      priority_waited_for = parameters.sched_priority;
    });
    work.wait();
    work.start([&] { policy_next = sched_getscheduler(0); });
    while (work.busy()) std::this_thread::sleep_for(std::chrono::microseconds(100));
    work.wait();
  });
  if (!fifo) GTEST_SKIP() << "SCHED_FIFO not permitted here (not root, no CAP_SYS_NICE)";
  EXPECT_EQ(policy_waited_for, SCHED_FIFO);
  EXPECT_EQ(priority_waited_for, 10);
  EXPECT_EQ(policy_next, SCHED_OTHER);
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
