/*
 * fmi3_abi.h - the project's own C declaration of the FMI 3.0 application binary interface.
 *
 * Written from the FMI 3.0 specification (chapter 2.2 "FMI Application Programming
 * Interface"): the platform types (standard header fmi3PlatformTypes.h), the enums, callback
 * types and one function type per FMI function (fmi3FunctionTypes.h), and the prototypes of
 * the functions an FMU exports (fmi3Functions.h). The FMU (fmu_src/fmi3) implements the
 * prototypes; the importer (host/importer) dlsym()s them and calls them through the *TYPE
 * function types. Names, parameter order and types must match the standard exactly: they
 * are the binary contract with every other FMI tool.
 *
 * Plain C99, usable from C and C++.
 */
#ifndef TISSUE_FMI3_ABI_H
#define TISSUE_FMI3_ABI_H

#include <stddef.h>
#include <stdint.h>
#ifndef __cplusplus
#include <stdbool.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Version string returned by fmi3GetVersion() and written as fmiVersion in modelDescription.xml. */
#define fmi3Version "3.0"

/**
 * Marks the FMI functions an FMU exports. The FMU is built with -fvisibility=hidden, so the
 * FMI entry points (and nothing else) must be given default visibility explicitly.
 */
#if defined(_WIN32)
#define FMI3_EXPORT __declspec(dllexport)
#elif defined(__GNUC__) || defined(__clang__)
#define FMI3_EXPORT __attribute__((visibility("default")))
#else
#define FMI3_EXPORT
#endif

/* ---------------------------------------------------------------------------------------------
 * Platform types (FMI 3.0, section 2.2.2).
 * ------------------------------------------------------------------------------------------- */

/** Opaque pointer to an FMU instance, created by one of the fmi3Instantiate* functions. */
typedef void* fmi3Instance;
/** Opaque pointer the importer passes at instantiation and receives back in every callback. */
typedef void* fmi3InstanceEnvironment;
/** Opaque pointer to a snapshot of an instance's state (fmi3GetFMUState). */
typedef void* fmi3FMUState;
/** Handle of a variable, the valueReference attribute in modelDescription.xml. */
typedef uint32_t fmi3ValueReference;

typedef float fmi3Float32;
typedef double fmi3Float64;
typedef int8_t fmi3Int8;
typedef uint8_t fmi3UInt8;
typedef int16_t fmi3Int16;
typedef uint16_t fmi3UInt16;
typedef int32_t fmi3Int32;
typedef uint32_t fmi3UInt32;
typedef int64_t fmi3Int64;
typedef uint64_t fmi3UInt64;
typedef bool fmi3Boolean;
typedef char fmi3Char;
/** Zero-terminated UTF-8 string. */
typedef const fmi3Char* fmi3String;
typedef uint8_t fmi3Byte;
/** Pointer to the bytes of a Binary variable; its length travels separately. */
typedef const fmi3Byte* fmi3Binary;
typedef bool fmi3Clock;

#define fmi3True true
#define fmi3False false
#define fmi3ClockActive true
#define fmi3ClockInactive false

/* ---------------------------------------------------------------------------------------------
 * Enumerations (section 2.2.3 and following).
 * ------------------------------------------------------------------------------------------- */

/** Result of every FMI function, in increasing order of severity. */
typedef enum {
    fmi3OK,
    fmi3Warning,
    fmi3Discard,
    fmi3Error,
    fmi3Fatal
} fmi3Status;

/** The three interface types an FMU can implement. */
typedef enum {
    fmi3ModelExchange,
    fmi3CoSimulation,
    fmi3ScheduledExecution
} fmi3Type;

/** Kind of dependency reported by fmi3GetVariableDependencies. */
typedef enum {
    fmi3Independent,
    fmi3Constant,
    fmi3Fixed,
    fmi3Tunable,
    fmi3Discrete,
    fmi3Dependent
} fmi3DependencyKind;

