// The haptic clock's rule, in one place for the haptic thread (realtime_schedule.cpp) and the
// machine's own timer check (timer_check.hpp): tick n is due at start + n period (absolute
// deadlines: no drift), and it misses its deadline when it ends after the next tick is due (the
// next tick then starts late). The threads' SCHED_FIFO priorities are here too: the haptic thread
// above the dynamics thread, so that a step never delays a tick.
#pragma once

#include "sync/realtime_clock.hpp"

#include <cstdint>

namespace tissue::host {

inline constexpr int HAPTIC_FIFO_PRIORITY = 80;
inline constexpr int DYNAMICS_FIFO_PRIORITY = 70;

struct TickDeadlines {
  Nanoseconds start = 0;   ///< tick 0's deadline
  Nanoseconds period = 0;  ///< the haptic period

  [[nodiscard]] Nanoseconds deadline(std::uint64_t n) const { return start + static_cast<Nanoseconds>(n) * period; }
  /// Whether tick n, ended at `ended`, missed its deadline.
  [[nodiscard]] bool missed(std::uint64_t n, Nanoseconds ended) const { return ended > deadline(n) + period; }
};

}  // namespace tissue::host
