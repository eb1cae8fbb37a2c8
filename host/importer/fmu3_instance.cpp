// fmu3_instance.cpp - the co-simulation instance: instantiation, log collection, checked calls.
#include "importer/fmu3_instance.hpp"

#include "importer/fmu_error.hpp"

#include <algorithm>
#include <mutex>
#include <utility>

namespace tissue::host {

/// Where the FMU's log messages go; its address is the instanceEnvironment of the instance.
class LogBuffer {
 public:
  void append(LogRecord record) {
    const std::lock_guard lock(m_mutex);
    m_records.push_back(std::move(record));
  }
  [[nodiscard]] std::vector<LogRecord> records() const {
    const std::lock_guard lock(m_mutex);
    return m_records;
  }
  void clear() {
    const std::lock_guard lock(m_mutex);
    m_records.clear();
  }

 private:
  mutable std::mutex m_mutex;
  std::vector<LogRecord> m_records;
};

extern "C" {
/// fmi3LogMessageCallback: appends to the instance's LogBuffer. Nothing may cross the C ABI,
/// so an allocation failure loses the message rather than throwing into the FMU.
static void tissue_host_log_message(fmi3InstanceEnvironment instance_environment, fmi3Status status,
                                    fmi3String category, fmi3String message) {
  auto* buffer = static_cast<LogBuffer*>(instance_environment);
  if (buffer == nullptr) {
    return;
  }
  try {
    buffer->append({category == nullptr ? "" : category, status, message == nullptr ? "" : message});
  } catch (...) {  // NOLINT(bugprone-empty-catch): see above
  }
}
}

namespace {

bool is_success(fmi3Status status) { return status == fmi3OK || status == fmi3Warning; }

std::string join_types(std::initializer_list<std::string_view> types) {
  std::string text;
  for (const std::string_view type : types) {
    text += (text.empty() ? "<" : " or <") + std::string(type) + ">";
  }
  return text;
}

}  // namespace

const char* status_name(fmi3Status status) {
  switch (status) {
    case fmi3OK:
      return "fmi3OK";
    case fmi3Warning:
      return "fmi3Warning";
    case fmi3Discard:
      return "fmi3Discard";
    case fmi3Error:
      return "fmi3Error";
    case fmi3Fatal:
      return "fmi3Fatal";
  }
  return "unknown fmi3Status";
}

// --- Construction ---------------------------------------------------------------------------

Fmu3Instance::Fmu3Instance(const Fmu3& fmu, std::string instance_name, bool logging_on)
    : m_fmu(&fmu), m_name(std::move(instance_name)), m_log(std::make_unique<LogBuffer>()) {
  instantiate(fmu.description().instantiation_token(), logging_on);
}

Fmu3Instance::Fmu3Instance(const Fmu3& fmu, std::string instance_name, std::string instantiation_token, bool logging_on)
    : m_fmu(&fmu), m_name(std::move(instance_name)), m_log(std::make_unique<LogBuffer>()) {
  instantiate(instantiation_token, logging_on);
}

Fmu3Instance::~Fmu3Instance() { free_instance(); }

Fmu3Instance::Fmu3Instance(Fmu3Instance&& other) noexcept
    : m_fmu(other.m_fmu),
      m_name(std::move(other.m_name)),
      m_log(std::move(other.m_log)),
      m_instance(std::exchange(other.m_instance, nullptr)),
      m_structural_values(std::move(other.m_structural_values)) {}

Fmu3Instance& Fmu3Instance::operator=(Fmu3Instance&& other) noexcept {
  if (this != &other) {
    free_instance();
    m_fmu = other.m_fmu;
    m_name = std::move(other.m_name);
    m_log = std::move(other.m_log);
    m_instance = std::exchange(other.m_instance, nullptr);
    m_structural_values = std::move(other.m_structural_values);
  }
  return *this;
}

void Fmu3Instance::instantiate(const std::string& instantiation_token, bool logging_on) {
  const ModelDescription& description = m_fmu->description();
  if (description.co_simulation().can_be_instantiated_only_once_per_process && m_fmu->m_instance_count.load() > 0) {
    throw FmuError("FMU '" + description.model_name() +
                   "' has canBeInstantiatedOnlyOncePerProcess=\"true\" and is already instantiated");
  }
  const std::string resource_path = m_fmu->archive().resource_path();
  m_instance = m_fmu->functions().fmi3InstantiateCoSimulation(
      m_name.c_str(), instantiation_token.c_str(), resource_path.c_str(), /*visible=*/false, logging_on,
      /*eventModeUsed=*/false, /*earlyReturnAllowed=*/false, /*requiredIntermediateVariables=*/nullptr, 0, m_log.get(),
      &tissue_host_log_message, /*intermediateUpdate=*/nullptr);
  if (m_instance == nullptr) {
    const std::string messages = log_text();
    throw FmuError("fmi3InstantiateCoSimulation of FMU '" + description.model_name() + "' (instance '" + m_name +
                   "', instantiationToken '" + instantiation_token + "') returned NULL" +
                   (messages.empty() ? std::string(" and logged nothing") : "; the FMU logged:\n" + messages));
  }
  ++m_fmu->m_instance_count;
}

void Fmu3Instance::free_instance() noexcept {
  if (m_instance != nullptr) {
    m_fmu->functions().fmi3FreeInstance(m_instance);
    m_instance = nullptr;
    --m_fmu->m_instance_count;
  }
}

// --- Log -----------------------------------------------------------------------------------

std::vector<LogRecord> Fmu3Instance::log() const { return m_log ? m_log->records() : std::vector<LogRecord>{}; }

std::string Fmu3Instance::log_text() const {
  std::string text;
  for (const LogRecord& record : log()) {
    text.append("[").append(status_name(record.status)).append("] ");
    text.append(record.category).append(": ").append(record.message).append("\n");
  }
  return text;
}

void Fmu3Instance::clear_log() {
  if (m_log) {
    m_log->clear();
  }
}

// --- Life cycle ----------------------------------------------------------------------------

fmi3Status Fmu3Instance::set_debug_logging(bool logging_on, const std::vector<std::string>& categories) {
  std::vector<fmi3String> names;
  names.reserve(categories.size());
  for (const std::string& category : categories) {
    names.push_back(category.c_str());
  }
  return m_fmu->functions().fmi3SetDebugLogging(m_instance, logging_on, names.size(),
                                                names.empty() ? nullptr : names.data());
}

fmi3Status Fmu3Instance::enter_initialization_mode(std::optional<double> tolerance, double start_time_s,
                                                   std::optional<double> stop_time_s) {
  return m_fmu->functions().fmi3EnterInitializationMode(m_instance, tolerance.has_value(), tolerance.value_or(0.0),
                                                        start_time_s, stop_time_s.has_value(),
                                                        stop_time_s.value_or(0.0));
}

fmi3Status Fmu3Instance::exit_initialization_mode() {
  return m_fmu->functions().fmi3ExitInitializationMode(m_instance);
}

DoStepResult Fmu3Instance::do_step(double current_time_s, double step_size_s,
                                   bool no_set_fmu_state_prior_to_current_point) {
  DoStepResult result;
  fmi3Boolean event_handling_needed = false;
  fmi3Boolean terminate_simulation = false;
  fmi3Boolean early_return = false;
  fmi3Float64 last_successful_time = current_time_s;
  result.status = m_fmu->functions().fmi3DoStep(m_instance, current_time_s, step_size_s,
                                                no_set_fmu_state_prior_to_current_point, &event_handling_needed,
                                                &terminate_simulation, &early_return, &last_successful_time);
  result.event_handling_needed = event_handling_needed;
  result.terminate_simulation = terminate_simulation;
  result.early_return = early_return;
  result.last_successful_time_s = last_successful_time;
  return result;
}

fmi3Status Fmu3Instance::terminate() { return m_fmu->functions().fmi3Terminate(m_instance); }

fmi3Status Fmu3Instance::reset() {
  const fmi3Status status = m_fmu->functions().fmi3Reset(m_instance);
  if (is_success(status)) {
    m_structural_values.clear();
  }
  return status;
}

// --- Thin access by value reference ----------------------------------------------------------

#define TISSUE_HOST_THIN_ACCESS(method, function, type)                                                            \
  fmi3Status Fmu3Instance::get_##method(std::span<const fmi3ValueReference> vrs, std::span<type> values) {         \
    return m_fmu->functions().fmi3Get##function(m_instance, vrs.data(), vrs.size(), values.data(), values.size()); \
  }                                                                                                                \
  fmi3Status Fmu3Instance::set_##method(std::span<const fmi3ValueReference> vrs, std::span<const type> values) {   \
    return m_fmu->functions().fmi3Set##function(m_instance, vrs.data(), vrs.size(), values.data(), values.size()); \
  }

