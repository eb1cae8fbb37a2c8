// Instance (see instance.hpp).
#include "fmi3/instance.hpp"

#include <cmath>
#include <new>
#include <type_traits>

namespace tissue::fmi3 {
namespace {

// FMU states serialized by the layer: a tag, a version, the model identifier, then the mode, the
// stored values and the model's own section.
constexpr std::uint64_t STATE_MAGIC = 0x45544154'53334946ULL;  // "FI3STATE" as little-endian bytes
// 2: the Tissue FMU saves its iteration count; 3: the HapticLoop's sample says whether the surface is
// near; 4: and carries the contact's damping and the tool's velocity over the tissue's step
constexpr std::uint32_t STATE_VERSION = 4;

}  // namespace

Instance::Instance(const ModelDescription& description, std::string name, std::string resource_path, bool logging_on,
                   StatusLogger logger)
    : m_description(description),
      m_name(std::move(name)),
      m_logger(std::move(logger)),
      m_logging_on(logging_on),
      m_values(description),
      m_candidate(description) {
  ModelContext context;
  context.instance_name = m_name;
  context.resource_path = std::move(resource_path);
  context.log = [this](LogLevel level, const std::string& message) {
    if (level == LogLevel::warning) {
      log(Status::warning, "logStatusWarning", message);
    } else {
      log(Status::ok, "logEvents", message);
    }
  };
  m_model = make_model(context, m_values);
  m_model->validate_parameters(m_values);  // the start values must run: a table that says otherwise is a bug
}

// Takes C strings so that a call with logging off costs no allocation (the haptic loop calls at 1 kHz).
void Instance::log(Status status, const char* category, const char* message) const {
  if (!m_logger || (status == Status::ok && !m_logging_on)) return;
  const std::string_view name(category);
  if (name == "logCalls" && !m_log_calls) return;
  if (name == "logEvents" && !m_log_events) return;
  m_logger(status, category, message);
}

void Instance::log_exception(const char* function, Status status) const noexcept {
  try {
    try {
      throw;
    } catch (const std::bad_alloc&) {
      log(status, "logStatusError", std::string(function) + ": out of memory");
    } catch (const std::exception& error) {
      log(status, "logStatusError", std::string(function) + ": " + error.what());
    } catch (...) {
      log(status, "logStatusError", std::string(function) + ": unknown error");
    }
  } catch (...) {
    // The logger itself failed; nothing more can be said.
  }
}

void Instance::set_debug_logging(bool logging_on, std::span<const char* const> categories) {
  bool calls = categories.empty(), events = categories.empty();
  for (const char* name : categories) {
    const std::string category = name == nullptr ? "" : name;
    if (category == "logCalls") {
      calls = true;
    } else if (category == "logEvents") {
      events = true;
    } else if (category != "logStatusWarning" && category != "logStatusError" && category != "logStatusFatal") {
      throw VariableError("unknown log category '" + category + "'");
    }
  }
  m_logging_on = logging_on;
  m_log_calls = calls;
  m_log_events = events;
}

void Instance::enter_initialization_mode(double start_time_s) {
  if (!std::isfinite(start_time_s)) throw VariableError("the start time must be finite");
  m_model->enter_initialization_mode(start_time_s);
  m_state = State::initialization;
}

void Instance::exit_initialization_mode() {
  m_model->exit_initialization_mode();
  m_state = State::step;
}

Status Instance::do_step(double current_time_s, double step_s, double& last_successful_time_s) {
  last_successful_time_s = current_time_s;
  if (!std::isfinite(current_time_s) || !std::isfinite(step_s) || !(step_s > 0.0)) {
    throw VariableError("doStep: the communication point must be finite and the step > 0");
  }
  const StepOutcome outcome = m_model->do_step(current_time_s, step_s);
  last_successful_time_s = outcome.last_successful_time_s;
  if (outcome.completed) return outcome.warning ? Status::warning : Status::ok;
  log(Status::discard, "logStatusError",
      "fmi3DoStep: stopped at t = " + std::to_string(outcome.last_successful_time_s) + " s");
  return Status::discard;
}

void Instance::terminate() { m_state = State::terminated; }

void Instance::reset() {
  m_values.set_starts();
  m_model->reset();
  m_state = State::instantiated;
}

// --- values ---

template <class T>
const VariableInfo& Instance::variable(ValueReference vr, bool setting) const {
  const VariableInfo& info = variable(vr, setting);
  if (!accepts<T>(info.type)) {
    throw VariableError(std::string(info.name) + " (value reference " + std::to_string(vr) + ") is of type " +
                        std::string(to_string(info.type)) + ", not " + std::string(accessor_name<T>()));
  }
  return info;
}

const VariableInfo& Instance::variable(ValueReference vr, bool setting) const {
  const VariableInfo* info = m_description.find(vr);
  if (info == nullptr) throw VariableError("unknown value reference " + std::to_string(vr));
  if (!setting) return *info;
  const StateMask allowed = variable_settable_states(info->causality, info->variability);
  if ((allowed & mask(m_state)) == 0) {
    if (allowed == 0) {
      throw VariableError(std::string(info->name) + " is an " + std::string(to_string(info->causality)) +
                          " and cannot be set");
    }
    throw CallOrderError(std::string(to_string(info->causality)) + " " + std::string(info->name) +
                         " can be set only in " + describe(allowed) + ", not in " + std::string(to_string(m_state)));
  }
  return *info;
}

std::size_t Instance::element_count(const VariableInfo& info) const {
  std::size_t count = 1;
  for (int k = 0; k < info.rank; ++k) {
    const Dimension& d = info.dimensions[static_cast<std::size_t>(k)];
    count *= d.size_vr < 0 ? d.size : m_values.uint64(static_cast<ValueReference>(d.size_vr));
  }
  return count;
}

template <class T>
void Instance::get(std::span<const ValueReference> vrs, std::span<T> values) {
  std::size_t at = 0;
  for (const ValueReference vr : vrs) {
    const VariableInfo& info = variable<T>(vr, false);
    const std::size_t n = element_count(info);
    if (at + n > values.size()) {
      throw VariableError("too few values for " + std::string(info.name) + ": it has " + std::to_string(n));
    }
    const std::span<T> out = values.subspan(at, n);
    at += n;
    if (m_values.holds(info)) {
      m_values.read(info, out);
    } else if constexpr (std::is_same_v<T, double>) {
      m_model->get_float64(info, out);
    } else if constexpr (std::is_same_v<T, std::uint32_t>) {
      m_model->get_uint32(info, out);
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {
      m_model->get_uint64(info, out);
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      m_model->get_int64(info, out);
    } else if constexpr (std::is_same_v<T, bool>) {
      m_model->get_boolean(info, out);
    } else {
      throw VariableError("no " + std::string(accessor_name<T>()) + " output " + std::string(info.name));
    }
  }
  if (at != values.size()) {
    throw VariableError("the variables have " + std::to_string(at) + " values, " + std::to_string(values.size()) +
                        " were passed");
  }
}

template <class T>
void Instance::set(std::span<const ValueReference> vrs, std::span<const T> values) {
  // Check everything on a copy first, then commit: a refused call changes nothing.
  m_candidate.copy_values_from(m_values);
  bool parameter_set = false;
  std::size_t at = 0;
  for (const ValueReference vr : vrs) {
    const VariableInfo& info = variable<T>(vr, true);
    const std::size_t n = m_candidate.count(info);
    if (at + n > values.size()) {
      throw VariableError("too few values for " + std::string(info.name) + ": it takes " + std::to_string(n));
    }
    m_candidate.write(info, values.subspan(at, n));
    at += n;
    parameter_set = parameter_set || info.causality != Causality::input;
  }
  if (at != values.size()) {
    throw VariableError("the variables take " + std::to_string(at) + " values, " + std::to_string(values.size()) +
                        " were passed");
  }
  try {
    if (parameter_set) m_model->validate_parameters(m_candidate);
  } catch (const std::exception& error) {
    // The model's checks speak of its settings; say which variables were being set.
    std::string names;
    for (const ValueReference vr : vrs) names += (names.empty() ? "" : ", ") + std::string(variable(vr, false).name);
    throw VariableError("refused setting " + names + ": " + error.what());
  }
  std::swap(m_values, m_candidate);
  if (parameter_set) m_model->parameters_changed();
}

void Instance::get_binary(std::span<const ValueReference> vrs, std::span<std::size_t> sizes,
                          std::span<const std::uint8_t*> values) {
  if (sizes.size() != vrs.size() || values.size() != vrs.size()) {
    throw VariableError("the Binary variables have " + std::to_string(vrs.size()) + " values, " +
                        std::to_string(values.size()) + " were passed");
  }
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], false);
    if (info.type != VariableType::binary) {
      throw VariableError(std::string(info.name) + " (value reference " + std::to_string(vrs[k]) + ") is of type " +
                          std::string(to_string(info.type)) + ", not Binary");
    }
    const std::span<const std::uint8_t> bytes = m_model->get_binary(info);
    sizes[k] = bytes.size();
    values[k] = bytes.data();
  }
}

