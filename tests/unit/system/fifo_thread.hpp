// For the background-policy tests: runs `job` on a new thread that has made itself SCHED_FIFO
// (priority 10), as a real-time importer's threads are. Returns false, without running the job, where
// SCHED_FIFO is not permitted (not root, no CAP_SYS_NICE): the caller skips.
#pragma once

#include <pthread.h>
#include <sched.h>

#include <thread>

namespace tissue::test {

template <class Job>
bool run_on_a_fifo_thread(Job&& job) {
  bool fifo = false;
  std::thread owner([&] {
    sched_param priority{};
    priority.sched_priority = 10;
    fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &priority) == 0;
    if (fifo) job();
  });
  owner.join();
  return fifo;
}

}  // namespace tissue::test
