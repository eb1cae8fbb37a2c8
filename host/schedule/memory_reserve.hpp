// Memory for the real-time threads without page faults (docs/DESIGN.md, "Host"): the Linux
// real-time recipe (the Linux Foundation's real-time wiki, "Memory for Real-time Applications"):
// freed memory stays in the process (no trimming, no chunk of its own mapping), and the dynamics
// thread's heap is touched once before the session, so that what the tissue allocates during the
// session (after a cut: the re-meshed fine surface's buffers, megabytes) lands on pages already
// there. Without it the first capture after the organ's first cut took 9-12 ms of a 10 ms slot.
#pragma once

#include <cstddef>

namespace tissue::host {

/// Bytes of heap the dynamics thread touches before a real-time session (below glibc's 64 MiB
/// per-thread heap, so that they are that thread's own heap).
inline constexpr std::size_t DYNAMICS_HEAP_RESERVE_BYTES = std::size_t{32} << 20;

/// From now on freed memory is kept by the process and large blocks come from the heap (mallopt:
/// M_TRIM_THRESHOLD and M_MMAP_MAX). Process-wide; for a process that runs real-time sessions.
void keep_freed_memory();
/// Allocates `bytes` on the calling thread's heap, writes one byte per page and frees them: the
/// pages stay with that heap (after keep_freed_memory()) for its later allocations.
void touch_heap(std::size_t bytes);

}  // namespace tissue::host
