/*
 * abi_compiles.c - proves that fmi3_abi.h is valid C (C11, -Wall -Wextra -Wpedantic) and that it
 * declares every FMI 3.0 function type: one pointer of each *TYPE. Linked into the host tests,
 * which compare the count with FMI3_FUNCTION_NAMES.
 */
#include "fmi3_abi.h"

_Static_assert(sizeof(fmi3ValueReference) == 4, "fmi3ValueReference is a 32-bit unsigned integer");
_Static_assert(sizeof(fmi3Float64) == 8, "fmi3Float64 is an IEEE double");
_Static_assert(sizeof(fmi3Int64) == 8 && sizeof(fmi3UInt64) == 8, "64-bit integers");
_Static_assert(sizeof(fmi3Byte) == 1, "fmi3Byte is a byte");
_Static_assert(fmi3OK == 0 && fmi3Warning == 1 && fmi3Discard == 2 && fmi3Error == 3 && fmi3Fatal == 4,
               "fmi3Status values are fixed by the standard");
_Static_assert(fmi3ModelExchange == 0 && fmi3CoSimulation == 1 && fmi3ScheduledExecution == 2, "fmi3Type values");
_Static_assert(fmi3Independent == 0 && fmi3Dependent == 5, "fmi3DependencyKind values");
_Static_assert(fmi3IntervalNotYetKnown == 0 && fmi3IntervalChanged == 2, "fmi3IntervalQualifier values");

/* Callback types; assigning NULL only checks that they are pointer types. */
static fmi3LogMessageCallback log_message_callback = NULL;
static fmi3ClockUpdateCallback clock_update_callback = NULL;
static fmi3IntermediateUpdateCallback intermediate_update_callback = NULL;
static fmi3LockPreemptionCallback lock_preemption_callback = NULL;
static fmi3UnlockPreemptionCallback unlock_preemption_callback = NULL;

