// The C ABI of every FMU of the project: all FMI 3.0 functions over the layer's Instance
// (instance.hpp), compiled into each FMU's shared library, which supplies model_description() and
// make_model() (model.hpp). Each function checks its arguments, runs through Instance::run (the
// state table checked once on entry, everything caught, the reason of any status worse than fmi3OK
// logged, the standard's transition after an error), and answers a status. Interfaces the FMUs do
// not offer (Model Exchange, Scheduled Execution, clocks, event mode, derivatives, other integer
// widths, binaries) answer fmi3Error with the reason. Nothing here throws or aborts across the ABI.
#include "fmi3/fmu_state_calls.hpp"
#include "fmi3/instance.hpp"
#include "fmi3/model.hpp"

#include "fmi3_abi.h"

#include <algorithm>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace {

using tissue::fmi3::Call;
using tissue::fmi3::Instance;
using tissue::fmi3::InstanceState;
using tissue::fmi3::Status;
using tissue::fmi3::VariableError;

fmi3Status to_fmi(Status status) { return static_cast<fmi3Status>(status); }

static_assert(static_cast<int>(Status::ok) == fmi3OK && static_cast<int>(Status::warning) == fmi3Warning &&
              static_cast<int>(Status::discard) == fmi3Discard && static_cast<int>(Status::error) == fmi3Error &&
              static_cast<int>(Status::fatal) == fmi3Fatal);

// Runs `body` on the instance under `call`'s allowed states; `body` returns a Status (ok if void).
template <class Body>
fmi3Status run(fmi3Instance handle, Call call, const char* function, Body&& body) {
  if (handle == nullptr) return fmi3Error;
  auto& instance = *static_cast<Instance*>(handle);
  return to_fmi(instance.run(call, function, [&]() -> Status {
    if constexpr (std::is_void_v<decltype(body(instance))>) {
      body(instance);
      return Status::ok;
    } else {
      return body(instance);
    }
  }));
}

fmi3Status not_offered(fmi3Instance handle, const char* function, const char* why) {
  return run(handle, Call::not_offered, function, [&](Instance& instance) -> Status {
    instance.log(Status::error, "logStatusError",
                 std::string(function) + ": not offered by the " +
                     std::string(instance.description().model_identifier) + " FMU (" + why + ")");
    return Status::error;
  });
}

template <class T>
std::span<const T> input_span(const T* data, size_t n) {
  if (n > 0 && data == nullptr) throw VariableError("a null array was passed with a non-zero length");
  return std::span<const T>(data, n);
}

template <class T>
std::span<T> output_span(T* data, size_t n) {
  if (n > 0 && data == nullptr) throw VariableError("a null array was passed with a non-zero length");
  return std::span<T>(data, n);
}

template <class T>
fmi3Status get_values(fmi3Instance handle, const char* function, const fmi3ValueReference vr[], size_t nvr, T values[],
                      size_t n) {
  return run(handle, Call::get_value, function,
             [&](Instance& self) { self.get<T>(input_span(vr, nvr), output_span(values, n)); });
}

template <class T>
fmi3Status set_values(fmi3Instance handle, const char* function, const fmi3ValueReference vr[], size_t nvr,
                      const T values[], size_t n) {
  return run(handle, Call::set_value, function,
             [&](Instance& self) { self.set<T>(input_span(vr, nvr), input_span(values, n)); });
}

fmi3Instance instantiate_refused(fmi3InstanceEnvironment environment, fmi3LogMessageCallback log,
                                 const std::string& why) {
  if (log != nullptr) log(environment, fmi3Error, "logStatusError", why.c_str());
  return nullptr;
}

}  // namespace

extern "C" {

const char* fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
  return run(instance, Call::set_debug_logging, "fmi3SetDebugLogging",
             [&](Instance& self) { self.set_debug_logging(loggingOn, input_span(categories, nCategories)); });
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean,
                                          fmi3InstanceEnvironment environment, fmi3LogMessageCallback log) {
  return instantiate_refused(environment, log, "this FMU offers Co-Simulation only");
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean, const fmi3ValueReference[],
                                         size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment environment,
                                         fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback) {
  const auto refuse = [&](const std::string& why) {
    return instantiate_refused(environment, log, "fmi3InstantiateCoSimulation: " + why);
  };
  try {
    const tissue::fmi3::ModelDescription& description = tissue::fmi3::model_description();
    if (instanceName == nullptr || instanceName[0] == '\0') return refuse("the instance name is missing");
    if (instantiationToken == nullptr || description.instantiation_token != instantiationToken) {
      return refuse(std::string("the instantiation token '") + (instantiationToken ? instantiationToken : "(null)") +
                    "' is not this FMU's " + std::string(description.instantiation_token));
    }
    if (eventModeUsed) return refuse("event mode is not offered (hasEventMode is false)");
    if (nRequiredIntermediateVariables > 0) return refuse("intermediate updates are not offered");
    auto logger = [environment, log](Status status, const char* category, const char* message) {
      if (log != nullptr) log(environment, to_fmi(status), category, message);
    };
    auto instance = std::make_unique<Instance>(description, instanceName, resourcePath == nullptr ? "" : resourcePath,
                                               loggingOn, logger);
    return instance.release();
  } catch (const std::exception& error) {
    return refuse(error.what());
  } catch (...) {
    return refuse("unknown error");
  }
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean,
                                               fmi3InstanceEnvironment environment, fmi3LogMessageCallback log,
                                               fmi3ClockUpdateCallback, fmi3LockPreemptionCallback,
                                               fmi3UnlockPreemptionCallback) {
  return instantiate_refused(environment, log, "this FMU offers Co-Simulation only");
}