#define TISSUE_INSTANCE_TYPES(T)                                                 \
  template void Instance::get<T>(std::span<const ValueReference>, std::span<T>); \
  template void Instance::set<T>(std::span<const ValueReference>, std::span<const T>);
TISSUE_INSTANCE_TYPES(double)
TISSUE_INSTANCE_TYPES(std::int32_t)
TISSUE_INSTANCE_TYPES(std::uint32_t)
TISSUE_INSTANCE_TYPES(std::int64_t)
TISSUE_INSTANCE_TYPES(std::uint64_t)
TISSUE_INSTANCE_TYPES(bool)
using CString = const char*;
TISSUE_INSTANCE_TYPES(CString)
#undef TISSUE_INSTANCE_TYPES

// --- FMU states ---

std::unique_ptr<InstanceState> Instance::save() const {
  auto saved = std::make_unique<InstanceState>(InstanceState{m_state, ValueStore(m_description), m_model->save()});
  saved->values.copy_values_from(m_values);
  return saved;
}

void Instance::restore(const InstanceState& saved) {
  if (&saved.values.model() != &m_description) throw VariableError("the FMU state is of another model");
  // Stored values first (the model rebuilds from them if the parameters differ), back if it fails.
  m_candidate.copy_values_from(m_values);
  const bool parameters_differ = saved.values.parameters_differ(m_values);
  m_values.copy_values_from(saved.values);
  try {
    if (parameters_differ) m_model->parameters_changed();
    m_model->restore(*saved.model);
  } catch (...) {
    m_values.copy_values_from(m_candidate);
    if (parameters_differ) m_model->parameters_changed();
    throw;
  }
  m_state = saved.mode;
}

