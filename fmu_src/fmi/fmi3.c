/*
 * fmi3.c -- FMI 3.0 co-simulation interface of the friction element.
 *
 * A thin mapping of the fmi3* functions onto fmu_instance.c. All 75 fmi3 functions
 * are defined (importers such as fmpy resolve every one of them); Model Exchange,
 * Scheduled Execution, clocks, event mode and non-Float64 types are not supported
 * and return fmi3Error with a logged message.
 */
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "fmu_instance.h"

typedef struct {
    fmi3LogMessageCallback logger;
    fmi3InstanceEnvironment env;
    fmu_instance *inst;
} fmu3;

static const fmi3Status status3[] = {fmi3OK, fmi3Warning, fmi3Error};

static void log_fmi3(void *ctx, fmu_status status, const char *category, const char *message)
{
    fmu3 *w = (fmu3 *)ctx;
    if (w->logger) w->logger(w->env, status3[status], category, message);
}

#define WRAPPER(i) fmu3 *w = (fmu3 *)(i); if (!w || !w->inst) return fmi3Error
#define RET(expr) return status3[(expr)]
#define UNSUPPORTED(what) \
    WRAPPER(instance);    \
    RET(fmu_log(w->inst, FMU_ERROR, "%s is not supported by this co-simulation FMU", what))

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn,
                               size_t nCategories, const fmi3String categories[])
{
    size_t i;
    int k, known;
    WRAPPER(instance);
    (void)loggingOn;  /* errors are always logged; there are no debug messages */
    for (i = 0; i < nCategories; i++) {
        for (known = 0, k = 0; k < DAMPER_N_LOG_CATEGORIES; k++)
            known |= categories && categories[i] && !strcmp(categories[i], damper_log_categories[k]);
        if (!known) RET(fmu_log(w->inst, FMU_ERROR, "unknown log category"));
    }
    return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible;
    (void)loggingOn;
    if (logMessage)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   "this FMU supports co-simulation only");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
    fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate)
{
    fmu3 *w = (fmu3 *)calloc(1, sizeof(fmu3));
    (void)visible; (void)loggingOn; (void)eventModeUsed; (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    if (!w) return NULL;
    w->logger = logMessage;
    w->env = instanceEnvironment;
    w->inst = fmu_new(instanceName, instantiationToken, resourcePath, log_fmi3, w);
    if (!w->inst) {
        free(w);
        return NULL;
    }
    return w;
}

fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
    fmi3LockPreemptionCallback lockPreemption, fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible;
    (void)loggingOn; (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   "this FMU supports co-simulation only");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance)
{
    fmu3 *w = (fmu3 *)instance;
    if (!w) return;
    fmu_free(w->inst);
    free(w);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    WRAPPER(instance);
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    RET(fmu_enter_init(w->inst, startTime));
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    WRAPPER(instance);
    RET(fmu_exit_init(w->inst));  /* no event mode: straight into step mode */
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) { UNSUPPORTED("fmi3EnterEventMode"); }

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    WRAPPER(instance);
    RET(fmu_terminate(w->inst));
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    WRAPPER(instance);
    fmu_reset(w->inst);
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Float64 values[], size_t nValues)
{
    WRAPPER(instance);
    if (nValues != nValueReferences)
        RET(fmu_log(w->inst, FMU_ERROR, "fmi3GetFloat64: nValues != nValueReferences "
                    "(all variables are scalars)"));
    RET(fmu_get(w->inst, valueReferences, nValueReferences, values));
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Float64 values[], size_t nValues)
{
    WRAPPER(instance);
    if (nValues != nValueReferences)
        RET(fmu_log(w->inst, FMU_ERROR, "fmi3SetFloat64: nValues != nValueReferences "
                    "(all variables are scalars)"));
    RET(fmu_set(w->inst, valueReferences, nValueReferences, values));
}