void fmi3FreeInstance(fmi3Instance instance) { delete static_cast<Instance*>(instance); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean, fmi3Float64, fmi3Float64 startTime,
                                       fmi3Boolean, fmi3Float64) {
  return run(instance, Call::enter_initialization_mode, "fmi3EnterInitializationMode",
             [&](Instance& self) { self.enter_initialization_mode(startTime); });
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
  return run(instance, Call::exit_initialization_mode, "fmi3ExitInitializationMode",
             [&](Instance& self) { self.exit_initialization_mode(); });
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
  return not_offered(instance, "fmi3EnterEventMode", "hasEventMode is false");
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
  return run(instance, Call::terminate, "fmi3Terminate", [&](Instance& self) { self.terminate(); });
}

fmi3Status fmi3Reset(fmi3Instance instance) {
  return run(instance, Call::reset, "fmi3Reset", [&](Instance& self) { self.reset(); });
}

#define TISSUE_NOT_OFFERED_GET_SET(Type, CType)                                                                \
  fmi3Status fmi3Get##Type(fmi3Instance instance, const fmi3ValueReference[], size_t, CType[], size_t) {       \
    return not_offered(instance, "fmi3Get" #Type, "no variable of type " #Type);                               \
  }                                                                                                            \
  fmi3Status fmi3Set##Type(fmi3Instance instance, const fmi3ValueReference[], size_t, const CType[], size_t) { \
    return not_offered(instance, "fmi3Set" #Type, "no variable of type " #Type);                               \
  }

TISSUE_NOT_OFFERED_GET_SET(Float32, fmi3Float32)
TISSUE_NOT_OFFERED_GET_SET(Int8, fmi3Int8)
TISSUE_NOT_OFFERED_GET_SET(UInt8, fmi3UInt8)
TISSUE_NOT_OFFERED_GET_SET(Int16, fmi3Int16)
TISSUE_NOT_OFFERED_GET_SET(UInt16, fmi3UInt16)
#undef TISSUE_NOT_OFFERED_GET_SET