std::vector<std::uint8_t> Instance::serialize(const InstanceState& saved) const {
  serial::ByteWriter writer;
  writer.put(STATE_MAGIC);
  writer.put(STATE_VERSION);
  writer.put_string(std::string(m_description.model_identifier));
  writer.put(static_cast<std::uint8_t>(saved.mode));
  saved.values.serialize(writer);
  m_model->serialize(*saved.model, writer);
  return writer.take();
}

std::unique_ptr<InstanceState> Instance::deserialize(std::span<const std::uint8_t> bytes) const {
  try {
    serial::ByteReader reader(bytes);
    if (reader.get<std::uint64_t>() != STATE_MAGIC) serial::ByteReader::fail("not an FMU state (bad tag)");
    if (const auto version = reader.get<std::uint32_t>(); version != STATE_VERSION) {
      serial::ByteReader::fail("version " + std::to_string(version) + " is not " + std::to_string(STATE_VERSION));
    }
    if (reader.get_string() != m_description.model_identifier) {
      serial::ByteReader::fail("a state of another FMU than " + std::string(m_description.model_identifier));
    }
    const auto mode = static_cast<State>(reader.get<std::uint8_t>());
    if (mode != State::initialization && mode != State::step && mode != State::terminated) {
      serial::ByteReader::fail("a state in no mode a state can be taken in");
    }
    auto saved = std::make_unique<InstanceState>(InstanceState{mode, ValueStore(m_description), nullptr});
    saved->values.deserialize(reader);
    m_model->validate_parameters(saved->values);
    saved->model = m_model->deserialize(reader);
    reader.finish();
    return saved;
  } catch (const std::exception& error) {
    throw VariableError(std::string("deserialize FMU state: ") + error.what());
  }
}

}  // namespace tissue::fmi3