/* One pointer per function type (the prototypes themselves are declared with these types). */
static fmi3GetVersionTYPE* fmi3GetVersion_pointer = NULL;
static fmi3SetDebugLoggingTYPE* fmi3SetDebugLogging_pointer = NULL;
static fmi3InstantiateModelExchangeTYPE* fmi3InstantiateModelExchange_pointer = NULL;
static fmi3InstantiateCoSimulationTYPE* fmi3InstantiateCoSimulation_pointer = NULL;
static fmi3InstantiateScheduledExecutionTYPE* fmi3InstantiateScheduledExecution_pointer = NULL;
static fmi3FreeInstanceTYPE* fmi3FreeInstance_pointer = NULL;
static fmi3EnterInitializationModeTYPE* fmi3EnterInitializationMode_pointer = NULL;
static fmi3ExitInitializationModeTYPE* fmi3ExitInitializationMode_pointer = NULL;
static fmi3EnterEventModeTYPE* fmi3EnterEventMode_pointer = NULL;
static fmi3TerminateTYPE* fmi3Terminate_pointer = NULL;
static fmi3ResetTYPE* fmi3Reset_pointer = NULL;
static fmi3GetFloat32TYPE* fmi3GetFloat32_pointer = NULL;
static fmi3GetFloat64TYPE* fmi3GetFloat64_pointer = NULL;
static fmi3GetInt8TYPE* fmi3GetInt8_pointer = NULL;
static fmi3GetUInt8TYPE* fmi3GetUInt8_pointer = NULL;
static fmi3GetInt16TYPE* fmi3GetInt16_pointer = NULL;
static fmi3GetUInt16TYPE* fmi3GetUInt16_pointer = NULL;
static fmi3GetInt32TYPE* fmi3GetInt32_pointer = NULL;
static fmi3GetUInt32TYPE* fmi3GetUInt32_pointer = NULL;
static fmi3GetInt64TYPE* fmi3GetInt64_pointer = NULL;
static fmi3GetUInt64TYPE* fmi3GetUInt64_pointer = NULL;
static fmi3GetBooleanTYPE* fmi3GetBoolean_pointer = NULL;
static fmi3GetStringTYPE* fmi3GetString_pointer = NULL;
static fmi3GetBinaryTYPE* fmi3GetBinary_pointer = NULL;
static fmi3GetClockTYPE* fmi3GetClock_pointer = NULL;
static fmi3SetFloat32TYPE* fmi3SetFloat32_pointer = NULL;
static fmi3SetFloat64TYPE* fmi3SetFloat64_pointer = NULL;
static fmi3SetInt8TYPE* fmi3SetInt8_pointer = NULL;
static fmi3SetUInt8TYPE* fmi3SetUInt8_pointer = NULL;
static fmi3SetInt16TYPE* fmi3SetInt16_pointer = NULL;
static fmi3SetUInt16TYPE* fmi3SetUInt16_pointer = NULL;
static fmi3SetInt32TYPE* fmi3SetInt32_pointer = NULL;
static fmi3SetUInt32TYPE* fmi3SetUInt32_pointer = NULL;
static fmi3SetInt64TYPE* fmi3SetInt64_pointer = NULL;
static fmi3SetUInt64TYPE* fmi3SetUInt64_pointer = NULL;
static fmi3SetBooleanTYPE* fmi3SetBoolean_pointer = NULL;
static fmi3SetStringTYPE* fmi3SetString_pointer = NULL;
static fmi3SetBinaryTYPE* fmi3SetBinary_pointer = NULL;
static fmi3SetClockTYPE* fmi3SetClock_pointer = NULL;
static fmi3GetNumberOfVariableDependenciesTYPE* fmi3GetNumberOfVariableDependencies_pointer = NULL;
static fmi3GetVariableDependenciesTYPE* fmi3GetVariableDependencies_pointer = NULL;
static fmi3GetFMUStateTYPE* fmi3GetFMUState_pointer = NULL;
static fmi3SetFMUStateTYPE* fmi3SetFMUState_pointer = NULL;
static fmi3FreeFMUStateTYPE* fmi3FreeFMUState_pointer = NULL;
static fmi3SerializedFMUStateSizeTYPE* fmi3SerializedFMUStateSize_pointer = NULL;
static fmi3SerializeFMUStateTYPE* fmi3SerializeFMUState_pointer = NULL;
static fmi3DeserializeFMUStateTYPE* fmi3DeserializeFMUState_pointer = NULL;
static fmi3GetDirectionalDerivativeTYPE* fmi3GetDirectionalDerivative_pointer = NULL;
static fmi3GetAdjointDerivativeTYPE* fmi3GetAdjointDerivative_pointer = NULL;
static fmi3EnterConfigurationModeTYPE* fmi3EnterConfigurationMode_pointer = NULL;
static fmi3ExitConfigurationModeTYPE* fmi3ExitConfigurationMode_pointer = NULL;
static fmi3GetIntervalDecimalTYPE* fmi3GetIntervalDecimal_pointer = NULL;
static fmi3GetIntervalFractionTYPE* fmi3GetIntervalFraction_pointer = NULL;
static fmi3GetShiftDecimalTYPE* fmi3GetShiftDecimal_pointer = NULL;
static fmi3GetShiftFractionTYPE* fmi3GetShiftFraction_pointer = NULL;
static fmi3SetIntervalDecimalTYPE* fmi3SetIntervalDecimal_pointer = NULL;
static fmi3SetIntervalFractionTYPE* fmi3SetIntervalFraction_pointer = NULL;
static fmi3SetShiftDecimalTYPE* fmi3SetShiftDecimal_pointer = NULL;
static fmi3SetShiftFractionTYPE* fmi3SetShiftFraction_pointer = NULL;
static fmi3EvaluateDiscreteStatesTYPE* fmi3EvaluateDiscreteStates_pointer = NULL;
static fmi3UpdateDiscreteStatesTYPE* fmi3UpdateDiscreteStates_pointer = NULL;
static fmi3EnterContinuousTimeModeTYPE* fmi3EnterContinuousTimeMode_pointer = NULL;
static fmi3CompletedIntegratorStepTYPE* fmi3CompletedIntegratorStep_pointer = NULL;
static fmi3SetTimeTYPE* fmi3SetTime_pointer = NULL;
static fmi3SetContinuousStatesTYPE* fmi3SetContinuousStates_pointer = NULL;
static fmi3GetContinuousStateDerivativesTYPE* fmi3GetContinuousStateDerivatives_pointer = NULL;
static fmi3GetEventIndicatorsTYPE* fmi3GetEventIndicators_pointer = NULL;
static fmi3GetContinuousStatesTYPE* fmi3GetContinuousStates_pointer = NULL;
static fmi3GetNominalsOfContinuousStatesTYPE* fmi3GetNominalsOfContinuousStates_pointer = NULL;
static fmi3GetNumberOfEventIndicatorsTYPE* fmi3GetNumberOfEventIndicators_pointer = NULL;
static fmi3GetNumberOfContinuousStatesTYPE* fmi3GetNumberOfContinuousStates_pointer = NULL;
static fmi3EnterStepModeTYPE* fmi3EnterStepMode_pointer = NULL;
static fmi3GetOutputDerivativesTYPE* fmi3GetOutputDerivatives_pointer = NULL;
static fmi3DoStepTYPE* fmi3DoStep_pointer = NULL;
static fmi3ActivateModelPartitionTYPE* fmi3ActivateModelPartition_pointer = NULL;

