// The Tissue FMU's C ABI: every FMI 3.0 function. Each one checks its arguments, calls the
// TissueInstance, catches everything and answers a status, logging the reason of any status worse
// than fmi3OK through the importer's callback. Interfaces the FMU does not offer (Model Exchange,
// Scheduled Execution, clocks, event mode, derivatives, other integer widths, binaries) answer
// fmi3Error with the reason. Nothing here throws or aborts across the ABI.
#include "fmi3/tissue_instance.hpp"

#include "fmi3_abi.h"

#include <cstdarg>
#include <exception>
#include <new>
#include <string>
#include <vector>

namespace {

using tissue::fmi3::InstanceError;
using tissue::fmi3::InstanceSnapshot;
using tissue::fmi3::TissueInstance;

struct Instance {
  fmi3InstanceEnvironment environment = nullptr;
  fmi3LogMessageCallback log = nullptr;
  bool logging_on = false;
  bool log_calls = false;
  bool log_events = true;
  std::unique_ptr<TissueInstance> model;
  std::string name;

  // Warnings and errors always reach the importer (as Reference-FMUs does); calls and events only
  // with logging on and their category enabled.
  void message(fmi3Status status, const char* category, const std::string& text) const {
    if (log == nullptr || (status == fmi3OK && !logging_on)) return;
    const std::string category_name(category);
    if (category_name == "logCalls" && !log_calls) return;
    if (category_name == "logEvents" && !log_events) return;
    log(environment, status, category, text.c_str());
  }
};

const char* category_of(fmi3Status status) {
  switch (status) {
    case fmi3Warning:
      return "logStatusWarning";
    case fmi3Discard:
    case fmi3Error:
      return "logStatusError";
    case fmi3Fatal:
      return "logStatusFatal";
    default:
      return "logCalls";
  }
}

// Runs `body` on the instance, answering fmi3Error (with the reason logged) for anything thrown.
template <class Body>
fmi3Status guarded(fmi3Instance handle, const char* function, Body&& body) {
  if (handle == nullptr) return fmi3Error;
  auto* instance = static_cast<Instance*>(handle);
  try {
    instance->message(fmi3OK, "logCalls", function);
    return body(*instance);
  } catch (const InstanceError& error) {
    instance->message(fmi3Error, "logStatusError", std::string(function) + ": " + error.what());
  } catch (const std::bad_alloc&) {
    instance->message(fmi3Error, "logStatusError", std::string(function) + ": out of memory");
  } catch (const std::exception& error) {
    instance->message(fmi3Error, "logStatusError", std::string(function) + ": " + error.what());
  } catch (...) {
    instance->message(fmi3Error, "logStatusError", std::string(function) + ": unknown error");
  }
  return fmi3Error;
}

fmi3Status not_offered(fmi3Instance handle, const char* function, const char* why) {
  return guarded(handle, function, [&](Instance& instance) {
    instance.message(fmi3Error, "logStatusError",
                     std::string(function) + ": not offered by the Tissue FMU (" + why + ")");
    return fmi3Error;
  });
}

template <class T>
std::span<const T> input_span(const T* data, size_t n) {
  if (n > 0 && data == nullptr) throw InstanceError("a null array was passed with a non-zero length");
  return std::span<const T>(data, n);
}

template <class T>
std::span<T> output_span(T* data, size_t n) {
  if (n > 0 && data == nullptr) throw InstanceError("a null array was passed with a non-zero length");
  return std::span<T>(data, n);
}

}  // namespace

