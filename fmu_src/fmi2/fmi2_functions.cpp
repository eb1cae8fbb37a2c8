// The FMI 2.0 Co-Simulation C ABI of every FMU of the project, over the same layer as the FMI 3.0
// one (fmi3/fmi3_functions.cpp): a Component (component.hpp) wraps the layer's Instance, so the
// state table, the stored values, the model and FMU states are the 3.0 FMU's; only the calls'
// shapes differ (scalars, a start time from fmi2SetupExperiment, a resource URI). Compiled into
// each FMU's FMI 2.0 library, beside the entry that supplies model_description() and make_model().
// Functions the FMUs do not offer (derivatives, asynchronous steps) answer fmi2Error with the
// reason. Nothing throws or aborts across the ABI.
#include "fmi2/component.hpp"
#include "fmi2/scalar_layout.hpp"
#include "fmi3/fmu_state_calls.hpp"
#include "fmi3/model.hpp"

#include "fmi2_abi.h"

#include <algorithm>
#include <cctype>
#include <cstdarg>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace {

using tissue::fmi2::Component;
using tissue::fmi2::ScalarLayout;
using tissue::fmi2::ScalarType;
using tissue::fmi3::Call;
using tissue::fmi3::InstanceState;
using tissue::fmi3::Status;
using tissue::fmi3::VariableError;

fmi2Status to_fmi(Status status) { return static_cast<fmi2Status>(status); }

static_assert(static_cast<int>(Status::ok) == fmi2OK && static_cast<int>(Status::warning) == fmi2Warning &&
              static_cast<int>(Status::discard) == fmi2Discard && static_cast<int>(Status::error) == fmi2Error &&
              static_cast<int>(Status::fatal) == fmi2Fatal);

// The FMU's 2.0 layout, made once from its port schema.
const ScalarLayout& layout() {
  static const ScalarLayout the_layout(tissue::fmi3::model_description());
  return the_layout;
}

// Runs `body` on the component under `call`'s allowed states; `body` returns a Status (ok if void).
template <class Body>
fmi2Status run(fmi2Component handle, Call call, const char* function, Body&& body) {
  if (handle == nullptr) return fmi2Error;
  auto& component = *static_cast<Component*>(handle);
  return to_fmi(component.instance().run(call, function, [&]() -> Status {
    if constexpr (std::is_void_v<decltype(body(component))>) {
      body(component);
      return Status::ok;
    } else {
      return body(component);
    }
  }));
}

fmi2Status not_offered(fmi2Component handle, const char* function, const char* why) {
  return run(handle, Call::not_offered, function, [&](Component& self) -> Status {
    self.instance().log(Status::error, "logStatusError",
                        std::string(function) + ": not offered by the " +
                            std::string(self.layout().description().model_identifier) + " FMU (" + why + ")");
    return Status::error;
  });
}

template <class T>
std::span<T> checked_span(T* data, size_t n) {
  if (n > 0 && data == nullptr) throw VariableError("a null array was passed with a non-zero length");
  return std::span<T>(data, n);
}

template <class T>
fmi2Status get_values(fmi2Component handle, const char* function, const fmi2ValueReference vr[], size_t n, T values[],
                      ScalarType type) {
  return run(handle, Call::get_value, function,
             [&](Component& self) { self.get<T>(checked_span(vr, n), checked_span(values, n), type); });
}

template <class T>
fmi2Status set_values(fmi2Component handle, const char* function, const fmi2ValueReference vr[], size_t n,
                      const T values[], ScalarType type) {
  return run(handle, Call::set_value, function,
             [&](Component& self) { self.set<T>(checked_span(vr, n), checked_span(values, n), type); });
}