TISSUE_HOST_THIN_ACCESS(float64, Float64, fmi3Float64)
TISSUE_HOST_THIN_ACCESS(int32, Int32, fmi3Int32)
TISSUE_HOST_THIN_ACCESS(int64, Int64, fmi3Int64)
TISSUE_HOST_THIN_ACCESS(uint32, UInt32, fmi3UInt32)
TISSUE_HOST_THIN_ACCESS(boolean, Boolean, fmi3Boolean)
TISSUE_HOST_THIN_ACCESS(string, String, fmi3String)
#undef TISSUE_HOST_THIN_ACCESS

fmi3Status Fmu3Instance::get_binary(std::span<const fmi3ValueReference> vrs, std::span<std::size_t> sizes,
                                    std::span<fmi3Binary> values) {
  return m_fmu->functions().fmi3GetBinary(m_instance, vrs.data(), vrs.size(), sizes.data(), values.data(),
                                          values.size());
}

fmi3Status Fmu3Instance::get_uint64(std::span<const fmi3ValueReference> vrs, std::span<fmi3UInt64> values) {
  return m_fmu->functions().fmi3GetUInt64(m_instance, vrs.data(), vrs.size(), values.data(), values.size());
}

fmi3Status Fmu3Instance::set_uint64(std::span<const fmi3ValueReference> vrs, std::span<const fmi3UInt64> values) {
  const fmi3Status status =
      m_fmu->functions().fmi3SetUInt64(m_instance, vrs.data(), vrs.size(), values.data(), values.size());
  if (is_success(status)) {
    record_structural_values(vrs, values);
  }
  return status;
}