// The typed get/set: one line each, the table decides the rest.
#define TISSUE_GET_SET(Type, CType)                                                                                \
  fmi3Status fmi3Get##Type(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, CType values[],       \
                           size_t n) {                                                                             \
    return get_values(instance, "fmi3Get" #Type, vr, nvr, values, n);                                              \
  }                                                                                                                \
  fmi3Status fmi3Set##Type(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const CType values[], \
                           size_t n) {                                                                             \
    return set_values(instance, "fmi3Set" #Type, vr, nvr, values, n);                                              \
  }

TISSUE_GET_SET(Float64, fmi3Float64)
TISSUE_GET_SET(Int32, fmi3Int32)
TISSUE_GET_SET(UInt32, fmi3UInt32)
TISSUE_GET_SET(Int64, fmi3Int64)
TISSUE_GET_SET(UInt64, fmi3UInt64)
TISSUE_GET_SET(Boolean, fmi3Boolean)
TISSUE_GET_SET(String, fmi3String)
#undef TISSUE_GET_SET

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                         fmi3Binary values[], size_t nValues) {
  return run(instance, Call::get_value, "fmi3GetBinary", [&](Instance& self) {
    self.get_binary(input_span(vr, nvr), output_span(valueSizes, nValues), output_span(values, nValues));
  });
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference[], size_t, const size_t[], const fmi3Binary[],
                         size_t) {
  return not_offered(instance, "fmi3SetBinary", "no Binary input or parameter");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3Clock[]) {
  return not_offered(instance, "fmi3GetClock", "no clocks");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3Clock[]) {
  return not_offered(instance, "fmi3SetClock", "no clocks");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference, size_t*) {
  return not_offered(instance, "fmi3GetNumberOfVariableDependencies", "dependencies are not declared");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference, size_t[], fmi3ValueReference[],
                                       size_t[], fmi3DependencyKind[], size_t) {
  return not_offered(instance, "fmi3GetVariableDependencies", "dependencies are not declared");
}

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState* state) {
  return run(instance, Call::get_fmu_state, "fmi3GetFMUState",
             [&](Instance& self) { tissue::fmi3::get_fmu_state(self, state); });
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
  return run(instance, Call::set_fmu_state, "fmi3SetFMUState",
             [&](Instance& self) { tissue::fmi3::set_fmu_state(self, state); });
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState* state) {
  return run(instance, Call::free_fmu_state, "fmi3FreeFMUState", [&](Instance&) { tissue::fmi3::free_fmu_state(state); });
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState state, size_t* size) {
  return run(instance, Call::serialize_fmu_state, "fmi3SerializedFMUStateSize", [&](Instance& self) {
    if (size == nullptr) throw VariableError("the size pointer is null");
    *size = tissue::fmi3::serialized_fmu_state_size(self, state);
  });
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState state, fmi3Byte serializedState[], size_t size) {
  return run(instance, Call::serialize_fmu_state, "fmi3SerializeFMUState", [&](Instance& self) {
    tissue::fmi3::serialize_fmu_state(self, state, serializedState, size, "fmi3SerializedFMUStateSize");
  });
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState* state) {
  return run(instance, Call::serialize_fmu_state, "fmi3DeserializeFMUState",
             [&](Instance& self) { tissue::fmi3::deserialize_fmu_state(self, serializedState, size, state); });
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference[], size_t,
                                        const fmi3ValueReference[], size_t, const fmi3Float64[], size_t, fmi3Float64[],
                                        size_t) {
  return not_offered(instance, "fmi3GetDirectionalDerivative", "providesDirectionalDerivatives is false");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference[], size_t,
                                    const fmi3ValueReference[], size_t, const fmi3Float64[], size_t, fmi3Float64[],
                                    size_t) {
  return not_offered(instance, "fmi3GetAdjointDerivative", "providesAdjointDerivatives is false");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
  return not_offered(instance, "fmi3EnterConfigurationMode",
                     "the structural parameters are fixed: set them before entering initialization mode");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
  return not_offered(instance, "fmi3ExitConfigurationMode", "no configuration mode");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3Float64[],
                                  fmi3IntervalQualifier[]) {
  return not_offered(instance, "fmi3GetIntervalDecimal", "no clocks");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3UInt64[],
                                   fmi3UInt64[], fmi3IntervalQualifier[]) {
  return not_offered(instance, "fmi3GetIntervalFraction", "no clocks");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3Float64[]) {
  return not_offered(instance, "fmi3GetShiftDecimal", "no clocks");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3UInt64[], fmi3UInt64[]) {
  return not_offered(instance, "fmi3GetShiftFraction", "no clocks");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3Float64[]) {
  return not_offered(instance, "fmi3SetIntervalDecimal", "no clocks");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3UInt64[],
                                   const fmi3UInt64[]) {
  return not_offered(instance, "fmi3SetIntervalFraction", "no clocks");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3Float64[]) {
  return not_offered(instance, "fmi3SetShiftDecimal", "no clocks");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3UInt64[],
                                const fmi3UInt64[]) {
  return not_offered(instance, "fmi3SetShiftFraction", "no clocks");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
  return not_offered(instance, "fmi3EvaluateDiscreteStates", "providesEvaluateDiscreteStates is false");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean*, fmi3Boolean*, fmi3Boolean*, fmi3Boolean*,
                                    fmi3Boolean*, fmi3Float64*) {
  return not_offered(instance, "fmi3UpdateDiscreteStates", "no event mode");
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
  return not_offered(instance, "fmi3EnterContinuousTimeMode", "Co-Simulation only");
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean, fmi3Boolean*, fmi3Boolean*) {
  return not_offered(instance, "fmi3CompletedIntegratorStep", "Co-Simulation only");
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64) {
  return not_offered(instance, "fmi3SetTime", "Co-Simulation only");
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64[], size_t) {
  return not_offered(instance, "fmi3SetContinuousStates", "Co-Simulation only");
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64[], size_t) {
  return not_offered(instance, "fmi3GetContinuousStateDerivatives", "Co-Simulation only");
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64[], size_t) {
  return not_offered(instance, "fmi3GetEventIndicators", "Co-Simulation only");
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64[], size_t) {
  return not_offered(instance, "fmi3GetContinuousStates", "Co-Simulation only");
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64[], size_t) {
  return not_offered(instance, "fmi3GetNominalsOfContinuousStates", "Co-Simulation only");
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t*) {
  return not_offered(instance, "fmi3GetNumberOfEventIndicators", "Co-Simulation only");
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t*) {
  return not_offered(instance, "fmi3GetNumberOfContinuousStates", "Co-Simulation only");
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
  return not_offered(instance, "fmi3EnterStepMode", "no event mode: exit initialization mode enters step mode");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3Int32[],
                                    fmi3Float64[], size_t) {
  return not_offered(instance, "fmi3GetOutputDerivatives", "maxOutputDerivativeOrder is 0");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean, fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation,
                      fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime) {
  return run(instance, Call::do_step, "fmi3DoStep", [&](Instance& self) {
    if (eventHandlingNeeded != nullptr) *eventHandlingNeeded = false;
    if (terminateSimulation != nullptr) *terminateSimulation = false;
    if (earlyReturn != nullptr) *earlyReturn = false;
    double last = currentCommunicationPoint;
    const Status status = self.do_step(currentCommunicationPoint, communicationStepSize, last);
    if (lastSuccessfulTime != nullptr) *lastSuccessfulTime = last;
    return status;
  });
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference, fmi3Float64) {
  return not_offered(instance, "fmi3ActivateModelPartition", "Scheduled Execution is not offered");
}

}  // extern "C"