// The resources folder from fmi2Instantiate's URI (file:///p, file:/p or file://localhost/p,
// percent-encoded), with a trailing slash as the layer expects (the FMI 3.0 resourcePath form).
std::string resource_path(const char* uri) {
  if (uri == nullptr || uri[0] == '\0') return "";
  std::string_view text(uri);
  for (const std::string_view prefix : {"file://localhost/", "file:///", "file:/"}) {
    if (text.starts_with(prefix)) {
      text.remove_prefix(prefix.size() - 1);  // keep the path's leading slash
      break;
    }
  }
  if (text.find("://") != std::string_view::npos || text.starts_with("file:")) {
    throw VariableError(std::string("the resource URI '") + uri + "' is not a local file (file:///...)");
  }
  std::string path;
  for (std::size_t k = 0; k < text.size(); ++k) {
    if (text[k] == '%' && k + 2 < text.size() && std::isxdigit(static_cast<unsigned char>(text[k + 1])) &&
        std::isxdigit(static_cast<unsigned char>(text[k + 2]))) {
      path += static_cast<char>(std::stoi(std::string(text.substr(k + 1, 2)), nullptr, 16));
      k += 2;
    } else {
      path += text[k];
    }
  }
  if (!path.empty() && path.back() != '/') path += '/';
  return path;
}

void log_refusal(const fmi2CallbackFunctions* functions, const char* name, const std::string& why) {
  if (functions != nullptr && functions->logger != nullptr) {
    functions->logger(functions->componentEnvironment, name == nullptr ? "" : name, fmi2Error, "logStatusError", "%s",
                      why.c_str());
  }
}

}  // namespace

extern "C" {

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char* fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
  return run(c, Call::set_debug_logging, "fmi2SetDebugLogging", [&](Component& self) {
    self.instance().set_debug_logging(loggingOn != fmi2False, checked_span(categories, nCategories));
  });
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions,
                              fmi2Boolean /*visible*/, fmi2Boolean loggingOn) {
  const auto refuse = [&](const std::string& why) -> fmi2Component {
    log_refusal(functions, instanceName, "fmi2Instantiate: " + why);
    return nullptr;
  };
  try {
    if (functions == nullptr || functions->logger == nullptr)
      return refuse("no callback functions (a logger is required)");
    if (instanceName == nullptr || instanceName[0] == '\0') return refuse("the instance name is missing");
    if (fmuType != fmi2CoSimulation) return refuse("this FMU offers Co-Simulation only");
    const tissue::fmi3::ModelDescription& description = layout().description();
    if (fmuGUID == nullptr || description.instantiation_token != fmuGUID) {
      return refuse(std::string("the GUID '") + (fmuGUID ? fmuGUID : "(null)") + "' is not this FMU's " +
                    std::string(description.instantiation_token));
    }
    const fmi2CallbackLogger logger = functions->logger;
    const fmi2ComponentEnvironment environment = functions->componentEnvironment;
    const std::string name(instanceName);
    auto log = [logger, environment, name](Status status, const char* category, const char* message) {
      logger(environment, name.c_str(), to_fmi(status), category, "%s", message);
    };
    return std::make_unique<Component>(layout(), name, resource_path(fmuResourceLocation), loggingOn != fmi2False, log)
        .release();
  } catch (const std::exception& error) {
    return refuse(error.what());
  } catch (...) {
    return refuse("unknown error");
  }
}

