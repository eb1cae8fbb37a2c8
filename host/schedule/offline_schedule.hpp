// The offline scheduler: the real-time schedule's ticks and slots on the calling thread without
// sleeping. The result of tissue step k reaches the haptic loop at the start of slot k + 1 (the
// real-time worst case), so two offline runs of a scenario are byte-identical.
#pragma once

#include "output/frame_writer.hpp"
#include "output/session_summary.hpp"
#include "schedule/schedule.hpp"
#include "schedule/session_steps.hpp"

#include <iosfwd>

namespace tissue::host {

/// Runs `schedule` through `steps`; due frames go to `writer` (needed when steps.frame_due() can be
/// true), finished at the end. Sets summary's haptic_ticks, sim_time_s, wall_time_s and
/// frames_written. `progress`: a line every tenth of the run (nullptr: quiet).
void run_offline(SessionSteps& steps, const Schedule& schedule, FrameWriter* writer, std::ostream* progress,
                 SessionSummary& summary);

}  // namespace tissue::host
