/*
 * harness_api.h -- the FMI 2 / FMI 3 driver of the C test harnesses (test_harness.c
 * for the 1D element, test_point_harness.c for the contact point, test_model_harness.c
 * for the blade and the damper; fmu_vars.h gives the variable table each is compiled with):
 * one `api` per dlopen'ed binary, one `inst` per instance, and calls that return
 * the FMI status as int for both versions (OK = 0, Error = 3 in both).
 */
#ifndef HARNESS_API_H
#define HARNESS_API_H

#include <stddef.h>

#include "fmu_vars.h"
#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"

#define N_CURVE 200.0     /* normal load of the harness curve [N] */
#define U_SLIP 2.0e-6     /* gross-slip displacement of the harness curve [m] */
#define N_HIST 100        /* samples of the test histories */

extern int g_failures, g_checks, g_log_count;
extern char g_last_log[1024];

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

extern const fmi2CallbackFunctions callbacks2;
void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
             fmi3String message);

/* dlopen `path`, check every required fmi2* (co-simulation) or fmi3* symbol. */
int load(api *a, int v, const char *path, const char *dir);
void *instantiate(const api *a, const char *name, const char *token, const char *res);
/* Instantiation that must fail: a wrong token (logged), the resource location `missing`
 * (no such folder; logged), a NULL location, Model Exchange. */
void check_instantiation_errors(const api *a, const char *token, const char *missing);
void release(inst *x);
int enter_init(inst *x);
int exit_init(inst *x);
int set(inst *x, unsigned int vr, double value);
int get(inst *x, unsigned int vr, double *value);
int do_step(inst *x, double h);
int get_state(inst *x, void **s);
int set_state(inst *x, void *s);
void free_state(inst *x, void **s);
int serialize(inst *x, void *s, unsigned char **bytes, size_t *size);
int deserialize(inst *x, const unsigned char *bytes, size_t size, void **s);
int dir_deriv(inst *x, unsigned int unknown, unsigned int known, double seed, double *d);
/* A ready instance in step mode (inputs at their start values), or c == NULL on failure. */
inst start(const api *a, const char *name);

#endif /* HARNESS_API_H */
