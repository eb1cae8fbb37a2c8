// check_timer (see timer_check.hpp).
#include "schedule/timer_check.hpp"

#include "schedule/tick_deadlines.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

namespace tissue::host {
namespace {

constexpr double MAX_TICKS = 1e7;

// The haptic thread's loop (realtime_schedule.cpp) with nothing to do in a tick.
TimerCheck run_ticks(Nanoseconds period, std::uint64_t ticks, bool realtime_priority) {
  TimerCheck check;
  check.priority = realtime_priority ? try_fifo_priority(HAPTIC_FIFO_PRIORITY) : Priority{false, "not asked"};
  std::vector<double> periods_s, late_s;
  periods_s.reserve(ticks);
  late_s.reserve(ticks);
  const TickDeadlines clock{now_ns() + period, period};
  Nanoseconds previous_wake = 0;
  for (std::uint64_t n = 0; n < ticks; ++n) {
    const Nanoseconds deadline = clock.deadline(n);
    sleep_until_ns(deadline);
    const Nanoseconds woke = now_ns();
    late_s.push_back(static_cast<double>(woke - deadline) * 1e-9);
    if (n > 0) periods_s.push_back(static_cast<double>(woke - previous_wake) * 1e-9);
    previous_wake = woke;
    if (clock.missed(n, now_ns())) ++check.deadline_misses;
  }
  check.ticks = ticks;
  check.period_us = percentiles(std::move(periods_s), 1e6);
  check.wake_late_us = percentiles(std::move(late_s), 1e6);
  return check;
}

}  // namespace

TimerCheck check_timer(double period_s, double duration_s, bool realtime_priority) {
  if (!(period_s > 0.0) || !std::isfinite(period_s) || !(duration_s > 0.0) || !std::isfinite(duration_s)) {
    throw std::invalid_argument("timer check: the period and the duration must be finite and > 0 s");
  }
  const double ticks = std::max(1.0, std::round(duration_s / period_s));
  if (ticks > MAX_TICKS) throw std::invalid_argument("timer check: more than 10^7 ticks asked");
  const Nanoseconds period = to_ns(period_s);
  if (period <= 0) throw std::invalid_argument("timer check: the period is under a nanosecond");
  TimerCheck check;
  // A thread of its own: the priority is the thread's, not the caller's.
  std::thread thread([&] { check = run_ticks(period, static_cast<std::uint64_t>(ticks), realtime_priority); });
  thread.join();
  return check;
}

std::string TimerCheck::to_json() const {
  nlohmann::ordered_json j;
  j["ticks"] = ticks;
  j["deadline_misses"] = deadline_misses;
  j["period_us"] = percentiles_json(period_us);
  j["wake_late_us"] = percentiles_json(wake_late_us);
  j["realtime_priority"] = priority.granted;
  j["realtime_priority_note"] = priority.note;
  return j.dump(2) + "\n";
}

void print_timer_check(std::ostream& out, const TimerCheck& check, double period_s) {
  out << "timer alone: " << check.ticks << " ticks of " << period_s * 1e6 << " us, deadline misses "
      << check.deadline_misses << " (" << 100.0 * static_cast<double>(check.deadline_misses) /
                                              static_cast<double>(std::max<std::uint64_t>(check.ticks, 1))
      << " %), period p50/p99/max " << check.period_us.p50 << " / " << check.period_us.p99 << " / "
      << check.period_us.max << " us, woke late p50/p99/max " << check.wake_late_us.p50 << " / "
      << check.wake_late_us.p99 << " / " << check.wake_late_us.max << " us\n";
  out << "  priority: " << check.priority.note << "\n";
}

}  // namespace tissue::host