extern "C" {

const char* fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
  return guarded(instance, "fmi3SetDebugLogging", [&](Instance& self) {
    const auto names = input_span(categories, nCategories);
    bool calls = nCategories == 0, events = nCategories == 0;
    for (const fmi3String name : names) {
      const std::string category = name == nullptr ? "" : name;
      if (category == "logCalls") {
        calls = true;
      } else if (category == "logEvents") {
        events = true;
      } else if (category != "logStatusWarning" && category != "logStatusError" && category != "logStatusFatal") {
        throw InstanceError("unknown log category '" + category + "'");
      }
    }
    self.logging_on = loggingOn;
    self.log_calls = calls;
    self.log_events = events;
    return fmi3OK;
  });
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean,
                                          fmi3InstanceEnvironment environment, fmi3LogMessageCallback log) {
  if (log != nullptr) log(environment, fmi3Error, "logStatusError", "the Tissue FMU offers Co-Simulation only");
  return nullptr;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean, const fmi3ValueReference[],
                                         size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment environment,
                                         fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback) {
  const auto refuse = [&](const std::string& why) -> fmi3Instance {
    if (log != nullptr) log(environment, fmi3Error, "logStatusError", ("fmi3InstantiateCoSimulation: " + why).c_str());
    return nullptr;
  };
  try {
    if (instanceName == nullptr || instanceName[0] == '\0') return refuse("the instance name is missing");
    if (instantiationToken == nullptr || tissue::fmi3::INSTANTIATION_TOKEN != instantiationToken) {
      return refuse(std::string("the instantiation token '") + (instantiationToken ? instantiationToken : "(null)") +
                    "' is not this FMU's " + std::string(tissue::fmi3::INSTANTIATION_TOKEN));
    }
    if (eventModeUsed) return refuse("event mode is not offered (hasEventMode is false)");
    if (nRequiredIntermediateVariables > 0) return refuse("intermediate updates are not offered");
    auto instance = std::make_unique<Instance>();
    instance->environment = environment;
    instance->log = log;
    instance->logging_on = loggingOn;
    instance->name = instanceName;
    const Instance* raw = instance.get();
    instance->model =
        std::make_unique<TissueInstance>(instanceName, resourcePath == nullptr ? "" : resourcePath,
                                         [raw](int status, const char* category, const std::string& text) {
                                           raw->message(static_cast<fmi3Status>(status), category, text);
                                         });
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
  if (log != nullptr) log(environment, fmi3Error, "logStatusError", "the Tissue FMU offers Co-Simulation only");
  return nullptr;
}

void fmi3FreeInstance(fmi3Instance instance) { delete static_cast<Instance*>(instance); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean, fmi3Float64, fmi3Float64 startTime,
                                       fmi3Boolean, fmi3Float64) {
  return guarded(instance, "fmi3EnterInitializationMode", [&](Instance& self) {
    self.model->enter_initialization_mode(startTime);
    return fmi3OK;
  });
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
  return guarded(instance, "fmi3ExitInitializationMode", [&](Instance& self) {
    self.model->exit_initialization_mode();
    return fmi3OK;
  });
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
  return not_offered(instance, "fmi3EnterEventMode", "hasEventMode is false");
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
  return guarded(instance, "fmi3Terminate", [&](Instance& self) {
    self.model->terminate();
    return fmi3OK;
  });
}

fmi3Status fmi3Reset(fmi3Instance instance) {
  return guarded(instance, "fmi3Reset", [&](Instance& self) {
    self.model->reset();
    return fmi3OK;
  });
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

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 values[],
                          size_t n) {
  return guarded(instance, "fmi3GetFloat64", [&](Instance& self) {
    self.model->get_float64(input_span(vr, nvr), output_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 values[],
                          size_t n) {
  return guarded(instance, "fmi3SetFloat64", [&](Instance& self) {
    self.model->set_float64(input_span(vr, nvr), input_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Int32 values[],
                        size_t n) {
  return guarded(instance, "fmi3GetInt32", [&](Instance& self) {
    self.model->get_int32(input_span(vr, nvr), output_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Int32 values[],
                        size_t n) {
  return guarded(instance, "fmi3SetInt32", [&](Instance& self) {
    self.model->set_int32(input_span(vr, nvr), input_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3GetUInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3UInt32 values[],
                         size_t n) {
  return guarded(instance, "fmi3GetUInt32", [&](Instance& self) {
    self.model->get_uint32(input_span(vr, nvr), output_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3SetUInt32(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3UInt32[], size_t) {
  return not_offered(instance, "fmi3SetUInt32", "the only UInt32 variable, surface.triangles, is an output");
}

fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Int64 values[],
                        size_t n) {
  return guarded(instance, "fmi3GetInt64", [&](Instance& self) {
    self.model->get_int64(input_span(vr, nvr), output_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Int64 values[],
                        size_t n) {
  return guarded(instance, "fmi3SetInt64", [&](Instance& self) {
    self.model->set_int64(input_span(vr, nvr), input_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3GetUInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 values[],
                         size_t n) {
  return guarded(instance, "fmi3GetUInt64", [&](Instance& self) {
    self.model->get_uint64(input_span(vr, nvr), output_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3SetUInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3UInt64 values[],
                         size_t n) {
  return guarded(instance, "fmi3SetUInt64", [&](Instance& self) {
    self.model->set_uint64(input_span(vr, nvr), input_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Boolean values[],
                          size_t n) {
  return guarded(instance, "fmi3GetBoolean", [&](Instance& self) {
    self.model->get_boolean(input_span(vr, nvr), output_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Boolean values[],
                          size_t n) {
  return guarded(instance, "fmi3SetBoolean", [&](Instance& self) {
    self.model->set_boolean(input_span(vr, nvr), input_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3String values[],
                         size_t n) {
  return guarded(instance, "fmi3GetString", [&](Instance& self) {
    self.model->get_string(input_span(vr, nvr), output_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3String values[],
                         size_t n) {
  return guarded(instance, "fmi3SetString", [&](Instance& self) {
    self.model->set_string(input_span(vr, nvr), input_span(values, n));
    return fmi3OK;
  });
}

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference[], size_t, size_t[], fmi3Binary[], size_t) {
  return not_offered(instance, "fmi3GetBinary", "no Binary variable");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference[], size_t, const size_t[], const fmi3Binary[],
                         size_t) {
  return not_offered(instance, "fmi3SetBinary", "no Binary variable");
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
  return guarded(instance, "fmi3GetFMUState", [&](Instance& self) {
    if (state == nullptr) throw InstanceError("the state pointer is null");
    std::unique_ptr<InstanceSnapshot> snapshot = self.model->save();
    if (*state != nullptr) delete static_cast<InstanceSnapshot*>(*state);  // the standard: overwrite it
    *state = snapshot.release();
    return fmi3OK;
  });
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
  return guarded(instance, "fmi3SetFMUState", [&](Instance& self) {
    if (state == nullptr) throw InstanceError("the state is null");
    self.model->restore(*static_cast<const InstanceSnapshot*>(state));
    return fmi3OK;
  });
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState* state) {
  return guarded(instance, "fmi3FreeFMUState", [&](Instance&) {
    if (state == nullptr) return fmi3OK;
    delete static_cast<InstanceSnapshot*>(*state);
    *state = nullptr;
    return fmi3OK;
  });
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState state, size_t* size) {
  return guarded(instance, "fmi3SerializedFMUStateSize", [&](Instance& self) {
    if (state == nullptr || size == nullptr) throw InstanceError("null state or size");
    *size = self.model->serialize(*static_cast<const InstanceSnapshot*>(state)).size();
    return fmi3OK;
  });
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState state, fmi3Byte serializedState[], size_t size) {
  return guarded(instance, "fmi3SerializeFMUState", [&](Instance& self) {
    if (state == nullptr) throw InstanceError("the state is null");
    const std::vector<std::uint8_t> bytes = self.model->serialize(*static_cast<const InstanceSnapshot*>(state));
    if (size != bytes.size() || (size > 0 && serializedState == nullptr)) {
      throw InstanceError("the buffer holds " + std::to_string(size) + " bytes, the state needs " +
                          std::to_string(bytes.size()) + " (fmi3SerializedFMUStateSize)");
    }
    std::copy(bytes.begin(), bytes.end(), serializedState);
    return fmi3OK;
  });
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState* state) {
  return guarded(instance, "fmi3DeserializeFMUState", [&](Instance& self) {
    if (state == nullptr) throw InstanceError("the state pointer is null");
    std::unique_ptr<InstanceSnapshot> snapshot = self.model->deserialize(input_span(serializedState, size));
    if (*state != nullptr) delete static_cast<InstanceSnapshot*>(*state);
    *state = snapshot.release();
    return fmi3OK;
  });
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
  return guarded(instance, "fmi3DoStep", [&](Instance& self) {
    if (eventHandlingNeeded != nullptr) *eventHandlingNeeded = false;
    if (terminateSimulation != nullptr) *terminateSimulation = false;
    if (earlyReturn != nullptr) *earlyReturn = false;
    double last = currentCommunicationPoint;
    const bool done = self.model->do_step(currentCommunicationPoint, communicationStepSize, last);
    if (lastSuccessfulTime != nullptr) *lastSuccessfulTime = last;
    if (!done) {
      self.message(fmi3Discard, category_of(fmi3Discard), "fmi3DoStep: stopped at t = " + std::to_string(last) + " s");
      return fmi3Discard;
    }
    return fmi3OK;
  });
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference, fmi3Float64) {
  return not_offered(instance, "fmi3ActivateModelPartition", "Scheduled Execution is not offered");
}

}  // extern "C"
