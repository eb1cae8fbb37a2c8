// The FMI 3.0 co-simulation state machine as one table: for each call, the states in which it is
// allowed (checked once, on entry, as modelica/Reference-FMUs does with its MASK_fmi3* masks), and
// the standard's transitions after a failed call (FMI 3.0, "Status Returned by Functions"):
// fmi3Error leaves the instance in the error state, from which only fmi3SetFMUState (back to a
// saved state), fmi3Reset and fmi3FreeInstance lead on (values may still be read, for debugging);
// fmi3Fatal leaves it in the fatal state, in which only fmi3FreeInstance is allowed.
// Configuration, event and clock modes are not offered, so they are not states here.
#pragma once

#include "fmi3/variable_table.hpp"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace tissue::fmi3 {

/// One bit per state, so that a set of states is a mask.
enum class State : std::uint8_t {
  instantiated = 1U << 0U,
  initialization = 1U << 1U,
  step = 1U << 2U,
  terminated = 1U << 3U,
  error = 1U << 4U,  ///< after fmi3Error
  fatal = 1U << 5U,  ///< after fmi3Fatal
};

/// The calls whose allowed states differ; every FMI function maps to one of them.
enum class Call : std::uint8_t {
  set_debug_logging,
  enter_initialization_mode,
  exit_initialization_mode,
  terminate,
  reset,
  get_value,
  set_value,  ///< further restricted per variable by variable_settable_states()
  get_fmu_state,
  set_fmu_state,
  free_fmu_state,
  serialize_fmu_state,  ///< SerializedFMUStateSize, SerializeFMUState, DeserializeFMUState
  do_step,
  setup_experiment,  ///< FMI 2.0's fmi2SetupExperiment (fmi2/): before initialization only
  not_offered,  ///< a function of an interface or feature the FMU does not offer
  count
};

/// The status an FMI call answers, in the standard's order of severity.
enum class Status : std::uint8_t { ok, warning, discard, error, fatal };

/// A call made in a state that does not allow it (the standard: fmi3Error).
class CallOrderError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

using StateMask = std::uint8_t;

[[nodiscard]] constexpr StateMask mask(State state) { return static_cast<StateMask>(state); }

/// The states in which `call` is allowed.
[[nodiscard]] StateMask allowed_states(Call call);

/// The states in which a variable of this causality and variability may be set (FMI 3.0: fixed
/// parameters up to initialization mode, tunable ones also in step mode, structural parameters only
/// when instantiated since configuration mode is not offered, inputs until terminated; the
/// independent variable and outputs never).
[[nodiscard]] StateMask variable_settable_states(Causality causality, Variability variability);

/// Throws CallOrderError, naming the function, the state and the states that allow it.
void check_call(Call call, State state, std::string_view function);

/// The state after a call in `state` answered `status` (error and fatal transitions; otherwise
/// unchanged: the call itself made any regular transition).
[[nodiscard]] State state_after(State state, Status status);

std::string_view to_string(State state);
/// "initialization or step mode" for a mask.
std::string describe(StateMask states);

}  // namespace tissue::fmi3
