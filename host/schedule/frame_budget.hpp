// FrameBudget: whether the dynamics thread captures a due frame (the recording's) in this slot or
// leaves it to a later one. A frame is captured in the time the step left over: where the slot's
// remaining time does not cover what a capture has taken lately, the frame waits, so that recording
// a surface never makes the physics miss its slot (the organ's fine surface: re-meshed, encoded and
// copied after each cut, ~5 ms against a 3 ms step; issue 42). Never more than MAX_DEFERRALS slots in
// a row: a frame comes late, never not at all. 10 slots (three periods of a 30 Hz recording): the
// frames forced into a cutting step's slot are most of the organ's overruns; over three interleaved
// real-time runs each of cut_organ and resect_lobe, 131 overruns with 10 against 166 with 6
// (docs/BENCHMARKS.md, "The organ in a real session"). "Lately" is the longest recent capture, decaying
// by DECAY per capture, so that one costly capture (after a cut) keeps the next ones careful.
#pragma once

#include "sync/realtime_clock.hpp"

#include <algorithm>

namespace tissue::host {

class FrameBudget {
 public:
  static constexpr int MAX_DEFERRALS = 10;
  static constexpr double DECAY = 0.9;

  /// Whether to capture now, `now` being when the step ended and `slot_end` when its slot ends.
  [[nodiscard]] bool capture_now(Nanoseconds now, Nanoseconds slot_end) const {
    return m_deferred_in_row >= MAX_DEFERRALS || now + m_capture_estimate_ns <= slot_end;
  }
  /// A capture took `took` (>= 0).
  void captured(Nanoseconds took) {
    m_capture_estimate_ns =
        std::max(took, static_cast<Nanoseconds>(DECAY * static_cast<double>(m_capture_estimate_ns)));
    m_deferred_in_row = 0;
  }
  /// A due frame was left to a later slot.
  void deferred() { ++m_deferred_in_row; }
  [[nodiscard]] Nanoseconds capture_estimate_ns() const { return m_capture_estimate_ns; }

 private:
  Nanoseconds m_capture_estimate_ns = 0;
  int m_deferred_in_row = 0;
};

}  // namespace tissue::host
