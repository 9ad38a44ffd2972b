/* harness_api.c -- implementation of harness_api.h. */
#define _POSIX_C_SOURCE 200809L
#include "harness_api.h"

#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int g_failures, g_checks, g_log_count;
char g_last_log[1024];

/* ------------------------------------------------------------------ loggers */
static void logger2(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                    fmi2String category, fmi2String message, ...)
{
    va_list args;
    (void)env; (void)name; (void)status; (void)category;
    va_start(args, message);
    vsnprintf(g_last_log, sizeof g_last_log, message, args);
    va_end(args);
    g_log_count++;
}

void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
             fmi3String message)
{
    (void)env; (void)status; (void)category;
    snprintf(g_last_log, sizeof g_last_log, "%s", message);
    g_log_count++;
}

const fmi2CallbackFunctions callbacks2 = {logger2, NULL, NULL, NULL, NULL};

/* ----------------------------------------------------- required symbols */
static const char *const symbols2[] = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate",
    "fmi2FreeInstance", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset", "fmi2GetReal",
    "fmi2GetInteger", "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger",
    "fmi2SetBoolean", "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate",
    "fmi2FreeFMUstate", "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate", "fmi2GetDirectionalDerivative", "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives", "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus",
    "fmi2GetRealStatus", "fmi2GetIntegerStatus", "fmi2GetBooleanStatus", "fmi2GetStringStatus"};

static const char *const symbols3[] = {
    "fmi3GetVersion", "fmi3SetDebugLogging", "fmi3InstantiateModelExchange",
    "fmi3InstantiateCoSimulation", "fmi3InstantiateScheduledExecution", "fmi3FreeInstance",
    "fmi3EnterInitializationMode", "fmi3ExitInitializationMode", "fmi3EnterEventMode",
    "fmi3Terminate", "fmi3Reset", "fmi3GetFloat32", "fmi3GetFloat64", "fmi3GetInt8",
    "fmi3GetUInt8", "fmi3GetInt16", "fmi3GetUInt16", "fmi3GetInt32", "fmi3GetUInt32",
    "fmi3GetInt64", "fmi3GetUInt64", "fmi3GetBoolean", "fmi3GetString", "fmi3GetBinary",
    "fmi3GetClock", "fmi3SetFloat32", "fmi3SetFloat64", "fmi3SetInt8", "fmi3SetUInt8",
    "fmi3SetInt16", "fmi3SetUInt16", "fmi3SetInt32", "fmi3SetUInt32", "fmi3SetInt64",
    "fmi3SetUInt64", "fmi3SetBoolean", "fmi3SetString", "fmi3SetBinary", "fmi3SetClock",
    "fmi3GetNumberOfVariableDependencies", "fmi3GetVariableDependencies", "fmi3GetFMUState",
    "fmi3SetFMUState", "fmi3FreeFMUState", "fmi3SerializedFMUStateSize",
    "fmi3SerializeFMUState", "fmi3DeserializeFMUState", "fmi3GetDirectionalDerivative",
    "fmi3GetAdjointDerivative", "fmi3EnterConfigurationMode", "fmi3ExitConfigurationMode",
    "fmi3GetIntervalDecimal", "fmi3GetIntervalFraction", "fmi3GetShiftDecimal",
    "fmi3GetShiftFraction", "fmi3SetIntervalDecimal", "fmi3SetIntervalFraction",
    "fmi3SetShiftDecimal", "fmi3SetShiftFraction", "fmi3EvaluateDiscreteStates",
    "fmi3UpdateDiscreteStates", "fmi3EnterContinuousTimeMode", "fmi3CompletedIntegratorStep",
    "fmi3SetTime", "fmi3SetContinuousStates", "fmi3GetContinuousStateDerivatives",
    "fmi3GetEventIndicators", "fmi3GetContinuousStates", "fmi3GetNominalsOfContinuousStates",
    "fmi3GetNumberOfEventIndicators", "fmi3GetNumberOfContinuousStates", "fmi3EnterStepMode",
    "fmi3GetOutputDerivatives", "fmi3DoStep", "fmi3ActivateModelPartition"};

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