/** Qualifier of a clock interval returned by fmi3GetIntervalDecimal/Fraction. */
typedef enum {
    fmi3IntervalNotYetKnown,
    fmi3IntervalUnchanged,
    fmi3IntervalChanged
} fmi3IntervalQualifier;

/* ---------------------------------------------------------------------------------------------
 * Callbacks the importer provides at instantiation.
 * ------------------------------------------------------------------------------------------- */

/** Called by the FMU to log a message; category is one of the declared log categories. */
typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment instanceEnvironment,
                                       fmi3Status status,
                                       fmi3String category,
                                       fmi3String message);

/** Scheduled Execution: the FMU signals that a clock ticked or an interval changed. */
typedef void (*fmi3ClockUpdateCallback)(fmi3InstanceEnvironment instanceEnvironment);

/** Co-Simulation: lets the FMU exchange intermediate values or return early inside fmi3DoStep. */
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3Float64 intermediateUpdateTime,
                                               fmi3Boolean intermediateVariableSetRequested,
                                               fmi3Boolean intermediateVariableGetAllowed,
                                               fmi3Boolean intermediateStepFinished,
                                               fmi3Boolean canReturnEarly,
                                               fmi3Boolean* earlyReturnRequested,
                                               fmi3Float64* earlyReturnTime);

/** Scheduled Execution: enter/leave a section that must not be preempted. */
typedef void (*fmi3LockPreemptionCallback)(void);
typedef void (*fmi3UnlockPreemptionCallback)(void);

/* ---------------------------------------------------------------------------------------------
 * Function types, one per FMI function, for loading with dlsym.
 * ------------------------------------------------------------------------------------------- */

/* Common functions: version, logging, instantiation and life cycle. */
typedef const char* fmi3GetVersionTYPE(void);

typedef fmi3Status fmi3SetDebugLoggingTYPE(fmi3Instance instance,
                                           fmi3Boolean loggingOn,
                                           size_t nCategories,
                                           const fmi3String categories[]);

typedef fmi3Instance fmi3InstantiateModelExchangeTYPE(fmi3String instanceName,
                                                      fmi3String instantiationToken,
                                                      fmi3String resourcePath,
                                                      fmi3Boolean visible,
                                                      fmi3Boolean loggingOn,
                                                      fmi3InstanceEnvironment instanceEnvironment,
                                                      fmi3LogMessageCallback logMessage);

typedef fmi3Instance fmi3InstantiateCoSimulationTYPE(fmi3String instanceName,
                                                     fmi3String instantiationToken,
                                                     fmi3String resourcePath,
                                                     fmi3Boolean visible,
                                                     fmi3Boolean loggingOn,
                                                     fmi3Boolean eventModeUsed,
                                                     fmi3Boolean earlyReturnAllowed,
                                                     const fmi3ValueReference requiredIntermediateVariables[],
                                                     size_t nRequiredIntermediateVariables,
                                                     fmi3InstanceEnvironment instanceEnvironment,
                                                     fmi3LogMessageCallback logMessage,
                                                     fmi3IntermediateUpdateCallback intermediateUpdate);

typedef fmi3Instance fmi3InstantiateScheduledExecutionTYPE(fmi3String instanceName,
                                                           fmi3String instantiationToken,
                                                           fmi3String resourcePath,
                                                           fmi3Boolean visible,
                                                           fmi3Boolean loggingOn,
                                                           fmi3InstanceEnvironment instanceEnvironment,
                                                           fmi3LogMessageCallback logMessage,
                                                           fmi3ClockUpdateCallback clockUpdate,
                                                           fmi3LockPreemptionCallback lockPreemption,
                                                           fmi3UnlockPreemptionCallback unlockPreemption);

typedef void fmi3FreeInstanceTYPE(fmi3Instance instance);

typedef fmi3Status fmi3EnterInitializationModeTYPE(fmi3Instance instance,
                                                   fmi3Boolean toleranceDefined,
                                                   fmi3Float64 tolerance,
                                                   fmi3Float64 startTime,
                                                   fmi3Boolean stopTimeDefined,
                                                   fmi3Float64 stopTime);