/* Every other type: the FMU has no such variables, so only empty calls succeed. */
#define NO_VARIABLES(fn, qualifier, T)                                                     \
    fmi3Status fn(fmi3Instance instance, const fmi3ValueReference valueReferences[],        \
                  size_t nValueReferences, qualifier T values[], size_t nValues)           \
    {                                                                                      \
        WRAPPER(instance);                                                                 \
        (void)valueReferences; (void)values; (void)nValues;                                \
        if (nValueReferences == 0) return fmi3OK;                                          \
        RET(fmu_log(w->inst, FMU_ERROR, #fn ": this FMU has only Float64 variables"));     \
    }
#define NOTHING

NO_VARIABLES(fmi3GetFloat32, NOTHING, fmi3Float32)
NO_VARIABLES(fmi3GetInt8, NOTHING, fmi3Int8)
NO_VARIABLES(fmi3GetUInt8, NOTHING, fmi3UInt8)
NO_VARIABLES(fmi3GetInt16, NOTHING, fmi3Int16)
NO_VARIABLES(fmi3GetUInt16, NOTHING, fmi3UInt16)
NO_VARIABLES(fmi3GetInt32, NOTHING, fmi3Int32)
NO_VARIABLES(fmi3GetUInt32, NOTHING, fmi3UInt32)
NO_VARIABLES(fmi3GetInt64, NOTHING, fmi3Int64)
NO_VARIABLES(fmi3GetUInt64, NOTHING, fmi3UInt64)
NO_VARIABLES(fmi3GetBoolean, NOTHING, fmi3Boolean)
NO_VARIABLES(fmi3GetString, NOTHING, fmi3String)
NO_VARIABLES(fmi3SetFloat32, const, fmi3Float32)
NO_VARIABLES(fmi3SetInt8, const, fmi3Int8)
NO_VARIABLES(fmi3SetUInt8, const, fmi3UInt8)
NO_VARIABLES(fmi3SetInt16, const, fmi3Int16)
NO_VARIABLES(fmi3SetUInt16, const, fmi3UInt16)
NO_VARIABLES(fmi3SetInt32, const, fmi3Int32)
NO_VARIABLES(fmi3SetUInt32, const, fmi3UInt32)
NO_VARIABLES(fmi3SetInt64, const, fmi3Int64)
NO_VARIABLES(fmi3SetUInt64, const, fmi3UInt64)
NO_VARIABLES(fmi3SetBoolean, const, fmi3Boolean)
NO_VARIABLES(fmi3SetString, const, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, size_t valueSizes[], fmi3Binary values[],
                         size_t nValues)
{
    (void)valueReferences; (void)nValueReferences; (void)valueSizes; (void)values; (void)nValues;
    UNSUPPORTED("fmi3GetBinary");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues)
{
    (void)valueReferences; (void)nValueReferences; (void)valueSizes; (void)values; (void)nValues;
    UNSUPPORTED("fmi3SetBinary");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Clock values[])
{
    (void)valueReferences; (void)nValueReferences; (void)values;
    UNSUPPORTED("fmi3GetClock");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Clock values[])
{
    (void)valueReferences; (void)nValueReferences; (void)values;
    UNSUPPORTED("fmi3SetClock");
}

/* With direct feedthrough every output depends on every input, without it on none
 * (as in ModelStructure). */
fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance,
                                               fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    WRAPPER(instance);
    if (valueReference >= DAMPER_N_VARIABLES || !nDependencies)
        RET(fmu_log(w->inst, FMU_ERROR, "unknown value reference %u", valueReference));
    *nDependencies = damper_causality_of[valueReference] == CAUS_OUTPUT && DAMPER_FEEDTHROUGH
                     ? DAMPER_N_INPUTS : 0;
    return fmi3OK;
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    const size_t n = DAMPER_FEEDTHROUGH ? DAMPER_N_INPUTS : 0;
    size_t i;
    WRAPPER(instance);
    if (dependent >= DAMPER_N_VARIABLES || damper_causality_of[dependent] != CAUS_OUTPUT
        || nDependencies != n || (n && (!elementIndicesOfDependent || !independents
        || !elementIndicesOfIndependents || !dependencyKinds)))
        RET(fmu_log(w->inst, FMU_ERROR, "fmi3GetVariableDependencies: only outputs have "
                    "dependencies (all inputs with direct feedthrough, else none)"));
    for (i = 0; i < n; i++) {
        elementIndicesOfDependent[i] = 0;
        independents[i] = damper_inputs[i];
        elementIndicesOfIndependents[i] = 0;
        dependencyKinds[i] = fmi3Dependent;
    }
    return fmi3OK;
}

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    WRAPPER(instance);
    RET(fmu_state_get(w->inst, FMUState));
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    WRAPPER(instance);
    RET(fmu_state_set(w->inst, FMUState));
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    WRAPPER(instance);
    RET(fmu_state_free(w->inst, FMUState));
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    WRAPPER(instance);
    RET(fmu_state_size(w->inst, FMUState, size));
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState,
                                 fmi3Byte serializedState[], size_t size)
{
    WRAPPER(instance);
    RET(fmu_state_serialize(w->inst, FMUState, serializedState, size));
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[],
                                   size_t size, fmi3FMUState *FMUState)
{
    WRAPPER(instance);
    RET(fmu_state_from_bytes(w->inst, serializedState, size, FMUState));
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                        size_t nUnknowns, const fmi3ValueReference knowns[],
                                        size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                        fmi3Float64 sensitivity[], size_t nSensitivity)
{
    WRAPPER(instance);
    if (nSeed != nKnowns || nSensitivity != nUnknowns)
        RET(fmu_log(w->inst, FMU_ERROR, "fmi3GetDirectionalDerivative: sizes do not match "
                    "(all variables are scalars)"));
    RET(fmu_directional_derivative(w->inst, unknowns, nUnknowns, knowns, nKnowns, seed,
                                   sensitivity));
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                    size_t nUnknowns, const fmi3ValueReference knowns[],
                                    size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                    fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed;
    (void)sensitivity; (void)nSensitivity;
    UNSUPPORTED("fmi3GetAdjointDerivative");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{ UNSUPPORTED("fmi3EnterConfigurationMode"); }
fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{ UNSUPPORTED("fmi3ExitConfigurationMode"); }

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[],
                                  size_t nvr, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[])
{
    (void)vr; (void)nvr; (void)intervals; (void)qualifiers;
    UNSUPPORTED("fmi3GetIntervalDecimal");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference vr[],
                                   size_t nvr, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    (void)vr; (void)nvr; (void)counters; (void)resolutions; (void)qualifiers;
    UNSUPPORTED("fmi3GetIntervalFraction");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[],
                               size_t nvr, fmi3Float64 shifts[])
{
    (void)vr; (void)nvr; (void)shifts;
    UNSUPPORTED("fmi3GetShiftDecimal");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference vr[],
                                size_t nvr, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    UNSUPPORTED("fmi3GetShiftFraction");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[],
                                  size_t nvr, const fmi3Float64 intervals[])
{
    (void)vr; (void)nvr; (void)intervals;
    UNSUPPORTED("fmi3SetIntervalDecimal");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference vr[],
                                   size_t nvr, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[])
{
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    UNSUPPORTED("fmi3SetIntervalFraction");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[],
                               size_t nvr, const fmi3Float64 shifts[])
{
    (void)vr; (void)nvr; (void)shifts;
    UNSUPPORTED("fmi3SetShiftDecimal");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference vr[],
                                size_t nvr, const fmi3UInt64 counters[],
                                const fmi3UInt64 resolutions[])
{
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    UNSUPPORTED("fmi3SetShiftFraction");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{ UNSUPPORTED("fmi3EvaluateDiscreteStates"); }

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation,
                                    fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged,
                                    fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime)
{
    (void)discreteStatesNeedUpdate; (void)terminateSimulation;
    (void)nominalsOfContinuousStatesChanged; (void)valuesOfContinuousStatesChanged;
    (void)nextEventTimeDefined; (void)nextEventTime;
    UNSUPPORTED("fmi3UpdateDiscreteStates");
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{ UNSUPPORTED("fmi3EnterContinuousTimeMode (Model Exchange)"); }

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance,
                                       fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint; (void)enterEventMode; (void)terminateSimulation;
    UNSUPPORTED("fmi3CompletedIntegratorStep (Model Exchange)");
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    (void)time;
    UNSUPPORTED("fmi3SetTime (Model Exchange)");
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    (void)continuousStates; (void)nContinuousStates;
    UNSUPPORTED("fmi3SetContinuousStates (Model Exchange)");
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates)
{
    (void)derivatives; (void)nContinuousStates;
    UNSUPPORTED("fmi3GetContinuousStateDerivatives (Model Exchange)");
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[],
                                  size_t nEventIndicators)
{
    (void)eventIndicators; (void)nEventIndicators;
    UNSUPPORTED("fmi3GetEventIndicators (Model Exchange)");
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    (void)continuousStates; (void)nContinuousStates;
    UNSUPPORTED("fmi3GetContinuousStates (Model Exchange)");
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[],
                                             size_t nContinuousStates)
{
    (void)nominals; (void)nContinuousStates;
    UNSUPPORTED("fmi3GetNominalsOfContinuousStates (Model Exchange)");
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    (void)nEventIndicators;
    UNSUPPORTED("fmi3GetNumberOfEventIndicators (Model Exchange)");
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    (void)nContinuousStates;
    UNSUPPORTED("fmi3GetNumberOfContinuousStates (Model Exchange)");
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{ UNSUPPORTED("fmi3EnterStepMode (there is no event mode)"); }

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference vr[],
                                    size_t nvr, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues)
{
    (void)vr; (void)nvr; (void)orders; (void)values; (void)nValues;
    UNSUPPORTED("fmi3GetOutputDerivatives");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    fmu_status st;
    WRAPPER(instance);
    (void)noSetFMUStatePriorToCurrentPoint;
    st = fmu_do_step(w->inst, currentCommunicationPoint, communicationStepSize);
    if (eventHandlingNeeded) *eventHandlingNeeded = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (earlyReturn) *earlyReturn = fmi3False;
    if (lastSuccessfulTime) *lastSuccessfulTime = fmu_time(w->inst);
    RET(st);
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference; (void)activationTime;
    UNSUPPORTED("fmi3ActivateModelPartition (Scheduled Execution)");
}
