/*
 * partial_fmi3_binary.c - a shared library that exports only fmi3GetVersion and fmi3DoStep.
 * Not an FMU: the host tests load it to check that Fmu3Library refuses a binary lacking FMI
 * functions and lists every missing name. Built with -fvisibility=hidden, so it also checks
 * that the FMI3_EXPORT prototypes of fmi3_abi.h export the functions defined.
 */
#include "fmi3_abi.h"

/** A non-FMI helper: stays local to the library. */
static fmi3Status helper(void) { return fmi3OK; }

const char* fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation, fmi3Boolean* earlyReturn,
                      fmi3Float64* lastSuccessfulTime) {
    (void)instance;
    (void)currentCommunicationPoint;
    (void)communicationStepSize;
    (void)noSetFMUStatePriorToCurrentPoint;
    (void)eventHandlingNeeded;
    (void)terminateSimulation;
    (void)earlyReturn;
    (void)lastSuccessfulTime;
    return helper() == fmi3OK ? fmi3Error : fmi3Fatal;
}