#define SYM(field, name) (*(void **)(&a->field) = dlsym(a->lib, name))

int load(api *a, int v, const char *path, const char *dir)
{
    size_t i, n = v == 2 ? COUNT(symbols2) : COUNT(symbols3);
    memset(a, 0, sizeof *a);
    a->v = v;
    a->lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    CHECK(a->lib != NULL, "dlopen %s: %s", path, dlerror());
    if (!a->lib) return 0;
    for (i = 0; i < n; i++) {
        const char *name = v == 2 ? symbols2[i] : symbols3[i];
        CHECK(dlsym(a->lib, name) != NULL, "FMI %d binary lacks %s", v, name);
    }
    snprintf(a->resources, sizeof a->resources, v == 2 ? "file://%s" : "%s/", dir);
    if (v == 2) {
        SYM(i2, "fmi2Instantiate"); SYM(free2, "fmi2FreeInstance");
        SYM(setup2, "fmi2SetupExperiment"); SYM(enter2, "fmi2EnterInitializationMode");
        SYM(exit2, "fmi2ExitInitializationMode"); SYM(term2, "fmi2Terminate");
        SYM(reset2, "fmi2Reset"); SYM(get2, "fmi2GetReal"); SYM(set2, "fmi2SetReal");
        SYM(step2, "fmi2DoStep"); SYM(gs2, "fmi2GetFMUstate"); SYM(ss2, "fmi2SetFMUstate");
        SYM(fs2, "fmi2FreeFMUstate"); SYM(ser2, "fmi2SerializeFMUstate");
        SYM(size2, "fmi2SerializedFMUstateSize"); SYM(des2, "fmi2DeSerializeFMUstate");
        SYM(dd2, "fmi2GetDirectionalDerivative"); SYM(sid2, "fmi2SetRealInputDerivatives");
    } else {
        SYM(i3, "fmi3InstantiateCoSimulation"); SYM(ime3, "fmi3InstantiateModelExchange");
        SYM(free3, "fmi3FreeInstance"); SYM(enter3, "fmi3EnterInitializationMode");
        SYM(exit3, "fmi3ExitInitializationMode"); SYM(term3, "fmi3Terminate");
        SYM(reset3, "fmi3Reset"); SYM(get3, "fmi3GetFloat64"); SYM(set3, "fmi3SetFloat64");
        SYM(step3, "fmi3DoStep"); SYM(gs3, "fmi3GetFMUState"); SYM(ss3, "fmi3SetFMUState");
        SYM(fs3, "fmi3FreeFMUState"); SYM(ser3, "fmi3SerializeFMUState");
        SYM(size3, "fmi3SerializedFMUStateSize"); SYM(des3, "fmi3DeserializeFMUState");
        SYM(dd3, "fmi3GetDirectionalDerivative");
    }
    return 1;
}

void *instantiate(const api *a, const char *name, const char *token, const char *res)
{
    if (a->v == 2)
        return a->i2(name, fmi2CoSimulation, token, res, &callbacks2, fmi2False, fmi2True);
    return a->i3(name, token, res, fmi3False, fmi3True, fmi3False, fmi3False, NULL, 0, NULL,
                 logger3, NULL);
}

void check_instantiation_errors(const api *a, const char *token, const char *missing)
{
    int logs = g_log_count;
    void *c = instantiate(a, "bad", "{00000000-0000-0000-0000-000000000000}", a->resources);
    CHECK(c == NULL && g_log_count > logs, "FMI %d: wrong token accepted or not logged", a->v);
    logs = g_log_count;
    c = instantiate(a, "bad", token, missing);
    CHECK(c == NULL && g_log_count > logs, "FMI %d: missing resources accepted", a->v);
    c = instantiate(a, "bad", token, NULL);
    CHECK(c == NULL, "FMI %d: NULL resource location accepted", a->v);
    if (a->v == 2)
        c = a->i2("me", fmi2ModelExchange, token, a->resources, &callbacks2, 0, 1);
    else
        c = a->ime3("me", token, a->resources, fmi3False, fmi3True, NULL, logger3);
    CHECK(c == NULL, "FMI %d: Model Exchange instantiation accepted", a->v);
}

