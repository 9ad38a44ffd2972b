/*
 * fmi2.c -- FMI 2.0 co-simulation interface of the friction element.
 *
 * A thin mapping of the fmi2* functions onto fmu_instance.c: status codes, the
 * logger callback, the resource URI. Every function checks the instance mode, so a
 * call in a wrong state returns fmi2Error with a logged message (never a crash).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu_instance.h"

typedef struct {
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment env;
    char name[128];
    double start_time;
    fmu_instance *inst;
} fmu2;

static const fmi2Status status2[] = {fmi2OK, fmi2Warning, fmi2Error};

/* The FMI 2 logger formats `message` printf-style: double every '%'. */
static void log_fmi2(void *ctx, fmu_status status, const char *category, const char *message)
{
    fmu2 *w = (fmu2 *)ctx;
    char escaped[1024];
    size_t i = 0;
    if (!w->logger) return;
    for (; *message && i + 2 < sizeof escaped; message++) {
        if (*message == '%') escaped[i++] = '%';
        escaped[i++] = *message;
    }
    escaped[i] = '\0';
    w->logger(w->env, w->name, status2[status], category, escaped);
}

/* fmi2Component -> wrapper; a NULL component cannot even log. */
#define WRAPPER(c) fmu2 *w = (fmu2 *)(c); if (!w || !w->inst) return fmi2Error
#define RET(expr) return status2[(expr)]

/* Native directory from an FMI 2 resource URI: file:///p, file://localhost/p or
 * file:/p, percent-decoded. Returns a malloc'ed string or NULL. */
static char *uri_to_path(const char *uri)
{
    const char *p;
    char *out, *q;
    if (!uri || strncmp(uri, "file:", 5) != 0) return NULL;
    p = uri + 5;
    if (strncmp(p, "//localhost/", 12) == 0) p += 11;
    else if (strncmp(p, "///", 3) == 0) p += 2;
    else if (strncmp(p, "//", 2) == 0) return NULL;  /* a remote host */
    out = q = (char *)malloc(strlen(p) + 1);
    if (!out) return NULL;
    for (; *p; p++) {
        unsigned int byte;
        if (*p == '%' && p[1] && p[2] && sscanf(p + 1, "%2x", &byte) == 1) {
            *q++ = (char)byte;
            p += 2;
        } else {
            *q++ = *p;
        }
    }
    *q = '\0';
    return out;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn)
{
    fmu2 *w = (fmu2 *)calloc(1, sizeof(fmu2));
    char *dir;
    (void)visible;
    (void)loggingOn;  /* errors are always logged; there are no debug messages */
    if (!w) return NULL;
    w->logger = functions ? functions->logger : NULL;
    w->env = functions ? functions->componentEnvironment : NULL;
    strncpy(w->name, instanceName ? instanceName : "", sizeof w->name - 1);
    if (fmuType != fmi2CoSimulation) {
        log_fmi2(w, FMU_ERROR, "logStatusError", "this FMU supports co-simulation only");
        free(w);
        return NULL;
    }
    dir = uri_to_path(fmuResourceLocation);
    if (!dir) {
        log_fmi2(w, FMU_ERROR, "logStatusError", "resource location is not a local file: URI");
        free(w);
        return NULL;
    }
    w->inst = fmu_new(w->name, fmuGUID, dir, log_fmi2, w);
    free(dir);
    if (!w->inst) {
        free(w);
        return NULL;
    }
    return w;
}

void fmi2FreeInstance(fmi2Component c)
{
    fmu2 *w = (fmu2 *)c;
    if (!w) return;
    fmu_free(w->inst);
    free(w);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    size_t i;
    int k, known;
    WRAPPER(c);
    (void)loggingOn;
    for (i = 0; i < nCategories; i++) {
        for (known = 0, k = 0; k < DAMPER_N_LOG_CATEGORIES; k++)
            known |= categories && categories[i] && !strcmp(categories[i], damper_log_categories[k]);
        if (!known) RET(fmu_log(w->inst, FMU_ERROR, "unknown log category"));
    }
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    WRAPPER(c);
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    if (fmu_check_mode(w->inst, MODE_INSTANTIATED, "fmi2SetupExperiment")) return fmi2Error;
    w->start_time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    WRAPPER(c);
    RET(fmu_enter_init(w->inst, w->start_time));
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    WRAPPER(c);
    RET(fmu_exit_init(w->inst));
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    WRAPPER(c);
    RET(fmu_terminate(w->inst));
}

