// FrameBudget: whether the dynamics thread captures a due frame (the recording's) in this slot or
// leaves it to a later one. A frame is captured in the time the step left over: where the slot's
// remaining time does not cover what a capture has taken lately, the frame waits, so that recording
// a surface never makes the physics miss its slot (the organ's fine surface: re-meshed, encoded and
// copied after each cut, ~5 ms against a 3 ms step; issue 42). Never more than MAX_DEFERRALS slots in
// a row: a frame comes late, never not at all. 10 slots (three periods of a 30 Hz recording): the
// frames forced into a cutting step's slot are most of the organ's overruns; over three interleaved
// real-time runs each of cut_organ and resect_lobe, 131 overruns with 10 against 166 with 6
// (docs/BENCHMARKS.md, "The organ in a real session"). "Lately" is the longest recent capture, decaying
// by DECAY per capture, so that one costly capture (after a cut) keeps the next ones careful; it is
// kept per kind of capture, since one after a cut (the surface re-meshed and its embedding copied,
// 3-7 ms on the organ) costs ten times one of the positions alone: with one estimate for both, a
// run of cheap captures let the next costly one into a slot it overran.
// A frame left to a later slot is taken at that slot's start, before its step, when the capture and
// the step (the longest recent one, decaying alike) fit: the state is the one the frame was due for.
// A frame of a re-meshed surface always waits for the next slot's start (forced there after
// MAX_DEFERRALS): the Tissue FMU prepares the re-meshed surface in between, in the time the slot
// leaves idle (surface.prepareAfterStep), so that its capture is a copy of ready bytes; if the
// preparation has not finished when the slot starts (surface.preparing), the frame waits another
// slot rather than the slot for it (those captures waited 1-10 ms: most of the organ's overruns
// left, issue 42).
#pragma once

#include "output/slot_timing.hpp"
#include "sync/realtime_clock.hpp"

#include <algorithm>
#include <array>
#include <cstddef>

namespace tissue::host {

class FrameBudget {
 public:
  static constexpr int MAX_DEFERRALS = 10;
  static constexpr double DECAY = 0.9;

  /// The estimate of `kind` before any capture of it (>= 0).
  void seed(CaptureKind kind, Nanoseconds estimate) { estimate_of(kind) = std::max<Nanoseconds>(estimate, 0); }
  /// Whether to capture now, `now` being when the step ended and `slot_end` when its slot ends (the
  /// positions after the step: capture_at()).
  [[nodiscard]] bool capture_now(Nanoseconds now, Nanoseconds slot_end, CaptureKind kind) const {
    return forced() || now + capture_estimate_ns(kind) <= slot_end;
  }
  /// Where in its slot a due frame is looked at: before the step (a frame left to this slot) or after it.
  enum class Point { before_step, after_step };
  /// Whether to capture a due frame of `kind` at `point`, `now` being then and `slot_end` the end of
  /// the slots the step covers. Before the step: when the capture and the step fit and the surface
  /// is not still being prepared (`preparing`: the capture would wait for it), or forced. After it:
  /// a re-meshed surface waits for the next slot's start (forced there); the positions as
  /// capture_now().
  [[nodiscard]] bool capture_at(Point point, Nanoseconds now, Nanoseconds slot_end, CaptureKind kind,
                                bool preparing = false) const {
    if (point == Point::before_step) return forced() || (!preparing && fits_before_step(now, slot_end, kind));
    return kind != CaptureKind::remeshed && capture_now(now, slot_end, kind);
  }
  /// Whether a frame of a re-meshed surface due after the coming step is worth preparing meanwhile
  /// (the Tissue's surface.prepareAfterStep): when it would be taken at the next slot's start, i.e. it
  /// and a step fit in `slot`, or it will be forced. Else the preparation would go to waste and the
  /// next step wait for it (a piece coming free: steps of 10-16 ms each waited for the last one's).
  [[nodiscard]] bool worth_preparing(Nanoseconds slot) const {
    return m_deferred_in_row + 1 >= MAX_DEFERRALS || fits_before_step(0, slot, CaptureKind::remeshed);
  }
  /// Whether a due frame has waited the most slots it may: it is captured at the next chance, whatever it costs.
  [[nodiscard]] bool forced() const { return m_deferred_in_row >= MAX_DEFERRALS; }
  /// A step took `took` (>= 0).
  void stepped(Nanoseconds took) {
    m_step_estimate_ns = std::max(took, static_cast<Nanoseconds>(DECAY * static_cast<double>(m_step_estimate_ns)));
  }
  /// A capture of `kind` took `took` (>= 0).
  void captured(Nanoseconds took, CaptureKind kind) {
    Nanoseconds& estimate = estimate_of(kind);
    estimate = std::max(took, static_cast<Nanoseconds>(DECAY * static_cast<double>(estimate)));
    m_deferred_in_row = 0;
  }
  /// A due frame was left to a later slot.
  void deferred() { ++m_deferred_in_row; }
  [[nodiscard]] Nanoseconds capture_estimate_ns(CaptureKind kind) const {
    return m_estimate_ns[static_cast<std::size_t>(kind)];
  }

 private:
  Nanoseconds& estimate_of(CaptureKind kind) { return m_estimate_ns[static_cast<std::size_t>(kind)]; }
  /// Whether a capture of `kind` from `now` and then a step (the longest recent one) end by `slot_end`.
  [[nodiscard]] bool fits_before_step(Nanoseconds now, Nanoseconds slot_end, CaptureKind kind) const {
    return now + capture_estimate_ns(kind) + m_step_estimate_ns <= slot_end;
  }

  std::array<Nanoseconds, 2> m_estimate_ns{};
  Nanoseconds m_step_estimate_ns = 0;
  int m_deferred_in_row = 0;
};

}  // namespace tissue::host
