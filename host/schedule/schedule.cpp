// make_schedule (see schedule.hpp).
#include "schedule/schedule.hpp"

#include <cmath>

namespace tissue::host {

Schedule make_schedule(const Scenario& scenario) {
  Schedule schedule;
  schedule.haptic_period_s = scenario.haptic_period_s;
  schedule.slot_s = scenario.tissue_step_s;
  schedule.ticks_per_slot = static_cast<std::uint64_t>(std::llround(schedule.slot_s / schedule.haptic_period_s));
  schedule.ticks = static_cast<std::uint64_t>(std::llround(std::ceil(scenario.duration_s / schedule.slot_s))) *
                   schedule.ticks_per_slot;
  schedule.duration_s = scenario.duration_s;
  schedule.overrun_policy = scenario.overrun_policy;
  schedule.max_catch_up_slots = scenario.max_catch_up_slots;
  return schedule;
}

}  // namespace tissue::host