typedef fmi3Status fmi3ExitInitializationModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3EnterEventModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3TerminateTYPE(fmi3Instance instance);
typedef fmi3Status fmi3ResetTYPE(fmi3Instance instance);

/* Getters. Arrays are passed flattened (row-major); nValues counts scalar elements. */
typedef fmi3Status fmi3GetFloat32TYPE(fmi3Instance instance,
                                      const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences,
                                      fmi3Float32 values[],
                                      size_t nValues);
typedef fmi3Status fmi3GetFloat64TYPE(fmi3Instance instance,
                                      const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences,
                                      fmi3Float64 values[],
                                      size_t nValues);
typedef fmi3Status fmi3GetInt8TYPE(fmi3Instance instance,
                                   const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences,
                                   fmi3Int8 values[],
                                   size_t nValues);
typedef fmi3Status fmi3GetUInt8TYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    fmi3UInt8 values[],
                                    size_t nValues);
typedef fmi3Status fmi3GetInt16TYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    fmi3Int16 values[],
                                    size_t nValues);
typedef fmi3Status fmi3GetUInt16TYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     fmi3UInt16 values[],
                                     size_t nValues);
typedef fmi3Status fmi3GetInt32TYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    fmi3Int32 values[],
                                    size_t nValues);
typedef fmi3Status fmi3GetUInt32TYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     fmi3UInt32 values[],
                                     size_t nValues);
typedef fmi3Status fmi3GetInt64TYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    fmi3Int64 values[],
                                    size_t nValues);
typedef fmi3Status fmi3GetUInt64TYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     fmi3UInt64 values[],
                                     size_t nValues);
typedef fmi3Status fmi3GetBooleanTYPE(fmi3Instance instance,
                                      const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences,
                                      fmi3Boolean values[],
                                      size_t nValues);
typedef fmi3Status fmi3GetStringTYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     fmi3String values[],
                                     size_t nValues);
typedef fmi3Status fmi3GetBinaryTYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     size_t valueSizes[],
                                     fmi3Binary values[],
                                     size_t nValues);
typedef fmi3Status fmi3GetClockTYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    fmi3Clock values[]);

/* Setters. */
typedef fmi3Status fmi3SetFloat32TYPE(fmi3Instance instance,
                                      const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences,
                                      const fmi3Float32 values[],
                                      size_t nValues);
typedef fmi3Status fmi3SetFloat64TYPE(fmi3Instance instance,
                                      const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences,
                                      const fmi3Float64 values[],
                                      size_t nValues);
typedef fmi3Status fmi3SetInt8TYPE(fmi3Instance instance,
                                   const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences,
                                   const fmi3Int8 values[],
                                   size_t nValues);
typedef fmi3Status fmi3SetUInt8TYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    const fmi3UInt8 values[],
                                    size_t nValues);
typedef fmi3Status fmi3SetInt16TYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    const fmi3Int16 values[],
                                    size_t nValues);
typedef fmi3Status fmi3SetUInt16TYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     const fmi3UInt16 values[],
                                     size_t nValues);
typedef fmi3Status fmi3SetInt32TYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    const fmi3Int32 values[],
                                    size_t nValues);
typedef fmi3Status fmi3SetUInt32TYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     const fmi3UInt32 values[],
                                     size_t nValues);
typedef fmi3Status fmi3SetInt64TYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    const fmi3Int64 values[],
                                    size_t nValues);
typedef fmi3Status fmi3SetUInt64TYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     const fmi3UInt64 values[],
                                     size_t nValues);
typedef fmi3Status fmi3SetBooleanTYPE(fmi3Instance instance,
                                      const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences,
                                      const fmi3Boolean values[],
                                      size_t nValues);
typedef fmi3Status fmi3SetStringTYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     const fmi3String values[],
                                     size_t nValues);
typedef fmi3Status fmi3SetBinaryTYPE(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences,
                                     const size_t valueSizes[],
                                     const fmi3Binary values[],
                                     size_t nValues);
