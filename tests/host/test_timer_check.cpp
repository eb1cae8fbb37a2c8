// The haptic clock's rule (host/schedule/tick_deadlines.hpp) and the machine's timer check
// (timer_check.hpp): what is counted, never how fast the machine is (CI shares its cores).
#include "schedule/tick_deadlines.hpp"
#include "schedule/timer_check.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

namespace tissue::host {
namespace {

TEST(TickDeadlines, TickNIsDueAtStartPlusNPeriodsWithoutDrift) {
  const TickDeadlines clock{5'000, 1'000'000};
  EXPECT_EQ(clock.deadline(0), 5'000);
  EXPECT_EQ(clock.deadline(3), 3'005'000);
  EXPECT_EQ(clock.deadline(1'000'000), 1'000'000'005'000);  // 1000 s of 1 ms ticks, exact
}

TEST(TickDeadlines, ATickMissesOnlyWhenItEndsAfterTheNextTickIsDue) {
  const TickDeadlines clock{0, 1'000'000};
  EXPECT_FALSE(clock.missed(2, 2'999'999));  // woke late, done before tick 3 is due
  EXPECT_FALSE(clock.missed(2, 3'000'000));  // done as tick 3 is due: it starts on time
  EXPECT_TRUE(clock.missed(2, 3'000'001));
  EXPECT_TRUE(clock.missed(0, 5'000'000));  // a stall of several periods is one miss of this tick
}

TEST(TimerCheck, RunsTheTicksAskedAndReportsTheirPeriods) {
  const TimerCheck check = check_timer(1e-3, 0.05, /*realtime_priority=*/false);
  EXPECT_EQ(check.ticks, 50U);
  EXPECT_LE(check.deadline_misses, check.ticks);
  // Absolute deadlines: a late wake-up is followed by a short period, never a drift; each period is
  // positive and the slowest is at least the period (the p50 itself depends on the machine's load).
  EXPECT_GT(check.period_us.p50, 0.0);
  EXPECT_GE(check.period_us.max, 1000.0 - 1e-6 - check.wake_late_us.max);
  EXPECT_GE(check.wake_late_us.p50, 0.0);
  EXPECT_LE(check.wake_late_us.p50, check.wake_late_us.max);
  EXPECT_FALSE(check.priority.granted);
  EXPECT_EQ(check.priority.note, "not asked");
  const std::string json = check.to_json();
  EXPECT_NE(json.find("\"ticks\": 50"), std::string::npos) << json;
  EXPECT_NE(json.find("\"wake_late_us\""), std::string::npos) << json;
}

TEST(TimerCheck, RefusesPeriodsAndDurationsThatAreNotPositiveAndFinite) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [period_s, duration_s] : {std::pair{0.0, 1.0}, std::pair{-1e-3, 1.0}, std::pair{nan, 1.0},
                                             std::pair{1e-3, 0.0}, std::pair{1e-3, inf}, std::pair{1e-3, nan}}) {
    EXPECT_THROW((void)check_timer(period_s, duration_s, false), std::invalid_argument) << period_s << " " << duration_s;
  }
  EXPECT_THROW((void)check_timer(1e-9, 1e3, false), std::invalid_argument);  // 10^12 ticks
}

}  // namespace
}  // namespace tissue::host