void Fmu3Instance::record_structural_values(std::span<const fmi3ValueReference> vrs,
                                            std::span<const fmi3UInt64> values) {
  // Structural parameters are scalars, so the values line up with the references unless an
  // array was set in the same call; then the offsets follow the array sizes.
  std::size_t offset = 0;
  for (const fmi3ValueReference vr : vrs) {
    const ModelVariable* variable = description().find_variable(vr);
    if (variable == nullptr) {
      return;  // the FMU accepted an unknown reference; nothing reliable to record
    }
    const std::size_t count = array_size(*variable);
    if (variable->causality == "structuralParameter" && !variable->is_array() && offset < values.size()) {
      m_structural_values[vr] = values[offset];
    }
    offset += count;
  }
}

// --- Checked access by name --------------------------------------------------------------------

std::size_t Fmu3Instance::array_size(const ModelVariable& variable) const {
  return description().array_size(variable, m_structural_values);
}

const ModelVariable& Fmu3Instance::typed_variable(std::string_view name, std::initializer_list<std::string_view> types,
                                                  const char* accessor) const {
  const ModelVariable* variable = description().find_variable(name);
  if (variable == nullptr) {
    throw FmuError(std::string(accessor) + ": FMU '" + description().model_name() + "' has no variable named '" +
                   std::string(name) + "'");
  }
  if (std::find(types.begin(), types.end(), variable->type) == types.end()) {
    throw FmuError(std::string(accessor) + ": variable '" + variable->name + "' is <" + variable->type + ">, not " +
                   join_types(types));
  }
  return *variable;
}

