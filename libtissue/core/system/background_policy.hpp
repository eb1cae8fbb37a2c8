// Background threads (a factorization for a later step, a surface prepared for a later read) run at
// the operating system's normal policy, whatever their creator's. A thread inherits its creator's
// scheduling, and a real-time host steps the tissue from a SCHED_FIFO thread: inherited, a
// background factorization held a core at the dynamics thread's priority until it finished (threads
// of one FIFO priority do not preempt each other; the palpated organ's K_c, 0.6-1.5 s of a core,
// refreshed again and again), and everything else on the machine shared the other core with the
// dynamics thread. At the normal policy the work takes only what the real-time threads leave idle;
// whoever needs its result waits for it as before (the caller blocks, the work runs).
#pragma once

namespace tissue {

/// Puts the calling thread at SCHED_OTHER (priority 0) if it runs at a real-time policy; nothing
/// otherwise. Lowering needs no privilege; a failure leaves the policy as it was.
void leave_realtime_policy() noexcept;

}  // namespace tissue
