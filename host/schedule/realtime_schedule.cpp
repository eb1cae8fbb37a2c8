// run_realtime (see realtime_schedule.hpp).
#include "schedule/realtime_schedule.hpp"

#include "schedule/frame_budget.hpp"
#include "schedule/memory_reserve.hpp"
#include "schedule/tick_deadlines.hpp"
#include "sync/frame_pipe.hpp"
#include "sync/realtime_clock.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <ostream>
#include <thread>
#include <vector>

namespace tissue::host {
namespace {

double ms_between(Nanoseconds from, Nanoseconds to) { return static_cast<double>(to - from) / 1e6; }

// What the two real-time threads and the calling thread share during a run.
struct RealtimeRun {
  std::atomic<int> ready{0};
  std::atomic<bool> go{false};
  std::atomic<bool> haptic_done{false};
  std::atomic<std::uint64_t> ticks_done{0};
  Nanoseconds start = 0;       // the first deadline (set before `go`)
  Nanoseconds haptic_end = 0;  // haptic thread's, read after the join
  Priority haptic_priority, dynamics_priority;
  std::optional<std::uint64_t> stopped_at;  // haptic thread's, read after the join
};

class RealtimeScheduler {
 public:
  RealtimeScheduler(SessionSteps& steps, const Schedule& schedule, const RealtimeOptions& options, FrameWriter* writer,
                    SessionSummary& summary)
      : m_steps(steps), m_schedule(schedule), m_options(options), m_writer(writer), m_summary(summary) {
    m_periods_s.reserve(schedule.ticks);
  }

  void run();

 private:
  void haptic_thread(RealtimeRun& run);
  void dynamics_thread(RealtimeRun& run, FramePipe& pipe);
  void record_frame(FramePipe& pipe, FrameBudget& frames, Nanoseconds slot_end, double tissue_time_s,
                    FrameBudget::Point point, SlotTiming& timing);