const ModelVariable& Fmu3Instance::settable_variable(std::string_view name,
                                                     std::initializer_list<std::string_view> types,
                                                     const char* accessor, std::size_t count) const {
  const ModelVariable& variable = typed_variable(name, types, accessor);
  const std::string prefix = std::string(accessor) + ": variable '" + variable.name + "' ";
  if (variable.causality == "independent") {
    throw FmuError(prefix + "is the independent variable; it is set by the step, not by the importer");
  }
  if (variable.causality == "calculatedParameter") {
    throw FmuError(prefix + "is a calculated parameter and cannot be set");
  }
  if (variable.variability == "constant") {
    throw FmuError(prefix + "is a constant and cannot be set");
  }
  // FMI 3.0 section 2.4.7.4: outputs and locals can be set only if initial is exact or approx.
  if ((variable.causality == "output" || variable.causality == "local") && variable.initial != "exact" &&
      variable.initial != "approx") {
    throw FmuError(prefix + "has causality '" + variable.causality + "' and initial '" +
                   (variable.initial.empty() ? std::string("calculated") : variable.initial) + "'; it cannot be set");
  }
  const std::size_t expected = array_size(variable);
  if (count != expected) {
    throw FmuError(prefix + "has " + std::to_string(expected) + " element(s), but " + std::to_string(count) +
                   " value(s) were given");
  }
  return variable;
}

