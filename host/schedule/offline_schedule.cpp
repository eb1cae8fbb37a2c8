// run_offline (see offline_schedule.hpp).
#include "schedule/offline_schedule.hpp"

#include "sync/realtime_clock.hpp"

#include <ostream>

namespace tissue::host {

void run_offline(SessionSteps& steps, const Schedule& schedule, FrameWriter* writer, std::ostream* progress,
                 SessionSummary& summary) {
  const Nanoseconds wall_start = now_ns();
  SurfaceFrame frame;
  bool pending = false;
  double tissue_time_s = 0.0;
  std::uint64_t next_progress = 0;
  for (std::uint64_t n = 0; n < schedule.ticks; ++n) {
    if (n % schedule.ticks_per_slot == 0) {
      // The result of the previous step arrives at the start of this slot, then the next starts.
      if (pending) {
        steps.publish_tissue_sample();
        pending = false;
      }
      if (!steps.tissue_failed()) {
        tissue_time_s = steps.tissue_step(tissue_time_s, 1);
        pending = true;
        if (steps.frame_due(tissue_time_s)) {
          steps.capture_frame(frame, tissue_time_s);
          steps.complete_frame(frame);
          writer->write(frame);
        }
      }
    }
    steps.haptic_tick(n);
    if (progress != nullptr && n >= next_progress) {
      *progress << "offline: t = " << static_cast<double>(n) * schedule.haptic_period_s << " / " << schedule.duration_s
                << " s, cut tets " << steps.cut_tets() << "\n";
      next_progress += schedule.ticks / 10 + 1;
    }
  }
  summary.haptic_ticks = schedule.ticks;
  summary.sim_time_s = static_cast<double>(schedule.ticks) * schedule.haptic_period_s;
  if (writer != nullptr) {
    summary.frames_written = writer->count();
    writer->finish();
  }
  summary.wall_time_s = static_cast<double>(now_ns() - wall_start) * 1e-9;
}

}  // namespace tissue::host