fmi2Status fmi2Reset(fmi2Component c)
{
    WRAPPER(c);
    fmu_reset(w->inst);
    w->start_time = 0.0;
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[])
{
    WRAPPER(c);
    RET(fmu_get(w->inst, vr, nvr, value));
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[])
{
    WRAPPER(c);
    RET(fmu_set(w->inst, vr, nvr, value));
}

/* There are no Integer, Boolean or String variables: only empty calls succeed. */
#define NO_VARIABLES(type)                                                                 \
    WRAPPER(c);                                                                            \
    (void)vr; (void)value;                                                                 \
    if (nvr == 0) return fmi2OK;                                                           \
    RET(fmu_log(w->inst, FMU_ERROR, "this FMU has no " type " variables (vr %u)",         \
                vr ? vr[0] : 0u))

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[]) { NO_VARIABLES("Integer"); }
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) { NO_VARIABLES("Boolean"); }
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) { NO_VARIABLES("String"); }
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) { NO_VARIABLES("Integer"); }
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) { NO_VARIABLES("Boolean"); }
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) { NO_VARIABLES("String"); }

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    WRAPPER(c);
    RET(fmu_state_get(w->inst, FMUstate));
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    WRAPPER(c);
    RET(fmu_state_set(w->inst, FMUstate));
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    WRAPPER(c);
    RET(fmu_state_free(w->inst, FMUstate));
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    WRAPPER(c);
    RET(fmu_state_size(w->inst, FMUstate, size));
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate,
                                 fmi2Byte serializedState[], size_t size)
{
    WRAPPER(c);
    RET(fmu_state_serialize(w->inst, FMUstate, serializedState, size));
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[],
                                   size_t size, fmi2FMUstate *FMUstate)
{
    WRAPPER(c);
    RET(fmu_state_from_bytes(w->inst, serializedState, size, FMUstate));
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[])
{
    WRAPPER(c);
    RET(fmu_directional_derivative(w->inst, vUnknown_ref, nUnknown, vKnown_ref, nKnown,
                                   dvKnown, dvUnknown));
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[])
{
    WRAPPER(c);
    RET(fmu_set_derivative(w->inst, vr, nvr, order, value));
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[])
{
    WRAPPER(c);
    (void)vr; (void)nvr; (void)order; (void)value;
    RET(fmu_log(w->inst, FMU_ERROR, "output derivatives are not provided "
                "(maxOutputDerivativeOrder = 0)"));
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    WRAPPER(c);
    (void)noSetFMUStatePriorToCurrentPoint;
    RET(fmu_do_step(w->inst, currentCommunicationPoint, communicationStepSize));
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    WRAPPER(c);
    RET(fmu_log(w->inst, FMU_ERROR, "fmi2CancelStep: doStep is never asynchronous"));
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    WRAPPER(c);
    (void)s; (void)value;
    RET(fmu_log(w->inst, FMU_ERROR, "fmi2GetStatus: doStep is never asynchronous"));
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    WRAPPER(c);
    if (s == fmi2LastSuccessfulTime && value) {
        *value = fmu_time(w->inst);
        return fmi2OK;
    }
    RET(fmu_log(w->inst, FMU_ERROR, "fmi2GetRealStatus: only fmi2LastSuccessfulTime"));
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    WRAPPER(c);
    (void)s; (void)value;
    RET(fmu_log(w->inst, FMU_ERROR, "fmi2GetIntegerStatus: not supported"));
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    WRAPPER(c);
    (void)s; (void)value;
    RET(fmu_log(w->inst, FMU_ERROR, "fmi2GetBooleanStatus: not supported"));
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    WRAPPER(c);
    (void)s; (void)value;
    RET(fmu_log(w->inst, FMU_ERROR, "fmi2GetStringStatus: not supported"));
}
