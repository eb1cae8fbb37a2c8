// Background threads (a factorization for a later step, a surface prepared for a later read) run at
// the operating system's normal policy, whatever their creator's. A thread inherits its creator's
// scheduling, and a real-time host steps the tissue from a SCHED_FIFO thread: inherited, a
// background factorization held a core at the dynamics thread's priority until it finished (threads
// of one FIFO priority do not preempt each other; the palpated organ's K_c, 0.6-1.5 s of a core,
// refreshed again and again), and everything else on the machine shared the other core with the
// dynamics thread. At the normal policy the work takes only what the real-time threads leave idle;
// whoever needs its result waits for it as before (the caller blocks, the work runs). While a
// real-time thread waits for it, the work runs at that thread's priority (lend_realtime_policy):
// at the normal policy it shared its core with the host's writer, and the organ's first cut, whose
// surface the next step waited for, took 13-49 ms of that step's slot (docs/BENCHMARKS.md).
#pragma once

#include <pthread.h>

namespace tissue {

/// Puts the calling thread at SCHED_OTHER (priority 0) if it runs at a real-time policy; nothing
/// otherwise. Lowering needs no privilege; a failure leaves the policy as it was.
void leave_realtime_policy() noexcept;

/// Gives `thread` the calling thread's real-time policy and priority, if the caller has one (a
/// real-time thread about to wait for a background job: priority inheritance, so that the job is
/// not held back by normal threads meanwhile); nothing otherwise. Needs the privilege the caller's
/// own policy needed (a failure leaves `thread` as it was).
void lend_realtime_policy(pthread_t thread) noexcept;

}  // namespace tissue
