// fmu3_instance.hpp - one FMI 3.0 co-simulation instance of an imported FMU (RAII).
//
// Two layers of access:
//  * thin calls by value reference that pass the caller's buffers straight to the FMU and
//    return its fmi3Status (no allocation, never throw for a status; for the real-time loop);
//  * checked calls by variable name that look the variable up in the model description and
//    refuse, with an FmuError naming the variable, an unknown name, a type that does not match
//    the accessor, a value count that is not the variable's size, or a variable the importer
//    may not set (independent, calculated parameter, constant, output/local without
//    initial="exact"/"approx").
// Calls the FMU's description does not allow (FMU state without canGetAndSetFMUState,
// serialization without canSerializeFMUState) are refused with FmuError, never forwarded.
#pragma once

#include "fmi3_abi.h"
#include "importer/fmu3.hpp"

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tissue::host {

/// One message the FMU logged through fmi3LogMessageCallback.
struct LogRecord {
  std::string category;
  fmi3Status status = fmi3OK;
  std::string message;
};

/// The outputs of fmi3DoStep.
struct DoStepResult {
  fmi3Status status = fmi3Error;
  bool event_handling_needed = false;
  bool terminate_simulation = false;
  bool early_return = false;
  double last_successful_time_s = 0.0;
};

/// Text of a status ("fmi3OK", ...), for messages and test output.
[[nodiscard]] const char* status_name(fmi3Status status);

class LogBuffer;

/**
 * A co-simulation instance created with fmi3InstantiateCoSimulation (not visible, no event
 * mode, no early return, no intermediate variables) and freed with fmi3FreeInstance by the
 * destructor. The FMU's log messages are collected in this object (log()). Movable, not
 * copyable; the Fmu3 must outlive it, and a moved-from instance must not be called.
 */
class Fmu3Instance {
 public:
  /// Instantiates with the description's instantiationToken; throws FmuError (with the
  /// messages the FMU logged) if instantiation returns NULL.
  Fmu3Instance(const Fmu3& fmu, std::string instance_name, bool logging_on = false);
  /// As above but passes @p instantiation_token instead, e.g. to check that an FMU refuses a
  /// wrong token.
  Fmu3Instance(const Fmu3& fmu, std::string instance_name, std::string instantiation_token, bool logging_on);
  ~Fmu3Instance();

  Fmu3Instance(const Fmu3Instance&) = delete;
  Fmu3Instance& operator=(const Fmu3Instance&) = delete;
  Fmu3Instance(Fmu3Instance&& other) noexcept;
  Fmu3Instance& operator=(Fmu3Instance&& other) noexcept;

  [[nodiscard]] fmi3Instance handle() const { return m_instance; }
  [[nodiscard]] const Fmu3& fmu() const { return *m_fmu; }
  [[nodiscard]] const ModelDescription& description() const { return m_fmu->description(); }
  [[nodiscard]] const std::string& name() const { return m_name; }

  /// Copy of the messages logged so far (the FMU may log from any thread; access is locked).
  [[nodiscard]] std::vector<LogRecord> log() const;
  /// All logged messages, one "[status] category: message" per line.
  [[nodiscard]] std::string log_text() const;
  void clear_log();

  // --- Life cycle -----------------------------------------------------------------------
  fmi3Status set_debug_logging(bool logging_on, const std::vector<std::string>& categories = {});
  fmi3Status enter_initialization_mode(std::optional<double> tolerance, double start_time_s,
                                       std::optional<double> stop_time_s);
  fmi3Status exit_initialization_mode();
  DoStepResult do_step(double current_time_s, double step_size_s, bool no_set_fmu_state_prior_to_current_point = false);
  fmi3Status terminate();
  /// fmi3Reset; also forgets the structural parameter values set so far.
  fmi3Status reset();

  // --- Thin access by value reference: values.size() is nValues (elements of all arrays) --
  fmi3Status get_float64(std::span<const fmi3ValueReference> vrs, std::span<fmi3Float64> values);
  fmi3Status get_int32(std::span<const fmi3ValueReference> vrs, std::span<fmi3Int32> values);
  fmi3Status get_int64(std::span<const fmi3ValueReference> vrs, std::span<fmi3Int64> values);
  fmi3Status get_uint32(std::span<const fmi3ValueReference> vrs, std::span<fmi3UInt32> values);
  fmi3Status get_uint64(std::span<const fmi3ValueReference> vrs, std::span<fmi3UInt64> values);
  /// Not std::vector<bool> (not contiguous); use e.g. std::unique_ptr<bool[]> or std::array.
  fmi3Status get_boolean(std::span<const fmi3ValueReference> vrs, std::span<fmi3Boolean> values);
  /// Binary values: their sizes and pointers to bytes the FMU owns, valid until its next call.
  fmi3Status get_binary(std::span<const fmi3ValueReference> vrs, std::span<std::size_t> sizes,
                        std::span<fmi3Binary> values);
  /// The strings belong to the FMU and stay valid only until its next call.
  fmi3Status get_string(std::span<const fmi3ValueReference> vrs, std::span<fmi3String> values);

  fmi3Status set_float64(std::span<const fmi3ValueReference> vrs, std::span<const fmi3Float64> values);
  fmi3Status set_int32(std::span<const fmi3ValueReference> vrs, std::span<const fmi3Int32> values);
  fmi3Status set_int64(std::span<const fmi3ValueReference> vrs, std::span<const fmi3Int64> values);
  fmi3Status set_uint32(std::span<const fmi3ValueReference> vrs, std::span<const fmi3UInt32> values);
  /// Also records the values of scalar structural parameters, which size arrays.
  fmi3Status set_uint64(std::span<const fmi3ValueReference> vrs, std::span<const fmi3UInt64> values);
  fmi3Status set_boolean(std::span<const fmi3ValueReference> vrs, std::span<const fmi3Boolean> values);
  fmi3Status set_string(std::span<const fmi3ValueReference> vrs, std::span<const fmi3String> values);

  // --- Checked access by variable name (all elements of an array, row-major) ---------------
  fmi3Status get_float64(std::string_view name, std::vector<double>& values);
  fmi3Status get_int32(std::string_view name, std::vector<std::int32_t>& values);
  /// Int64 and Enumeration variables.
  fmi3Status get_int64(std::string_view name, std::vector<std::int64_t>& values);
  fmi3Status get_uint32(std::string_view name, std::vector<std::uint32_t>& values);
  fmi3Status get_uint64(std::string_view name, std::vector<std::uint64_t>& values);
  fmi3Status get_boolean(std::string_view name, std::vector<bool>& values);
  fmi3Status get_string(std::string_view name, std::vector<std::string>& values);

  fmi3Status set_float64(std::string_view name, const std::vector<double>& values);
  fmi3Status set_int32(std::string_view name, const std::vector<std::int32_t>& values);
  /// Int64 and Enumeration variables.
  fmi3Status set_int64(std::string_view name, const std::vector<std::int64_t>& values);
  fmi3Status set_uint32(std::string_view name, const std::vector<std::uint32_t>& values);
  fmi3Status set_uint64(std::string_view name, const std::vector<std::uint64_t>& values);
  fmi3Status set_boolean(std::string_view name, const std::vector<bool>& values);
  fmi3Status set_string(std::string_view name, const std::vector<std::string>& values);

  /// Number of elements of @p variable with the structural parameters set on this instance.
  [[nodiscard]] std::size_t array_size(const ModelVariable& variable) const;

  // --- FMU state (FmuError unless canGetAndSetFMUState / canSerializeFMUState) -------------
  fmi3Status get_fmu_state(fmi3FMUState& state);
  fmi3Status set_fmu_state(fmi3FMUState state);
  /// Frees @p state and sets it to nullptr (as fmi3FreeFMUState does).
  fmi3Status free_fmu_state(fmi3FMUState& state);
  fmi3Status serialized_fmu_state_size(fmi3FMUState state, std::size_t& size);
  /// Asks the size, then serializes into @p bytes (resized to it).
  fmi3Status serialize_fmu_state(fmi3FMUState state, std::vector<std::uint8_t>& bytes);
  fmi3Status deserialize_fmu_state(std::span<const std::uint8_t> bytes, fmi3FMUState& state);

 private:
  void instantiate(const std::string& instantiation_token, bool logging_on);
  void free_instance() noexcept;
  void require_get_and_set_state(const char* function) const;
  void require_serialize_state(const char* function) const;
  /// The variable called @p name, checked to be of one of @p types (for @p accessor).
  const ModelVariable& typed_variable(std::string_view name, std::initializer_list<std::string_view> types,
                                      const char* accessor) const;
  /// As typed_variable, and checked that the importer may set it with @p count values.
  const ModelVariable& settable_variable(std::string_view name, std::initializer_list<std::string_view> types,
                                         const char* accessor, std::size_t count) const;
  void record_structural_values(std::span<const fmi3ValueReference> vrs, std::span<const fmi3UInt64> values);

  const Fmu3* m_fmu = nullptr;
  std::string m_name;
  std::unique_ptr<LogBuffer> m_log;  ///< on the heap: its address is the FMU's instanceEnvironment
  fmi3Instance m_instance = nullptr;
  std::map<fmi3ValueReference, std::uint64_t> m_structural_values;
};

}  // namespace tissue::host