void fmi2FreeInstance(fmi2Component c) { delete static_cast<Component*>(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean /*toleranceDefined*/, fmi2Real /*tolerance*/,
                               fmi2Real startTime, fmi2Boolean /*stopTimeDefined*/, fmi2Real /*stopTime*/) {
  return run(c, Call::setup_experiment, "fmi2SetupExperiment",
             [&](Component& self) { self.setup_experiment(startTime); });
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  return run(c, Call::enter_initialization_mode, "fmi2EnterInitializationMode",
             [&](Component& self) { self.enter_initialization_mode(); });
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  return run(c, Call::exit_initialization_mode, "fmi2ExitInitializationMode",
             [&](Component& self) { self.exit_initialization_mode(); });
}

fmi2Status fmi2Terminate(fmi2Component c) {
  return run(c, Call::terminate, "fmi2Terminate", [&](Component& self) { self.instance().terminate(); });
}

fmi2Status fmi2Reset(fmi2Component c) {
  return run(c, Call::reset, "fmi2Reset", [&](Component& self) { self.reset(); });
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
  return get_values(c, "fmi2GetReal", vr, n, value, ScalarType::real);
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
  return get_values(c, "fmi2GetInteger", vr, n, value, ScalarType::integer);
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
  return get_values(c, "fmi2GetBoolean", vr, n, value, ScalarType::boolean);
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
  return get_values(c, "fmi2GetString", vr, n, value, ScalarType::string);
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
  return set_values(c, "fmi2SetReal", vr, n, value, ScalarType::real);
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
  return set_values(c, "fmi2SetInteger", vr, n, value, ScalarType::integer);
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
  return set_values(c, "fmi2SetBoolean", vr, n, value, ScalarType::boolean);
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
  return set_values(c, "fmi2SetString", vr, n, value, ScalarType::string);
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* state) {
  return run(c, Call::get_fmu_state, "fmi2GetFMUstate",
             [&](Component& self) { tissue::fmi3::get_fmu_state(self.instance(), state); });
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
  return run(c, Call::set_fmu_state, "fmi2SetFMUstate", [&](Component& self) {
    if (state == nullptr) throw VariableError("the state is null");
    self.restore(*static_cast<const InstanceState*>(state));
  });
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* state) {
  return run(c, Call::free_fmu_state, "fmi2FreeFMUstate", [&](Component&) { tissue::fmi3::free_fmu_state(state); });
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t* size) {
  return run(c, Call::serialize_fmu_state, "fmi2SerializedFMUstateSize", [&](Component& self) {
    if (size == nullptr) throw VariableError("the size pointer is null");
    *size = tissue::fmi3::serialized_fmu_state_size(self.instance(), state);
  });
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte serializedState[], size_t size) {
  return run(c, Call::serialize_fmu_state, "fmi2SerializeFMUstate", [&](Component& self) {
    tissue::fmi3::serialize_fmu_state(self.instance(), state, serializedState, size, "fmi2SerializedFMUstateSize");
  });
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate* state) {
  return run(c, Call::serialize_fmu_state, "fmi2DeSerializeFMUstate", [&](Component& self) {
    tissue::fmi3::deserialize_fmu_state(self.instance(), serializedState, size, state);
  });
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2ValueReference[],
                                        size_t, const fmi2Real[], fmi2Real[]) {
  return not_offered(c, "fmi2GetDirectionalDerivative", "providesDirectionalDerivative is false");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[],
                                       const fmi2Real[]) {
  return not_offered(c, "fmi2SetRealInputDerivatives", "canInterpolateInputs is false");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[],
                                        fmi2Real[]) {
  return not_offered(c, "fmi2GetRealOutputDerivatives", "maxOutputDerivativeOrder is 0");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean /*noSetFMUStatePriorToCurrentPoint*/) {
  return run(c, Call::do_step, "fmi2DoStep",
             [&](Component& self) { return self.do_step(currentCommunicationPoint, communicationStepSize); });
}

fmi2Status fmi2CancelStep(fmi2Component c) {
  return not_offered(c, "fmi2CancelStep", "doStep never returns fmi2Pending");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind, fmi2Status*) {
  return not_offered(c, "fmi2GetStatus", "doStep never returns fmi2Pending");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Real* value) {
  if (kind != fmi2LastSuccessfulTime) return not_offered(c, "fmi2GetRealStatus", "only fmi2LastSuccessfulTime");
  return run(c, Call::get_value, "fmi2GetRealStatus", [&](Component& self) {
    if (value == nullptr) throw VariableError("the value pointer is null");
    *value = self.last_successful_time_s();
  });
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind, fmi2Integer*) {
  return not_offered(c, "fmi2GetIntegerStatus", "no integer status");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Boolean* value) {
  if (kind != fmi2Terminated) return not_offered(c, "fmi2GetBooleanStatus", "only fmi2Terminated");
  return run(c, Call::get_value, "fmi2GetBooleanStatus", [&](Component&) {
    if (value == nullptr) throw VariableError("the value pointer is null");
    *value = fmi2False;  // the FMUs never ask to end the simulation
  });
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind, fmi2String*) {
  return not_offered(c, "fmi2GetStringStatus", "no string status");
}

}  // extern "C"
