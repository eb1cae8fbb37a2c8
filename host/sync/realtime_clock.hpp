// The host's clocks and real-time priority: the monotonic clock in nanoseconds, sleeping until an
// absolute deadline (the haptic and dynamics threads' schedules), a thread's CPU time (what a doStep
// cost whatever else the machine runs), and SCHED_FIFO when the system permits it.
#pragma once

#include <cstdint>
#include <string>

namespace tissue::host {

using Nanoseconds = std::int64_t;

/// CLOCK_MONOTONIC.
Nanoseconds now_ns();
/// Sleeps until `deadline` on CLOCK_MONOTONIC (absolute: no drift), through signals.
void sleep_until_ns(Nanoseconds deadline);
/// CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID).
Nanoseconds thread_cpu_ns();
/// Seconds to nanoseconds, rounded.
Nanoseconds to_ns(double seconds);

struct Priority {
  bool granted = false;
  std::string note;  ///< "SCHED_FIFO", or why not and how to allow it
};

/// Gives the calling thread SCHED_FIFO at `priority`, if the system permits it.
Priority try_fifo_priority(int priority);

}  // namespace tissue::host
