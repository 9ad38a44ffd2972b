/*
 * test_harness.c -- our own importer test of the friction-element FMU binaries.
 *
 * Usage: fmu_test_harness <fmi2 damper.so> <fmi3 damper.so> <scratch dir>
 *
 * Loads both binaries with dlopen (side by side in one process) and drives them
 * through the FMI C API: every required symbol present; calls in a wrong state
 * answered with an error and a logged message, never a crash; NaN and infinite
 * inputs rejected with a logged message; rollback (get/set FMU state) and
 * serialization giving bit-identical continuations, also in another instance;
 * directional derivatives against finite differences; several instances side by
 * side giving the results of one instance alone. Exit status 0 when all pass.
 * Meant to run under valgrind as well (ctest fmu_harness_valgrind).
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "damper_vr.h"
#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"

/* Finite differences of a piecewise-linear force: exact up to round-off when the
 * increment crosses no slider switch; relative tolerance for that round-off. */
#define FD_RTOL 1e-6
#define N_CURVE 200.0     /* normal load of the harness curve [N] */
#define U_SLIP 2.0e-6     /* gross-slip displacement of the harness curve [m] */
#define N_HIST 100        /* samples of the test histories */

static int g_failures, g_checks, g_log_count;
static char g_last_log[1024];

#define CHECK(cond, ...)                                                   \
    do {                                                                   \
        g_checks++;                                                        \
        if (!(cond)) {                                                     \
            g_failures++;                                                  \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);          \
            fprintf(stderr, __VA_ARGS__);                                  \
            fputc('\n', stderr);                                           \
        }                                                                  \
    } while (0)

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

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                    fmi3String message)
{
    (void)env; (void)status; (void)category;
    snprintf(g_last_log, sizeof g_last_log, "%s", message);
    g_log_count++;
}

static const fmi2CallbackFunctions callbacks2 = {logger2, NULL, NULL, NULL, NULL};

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

/* ------------------------------------------- one driver for both versions */
typedef struct {
    int v;                 /* FMI version: 2 or 3 */
    void *lib;
    char resources[1200];  /* FMI 2: file URI; FMI 3: directory ending in '/' */
    fmi2InstantiateTYPE *i2; fmi2FreeInstanceTYPE *free2; fmi2SetupExperimentTYPE *setup2;
    fmi2EnterInitializationModeTYPE *enter2; fmi2ExitInitializationModeTYPE *exit2;
    fmi2TerminateTYPE *term2; fmi2ResetTYPE *reset2; fmi2GetRealTYPE *get2;
    fmi2SetRealTYPE *set2; fmi2DoStepTYPE *step2; fmi2GetFMUstateTYPE *gs2;
    fmi2SetFMUstateTYPE *ss2; fmi2FreeFMUstateTYPE *fs2; fmi2SerializeFMUstateTYPE *ser2;
    fmi2SerializedFMUstateSizeTYPE *size2; fmi2DeSerializeFMUstateTYPE *des2;
    fmi2GetDirectionalDerivativeTYPE *dd2; fmi2SetRealInputDerivativesTYPE *sid2;
    fmi3InstantiateCoSimulationTYPE *i3; fmi3InstantiateModelExchangeTYPE *ime3;
    fmi3FreeInstanceTYPE *free3; fmi3EnterInitializationModeTYPE *enter3;
    fmi3ExitInitializationModeTYPE *exit3; fmi3TerminateTYPE *term3; fmi3ResetTYPE *reset3;
    fmi3GetFloat64TYPE *get3; fmi3SetFloat64TYPE *set3; fmi3DoStepTYPE *step3;
    fmi3GetFMUStateTYPE *gs3; fmi3SetFMUStateTYPE *ss3; fmi3FreeFMUStateTYPE *fs3;
    fmi3SerializeFMUStateTYPE *ser3; fmi3SerializedFMUStateSizeTYPE *size3;
    fmi3DeserializeFMUStateTYPE *des3; fmi3GetDirectionalDerivativeTYPE *dd3;
} api;