typedef fmi3Status fmi3SetClockTYPE(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences,
                                    const fmi3Clock values[]);

/* Variable dependencies. */
typedef fmi3Status fmi3GetNumberOfVariableDependenciesTYPE(fmi3Instance instance,
                                                           fmi3ValueReference valueReference,
                                                           size_t* nDependencies);
typedef fmi3Status fmi3GetVariableDependenciesTYPE(fmi3Instance instance,
                                                   fmi3ValueReference dependent,
                                                   size_t elementIndicesOfDependent[],
                                                   fmi3ValueReference independents[],
                                                   size_t elementIndicesOfIndependents[],
                                                   fmi3DependencyKind dependencyKinds[],
                                                   size_t nDependencies);

/* FMU state: snapshot, restore, serialization. */
typedef fmi3Status fmi3GetFMUStateTYPE(fmi3Instance instance, fmi3FMUState* FMUState);
typedef fmi3Status fmi3SetFMUStateTYPE(fmi3Instance instance, fmi3FMUState FMUState);
typedef fmi3Status fmi3FreeFMUStateTYPE(fmi3Instance instance, fmi3FMUState* FMUState);
typedef fmi3Status fmi3SerializedFMUStateSizeTYPE(fmi3Instance instance,
                                                  fmi3FMUState FMUState,
                                                  size_t* size);
typedef fmi3Status fmi3SerializeFMUStateTYPE(fmi3Instance instance,
                                             fmi3FMUState FMUState,
                                             fmi3Byte serializedState[],
                                             size_t size);
typedef fmi3Status fmi3DeserializeFMUStateTYPE(fmi3Instance instance,
                                               const fmi3Byte serializedState[],
                                               size_t size,
                                               fmi3FMUState* FMUState);

/* Partial derivatives. */
typedef fmi3Status fmi3GetDirectionalDerivativeTYPE(fmi3Instance instance,
                                                    const fmi3ValueReference unknowns[],
                                                    size_t nUnknowns,
                                                    const fmi3ValueReference knowns[],
                                                    size_t nKnowns,
                                                    const fmi3Float64 seed[],
                                                    size_t nSeed,
                                                    fmi3Float64 sensitivity[],
                                                    size_t nSensitivity);
typedef fmi3Status fmi3GetAdjointDerivativeTYPE(fmi3Instance instance,
                                                const fmi3ValueReference unknowns[],
                                                size_t nUnknowns,
                                                const fmi3ValueReference knowns[],
                                                size_t nKnowns,
                                                const fmi3Float64 seed[],
                                                size_t nSeed,
                                                fmi3Float64 sensitivity[],
                                                size_t nSensitivity);

/* Configuration mode (structural parameters). */
typedef fmi3Status fmi3EnterConfigurationModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3ExitConfigurationModeTYPE(fmi3Instance instance);

/* Clocks: intervals and shifts. */
typedef fmi3Status fmi3GetIntervalDecimalTYPE(fmi3Instance instance,
                                              const fmi3ValueReference valueReferences[],
                                              size_t nValueReferences,
                                              fmi3Float64 intervals[],
                                              fmi3IntervalQualifier qualifiers[]);
typedef fmi3Status fmi3GetIntervalFractionTYPE(fmi3Instance instance,
                                               const fmi3ValueReference valueReferences[],
                                               size_t nValueReferences,
                                               fmi3UInt64 counters[],
                                               fmi3UInt64 resolutions[],
                                               fmi3IntervalQualifier qualifiers[]);
typedef fmi3Status fmi3GetShiftDecimalTYPE(fmi3Instance instance,
                                           const fmi3ValueReference valueReferences[],
                                           size_t nValueReferences,
                                           fmi3Float64 shifts[]);
typedef fmi3Status fmi3GetShiftFractionTYPE(fmi3Instance instance,
                                            const fmi3ValueReference valueReferences[],
                                            size_t nValueReferences,
                                            fmi3UInt64 counters[],
                                            fmi3UInt64 resolutions[]);
