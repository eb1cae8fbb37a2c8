// A session's timeline (docs/DESIGN.md, "Host"): the haptic loop ticks every haptic period, the tissue
// steps once per slot (its communication step, a whole number of ticks), and a session runs whole
// slots. Both schedulers (offline_schedule.hpp, realtime_schedule.hpp) and the session's log use it.
#pragma once

#include "scenario/scenario.hpp"

#include <cstdint>

namespace tissue::host {

struct Schedule {
  double haptic_period_s = 0.001;
  double slot_s = 0.01;  ///< the tissue's communication step
  std::uint64_t ticks_per_slot = 10;
  std::uint64_t ticks = 0;  ///< of the whole session: the duration rounded up to whole slots
  double duration_s = 0.0;  ///< the scenario's, for the progress lines
  OverrunPolicy overrun_policy = OverrunPolicy::catch_up;
  int max_catch_up_slots = 4;

  [[nodiscard]] std::uint64_t slots() const { return ticks / ticks_per_slot; }
};

/// The scenario's timeline (its haptic period, communication step, duration and overrun policy).
Schedule make_schedule(const Scenario& scenario);

}  // namespace tissue::host
