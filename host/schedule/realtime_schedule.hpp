// The real-time scheduler (docs/DESIGN.md, "Host"; dissertation 5.1.3): a haptic thread ticking on
// absolute deadlines of the haptic period (SCHED_FIFO 80 when permitted), a dynamics thread stepping
// the tissue once per slot (SCHED_FIFO 70) under the scenario's overrun policy, and the calling
// thread writing the surface frames the dynamics thread hands over (FramePipe) and the progress lines.
#pragma once

#include "output/frame_writer.hpp"
#include "output/session_summary.hpp"
#include "output/slot_timing.hpp"
#include "schedule/schedule.hpp"
#include "schedule/session_steps.hpp"

#include <atomic>
#include <functional>
#include <iosfwd>
#include <vector>

namespace tissue::host {

struct RealtimeOptions {
  /// Try SCHED_FIFO for the two threads, and lock the memory mapped once both exist.
  bool realtime_priority = true;
  /// Called on the haptic thread right before its first tick (tests watch that thread with it).
  std::function<void()> haptic_thread_started;
  /// Set (e.g. by Ctrl-C) to end the run early; the summary covers the ticks run.
  const std::atomic<bool>* stop = nullptr;
  /// A progress line a second (nullptr: quiet).
  std::ostream* progress = nullptr;
  /// Where each step's timing goes (nullptr: nowhere); reserved for every slot before the threads start.
  std::vector<SlotTiming>* slot_timings = nullptr;
};

/// Runs `schedule` through `steps` on a haptic and a dynamics thread; due frames go to `writer`
/// (needed when steps.frame_due() can be true), finished at the end. Sets summary's timing fields:
/// haptic_ticks (fewer when stopped), haptic_period_us, haptic_period_max_at_s,
/// haptic_first_tick_late_us, deadline_misses, tissue_overruns, catch_up_slots, skipped_slots,
/// sim_time_s, wall_time_s (from the first deadline), frames_written, frames_dropped, frames_deferred and
/// realtime_priority with its note.
void run_realtime(SessionSteps& steps, const Schedule& schedule, const RealtimeOptions& options, FrameWriter* writer,
                  SessionSummary& summary);

}  // namespace tissue::host