typedef fmi3Status fmi3SetIntervalDecimalTYPE(fmi3Instance instance,
                                              const fmi3ValueReference valueReferences[],
                                              size_t nValueReferences,
                                              const fmi3Float64 intervals[]);
typedef fmi3Status fmi3SetIntervalFractionTYPE(fmi3Instance instance,
                                               const fmi3ValueReference valueReferences[],
                                               size_t nValueReferences,
                                               const fmi3UInt64 counters[],
                                               const fmi3UInt64 resolutions[]);
typedef fmi3Status fmi3SetShiftDecimalTYPE(fmi3Instance instance,
                                           const fmi3ValueReference valueReferences[],
                                           size_t nValueReferences,
                                           const fmi3Float64 shifts[]);
typedef fmi3Status fmi3SetShiftFractionTYPE(fmi3Instance instance,
                                            const fmi3ValueReference valueReferences[],
                                            size_t nValueReferences,
                                            const fmi3UInt64 counters[],
                                            const fmi3UInt64 resolutions[]);

/* Discrete states and events. */
typedef fmi3Status fmi3EvaluateDiscreteStatesTYPE(fmi3Instance instance);
typedef fmi3Status fmi3UpdateDiscreteStatesTYPE(fmi3Instance instance,
                                                fmi3Boolean* discreteStatesNeedUpdate,
                                                fmi3Boolean* terminateSimulation,
                                                fmi3Boolean* nominalsOfContinuousStatesChanged,
                                                fmi3Boolean* valuesOfContinuousStatesChanged,
                                                fmi3Boolean* nextEventTimeDefined,
                                                fmi3Float64* nextEventTime);

/* Model Exchange. */
typedef fmi3Status fmi3EnterContinuousTimeModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3CompletedIntegratorStepTYPE(fmi3Instance instance,
                                                   fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                                   fmi3Boolean* enterEventMode,
                                                   fmi3Boolean* terminateSimulation);
typedef fmi3Status fmi3SetTimeTYPE(fmi3Instance instance, fmi3Float64 time);
typedef fmi3Status fmi3SetContinuousStatesTYPE(fmi3Instance instance,
                                               const fmi3Float64 continuousStates[],
                                               size_t nContinuousStates);
typedef fmi3Status fmi3GetContinuousStateDerivativesTYPE(fmi3Instance instance,
                                                         fmi3Float64 derivatives[],
                                                         size_t nContinuousStates);
typedef fmi3Status fmi3GetEventIndicatorsTYPE(fmi3Instance instance,
                                              fmi3Float64 eventIndicators[],
                                              size_t nEventIndicators);
typedef fmi3Status fmi3GetContinuousStatesTYPE(fmi3Instance instance,
                                               fmi3Float64 continuousStates[],
                                               size_t nContinuousStates);
typedef fmi3Status fmi3GetNominalsOfContinuousStatesTYPE(fmi3Instance instance,
                                                         fmi3Float64 nominals[],
                                                         size_t nContinuousStates);
typedef fmi3Status fmi3GetNumberOfEventIndicatorsTYPE(fmi3Instance instance,
                                                      size_t* nEventIndicators);
typedef fmi3Status fmi3GetNumberOfContinuousStatesTYPE(fmi3Instance instance,
                                                       size_t* nContinuousStates);

/* Co-Simulation. */
typedef fmi3Status fmi3EnterStepModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3GetOutputDerivativesTYPE(fmi3Instance instance,
                                                const fmi3ValueReference valueReferences[],
                                                size_t nValueReferences,
                                                const fmi3Int32 orders[],
                                                fmi3Float64 values[],
                                                size_t nValues);
typedef fmi3Status fmi3DoStepTYPE(fmi3Instance instance,
                                  fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize,
                                  fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean* eventHandlingNeeded,
                                  fmi3Boolean* terminateSimulation,
                                  fmi3Boolean* earlyReturn,
                                  fmi3Float64* lastSuccessfulTime);

