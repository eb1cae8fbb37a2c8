// Whether this machine can keep a haptic clock at all: the haptic thread's loop with no work in it
// (the same deadlines, priority and miss rule, tick_deadlines.hpp), on an otherwise idle process.
// A session cannot miss fewer deadlines than the machine's timer does alone: on a virtual machine
// whose host deschedules it, a SCHED_FIFO thread sleeping on 1 ms deadlines wakes late by several
// ms now and then with nothing else running (docs/BENCHMARKS.md, "The machine's own timer").
// `tissue-host timer` runs it; tests/bench/realtime_table.py prints it beside each scenario's runs.
#pragma once

#include "output/session_summary.hpp"
#include "sync/realtime_clock.hpp"

#include <cstdint>
#include <string>

namespace tissue::host {

struct TimerCheck {
  std::uint64_t ticks = 0;
  std::uint64_t deadline_misses = 0;  ///< ticks that ended after the next tick's deadline
  Percentiles period_us;              ///< between consecutive wake-ups
  Percentiles wake_late_us;           ///< wake-up after the tick's deadline
  Priority priority;                  ///< whether SCHED_FIFO was granted (asked when realtime_priority)

  [[nodiscard]] std::string to_json() const;
};

/// Ticks every `period_s` for `duration_s` (at least one tick) on a thread of its own, at the haptic
/// thread's SCHED_FIFO priority when `realtime_priority` and the system permits it. Throws
/// std::invalid_argument for a period or duration that is not finite and > 0, or over 10^7 ticks.
TimerCheck check_timer(double period_s, double duration_s, bool realtime_priority);

/// The check in two lines, for a terminal.
void print_timer_check(std::ostream& out, const TimerCheck& check, double period_s);

}  // namespace tissue::host