fmi3Status Fmu3Instance::get_float64(std::string_view name, std::vector<double>& values) {
  const ModelVariable& variable = typed_variable(name, {"Float64"}, "get_float64");
  values.assign(array_size(variable), 0.0);
  return get_float64(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::get_int32(std::string_view name, std::vector<std::int32_t>& values) {
  const ModelVariable& variable = typed_variable(name, {"Int32"}, "get_int32");
  values.assign(array_size(variable), 0);
  return get_int32(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::get_int64(std::string_view name, std::vector<std::int64_t>& values) {
  const ModelVariable& variable = typed_variable(name, {"Int64", "Enumeration"}, "get_int64");
  values.assign(array_size(variable), 0);
  return get_int64(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::get_uint32(std::string_view name, std::vector<std::uint32_t>& values) {
  const ModelVariable& variable = typed_variable(name, {"UInt32"}, "get_uint32");
  values.assign(array_size(variable), 0);
  return get_uint32(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::get_uint64(std::string_view name, std::vector<std::uint64_t>& values) {
  const ModelVariable& variable = typed_variable(name, {"UInt64"}, "get_uint64");
  values.assign(array_size(variable), 0);
  return get_uint64(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::get_boolean(std::string_view name, std::vector<bool>& values) {
  const ModelVariable& variable = typed_variable(name, {"Boolean"}, "get_boolean");
  const std::size_t count = array_size(variable);
  const std::unique_ptr<fmi3Boolean[]> buffer = std::make_unique<fmi3Boolean[]>(count);
  const fmi3Status status = get_boolean(std::span(&variable.value_reference, 1), std::span(buffer.get(), count));
  values.assign(buffer.get(), buffer.get() + count);
  return status;
}

fmi3Status Fmu3Instance::get_string(std::string_view name, std::vector<std::string>& values) {
  const ModelVariable& variable = typed_variable(name, {"String"}, "get_string");
  std::vector<fmi3String> pointers(array_size(variable), nullptr);
  const fmi3Status status = get_string(std::span(&variable.value_reference, 1), pointers);
  values.assign(pointers.size(), std::string());
  if (is_success(status)) {  // otherwise the pointers are not valid values
    for (std::size_t i = 0; i < pointers.size(); ++i) {
      values[i] = pointers[i] == nullptr ? std::string() : std::string(pointers[i]);
    }
  }
  return status;
}

fmi3Status Fmu3Instance::set_float64(std::string_view name, const std::vector<double>& values) {
  const ModelVariable& variable = settable_variable(name, {"Float64"}, "set_float64", values.size());
  return set_float64(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::set_int32(std::string_view name, const std::vector<std::int32_t>& values) {
  const ModelVariable& variable = settable_variable(name, {"Int32"}, "set_int32", values.size());
  return set_int32(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::set_int64(std::string_view name, const std::vector<std::int64_t>& values) {
  const ModelVariable& variable = settable_variable(name, {"Int64", "Enumeration"}, "set_int64", values.size());
  return set_int64(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::set_uint32(std::string_view name, const std::vector<std::uint32_t>& values) {
  const ModelVariable& variable = settable_variable(name, {"UInt32"}, "set_uint32", values.size());
  return set_uint32(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::set_uint64(std::string_view name, const std::vector<std::uint64_t>& values) {
  const ModelVariable& variable = settable_variable(name, {"UInt64"}, "set_uint64", values.size());
  return set_uint64(std::span(&variable.value_reference, 1), values);
}

fmi3Status Fmu3Instance::set_boolean(std::string_view name, const std::vector<bool>& values) {
  const ModelVariable& variable = settable_variable(name, {"Boolean"}, "set_boolean", values.size());
  const std::unique_ptr<fmi3Boolean[]> buffer = std::make_unique<fmi3Boolean[]>(values.size());
  std::copy(values.begin(), values.end(), buffer.get());
  return set_boolean(std::span(&variable.value_reference, 1),
                     std::span<const fmi3Boolean>(buffer.get(), values.size()));
}

fmi3Status Fmu3Instance::set_string(std::string_view name, const std::vector<std::string>& values) {
  const ModelVariable& variable = settable_variable(name, {"String"}, "set_string", values.size());
  std::vector<fmi3String> pointers;
  pointers.reserve(values.size());
  for (const std::string& value : values) {
    pointers.push_back(value.c_str());
  }
  return set_string(std::span(&variable.value_reference, 1), pointers);
}

// --- FMU state -------------------------------------------------------------------------------

void Fmu3Instance::require_get_and_set_state(const char* function) const {
  if (!description().co_simulation().can_get_and_set_fmu_state) {
    throw FmuError(std::string(function) + ": FMU '" + description().model_name() +
                   "' does not declare canGetAndSetFMUState=\"true\"");
  }
}

void Fmu3Instance::require_serialize_state(const char* function) const {
  require_get_and_set_state(function);
  if (!description().co_simulation().can_serialize_fmu_state) {
    throw FmuError(std::string(function) + ": FMU '" + description().model_name() +
                   "' does not declare canSerializeFMUState=\"true\"");
  }
}

fmi3Status Fmu3Instance::get_fmu_state(fmi3FMUState& state) {
  require_get_and_set_state("fmi3GetFMUState");
  return m_fmu->functions().fmi3GetFMUState(m_instance, &state);
}

fmi3Status Fmu3Instance::set_fmu_state(fmi3FMUState state) {
  require_get_and_set_state("fmi3SetFMUState");
  return m_fmu->functions().fmi3SetFMUState(m_instance, state);
}

fmi3Status Fmu3Instance::free_fmu_state(fmi3FMUState& state) {
  require_get_and_set_state("fmi3FreeFMUState");
  return m_fmu->functions().fmi3FreeFMUState(m_instance, &state);
}

fmi3Status Fmu3Instance::serialized_fmu_state_size(fmi3FMUState state, std::size_t& size) {
  require_serialize_state("fmi3SerializedFMUStateSize");
  return m_fmu->functions().fmi3SerializedFMUStateSize(m_instance, state, &size);
}

fmi3Status Fmu3Instance::serialize_fmu_state(fmi3FMUState state, std::vector<std::uint8_t>& bytes) {
  std::size_t size = 0;
  const fmi3Status size_status = serialized_fmu_state_size(state, size);
  if (!is_success(size_status)) {
    bytes.clear();
    return size_status;
  }
  bytes.assign(size, 0);
  const fmi3Status status = m_fmu->functions().fmi3SerializeFMUState(m_instance, state, bytes.data(), bytes.size());
  return std::max(size_status, status);  // statuses are ordered by severity
}

fmi3Status Fmu3Instance::deserialize_fmu_state(std::span<const std::uint8_t> bytes, fmi3FMUState& state) {
  require_serialize_state("fmi3DeserializeFMUState");
  return m_fmu->functions().fmi3DeserializeFMUState(m_instance, bytes.data(), bytes.size(), &state);
}

}  // namespace tissue::host
