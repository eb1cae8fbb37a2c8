// The state table (see state_machine.hpp).
#include "fmi3/state_machine.hpp"

#include <array>

namespace tissue::fmi3 {
namespace {

constexpr StateMask INSTANTIATED = mask(State::instantiated);
constexpr StateMask INITIALIZATION = mask(State::initialization);
constexpr StateMask STEP = mask(State::step);
constexpr StateMask TERMINATED = mask(State::terminated);
constexpr StateMask ERROR = mask(State::error);
constexpr StateMask FATAL = mask(State::fatal);
constexpr StateMask ANY_BUT_FATAL = INSTANTIATED | INITIALIZATION | STEP | TERMINATED | ERROR;

// One row per Call, in the enum's order. What we keep stricter than Reference-FMUs: no setting
// after termination, and no FMU state before initialization (there is no model to save yet).
constexpr std::array<StateMask, static_cast<std::size_t>(Call::count)> ALLOWED = {
    /* set_debug_logging */ ANY_BUT_FATAL,
    /* enter_initialization_mode */ INSTANTIATED,
    /* exit_initialization_mode */ INITIALIZATION,
    /* terminate */ INITIALIZATION | STEP,
    /* reset */ ANY_BUT_FATAL,
    /* get_value */ INITIALIZATION | STEP | TERMINATED | ERROR,
    /* set_value */ INSTANTIATED | INITIALIZATION | STEP,
    /* get_fmu_state */ INITIALIZATION | STEP | TERMINATED,
    /* set_fmu_state */ INITIALIZATION | STEP | ERROR,
    /* free_fmu_state */ ANY_BUT_FATAL | FATAL,
    /* serialize_fmu_state */ INITIALIZATION | STEP | TERMINATED | ERROR,
    /* do_step */ STEP,
    /* setup_experiment */ INSTANTIATED,
    /* not_offered */ 0,
};

}  // namespace

StateMask allowed_states(Call call) { return ALLOWED.at(static_cast<std::size_t>(call)); }

StateMask variable_settable_states(Causality causality, Variability variability) {
  switch (causality) {
    case Causality::structural_parameter:
      return INSTANTIATED;
    case Causality::parameter:
      return variability == Variability::tunable ? (INSTANTIATED | INITIALIZATION | STEP)
                                                 : (INSTANTIATED | INITIALIZATION);
    case Causality::input:
      return INSTANTIATED | INITIALIZATION | STEP;
    case Causality::independent:
    case Causality::output:
      return 0;
  }
  return 0;
}

void check_call(Call call, State state, std::string_view function) {
  const StateMask allowed = allowed_states(call);
  if ((allowed & mask(state)) != 0) return;
  std::string message = std::string(function) + " is not allowed in the " + std::string(to_string(state)) + " state";
  if (allowed != 0) message += " (only in " + describe(allowed) + ")";
  if (state == State::error) message += "; after an error only SetFMUState, Reset or FreeInstance lead on";
  throw CallOrderError(message);
}

State state_after(State state, Status status) {
  if (status == Status::fatal || state == State::fatal) return State::fatal;
  if (status == Status::error) return State::error;
  return state;
}

std::string_view to_string(State state) {
  switch (state) {
    case State::instantiated:
      return "instantiated";
    case State::initialization:
      return "initialization mode";
    case State::step:
      return "step mode";
    case State::terminated:
      return "terminated";
    case State::error:
      return "error";
    case State::fatal:
      return "fatal";
  }
  return "";
}

std::string describe(StateMask states) {
  std::string text;
  for (const State state :
       {State::instantiated, State::initialization, State::step, State::terminated, State::error, State::fatal}) {
    if ((states & mask(state)) == 0) continue;
    if (!text.empty()) text += ", ";
    text += to_string(state);
  }
  return text;
}

}  // namespace tissue::fmi3
