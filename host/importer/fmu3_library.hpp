// fmu3_library.hpp - the shared library of an FMI 3.0 FMU, loaded with dlopen.
//
// Fmu3Functions holds one typed pointer per FMI 3.0 function (types from fmi3_abi.h). The
// member list is written once as the X-macro TISSUE_FMI3_FOR_EACH_FUNCTION; a static_assert in
// fmu3_library.cpp checks it against FMI3_FUNCTION_NAMES, the list the FMU is tested against.
#pragma once

#include "fmi3_abi.h"

#include <filesystem>

/// Calls X(name) for every FMI 3.0 function, in the order of fmi3_abi.h.
#define TISSUE_FMI3_FOR_EACH_FUNCTION(X)                                                                               \
  X(fmi3GetVersion)                                                                                                    \
  X(fmi3SetDebugLogging) X(fmi3InstantiateModelExchange) X(fmi3InstantiateCoSimulation)                                \
      X(fmi3InstantiateScheduledExecution) X(fmi3FreeInstance) X(fmi3EnterInitializationMode)                          \
          X(fmi3ExitInitializationMode) X(fmi3EnterEventMode) X(fmi3Terminate) X(fmi3Reset) X(fmi3GetFloat32) X(       \
              fmi3GetFloat64) X(fmi3GetInt8) X(fmi3GetUInt8) X(fmi3GetInt16) X(fmi3GetUInt16) X(fmi3GetInt32)          \
              X(fmi3GetUInt32) X(fmi3GetInt64) X(fmi3GetUInt64) X(fmi3GetBoolean) X(fmi3GetString) X(fmi3GetBinary) X( \
                  fmi3GetClock) X(fmi3SetFloat32) X(fmi3SetFloat64) X(fmi3SetInt8) X(fmi3SetUInt8) X(fmi3SetInt16)     \
                  X(fmi3SetUInt16) X(fmi3SetInt32) X(fmi3SetUInt32) X(fmi3SetInt64) X(fmi3SetUInt64) X(fmi3SetBoolean) \
                      X(fmi3SetString) X(fmi3SetBinary) X(fmi3SetClock) X(fmi3GetNumberOfVariableDependencies) X(      \
                          fmi3GetVariableDependencies) X(fmi3GetFMUState) X(fmi3SetFMUState) X(fmi3FreeFMUState)       \
                          X(fmi3SerializedFMUStateSize) X(fmi3SerializeFMUState) X(fmi3DeserializeFMUState) X(         \
                              fmi3GetDirectionalDerivative) X(fmi3GetAdjointDerivative) X(fmi3EnterConfigurationMode)  \
                              X(fmi3ExitConfigurationMode) X(fmi3GetIntervalDecimal) X(fmi3GetIntervalFraction)        \
                                  X(fmi3GetShiftDecimal) X(fmi3GetShiftFraction) X(fmi3SetIntervalDecimal)             \
                                      X(fmi3SetIntervalFraction) X(fmi3SetShiftDecimal) X(fmi3SetShiftFraction) X(     \
                                          fmi3EvaluateDiscreteStates) X(fmi3UpdateDiscreteStates)                      \
                                          X(fmi3EnterContinuousTimeMode) X(fmi3CompletedIntegratorStep) X(fmi3SetTime) \
                                              X(fmi3SetContinuousStates) X(fmi3GetContinuousStateDerivatives)          \
                                                  X(fmi3GetEventIndicators) X(fmi3GetContinuousStates)                 \
                                                      X(fmi3GetNominalsOfContinuousStates)                             \
                                                          X(fmi3GetNumberOfEventIndicators)                            \
                                                              X(fmi3GetNumberOfContinuousStates) X(fmi3EnterStepMode)  \
                                                                  X(fmi3GetOutputDerivatives) X(fmi3DoStep)            \
                                                                      X(fmi3ActivateModelPartition)

namespace tissue::host {

/**
 * One pointer per FMI 3.0 function, named exactly as the standard's function so that calls
 * read like the specification: functions.fmi3DoStep(instance, ...). All non-null once loaded.
 */
struct Fmu3Functions {
#define TISSUE_FMI3_DECLARE_MEMBER(name) name##TYPE* name = nullptr;
  TISSUE_FMI3_FOR_EACH_FUNCTION(TISSUE_FMI3_DECLARE_MEMBER)
#undef TISSUE_FMI3_DECLARE_MEMBER
};

/**
 * An FMU binary opened with dlopen(RTLD_NOW | RTLD_LOCAL) and closed with dlclose by the
 * destructor. The constructor resolves every FMI 3.0 function; if any is missing it refuses
 * the binary with an FmuError listing all missing names, as a strict importer must (FMI 3.0
 * requires every function to be exported, even those of unsupported interface types).
 * Movable, not copyable.
 */
class Fmu3Library {
 public:
  /// Loads @p binary_path; throws FmuError if it is missing, cannot be loaded or lacks functions.
  explicit Fmu3Library(const std::filesystem::path& binary_path);
  ~Fmu3Library();

  Fmu3Library(const Fmu3Library&) = delete;
  Fmu3Library& operator=(const Fmu3Library&) = delete;
  Fmu3Library(Fmu3Library&& other) noexcept;
  Fmu3Library& operator=(Fmu3Library&& other) noexcept;

  [[nodiscard]] const Fmu3Functions& functions() const { return m_functions; }
  [[nodiscard]] const std::filesystem::path& path() const { return m_path; }

 private:
  void close() noexcept;

  std::filesystem::path m_path;
  void* m_handle = nullptr;
  Fmu3Functions m_functions;
};

}  // namespace tissue::host
