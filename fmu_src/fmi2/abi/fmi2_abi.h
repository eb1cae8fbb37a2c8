/*
 * fmi2_abi.h - the project's own C declaration of the FMI 2.0 Co-Simulation binary interface.
 *
 * Written from the FMI 2.0 specification (sections 2.1.2-2.1.4 and 4.2: the platform types of
 * fmi2TypesPlatform.h, the types and function types of fmi2FunctionTypes.h, the prototypes of
 * fmi2Functions.h), for the functions a Co-Simulation FMU exports. Names, parameter order and
 * types must match the standard exactly: they are the binary contract with every FMI 2.0 tool.
 * The Model Exchange functions are not declared (the FMUs offer Co-Simulation only).
 *
 * Plain C99, usable from C and C++.
 */
#ifndef TISSUE_FMI2_ABI_H
#define TISSUE_FMI2_ABI_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Returned by fmi2GetVersion() and written as fmiVersion in modelDescription.xml. */
#define fmi2Version "2.0"
/** Returned by fmi2GetTypesPlatform(): the standard's default platform types below. */
#define fmi2TypesPlatform "default"

#if defined(__GNUC__) || defined(__clang__)
#define FMI2_EXPORT __attribute__((visibility("default")))
#else
#define FMI2_EXPORT
#endif

/* Platform types ("default"). */
typedef void* fmi2Component;
typedef void* fmi2ComponentEnvironment;
typedef void* fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char* fmi2String;
typedef char fmi2Byte;

#define fmi2True 1
#define fmi2False 0

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

/* Callbacks the importer passes to fmi2Instantiate. The logger is printf-like. */
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String instanceName, fmi2Status status,
                                   fmi2String category, fmi2String message, ...);
typedef void* (*fmi2CallbackAllocateMemory)(size_t nobj, size_t size);
typedef void (*fmi2CallbackFreeMemory)(void* obj);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);

typedef struct {
  const fmi2CallbackLogger logger;
  const fmi2CallbackAllocateMemory allocateMemory;
  const fmi2CallbackFreeMemory freeMemory;
  const fmi2StepFinished stepFinished;
  const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

/* Function types, for importers that dlsym() the functions. */
typedef const char* fmi2GetTypesPlatformTYPE(void);
typedef const char* fmi2GetVersionTYPE(void);
typedef fmi2Status fmi2SetDebugLoggingTYPE(fmi2Component, fmi2Boolean, size_t, const fmi2String[]);
typedef fmi2Component fmi2InstantiateTYPE(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions*,
                                          fmi2Boolean, fmi2Boolean);
typedef void fmi2FreeInstanceTYPE(fmi2Component);
typedef fmi2Status fmi2SetupExperimentTYPE(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status fmi2EnterInitializationModeTYPE(fmi2Component);
typedef fmi2Status fmi2ExitInitializationModeTYPE(fmi2Component);
typedef fmi2Status fmi2TerminateTYPE(fmi2Component);
typedef fmi2Status fmi2ResetTYPE(fmi2Component);
typedef fmi2Status fmi2GetRealTYPE(fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]);
typedef fmi2Status fmi2GetIntegerTYPE(fmi2Component, const fmi2ValueReference[], size_t, fmi2Integer[]);
typedef fmi2Status fmi2GetBooleanTYPE(fmi2Component, const fmi2ValueReference[], size_t, fmi2Boolean[]);
typedef fmi2Status fmi2GetStringTYPE(fmi2Component, const fmi2ValueReference[], size_t, fmi2String[]);
typedef fmi2Status fmi2SetRealTYPE(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Real[]);
typedef fmi2Status fmi2SetIntegerTYPE(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Integer[]);
typedef fmi2Status fmi2SetBooleanTYPE(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Boolean[]);
typedef fmi2Status fmi2SetStringTYPE(fmi2Component, const fmi2ValueReference[], size_t, const fmi2String[]);
typedef fmi2Status fmi2GetFMUstateTYPE(fmi2Component, fmi2FMUstate*);
typedef fmi2Status fmi2SetFMUstateTYPE(fmi2Component, fmi2FMUstate);
typedef fmi2Status fmi2FreeFMUstateTYPE(fmi2Component, fmi2FMUstate*);
typedef fmi2Status fmi2SerializedFMUstateSizeTYPE(fmi2Component, fmi2FMUstate, size_t*);
typedef fmi2Status fmi2SerializeFMUstateTYPE(fmi2Component, fmi2FMUstate, fmi2Byte[], size_t);
typedef fmi2Status fmi2DeSerializeFMUstateTYPE(fmi2Component, const fmi2Byte[], size_t, fmi2FMUstate*);
typedef fmi2Status fmi2GetDirectionalDerivativeTYPE(fmi2Component, const fmi2ValueReference[], size_t,
                                                    const fmi2ValueReference[], size_t, const fmi2Real[], fmi2Real[]);
typedef fmi2Status fmi2SetRealInputDerivativesTYPE(fmi2Component, const fmi2ValueReference[], size_t,
                                                   const fmi2Integer[], const fmi2Real[]);
typedef fmi2Status fmi2GetRealOutputDerivativesTYPE(fmi2Component, const fmi2ValueReference[], size_t,
                                                    const fmi2Integer[], fmi2Real[]);
typedef fmi2Status fmi2DoStepTYPE(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef fmi2Status fmi2CancelStepTYPE(fmi2Component);
typedef fmi2Status fmi2GetStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2Status*);
typedef fmi2Status fmi2GetRealStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2Real*);
typedef fmi2Status fmi2GetIntegerStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2Integer*);
typedef fmi2Status fmi2GetBooleanStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2Boolean*);
typedef fmi2Status fmi2GetStringStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2String*);

