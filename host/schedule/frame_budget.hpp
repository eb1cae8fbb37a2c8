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
// run of cheap captures let the next costly one into a slot it overran. Until a capture after a cut
// has been measured, its estimate is the first read of the whole surface (seed()).
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
  /// Whether to capture now, `now` being when the step ended and `slot_end` when its slot ends.
  [[nodiscard]] bool capture_now(Nanoseconds now, Nanoseconds slot_end, CaptureKind kind) const {
    return m_deferred_in_row >= MAX_DEFERRALS || now + capture_estimate_ns(kind) <= slot_end;
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

  std::array<Nanoseconds, 2> m_estimate_ns{};
  int m_deferred_in_row = 0;
};

}  // namespace tissue::host