void release(inst *x)
{
    if (x->a->v == 2) x->a->free2(x->c);
    else x->a->free3(x->c);
    x->c = NULL;
}

/* All calls return the FMI status as int: OK = 0 and Error = 3 in both versions. */
int enter_init(inst *x)
{
    if (x->a->v == 2) {
        int st = (int)x->a->setup2(x->c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
        return st ? st : (int)x->a->enter2(x->c);
    }
    return (int)x->a->enter3(x->c, fmi3False, 0.0, 0.0, fmi3False, 0.0);
}

int exit_init(inst *x)
{
    return x->a->v == 2 ? (int)x->a->exit2(x->c) : (int)x->a->exit3(x->c);
}

int set(inst *x, unsigned int vr, double value)
{
    return x->a->v == 2 ? (int)x->a->set2(x->c, &vr, 1, &value)
                        : (int)x->a->set3(x->c, &vr, 1, &value, 1);
}

int get(inst *x, unsigned int vr, double *value)
{
    return x->a->v == 2 ? (int)x->a->get2(x->c, &vr, 1, value)
                        : (int)x->a->get3(x->c, &vr, 1, value, 1);
}

int do_step(inst *x, double h)
{
    int st;
    fmi3Boolean ev, term, early;
    fmi3Float64 last;
    if (x->a->v == 2) st = (int)x->a->step2(x->c, x->t, h, fmi2True);
    else st = (int)x->a->step3(x->c, x->t, h, fmi3True, &ev, &term, &early, &last);
    if (st == 0) x->t += h;
    return st;
}

int get_state(inst *x, void **s)
{
    return x->a->v == 2 ? (int)x->a->gs2(x->c, s) : (int)x->a->gs3(x->c, s);
}

int set_state(inst *x, void *s)
{
    return x->a->v == 2 ? (int)x->a->ss2(x->c, s) : (int)x->a->ss3(x->c, s);
}

void free_state(inst *x, void **s)
{
    if (x->a->v == 2) x->a->fs2(x->c, s);
    else x->a->fs3(x->c, s);
}

int serialize(inst *x, void *s, unsigned char **bytes, size_t *size)
{
    int st = x->a->v == 2 ? (int)x->a->size2(x->c, s, size) : (int)x->a->size3(x->c, s, size);
    if (st) return st;
    *bytes = (unsigned char *)malloc(*size);
    return x->a->v == 2 ? (int)x->a->ser2(x->c, s, (fmi2Byte *)*bytes, *size)
                        : (int)x->a->ser3(x->c, s, *bytes, *size);
}

int deserialize(inst *x, const unsigned char *bytes, size_t size, void **s)
{
    return x->a->v == 2 ? (int)x->a->des2(x->c, (const fmi2Byte *)bytes, size, s)
                        : (int)x->a->des3(x->c, bytes, size, s);
}

int dir_deriv(inst *x, unsigned int unknown, unsigned int known, double seed, double *d)
{
    return x->a->v == 2 ? (int)x->a->dd2(x->c, &unknown, 1, &known, 1, &seed, d)
                        : (int)x->a->dd3(x->c, &unknown, 1, &known, 1, &seed, 1, d, 1);
}

/* A ready instance in step mode (inputs at their start values), or c == NULL on failure. */
inst start(const api *a, const char *name)
{
    inst x;
    x.a = a;
    x.t = 0.0;
    x.c = instantiate(a, name, DAMPER_TOKEN, a->resources);
    CHECK(x.c != NULL, "FMI %d: instantiate failed: %s", a->v, g_last_log);
    if (!x.c) return x;
    CHECK(enter_init(&x) == 0 && exit_init(&x) == 0, "FMI %d: initialization failed", a->v);
    return x;
}
