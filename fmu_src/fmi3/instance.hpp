// One FMU instance in the FMI 3.0 layer, shared by every FMU of the project: the state machine
// (state_machine.hpp), the stored values (value_store.hpp) with typed get/set driven by the
// variable table, FMU states, and logging through the importer's callback. The model behind it
// (model.hpp) holds the physics. fmi3_functions.cpp is the C ABI over this class: it calls
// `run()` with the function's Call so that the state is checked once, on entry, and the standard's
// transition after an error is made in one place.
#pragma once

#include "fmi3/model.hpp"
#include "fmi3/state_machine.hpp"
#include "fmi3/value_store.hpp"

#include <cstdint>
#include <exception>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace tissue::fmi3 {

/// The importer's log callback, without FMI types: (status, category, message).
using StatusLogger = std::function<void(Status status, const char* category, const char* message)>;

/// An FMU state as the importer holds it: the mode, the stored values, the model's state.
struct InstanceState {
  State mode = State::step;
  ValueStore values;
  std::unique_ptr<ModelState> model;
};

class Instance {
 public:
  /// Throws std::exception if the model cannot be made.
  Instance(const ModelDescription& description, std::string name, std::string resource_path, bool logging_on,
           StatusLogger logger);

  [[nodiscard]] State state() const { return m_state; }
  [[nodiscard]] const ModelDescription& description() const { return m_description; }
  [[nodiscard]] Model& model() { return *m_model; }
  [[nodiscard]] const ValueStore& values() const { return m_values; }

  /// Checks that `call` is allowed now, runs `body` (which returns a Status), catches everything,
  /// logs the reason of any status worse than ok and makes the standard's transition after an error.
  template <class Body>
  Status run(Call call, const char* function, Body&& body) noexcept;

  // The calls (each assumes its state was checked by run()).
  void set_debug_logging(bool logging_on, std::span<const char* const> categories);
  void enter_initialization_mode(double start_time_s);
  void exit_initialization_mode();
  /// fmi3Discard (with the last good time) when the model stopped early.
  Status do_step(double current_time_s, double step_s, double& last_successful_time_s);
  void terminate();
  void reset();

  template <class T>
  void get(std::span<const ValueReference> vrs, std::span<T> values);
  template <class T>
  void set(std::span<const ValueReference> vrs, std::span<const T> values);
  /// Binary outputs: per variable its size and a pointer to the model's bytes.
  void get_binary(std::span<const ValueReference> vrs, std::span<std::size_t> sizes,
                  std::span<const std::uint8_t*> values);

  [[nodiscard]] std::unique_ptr<InstanceState> save() const;
  void restore(const InstanceState& saved);
  [[nodiscard]] std::vector<std::uint8_t> serialize(const InstanceState& saved) const;
  [[nodiscard]] std::unique_ptr<InstanceState> deserialize(std::span<const std::uint8_t> bytes) const;

  /// Logs through the importer: warnings and errors always (as Reference-FMUs does), calls and
  /// events only with logging on and their category enabled.
  void log(Status status, const char* category, const char* message) const;
  void log(Status status, const char* category, const std::string& message) const {
    log(status, category, message.c_str());
  }

 private:
  const VariableInfo& variable(ValueReference vr, bool setting) const;
  /// As above, and refused unless the variable's type is got and set as T.
  template <class T>
  const VariableInfo& variable(ValueReference vr, bool setting) const;
  [[nodiscard]] std::size_t element_count(const VariableInfo& info) const;
  void log_exception(const char* function, Status status) const noexcept;

  const ModelDescription& m_description;
  std::string m_name;
  StatusLogger m_logger;
  bool m_logging_on = false;
  bool m_log_calls = false;
  bool m_log_events = true;
  State m_state = State::instantiated;
  State m_mode_before_error = State::instantiated;
  ValueStore m_values;
  ValueStore m_candidate;  // a set is checked here first: a refused call changes nothing
  std::unique_ptr<Model> m_model;
};

template <class Body>
Status Instance::run(Call call, const char* function, Body&& body) noexcept {
  Status status = Status::error;
  try {
    log(Status::ok, "logCalls", function);
    check_call(call, m_state, function);
    status = body();
  } catch (...) {
    status = Status::error;
    log_exception(function, status);
  }
  if (status == Status::error || status == Status::fatal) {
    if (m_state != State::error && m_state != State::fatal) m_mode_before_error = m_state;
    m_state = state_after(m_state, status);
  }
  return status;
}

}  // namespace tissue::fmi3