typedef struct {
    const api *a;
    void *c;       /* fmi2Component or fmi3Instance */
    double t;
} inst;

#define SYM(field, name) (*(void **)(&a->field) = dlsym(a->lib, name))

static int load(api *a, int v, const char *path, const char *dir)
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

static void *instantiate(const api *a, const char *name, const char *token, const char *res)
{
    if (a->v == 2)
        return a->i2(name, fmi2CoSimulation, token, res, &callbacks2, fmi2False, fmi2True);
    return a->i3(name, token, res, fmi3False, fmi3True, fmi3False, fmi3False, NULL, 0, NULL,
                 logger3, NULL);
}

static void release(inst *x)
{
    if (x->a->v == 2) x->a->free2(x->c);
    else x->a->free3(x->c);
    x->c = NULL;
}

/* All calls return the FMI status as int: OK = 0 and Error = 3 in both versions. */
static int enter_init(inst *x)
{
    if (x->a->v == 2) {
        int st = (int)x->a->setup2(x->c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
        return st ? st : (int)x->a->enter2(x->c);
    }
    return (int)x->a->enter3(x->c, fmi3False, 0.0, 0.0, fmi3False, 0.0);
}

static int exit_init(inst *x)
{
    return x->a->v == 2 ? (int)x->a->exit2(x->c) : (int)x->a->exit3(x->c);
}

static int set(inst *x, unsigned int vr, double value)
{
    return x->a->v == 2 ? (int)x->a->set2(x->c, &vr, 1, &value)
                        : (int)x->a->set3(x->c, &vr, 1, &value, 1);
}

static int get(inst *x, unsigned int vr, double *value)
{
    return x->a->v == 2 ? (int)x->a->get2(x->c, &vr, 1, value)
                        : (int)x->a->get3(x->c, &vr, 1, value, 1);
}

static int do_step(inst *x, double h)
{
    int st;
    fmi3Boolean ev, term, early;
    fmi3Float64 last;
    if (x->a->v == 2) st = (int)x->a->step2(x->c, x->t, h, fmi2True);
    else st = (int)x->a->step3(x->c, x->t, h, fmi3True, &ev, &term, &early, &last);
    if (st == 0) x->t += h;
    return st;
}

static int get_state(inst *x, void **s)
{
    return x->a->v == 2 ? (int)x->a->gs2(x->c, s) : (int)x->a->gs3(x->c, s);
}

static int set_state(inst *x, void *s)
{
    return x->a->v == 2 ? (int)x->a->ss2(x->c, s) : (int)x->a->ss3(x->c, s);
}

static void free_state(inst *x, void **s)
{
    if (x->a->v == 2) x->a->fs2(x->c, s);
    else x->a->fs3(x->c, s);
}

static int serialize(inst *x, void *s, unsigned char **bytes, size_t *size)
{
    int st = x->a->v == 2 ? (int)x->a->size2(x->c, s, size) : (int)x->a->size3(x->c, s, size);
    if (st) return st;
    *bytes = (unsigned char *)malloc(*size);
    return x->a->v == 2 ? (int)x->a->ser2(x->c, s, (fmi2Byte *)*bytes, *size)
                        : (int)x->a->ser3(x->c, s, *bytes, *size);
}

static int deserialize(inst *x, const unsigned char *bytes, size_t size, void **s)
{
    return x->a->v == 2 ? (int)x->a->des2(x->c, (const fmi2Byte *)bytes, size, s)
                        : (int)x->a->des3(x->c, bytes, size, s);
}

static int dir_deriv(inst *x, unsigned int unknown, unsigned int known, double seed, double *d)
{
    return x->a->v == 2 ? (int)x->a->dd2(x->c, &unknown, 1, &known, 1, &seed, d)
                        : (int)x->a->dd3(x->c, &unknown, 1, &known, 1, &seed, 1, d, 1);
}

/* A ready instance in step mode (u = 0, N = N_CURVE), or c == NULL on failure. */
static inst start(const api *a, const char *name)
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

/* u (and N) of sample k of the test history: reversals, minor loops, varying N. */
static double hist_u(int k) { return 1.3 * U_SLIP * sin(0.21 * k) * (1.0 + 0.4 * sin(0.9 * k)); }
static double hist_N(int k) { return N_CURVE * (1.0 + 0.25 * sin(0.13 * k)); }

/* Run samples k0..k0+n-1: set u, N, doStep; F and W after each into out[2n]. */
static void run(inst *x, int k0, int n, double *out)
{
    int k;
    for (k = 0; k < n; k++) {
        int ok = set(x, VR_U, hist_u(k0 + k)) == 0 && set(x, VR_N, hist_N(k0 + k)) == 0
                 && do_step(x, 1e-3) == 0 && get(x, VR_F, &out[2 * k]) == 0
                 && get(x, VR_W, &out[2 * k + 1]) == 0;
        CHECK(ok, "FMI %d: step %d failed: %s", x->a->v, k0 + k, g_last_log);
        if (!ok) return;
    }
}

/* ------------------------------------------------------------------ tests */
/* Calls the FMU must refuse, each with fmi?Error and a logged message. */
static void expect_error(inst *x, int status, const char *what)
{
    CHECK(status == 3, "FMI %d: %s returned %d, expected an error", x->a->v, what, status);
}

static void test_instantiation_errors(const api *a, const char *dir)
{
    int logs = g_log_count;
    void *c = instantiate(a, "bad", "{00000000-0000-0000-0000-000000000000}", a->resources);
    CHECK(c == NULL && g_log_count > logs, "FMI %d: wrong token accepted or not logged", a->v);
    logs = g_log_count;
    c = instantiate(a, "bad", DAMPER_TOKEN, a->v == 2 ? "file:///nonexistent/dir" : "/nonexistent/");
    CHECK(c == NULL && g_log_count > logs, "FMI %d: missing curve accepted", a->v);
    c = instantiate(a, "bad", DAMPER_TOKEN, NULL);
    CHECK(c == NULL, "FMI %d: NULL resource location accepted", a->v);
    if (a->v == 2)
        c = a->i2("me", fmi2ModelExchange, DAMPER_TOKEN, a->resources, &callbacks2, 0, 1);
    else
        c = a->ime3("me", DAMPER_TOKEN, dir, fmi3False, fmi3True, NULL, logger3);
    CHECK(c == NULL, "FMI %d: Model Exchange instantiation accepted", a->v);
}

static void test_state_machine(const api *a)
{
    inst x = {a, NULL, 0.0};
    double v;
    int logs;
    x.c = instantiate(a, "sm", DAMPER_TOKEN, a->resources);
    CHECK(x.c != NULL, "FMI %d: instantiate", a->v);
    if (!x.c) return;
    logs = g_log_count;
    expect_error(&x, do_step(&x, 1e-3), "DoStep before initialization");
    CHECK(g_log_count > logs, "FMI %d: wrong-state DoStep not logged", a->v);
    expect_error(&x, get(&x, VR_F, &v), "GetReal in Instantiated");
    expect_error(&x, exit_init(&x), "ExitInitializationMode before Enter");
    CHECK(enter_init(&x) == 0, "FMI %d: EnterInitializationMode", a->v);
    expect_error(&x, set(&x, VR_F, 1.0), "setting an output");
    expect_error(&x, set(&x, VR_TIME, 1.0), "setting the independent variable");
    expect_error(&x, set(&x, DAMPER_N_VARIABLES + 7, 1.0), "unknown value reference");
    expect_error(&x, set(&x, VR_N_REF, -1.0), "N_ref <= 0");
    expect_error(&x, set(&x, VR_SCALE, -0.5), "scale < 0");
    CHECK(exit_init(&x) == 0, "FMI %d: ExitInitializationMode", a->v);
    expect_error(&x, set(&x, VR_SCALE, 2.0), "fixed parameter in step mode");
    x.t = 5.0;
    expect_error(&x, do_step(&x, 1e-3), "DoStep at a wrong communication point");
    x.t = 0.0;
    expect_error(&x, do_step(&x, -1e-3), "DoStep with h < 0");
    CHECK(do_step(&x, 1e-3) == 0, "FMI %d: DoStep", a->v);
    CHECK((a->v == 2 ? (int)a->term2(x.c) : (int)a->term3(x.c)) == 0, "FMI %d: Terminate", a->v);
    expect_error(&x, do_step(&x, 1e-3), "DoStep after Terminate");
    expect_error(&x, set(&x, VR_U, 1e-7), "SetReal after Terminate");
    CHECK(get(&x, VR_F, &v) == 0, "FMI %d: GetReal after Terminate", a->v);
    CHECK((a->v == 2 ? (int)a->reset2(x.c) : (int)a->reset3(x.c)) == 0, "FMI %d: Reset", a->v);
    x.t = 0.0;
    CHECK(enter_init(&x) == 0 && exit_init(&x) == 0 && do_step(&x, 1e-3) == 0,
          "FMI %d: a reset instance runs again", a->v);
    release(&x);
    x.c = NULL;  /* a NULL instance must be refused, not dereferenced */
    expect_error(&x, set(&x, VR_U, 0.0), "SetReal on a NULL instance");
    expect_error(&x, do_step(&x, 1e-3), "DoStep on a NULL instance");
}

static void test_nonfinite_inputs(const api *a)
{
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    const unsigned int vrs[2] = {VR_U, VR_N};
    inst x = start(a, "nan");
    double before, after, F0, F1;
    int i, j, logs;
    if (!x.c) return;
    CHECK(set(&x, VR_U, 0.3 * U_SLIP) == 0 && do_step(&x, 1e-3) == 0, "FMI %d: step", a->v);
    get(&x, VR_F, &F0);
    for (i = 0; i < 3; i++) {
        for (j = 0; j < 2; j++) {
            get(&x, vrs[j], &before);
            logs = g_log_count;
            expect_error(&x, set(&x, vrs[j], bad[i]), "a non-finite input");
            CHECK(g_log_count > logs && strstr(g_last_log, "NaN or infinite"),
                  "FMI %d: non-finite input not logged clearly: '%s'", a->v, g_last_log);
            get(&x, vrs[j], &after);
            CHECK(memcmp(&before, &after, sizeof before) == 0, "FMI %d: bad input stored", a->v);
        }
    }
    CHECK(do_step(&x, 1e-3) == 0 && get(&x, VR_F, &F1) == 0 && F1 == F0,
          "FMI %d: history changed by refused inputs", a->v);
    /* finite but absurd inputs whose force or energy overflows: refused, history kept */
    CHECK(set(&x, VR_U, -1e300) == 0 && set(&x, VR_N, 1e300) == 0, "FMI %d: set", a->v);
    logs = g_log_count;
    expect_error(&x, get(&x, VR_W, &after), "outputs that overflow");
    expect_error(&x, do_step(&x, 1e-3), "a step whose outputs overflow");
    CHECK(g_log_count > logs && strstr(g_last_log, "overflow"),
          "FMI %d: overflow not logged clearly: '%s'", a->v, g_last_log);
    CHECK(set(&x, VR_U, 0.3 * U_SLIP) == 0 && set(&x, VR_N, N_CURVE) == 0
          && do_step(&x, 1e-3) == 0 && get(&x, VR_F, &F1) == 0 && F1 == F0,
          "FMI %d: history changed by a refused step", a->v);
    release(&x);
}

/* Save, continue, restore, continue again: bit-identical; the same through
 * serialized bytes restored into a second instance. */
static void test_rollback_and_serialization(const api *a)
{
    double first[2 * N_HIST], again[2 * N_HIST], other[2 * N_HIST];
    inst x = start(a, "roll"), y = start(a, "other");
    void *s = NULL, *s2 = NULL;
    unsigned char *bytes = NULL, junk[16] = {0};
    size_t size = 0;
    if (!x.c || !y.c) return;
    run(&x, 0, 40, first);
    CHECK(get_state(&x, &s) == 0 && serialize(&x, s, &bytes, &size) == 0,
          "FMI %d: get/serialize state: %s", a->v, g_last_log);
    run(&x, 40, N_HIST, first);
    x.t -= N_HIST * 1e-3;
    CHECK(set_state(&x, s) == 0, "FMI %d: SetFMUState", a->v);
    run(&x, 40, N_HIST, again);
    CHECK(memcmp(first, again, sizeof first) == 0, "FMI %d: rollback not bit-identical", a->v);
    CHECK(deserialize(&y, bytes, size, &s2) == 0 && set_state(&y, s2) == 0,
          "FMI %d: deserialize into another instance: %s", a->v, g_last_log);
    y.t = 40 * 1e-3;
    run(&y, 40, N_HIST, other);
    CHECK(memcmp(first, other, sizeof first) == 0,
          "FMI %d: deserialized continuation not bit-identical", a->v);
    expect_error(&y, deserialize(&y, junk, sizeof junk, &s2), "deserializing 16 junk bytes");
    memset(bytes, 0xAB, 8);  /* corrupt the magic and version */
    expect_error(&y, deserialize(&y, bytes, size, &s2), "deserializing a corrupted state");
    /* An importer passing an uninitialized FMUstate (FMI4j 0.38 does) gets a new
     * state; pointers the instance did not hand out are refused, never touched. */
    {
        void *garbage = (void *)junk, *fresh = garbage;
        CHECK(get_state(&x, &fresh) == 0 && fresh != garbage, "FMI %d: garbage FMUstate "
              "reused", a->v);
        expect_error(&x, set_state(&x, garbage), "SetFMUState with a foreign pointer");
        expect_error(&x, set_state(&x, s2), "SetFMUState with another instance's state");
        if (a->v == 2) expect_error(&x, (int)a->fs2(x.c, &garbage), "freeing a foreign pointer");
        else expect_error(&x, (int)a->fs3(x.c, &garbage), "freeing a foreign pointer");
        free_state(&x, &fresh);
    }
    free_state(&x, &s);
    free_state(&y, &s2);
    CHECK(s == NULL && s2 == NULL, "FMI %d: FreeFMUState leaves the pointer set", a->v);
    CHECK(get_state(&x, &s) == 0, "FMI %d: a state left to FreeInstance", a->v);
    free(bytes);
    release(&x);
    release(&y);
}

static void check_fd(inst *x, unsigned int known, double base, double delta, const char *what)
{
    double F0, F1, d = 0.0;
    set(x, known, base);
    get(x, VR_F, &F0);
    CHECK(dir_deriv(x, VR_F, known, 1.0, &d) == 0, "FMI %d: directional derivative", x->a->v);
    set(x, known, base + delta);
    get(x, VR_F, &F1);
    set(x, known, base);
    CHECK(fabs((F1 - F0) / delta - d) <= FD_RTOL * fabs(d) + 1e-9,
          "FMI %d: %s = %.12g but finite difference %.12g", x->a->v, what, d, (F1 - F0) / delta);
}

/* dF/du for continued motion (loading, partial slip) and dF/dN for a decreasing
 * load at fixed u (slipping sliders follow their limits), against differences of
 * trial evaluations (the getters never commit). */
static void test_directional_derivatives(const api *a)
{
    inst x = start(a, "dd");
    double u = 0.0, d = 0.0;
    int k;
    unsigned int W = VR_W;
    if (!x.c) return;
    for (k = 1; k <= 6; k++) {  /* monotonic loading into partial slip */
        u = 0.1 * k * U_SLIP;
        set(&x, VR_U, u);
        do_step(&x, 1e-3);
    }
    check_fd(&x, VR_U, u + 1e-3 * U_SLIP, 1e-6 * U_SLIP, "dF/du (loading)");
    set(&x, VR_U, u);
    check_fd(&x, VR_N, N_CURVE, -1e-6 * N_CURVE, "dF/dN (unloading N)");
    CHECK(dir_deriv(&x, VR_F, VR_U, 1.0, &d) == 0 && d > 0.0, "FMI %d: kt > 0", a->v);
    expect_error(&x, dir_deriv(&x, W, VR_U, 1.0, &d), "dW/du (not provided)");
    expect_error(&x, dir_deriv(&x, VR_F, VR_SCALE, 1.0, &d), "derivative w.r.t. a parameter");
    release(&x);
}

/* Interleaved instances (and both FMI versions at once) give the results of one
 * instance run alone: no shared state. */
static void test_side_by_side(const api *a, const api *b)
{
    double alone[2 * N_HIST], inter[2 * N_HIST], mirrored[2 * N_HIST], other[2];
    inst x = start(a, "alone"), y = start(a, "y"), z = start(a, "z"), w = start(b, "w");
    int k;
    if (!x.c || !y.c || !z.c || !w.c) return;
    run(&x, 0, N_HIST, alone);
    for (k = 0; k < N_HIST; k++) {
        run(&y, k, 1, &inter[2 * k]);
        run(&z, N_HIST - k, 1, other);      /* another history in between */
        run(&w, k, 1, &mirrored[2 * k]);    /* the other FMI version, same history */
    }
    CHECK(memcmp(alone, inter, sizeof alone) == 0, "FMI %d: instances interfere", a->v);
    CHECK(memcmp(alone, mirrored, sizeof alone) == 0, "FMI %d and %d differ", a->v, b->v);
    release(&x);
    release(&y);
    release(&z);
    release(&w);
}

/* FMI 2 input derivatives (u and N together): one step of 2h equals two steps of
 * h along the same straight path; derivatives hold for one step only. */
static void test_input_derivatives(const api *a)
{
    inst x = start(a, "deriv1"), y = start(a, "deriv2");
    const unsigned int vrs[2] = {VR_U, VR_N};
    const fmi2Integer order[2] = {1, 1};
    const double rate[2] = {0.15 * U_SLIP / 1e-3, -0.02 * N_CURVE / 1e-3};
    double Fx, Fy, u0, u1;
    int k;
    if (!x.c || !y.c) return;
    for (k = 0; k < 3; k++) {
        CHECK(a->sid2(x.c, vrs, 2, order, rate) == 0 && do_step(&x, 2e-3) == 0, "deriv step");
        CHECK(a->sid2(y.c, vrs, 2, order, rate) == 0 && do_step(&y, 1e-3) == 0
              && a->sid2(y.c, vrs, 2, order, rate) == 0 && do_step(&y, 1e-3) == 0,
              "deriv steps");
    }
    get(&x, VR_F, &Fx);
    get(&y, VR_F, &Fy);
    CHECK(fabs(Fx - Fy) <= 1e-12 * fabs(Fx) && Fx != 0.0,
          "input derivatives: one step %.17g vs two %.17g", Fx, Fy);
    get(&x, VR_U, &u0);
    CHECK(fabs(u0 - 6e-3 * rate[0]) <= 1e-12 * fabs(u0), "u extrapolated to %g", u0);
    do_step(&x, 1e-3);
    get(&x, VR_U, &u1);
    CHECK(u1 == u0, "FMI 2: input derivative kept beyond its step (u %g -> %g)", u0, u1);
    expect_error(&x, a->sid2(x.c, vrs, 1, (const fmi2Integer[]){2}, rate), "order 2");
    release(&x);
    release(&y);
}

/* Unsupported functions (other types, Model Exchange, events, clocks) answer with
 * an error, also when handed NULL arrays. */
static void test_unsupported(const api *a)
{
    inst x = start(a, "unsupported");
    void *fn;
    const unsigned int vr = VR_U;
    if (!x.c) return;
    if (a->v == 2) {
        fmi2GetIntegerTYPE *gi;
        fmi2CancelStepTYPE *cancel;
        fmi2GetRealOutputDerivativesTYPE *god;
        *(void **)(&gi) = dlsym(a->lib, "fmi2GetInteger");
        *(void **)(&cancel) = dlsym(a->lib, "fmi2CancelStep");
        *(void **)(&god) = dlsym(a->lib, "fmi2GetRealOutputDerivatives");
        expect_error(&x, (int)gi(x.c, NULL, 1, NULL), "fmi2GetInteger(NULL arrays)");
        expect_error(&x, (int)cancel(x.c), "fmi2CancelStep");
        expect_error(&x, (int)god(x.c, &vr, 1, NULL, NULL), "fmi2GetRealOutputDerivatives");
    } else {
        fmi3EnterEventModeTYPE *event;
        fmi3GetInt32TYPE *gi;
        fmi3SetTimeTYPE *set_time;
        fmi3UpdateDiscreteStatesTYPE *update;
        fmi3GetAdjointDerivativeTYPE *adjoint;
        *(void **)(&event) = dlsym(a->lib, "fmi3EnterEventMode");
        *(void **)(&gi) = dlsym(a->lib, "fmi3GetInt32");
        *(void **)(&set_time) = dlsym(a->lib, "fmi3SetTime");
        *(void **)(&update) = dlsym(a->lib, "fmi3UpdateDiscreteStates");
        *(void **)(&adjoint) = dlsym(a->lib, "fmi3GetAdjointDerivative");
        expect_error(&x, (int)event(x.c), "fmi3EnterEventMode");
        expect_error(&x, (int)gi(x.c, &vr, 1, NULL, 1), "fmi3GetInt32");
        expect_error(&x, (int)set_time(x.c, 1.0), "fmi3SetTime");
        expect_error(&x, (int)update(x.c, NULL, NULL, NULL, NULL, NULL, NULL),
                     "fmi3UpdateDiscreteStates");
        expect_error(&x, (int)adjoint(x.c, &vr, 1, &vr, 1, NULL, 1, NULL, 1),
                     "fmi3GetAdjointDerivative");
    }
    fn = dlsym(a->lib, a->v == 2 ? "fmi2GetVersion" : "fmi3GetVersion");
    {
        const char *(*version)(void);
        *(void **)(&version) = fn;
        CHECK(version && strcmp(version(), a->v == 2 ? "2.0" : "3.0") == 0, "GetVersion");
    }
    CHECK(do_step(&x, 1e-3) == 0, "FMI %d: instance usable after refused calls", a->v);
    release(&x);
}

static int write_curve(const char *dir)
{
    char path[1100];
    FILE *f;
    int i;
    mkdir(dir, 0755);
    snprintf(path, sizeof path, "%s/curve.txt", dir);
    f = fopen(path, "w");
    if (!f) return 0;
    /* Cattaneo-Mindlin: T = mu N (1 - (1 - u/u_s)^(3/2)), mu = 0.5, 21 points */
    fprintf(f, "damper-curve 1\nn_ref %.17g\nfit 0\npoints 21\n", N_CURVE);
    for (i = 0; i <= 20; i++) {
        double u = U_SLIP * i / 20.0;
        fprintf(f, "%.17g %.17g\n", u, 0.5 * N_CURVE * (1.0 - pow(1.0 - u / U_SLIP, 1.5)));
    }
    return fclose(f) == 0;
}

int main(int argc, char **argv)
{
    static api a2, a3;
    if (argc != 4) {
        fprintf(stderr, "usage: %s <fmi2 damper.so> <fmi3 damper.so> <scratch dir>\n", argv[0]);
        return 2;
    }
    if (!write_curve(argv[3])) {
        fprintf(stderr, "cannot write the curve into %s\n", argv[3]);
        return 2;
    }
    if (load(&a2, 2, argv[1], argv[3]) && load(&a3, 3, argv[2], argv[3])) {
        const api *apis[2] = {&a2, &a3};
        int i;
        for (i = 0; i < 2; i++) {
            test_instantiation_errors(apis[i], argv[3]);
            test_state_machine(apis[i]);
            test_nonfinite_inputs(apis[i]);
            test_rollback_and_serialization(apis[i]);
            test_directional_derivatives(apis[i]);
            test_side_by_side(apis[i], apis[1 - i]);
            test_unsupported(apis[i]);
        }
        test_input_derivatives(&a2);
    }
    if (a2.lib) dlclose(a2.lib);
    if (a3.lib) dlclose(a3.lib);
    printf("fmu_test_harness: %d checks, %d failures\n", g_checks, g_failures);
    return g_failures ? 1 : 0;
}