/* The functions a Co-Simulation FMU exports (25 common, 9 Co-Simulation). */
FMI2_EXPORT fmi2GetTypesPlatformTYPE fmi2GetTypesPlatform;
FMI2_EXPORT fmi2GetVersionTYPE fmi2GetVersion;
FMI2_EXPORT fmi2SetDebugLoggingTYPE fmi2SetDebugLogging;
FMI2_EXPORT fmi2InstantiateTYPE fmi2Instantiate;
FMI2_EXPORT fmi2FreeInstanceTYPE fmi2FreeInstance;
FMI2_EXPORT fmi2SetupExperimentTYPE fmi2SetupExperiment;
FMI2_EXPORT fmi2EnterInitializationModeTYPE fmi2EnterInitializationMode;
FMI2_EXPORT fmi2ExitInitializationModeTYPE fmi2ExitInitializationMode;
FMI2_EXPORT fmi2TerminateTYPE fmi2Terminate;
FMI2_EXPORT fmi2ResetTYPE fmi2Reset;
FMI2_EXPORT fmi2GetRealTYPE fmi2GetReal;
FMI2_EXPORT fmi2GetIntegerTYPE fmi2GetInteger;
FMI2_EXPORT fmi2GetBooleanTYPE fmi2GetBoolean;
FMI2_EXPORT fmi2GetStringTYPE fmi2GetString;
FMI2_EXPORT fmi2SetRealTYPE fmi2SetReal;
FMI2_EXPORT fmi2SetIntegerTYPE fmi2SetInteger;
FMI2_EXPORT fmi2SetBooleanTYPE fmi2SetBoolean;
FMI2_EXPORT fmi2SetStringTYPE fmi2SetString;
FMI2_EXPORT fmi2GetFMUstateTYPE fmi2GetFMUstate;
FMI2_EXPORT fmi2SetFMUstateTYPE fmi2SetFMUstate;
FMI2_EXPORT fmi2FreeFMUstateTYPE fmi2FreeFMUstate;
FMI2_EXPORT fmi2SerializedFMUstateSizeTYPE fmi2SerializedFMUstateSize;
FMI2_EXPORT fmi2SerializeFMUstateTYPE fmi2SerializeFMUstate;
FMI2_EXPORT fmi2DeSerializeFMUstateTYPE fmi2DeSerializeFMUstate;
FMI2_EXPORT fmi2GetDirectionalDerivativeTYPE fmi2GetDirectionalDerivative;
FMI2_EXPORT fmi2SetRealInputDerivativesTYPE fmi2SetRealInputDerivatives;
FMI2_EXPORT fmi2GetRealOutputDerivativesTYPE fmi2GetRealOutputDerivatives;
FMI2_EXPORT fmi2DoStepTYPE fmi2DoStep;
FMI2_EXPORT fmi2CancelStepTYPE fmi2CancelStep;
FMI2_EXPORT fmi2GetStatusTYPE fmi2GetStatus;
FMI2_EXPORT fmi2GetRealStatusTYPE fmi2GetRealStatus;
FMI2_EXPORT fmi2GetIntegerStatusTYPE fmi2GetIntegerStatus;
FMI2_EXPORT fmi2GetBooleanStatusTYPE fmi2GetBooleanStatus;
FMI2_EXPORT fmi2GetStringStatusTYPE fmi2GetStringStatus;

#ifdef __cplusplus
}
#endif

#endif /* TISSUE_FMI2_ABI_H */