/* Scheduled Execution. */
typedef fmi3Status fmi3ActivateModelPartitionTYPE(fmi3Instance instance,
                                                  fmi3ValueReference clockReference,
                                                  fmi3Float64 activationTime);

/* ---------------------------------------------------------------------------------------------
 * Prototypes of the functions an FMU exports (fmi3Functions.h without a name prefix).
 * ------------------------------------------------------------------------------------------- */

FMI3_EXPORT fmi3GetVersionTYPE fmi3GetVersion;
FMI3_EXPORT fmi3SetDebugLoggingTYPE fmi3SetDebugLogging;
FMI3_EXPORT fmi3InstantiateModelExchangeTYPE fmi3InstantiateModelExchange;
FMI3_EXPORT fmi3InstantiateCoSimulationTYPE fmi3InstantiateCoSimulation;
FMI3_EXPORT fmi3InstantiateScheduledExecutionTYPE fmi3InstantiateScheduledExecution;
FMI3_EXPORT fmi3FreeInstanceTYPE fmi3FreeInstance;
FMI3_EXPORT fmi3EnterInitializationModeTYPE fmi3EnterInitializationMode;
FMI3_EXPORT fmi3ExitInitializationModeTYPE fmi3ExitInitializationMode;
FMI3_EXPORT fmi3EnterEventModeTYPE fmi3EnterEventMode;
FMI3_EXPORT fmi3TerminateTYPE fmi3Terminate;
FMI3_EXPORT fmi3ResetTYPE fmi3Reset;

FMI3_EXPORT fmi3GetFloat32TYPE fmi3GetFloat32;
FMI3_EXPORT fmi3GetFloat64TYPE fmi3GetFloat64;
FMI3_EXPORT fmi3GetInt8TYPE fmi3GetInt8;
FMI3_EXPORT fmi3GetUInt8TYPE fmi3GetUInt8;
FMI3_EXPORT fmi3GetInt16TYPE fmi3GetInt16;
FMI3_EXPORT fmi3GetUInt16TYPE fmi3GetUInt16;
FMI3_EXPORT fmi3GetInt32TYPE fmi3GetInt32;
FMI3_EXPORT fmi3GetUInt32TYPE fmi3GetUInt32;
FMI3_EXPORT fmi3GetInt64TYPE fmi3GetInt64;
FMI3_EXPORT fmi3GetUInt64TYPE fmi3GetUInt64;
FMI3_EXPORT fmi3GetBooleanTYPE fmi3GetBoolean;
FMI3_EXPORT fmi3GetStringTYPE fmi3GetString;
FMI3_EXPORT fmi3GetBinaryTYPE fmi3GetBinary;
FMI3_EXPORT fmi3GetClockTYPE fmi3GetClock;

FMI3_EXPORT fmi3SetFloat32TYPE fmi3SetFloat32;
FMI3_EXPORT fmi3SetFloat64TYPE fmi3SetFloat64;
FMI3_EXPORT fmi3SetInt8TYPE fmi3SetInt8;
FMI3_EXPORT fmi3SetUInt8TYPE fmi3SetUInt8;
FMI3_EXPORT fmi3SetInt16TYPE fmi3SetInt16;
FMI3_EXPORT fmi3SetUInt16TYPE fmi3SetUInt16;
FMI3_EXPORT fmi3SetInt32TYPE fmi3SetInt32;
FMI3_EXPORT fmi3SetUInt32TYPE fmi3SetUInt32;
FMI3_EXPORT fmi3SetInt64TYPE fmi3SetInt64;
FMI3_EXPORT fmi3SetUInt64TYPE fmi3SetUInt64;
FMI3_EXPORT fmi3SetBooleanTYPE fmi3SetBoolean;
FMI3_EXPORT fmi3SetStringTYPE fmi3SetString;
FMI3_EXPORT fmi3SetBinaryTYPE fmi3SetBinary;
FMI3_EXPORT fmi3SetClockTYPE fmi3SetClock;