/** Number of function types declared above (compared with FMI3_FUNCTION_NAMES by the tests). */
int tissue_host_abi_function_type_count(void);
int tissue_host_abi_function_type_count(void) {
    const void* pointers[] = {
        (const void*)&fmi3GetVersion_pointer,
        (const void*)&fmi3SetDebugLogging_pointer,
        (const void*)&fmi3InstantiateModelExchange_pointer,
        (const void*)&fmi3InstantiateCoSimulation_pointer,
        (const void*)&fmi3InstantiateScheduledExecution_pointer,
        (const void*)&fmi3FreeInstance_pointer,
        (const void*)&fmi3EnterInitializationMode_pointer,
        (const void*)&fmi3ExitInitializationMode_pointer,
        (const void*)&fmi3EnterEventMode_pointer,
        (const void*)&fmi3Terminate_pointer,
        (const void*)&fmi3Reset_pointer,
        (const void*)&fmi3GetFloat32_pointer,
        (const void*)&fmi3GetFloat64_pointer,
        (const void*)&fmi3GetInt8_pointer,
        (const void*)&fmi3GetUInt8_pointer,
        (const void*)&fmi3GetInt16_pointer,
        (const void*)&fmi3GetUInt16_pointer,
        (const void*)&fmi3GetInt32_pointer,
        (const void*)&fmi3GetUInt32_pointer,
        (const void*)&fmi3GetInt64_pointer,
        (const void*)&fmi3GetUInt64_pointer,
        (const void*)&fmi3GetBoolean_pointer,
        (const void*)&fmi3GetString_pointer,
        (const void*)&fmi3GetBinary_pointer,
        (const void*)&fmi3GetClock_pointer,
        (const void*)&fmi3SetFloat32_pointer,
        (const void*)&fmi3SetFloat64_pointer,
        (const void*)&fmi3SetInt8_pointer,
        (const void*)&fmi3SetUInt8_pointer,
        (const void*)&fmi3SetInt16_pointer,
        (const void*)&fmi3SetUInt16_pointer,
        (const void*)&fmi3SetInt32_pointer,
        (const void*)&fmi3SetUInt32_pointer,
        (const void*)&fmi3SetInt64_pointer,
        (const void*)&fmi3SetUInt64_pointer,
        (const void*)&fmi3SetBoolean_pointer,
        (const void*)&fmi3SetString_pointer,
        (const void*)&fmi3SetBinary_pointer,
        (const void*)&fmi3SetClock_pointer,
        (const void*)&fmi3GetNumberOfVariableDependencies_pointer,
        (const void*)&fmi3GetVariableDependencies_pointer,
        (const void*)&fmi3GetFMUState_pointer,
        (const void*)&fmi3SetFMUState_pointer,
        (const void*)&fmi3FreeFMUState_pointer,
        (const void*)&fmi3SerializedFMUStateSize_pointer,
        (const void*)&fmi3SerializeFMUState_pointer,
        (const void*)&fmi3DeserializeFMUState_pointer,
        (const void*)&fmi3GetDirectionalDerivative_pointer,
        (const void*)&fmi3GetAdjointDerivative_pointer,
        (const void*)&fmi3EnterConfigurationMode_pointer,
        (const void*)&fmi3ExitConfigurationMode_pointer,
        (const void*)&fmi3GetIntervalDecimal_pointer,
        (const void*)&fmi3GetIntervalFraction_pointer,
        (const void*)&fmi3GetShiftDecimal_pointer,
        (const void*)&fmi3GetShiftFraction_pointer,
        (const void*)&fmi3SetIntervalDecimal_pointer,
        (const void*)&fmi3SetIntervalFraction_pointer,
        (const void*)&fmi3SetShiftDecimal_pointer,
        (const void*)&fmi3SetShiftFraction_pointer,
        (const void*)&fmi3EvaluateDiscreteStates_pointer,
        (const void*)&fmi3UpdateDiscreteStates_pointer,
        (const void*)&fmi3EnterContinuousTimeMode_pointer,
        (const void*)&fmi3CompletedIntegratorStep_pointer,
        (const void*)&fmi3SetTime_pointer,
        (const void*)&fmi3SetContinuousStates_pointer,
        (const void*)&fmi3GetContinuousStateDerivatives_pointer,
        (const void*)&fmi3GetEventIndicators_pointer,
        (const void*)&fmi3GetContinuousStates_pointer,
        (const void*)&fmi3GetNominalsOfContinuousStates_pointer,
        (const void*)&fmi3GetNumberOfEventIndicators_pointer,
        (const void*)&fmi3GetNumberOfContinuousStates_pointer,
        (const void*)&fmi3EnterStepMode_pointer,
        (const void*)&fmi3GetOutputDerivatives_pointer,
        (const void*)&fmi3DoStep_pointer,
        (const void*)&fmi3ActivateModelPartition_pointer,
        (const void*)&log_message_callback,
        (const void*)&clock_update_callback,
        (const void*)&intermediate_update_callback,
        (const void*)&lock_preemption_callback,
        (const void*)&unlock_preemption_callback,
    };
    return (int)(sizeof(pointers) / sizeof(pointers[0])) - 5; /* minus the five callbacks */
}
