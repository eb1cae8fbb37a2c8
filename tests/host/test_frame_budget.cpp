// FrameBudget (issue 42): a due frame is captured in the time the step left over in its slot, else
// left to a later slot, never more than MAX_DEFERRALS in a row. Times in ns, no clock.
#include "schedule/frame_budget.hpp"

#include <gtest/gtest.h>

namespace tissue::host {
namespace {

constexpr Nanoseconds MS = 1'000'000;

TEST(FrameBudget, ACaptureWaitsWhereTheStepLeftLessThanCapturesTake) {
  FrameBudget frames;
  // Nothing known yet: a capture within the slot goes ahead.
  EXPECT_TRUE(frames.capture_now(3 * MS, 10 * MS));
  frames.captured(5 * MS);
  EXPECT_EQ(frames.capture_estimate_ns(), 5 * MS);
  // A step that ends 3 ms before its slot's end leaves too little for a 5 ms capture; 6 ms do.
  EXPECT_FALSE(frames.capture_now(7 * MS, 10 * MS));
  EXPECT_TRUE(frames.capture_now(4 * MS, 10 * MS));
  // A step that overran its slot: the frame waits too.
  EXPECT_FALSE(frames.capture_now(12 * MS, 10 * MS));
}

TEST(FrameBudget, AFrameWaitsAtMostMaxDeferralsSlotsInARow) {
  FrameBudget frames;
  frames.captured(20 * MS);  // captures longer than any slot
  for (int k = 0; k < FrameBudget::MAX_DEFERRALS; ++k) {
    ASSERT_FALSE(frames.capture_now(1 * MS, 10 * MS)) << k;
    frames.deferred();
  }
  EXPECT_TRUE(frames.capture_now(1 * MS, 10 * MS));  // late, but it comes
  frames.captured(20 * MS);
  EXPECT_FALSE(frames.capture_now(1 * MS, 10 * MS));  // the count starts again
}

TEST(FrameBudget, OneCostlyCaptureFadesByDecayPerCapture) {
  FrameBudget frames;
  frames.captured(8 * MS);
  frames.captured(1 * MS);
  EXPECT_EQ(frames.capture_estimate_ns(), static_cast<Nanoseconds>(FrameBudget::DECAY * 8 * MS));
  for (int k = 0; k < 40; ++k) frames.captured(1 * MS);
  EXPECT_EQ(frames.capture_estimate_ns(), 1 * MS);  // 8 ms x 0.9^41 < 1 ms: the recent captures' own
}

}  // namespace
}  // namespace tissue::host
