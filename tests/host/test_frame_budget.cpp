// FrameBudget (issue 42): a due frame is captured in the time the step left over in its slot, else
// left to a later slot (taken at its start when it and the step fit), never more than MAX_DEFERRALS
// in a row. Times in ns, no clock.
#include "schedule/frame_budget.hpp"

#include <gtest/gtest.h>

namespace tissue::host {
namespace {

constexpr Nanoseconds MS = 1'000'000;
constexpr CaptureKind P = CaptureKind::positions;
constexpr CaptureKind R = CaptureKind::remeshed;

TEST(FrameBudget, ACaptureWaitsWhereTheStepLeftLessThanCapturesTake) {
  FrameBudget frames;
  // Nothing known yet: a capture within the slot goes ahead.
  EXPECT_TRUE(frames.capture_now(3 * MS, 10 * MS, P));
  frames.captured(5 * MS, P);
  EXPECT_EQ(frames.capture_estimate_ns(P), 5 * MS);
  // A step that ends 3 ms before its slot's end leaves too little for a 5 ms capture; 6 ms do.
  EXPECT_FALSE(frames.capture_now(7 * MS, 10 * MS, P));
  EXPECT_TRUE(frames.capture_now(4 * MS, 10 * MS, P));
  // A step that overran its slot: the frame waits too.
  EXPECT_FALSE(frames.capture_now(12 * MS, 10 * MS, P));
}

TEST(FrameBudget, AFrameWaitsAtMostMaxDeferralsSlotsInARow) {
  FrameBudget frames;
  frames.captured(20 * MS, P);  // captures longer than any slot
  for (int k = 0; k < FrameBudget::MAX_DEFERRALS; ++k) {
    ASSERT_FALSE(frames.capture_now(1 * MS, 10 * MS, P)) << k;
    frames.deferred();
  }
  EXPECT_TRUE(frames.capture_now(1 * MS, 10 * MS, P));  // late, but it comes
  frames.captured(20 * MS, P);
  EXPECT_FALSE(frames.capture_now(1 * MS, 10 * MS, P));  // the count starts again
}

TEST(FrameBudget, OneCostlyCaptureFadesByDecayPerCapture) {
  FrameBudget frames;
  frames.captured(8 * MS, P);
  frames.captured(1 * MS, P);
  EXPECT_EQ(frames.capture_estimate_ns(P), static_cast<Nanoseconds>(FrameBudget::DECAY * 8 * MS));
  for (int k = 0; k < 40; ++k) frames.captured(1 * MS, P);
  EXPECT_EQ(frames.capture_estimate_ns(P), 1 * MS);  // 8 ms x 0.9^41 < 1 ms: the recent captures' own
}

// Captures after a cut (the surface re-meshed: 3-7 ms on the organ) are judged by their own kind:
// a run of cheap captures of the positions (0.5 ms) does not let the next costly one into a slot
// with 5 ms left, which it would overrun (with one estimate for both it went ahead).
TEST(FrameBudget, ACaptureAfterACutIsJudgedByCapturesAfterCuts) {
  FrameBudget frames;
  frames.seed(R, 6 * MS);  // the first read of the whole surface
  EXPECT_FALSE(frames.capture_now(5 * MS, 10 * MS, R));
  EXPECT_TRUE(frames.capture_now(3 * MS, 10 * MS, R));
  frames.captured(7 * MS, R);
  for (int k = 0; k < 30; ++k) frames.captured(MS / 2, P);
  EXPECT_EQ(frames.capture_estimate_ns(R), 7 * MS);
  EXPECT_FALSE(frames.capture_now(5 * MS, 10 * MS, R));  // 5 ms left: the re-meshed frame waits
  EXPECT_TRUE(frames.capture_now(5 * MS, 10 * MS, P));   // one of the positions goes ahead
  frames.seed(P, -MS);                                    // a negative seed is none
  EXPECT_EQ(frames.capture_estimate_ns(P), 0);
}

// A frame of a re-meshed surface is never captured right after the step that re-meshed it (the Tissue
// prepares it meanwhile): it waits for the next slot's start, where it goes ahead of the step when the
// capture and the step (the longest recent one) fit, and when forced whatever they take. A frame of
// the positions goes after the step as before, and before it when left to the slot.
TEST(FrameBudget, AReMeshedFrameIsTakenAtTheNextSlotsStartBeforeTheStep) {
  using Point = FrameBudget::Point;
  FrameBudget frames;
  EXPECT_FALSE(frames.capture_at(Point::after_step, 1 * MS, 10 * MS, R));  // plenty of time: it still waits
  EXPECT_TRUE(frames.capture_at(Point::after_step, 1 * MS, 10 * MS, P));
  frames.stepped(4 * MS);
  frames.captured(2 * MS, R);
  EXPECT_TRUE(frames.capture_at(Point::before_step, 0, 10 * MS, R));       // 2 + 4 ms in 10
  EXPECT_FALSE(frames.capture_at(Point::before_step, 5 * MS, 10 * MS, R));  // a late start: 5 + 2 + 4 > 10
  frames.stepped(9 * MS);  // a long step: the capture would push it past the slot
  EXPECT_FALSE(frames.capture_at(Point::before_step, 0, 10 * MS, R));
  for (int k = 0; k < FrameBudget::MAX_DEFERRALS; ++k) {
    ASSERT_FALSE(frames.capture_at(Point::after_step, 1 * MS, 10 * MS, R)) << k;
    frames.deferred();
  }
  EXPECT_FALSE(frames.capture_at(Point::after_step, 1 * MS, 10 * MS, R));  // forced at the slot's start only
  EXPECT_TRUE(frames.capture_at(Point::before_step, 5 * MS, 10 * MS, R));
  frames.captured(1 * MS, R);
  EXPECT_FALSE(frames.forced());
}

// A re-meshed surface the Tissue still prepares when the slot starts (surface.preparing): reading it
// would wait for the preparation, so the frame waits a slot instead, until it is forced.
TEST(FrameBudget, AReMeshedFrameStillBeingPreparedWaitsASlotUnlessForced) {
  using Point = FrameBudget::Point;
  FrameBudget frames;
  frames.stepped(4 * MS);
  frames.captured(2 * MS, R);
  EXPECT_TRUE(frames.capture_at(Point::before_step, 0, 10 * MS, R, /*preparing=*/false));
  EXPECT_FALSE(frames.capture_at(Point::before_step, 0, 10 * MS, R, /*preparing=*/true));
  for (int k = 0; k < FrameBudget::MAX_DEFERRALS; ++k) {
    ASSERT_FALSE(frames.capture_at(Point::before_step, 0, 10 * MS, R, true)) << k;
    frames.deferred();
  }
  EXPECT_TRUE(frames.capture_at(Point::before_step, 0, 10 * MS, R, true));  // forced: it waits for the preparation
}

}  // namespace
}  // namespace tissue::host