  SessionSteps& m_steps;
  const Schedule& m_schedule;
  const RealtimeOptions& m_options;
  FrameWriter* m_writer;
  // Written by one thread each (each field by one thread only), read after both are joined.
  SessionSummary& m_summary;
  // Haptic thread's own.
  std::vector<double> m_periods_s;
  double m_longest_period_s = 0.0;
};

// The haptic thread: ticks on absolute deadlines of the haptic period, measuring the periods.
void RealtimeScheduler::haptic_thread(RealtimeRun& run) {
  if (m_options.realtime_priority) run.haptic_priority = try_fifo_priority(HAPTIC_FIFO_PRIORITY);
  run.ready.fetch_add(1);
  run.go.wait(false, std::memory_order_acquire);  // blocked, not spinning: see run()
  const TickDeadlines clock{run.start, to_ns(m_schedule.haptic_period_s)};
  Nanoseconds previous_wake = 0;
  if (m_options.haptic_thread_started) m_options.haptic_thread_started();
  for (std::uint64_t n = 0; n < m_schedule.ticks; ++n) {
    if (m_options.stop != nullptr && m_options.stop->load(std::memory_order_relaxed)) {
      run.stopped_at = n;  // asked to end early (Ctrl-C): the summary covers the ticks run
      break;
    }
    const Nanoseconds deadline = clock.deadline(n);
    sleep_until_ns(deadline);
    const Nanoseconds woke = now_ns();
    if (n == 0) m_summary.haptic_first_tick_late_us = static_cast<double>(woke - deadline) * 1e-3;
    if (n > 0) {
      const double period_s = static_cast<double>(woke - previous_wake) * 1e-9;
      m_periods_s.push_back(period_s);
      if (period_s > m_longest_period_s) {
        m_longest_period_s = period_s;
        m_summary.haptic_period_max_at_s = static_cast<double>(n) * m_schedule.haptic_period_s;
      }
    }
    previous_wake = woke;
    m_steps.haptic_tick(n);
    if (clock.missed(n, now_ns())) ++m_summary.deadline_misses;
    m_steps.haptic_tick_timed(n, m_periods_s.empty() ? 0.0 : m_periods_s.back(), m_summary.deadline_misses);
    run.ticks_done.store(n + 1, std::memory_order_relaxed);
  }
  run.haptic_end = now_ns();
  run.haptic_done.store(true, std::memory_order_release);
}

// The recording's due frame at `point` of a slot whose step(s) end at `slot_end` (FrameBudget says
// whether now): captured, left to a later slot (counted after the step only), or dropped when the
// writer has no free buffer.
void RealtimeScheduler::record_frame(FramePipe& pipe, FrameBudget& frames, Nanoseconds slot_end, double tissue_time_s,
                                     FrameBudget::Point point, SlotTiming& timing) {
  const CaptureKind kind = m_steps.frame_remeshed() ? CaptureKind::remeshed : CaptureKind::positions;
  const Nanoseconds begin = now_ns();
  timing.capture_kind = kind;
  // Asked only where it matters: a re-meshed surface looked at before the step.
  const bool preparing =
      point == FrameBudget::Point::before_step && kind == CaptureKind::remeshed && m_steps.frame_preparing();
  if (!frames.capture_at(point, begin, slot_end, kind, preparing)) {
    if (point == FrameBudget::Point::before_step) return;  // looked at again after the step
    frames.deferred();
    ++m_summary.frames_deferred;
    timing.frame = SlotFrame::deferred;
    return;
  }
  timing.frame_before_step = point == FrameBudget::Point::before_step;
  if (auto frame = pipe.take_free()) {
    m_steps.capture_frame(*frame, tissue_time_s);
    const Nanoseconds captured = now_ns();
    frames.captured(captured - begin, kind);
    pipe.push_filled(std::move(frame));
    timing.frame = SlotFrame::captured;
    timing.capture_ms = ms_between(begin, captured);
  } else {
    ++m_summary.frames_dropped;
    m_steps.frame_dropped();
    timing.frame = SlotFrame::dropped;
  }
}

// The dynamics thread: a tissue step per slot, the overrun policy when one takes longer.
void RealtimeScheduler::dynamics_thread(RealtimeRun& run, FramePipe& pipe) {
  if (m_options.realtime_priority) {
    run.dynamics_priority = try_fifo_priority(DYNAMICS_FIFO_PRIORITY);
    touch_heap(DYNAMICS_HEAP_RESERVE_BYTES);  // locked with the rest by run()
  }
  run.ready.fetch_add(1);
  run.go.wait(false, std::memory_order_acquire);  // blocked, not spinning: see run()
  const Nanoseconds slot = to_ns(m_schedule.slot_s);
  const std::uint64_t slots_total = m_schedule.slots();
  FrameBudget frames;    // due frames captured in the time the steps leave over
  std::uint64_t k = 0;  // the slot this step starts in
  int slots = 1;        // slots this step covers
  double tissue_time_s = 0.0;
  while (k < slots_total && !run.haptic_done.load(std::memory_order_acquire) && !m_steps.tissue_failed()) {
    const Nanoseconds slot_begin = run.start + static_cast<Nanoseconds>(k) * slot;
    sleep_until_ns(slot_begin);
    slots = static_cast<int>(std::min<std::uint64_t>(static_cast<std::uint64_t>(slots), slots_total - k));
    SlotTiming timing{k, slots};
    const Nanoseconds woke = now_ns();
    const Nanoseconds slot_end = run.start + static_cast<Nanoseconds>(k + static_cast<std::uint64_t>(slots)) * slot;
    if (m_steps.frame_due(tissue_time_s)) {  // one left to this slot
      record_frame(pipe, frames, slot_end, tissue_time_s, FrameBudget::Point::before_step, timing);
    }
    const double step_end_s = tissue_time_s + slots * m_schedule.slot_s;
    m_steps.prepare_surface_after_step(m_steps.frame_due(step_end_s) && frames.worth_preparing(slot));
    const Nanoseconds began = now_ns();
    tissue_time_s = m_steps.tissue_step(tissue_time_s, slots);
    const Nanoseconds stepped = now_ns();
    frames.stepped(stepped - began);
    m_steps.publish_tissue_sample();
    m_steps.tissue_sample_published(tissue_time_s);
    const Nanoseconds sampled = now_ns();
    k += static_cast<std::uint64_t>(slots);
    slots = 1;
    if (timing.frame == SlotFrame::none && m_steps.frame_due(tissue_time_s)) {
      record_frame(pipe, frames, slot_end, tissue_time_s, FrameBudget::Point::after_step, timing);
    }
    const Nanoseconds finished = now_ns();
    if (m_options.slot_timings != nullptr && m_options.slot_timings->size() < m_options.slot_timings->capacity()) {
      timing.start_late_ms = ms_between(slot_begin, woke);
      timing.step_ms = ms_between(began, stepped);
      timing.sample_ms = ms_between(stepped, sampled);
      timing.end_after_slot_ms = ms_between(slot_end, finished);
      m_options.slot_timings->push_back(timing);  // within the capacity run() reserved: no allocation
    }
    if (finished > slot_end) {
      // Overrun: the step took longer than its slot(s). Never silent: counted, and handled by
      // the scenario's policy.
      ++m_summary.tissue_overruns;
      const auto missed = static_cast<std::uint64_t>((finished - slot_end) / slot) + 1;
      if (m_schedule.overrun_policy == OverrunPolicy::catch_up) {
        // The next step starts now (its slot began already) and covers the slots up to the
        // one the wall clock is in, at most max_catch_up_slots more than its own; tissue time
        // stays on wall time, with a longer (still whole-internal-step) communication step.
        const std::uint64_t cover =
            std::min<std::uint64_t>(missed, static_cast<std::uint64_t>(m_schedule.max_catch_up_slots) + 1);
        slots = static_cast<int>(cover);
        m_summary.catch_up_slots += cover - 1;
        if (missed > cover) {
          m_summary.skipped_slots += missed - cover;
          k += missed - cover;
        }
      } else {
        // The missed slots are skipped: the next step waits for the next slot boundary.
        m_summary.skipped_slots += missed;
        k += missed;
      }
    }
  }
  m_summary.sim_time_s = tissue_time_s;
}

void RealtimeScheduler::run() {
  if (m_options.realtime_priority) keep_freed_memory();
  if (m_options.slot_timings != nullptr) m_options.slot_timings->reserve(m_schedule.slots());
  FramePipe pipe(8);
  pipe.prepare([&](SurfaceFrame& frame) { m_steps.reserve_frame(frame); });
  RealtimeRun run;
  std::thread haptic([&] { haptic_thread(run); });
  std::thread dynamics([&] { dynamics_thread(run, pipe); });

  while (run.ready.load() < 2) std::this_thread::yield();
  if (m_options.realtime_priority) {
    // Everything mapped now, the two threads' stacks and the frames included, is locked in
    // memory: no page fault in the loops. Not future mappings (MCL_FUTURE): then each large
    // allocation of the dynamics thread populated and locked its pages under the address-space
    // lock and stalled the haptic thread. May be refused like the priority.
    (void)mlockall(MCL_CURRENT);
  }
  run.start = now_ns() + 20'000'000;  // 20 ms from now: both threads are waiting
  // The two threads wait for this blocked: spinning at SCHED_FIFO on both cores while mlockall ran
  // (longer with a render surface's megabytes to lock) used up the real-time bandwidth
  // (sched_rt_runtime_us, 95% of each second) and the kernel held every real-time thread back for
  // the rest of the period: the first haptic ticks came up to 15 ms late.
  run.go.store(true, std::memory_order_release);
  run.go.notify_all();

  Nanoseconds next_progress = run.start + 1'000'000'000;
  const auto drain = [&](std::chrono::milliseconds timeout) {
    while (auto frame = pipe.wait_filled(timeout)) {
      m_steps.complete_frame(*frame);
      m_writer->write(*frame);
      pipe.give_back(std::move(frame));
      timeout = std::chrono::milliseconds(0);
    }
  };
  while (!run.haptic_done.load(std::memory_order_acquire)) {
    drain(std::chrono::milliseconds(50));
    if (m_options.progress != nullptr && now_ns() >= next_progress) {
      const double t = static_cast<double>(run.ticks_done.load(std::memory_order_relaxed)) * m_schedule.haptic_period_s;
      *m_options.progress << "real time: t = " << t << " / " << m_schedule.duration_s << " s, cut tets "
                          << m_steps.cut_tets() << "\n";
      next_progress += 1'000'000'000;
    }
  }
  haptic.join();
  dynamics.join();
  m_summary.haptic_ticks = run.stopped_at ? *run.stopped_at : m_schedule.ticks;
  m_summary.wall_time_s = static_cast<double>(run.haptic_end - run.start) * 1e-9;
  drain(std::chrono::milliseconds(0));
  if (m_writer != nullptr) {
    m_summary.frames_written = m_writer->count();
    m_writer->finish();
  }
  m_summary.haptic_period_us = percentiles(m_periods_s, 1e6);
  m_summary.realtime_priority = run.haptic_priority.granted && run.dynamics_priority.granted;
  m_summary.realtime_priority_note =
      m_options.realtime_priority
          ? (m_summary.realtime_priority ? "SCHED_FIFO (haptic 80, dynamics 70)" : run.haptic_priority.note)
          : "not asked for";
}

}  // namespace

void run_realtime(SessionSteps& steps, const Schedule& schedule, const RealtimeOptions& options, FrameWriter* writer,
                  SessionSummary& summary) {
  RealtimeScheduler(steps, schedule, options, writer, summary).run();
}

}  // namespace tissue::host