FMI3_EXPORT fmi3GetNumberOfVariableDependenciesTYPE fmi3GetNumberOfVariableDependencies;
FMI3_EXPORT fmi3GetVariableDependenciesTYPE fmi3GetVariableDependencies;

FMI3_EXPORT fmi3GetFMUStateTYPE fmi3GetFMUState;
FMI3_EXPORT fmi3SetFMUStateTYPE fmi3SetFMUState;
FMI3_EXPORT fmi3FreeFMUStateTYPE fmi3FreeFMUState;
FMI3_EXPORT fmi3SerializedFMUStateSizeTYPE fmi3SerializedFMUStateSize;
FMI3_EXPORT fmi3SerializeFMUStateTYPE fmi3SerializeFMUState;
FMI3_EXPORT fmi3DeserializeFMUStateTYPE fmi3DeserializeFMUState;

FMI3_EXPORT fmi3GetDirectionalDerivativeTYPE fmi3GetDirectionalDerivative;
FMI3_EXPORT fmi3GetAdjointDerivativeTYPE fmi3GetAdjointDerivative;

FMI3_EXPORT fmi3EnterConfigurationModeTYPE fmi3EnterConfigurationMode;
FMI3_EXPORT fmi3ExitConfigurationModeTYPE fmi3ExitConfigurationMode;

FMI3_EXPORT fmi3GetIntervalDecimalTYPE fmi3GetIntervalDecimal;
FMI3_EXPORT fmi3GetIntervalFractionTYPE fmi3GetIntervalFraction;
FMI3_EXPORT fmi3GetShiftDecimalTYPE fmi3GetShiftDecimal;
FMI3_EXPORT fmi3GetShiftFractionTYPE fmi3GetShiftFraction;
FMI3_EXPORT fmi3SetIntervalDecimalTYPE fmi3SetIntervalDecimal;
FMI3_EXPORT fmi3SetIntervalFractionTYPE fmi3SetIntervalFraction;
FMI3_EXPORT fmi3SetShiftDecimalTYPE fmi3SetShiftDecimal;
FMI3_EXPORT fmi3SetShiftFractionTYPE fmi3SetShiftFraction;

FMI3_EXPORT fmi3EvaluateDiscreteStatesTYPE fmi3EvaluateDiscreteStates;
FMI3_EXPORT fmi3UpdateDiscreteStatesTYPE fmi3UpdateDiscreteStates;

FMI3_EXPORT fmi3EnterContinuousTimeModeTYPE fmi3EnterContinuousTimeMode;
FMI3_EXPORT fmi3CompletedIntegratorStepTYPE fmi3CompletedIntegratorStep;
FMI3_EXPORT fmi3SetTimeTYPE fmi3SetTime;
FMI3_EXPORT fmi3SetContinuousStatesTYPE fmi3SetContinuousStates;
FMI3_EXPORT fmi3GetContinuousStateDerivativesTYPE fmi3GetContinuousStateDerivatives;
FMI3_EXPORT fmi3GetEventIndicatorsTYPE fmi3GetEventIndicators;
FMI3_EXPORT fmi3GetContinuousStatesTYPE fmi3GetContinuousStates;
FMI3_EXPORT fmi3GetNominalsOfContinuousStatesTYPE fmi3GetNominalsOfContinuousStates;
FMI3_EXPORT fmi3GetNumberOfEventIndicatorsTYPE fmi3GetNumberOfEventIndicators;
FMI3_EXPORT fmi3GetNumberOfContinuousStatesTYPE fmi3GetNumberOfContinuousStates;

FMI3_EXPORT fmi3EnterStepModeTYPE fmi3EnterStepMode;
FMI3_EXPORT fmi3GetOutputDerivativesTYPE fmi3GetOutputDerivatives;
FMI3_EXPORT fmi3DoStepTYPE fmi3DoStep;

FMI3_EXPORT fmi3ActivateModelPartitionTYPE fmi3ActivateModelPartition;

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* TISSUE_FMI3_ABI_H */
