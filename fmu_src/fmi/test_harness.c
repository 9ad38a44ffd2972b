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
 * side giving the results of one instance alone; a state restored into a fresh
 * instance (straight after instantiation, or during initialization) continuing
 * bit-identically; the same results under a decimal-comma locale (when the process
 * can switch to de_DE.UTF-8 or fr_FR.UTF-8). Exit status 0 when all pass.
 * Meant to run under valgrind as well (ctest fmu_harness_valgrind).
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "harness_api.h"

/* Finite differences of a piecewise-linear force: exact up to round-off when the
 * increment crosses no slider switch; relative tolerance for that round-off. */
#define FD_RTOL 1e-6

/* ------------------------------------------------------------ test history */
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
    /* Instantiated: start values, and outputs of the virgin history at the start inputs */
    CHECK(get(&x, VR_N_REF, &v) == 0 && v == N_CURVE && get(&x, VR_F, &v) == 0 && v == 0.0,
          "FMI %d: GetReal in Instantiated (start values): %s", a->v, g_last_log);
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
    expect_error(&x, do_step(&x, 0.0), "DoStep with h = 0");
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
    /* finite inputs beyond the input bound (double precision cannot resolve the slip
     * distances there): refused with a message naming the bound, history kept */
    logs = g_log_count;
    expect_error(&x, set(&x, VR_U, -1e300), "an input beyond the bound");
    expect_error(&x, set(&x, VR_U, 1e12), "u = 1e12");
    CHECK(g_log_count > logs && strstr(g_last_log, "bound"),
          "FMI %d: bound not logged clearly: '%s'", a->v, g_last_log);
    /* an input derivative that would carry u beyond the bound within the step */
    if (a->v == 2) {
        const unsigned int vu = VR_U;
        const int order = 1;
        const double du = 1e15;
        CHECK(a->sid2(x.c, &vu, 1, &order, &du) == 0, "FMI 2: set input derivative");
        expect_error(&x, do_step(&x, 1e-3), "a step extrapolated beyond the bound");
        CHECK(strstr(g_last_log, "bound") != NULL, "FMI 2: '%s'", g_last_log);
        CHECK(a->sid2(x.c, &vu, 1, &order, &(const double){0.0}) == 0, "FMI 2: derivative 0");
    }
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
    {   /* 1000 states with 1..4 bytes changed at random places: every one refused */
        unsigned char *bad = (unsigned char *)malloc(size);
        unsigned int seed = 20261123u, k, j, refused = 0;
        void *s3 = NULL;
        for (k = 0; bad && k < 1000; k++) {
            size_t pos;
            memcpy(bad, bytes, size);
            seed = seed * 1103515245u + 12345u;
            pos = (seed >> 8) % size;
            for (j = 0; j <= k % 4; j++) {  /* distinct bytes, each really changed */
                seed = seed * 1103515245u + 12345u;
                bad[(pos + 97u * j) % size] ^= (unsigned char)(1u + (seed >> 20) % 255u);
            }
            refused += deserialize(&y, bad, size, &s3) == 3;
        }
        CHECK(refused == 1000, "FMI %d: %u of 1000 corrupted states refused", a->v, refused);
        free(bad);
    }
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

/* A state restored into a fresh instance continues bit-identically: straight after
 * instantiation (the state brings step mode and its time), and during initialization
 * (Exit Initialization Mode keeps the restored history instead of a virgin one). */
static void test_restore_into_fresh_instances(const api *a)
{
    double first[2 * N_HIST], again[2 * N_HIST];
    inst x = start(a, "orig"), y = {a, NULL, 0.0};
    void *s = NULL, *s2 = NULL;
    unsigned char *bytes = NULL;
    size_t size = 0;
    int init;
    if (!x.c) return;
    run(&x, 0, 40, first);
    CHECK(get_state(&x, &s) == 0 && serialize(&x, s, &bytes, &size) == 0, "FMI %d: save", a->v);
    run(&x, 40, N_HIST - 40, first);
    for (init = 0; init < 2; init++) {
        y.c = instantiate(a, "fresh", DAMPER_TOKEN, a->resources);
        y.t = 0.0;
        if (!y.c) break;
        if (init) CHECK(enter_init(&y) == 0, "FMI %d: enter init", a->v);
        CHECK(deserialize(&y, bytes, size, &s2) == 0 && set_state(&y, s2) == 0,
              "FMI %d: restore %s: %s", a->v, init ? "in init" : "after instantiation", g_last_log);
        if (init) CHECK(exit_init(&y) == 0, "FMI %d: exit init after restore", a->v);
        y.t = 40 * 1e-3;
        run(&y, 40, N_HIST - 40, again);
        CHECK(memcmp(first, again, 2 * (N_HIST - 40) * sizeof(double)) == 0,
              "FMI %d: restored %s: continuation differs", a->v,
              init ? "during initialization" : "after instantiation");
        free_state(&y, &s2);
        release(&y);
    }
    free_state(&x, &s);
    free(bytes);
    release(&x);
}

/* Instantiation and results under a decimal-comma locale equal those in "C". */
static void test_decimal_comma_locale(const api *a)
{
    static const char *const names[2] = {"de_DE.UTF-8", "fr_FR.UTF-8"};
    double plain[2 * N_HIST], comma[2 * N_HIST];
    inst x = start(a, "C locale");
    int i;
    if (!x.c) return;
    run(&x, 0, N_HIST, plain);
    release(&x);
    for (i = 0; i < 2 && !setlocale(LC_ALL, names[i]); i++) {}
    if (i == 2) {
        printf("FMI %d: no decimal-comma locale (make locale generates one): skipped\n", a->v);
        return;
    }
    CHECK(strcmp(localeconv()->decimal_point, ",") == 0, "%s has no decimal comma", names[i]);
    x = start(a, "comma locale");
    if (x.c) {
        run(&x, 0, N_HIST, comma);
        CHECK(memcmp(plain, comma, sizeof plain) == 0, "FMI %d: results differ under %s",
              a->v, names[i]);
        release(&x);
    }
    setlocale(LC_ALL, "C");
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
            check_instantiation_errors(apis[i], DAMPER_TOKEN, apis[i]->v == 2 ? "file:///nonexistent/dir"
                                                                              : "/nonexistent/");
            test_state_machine(apis[i]);
            test_nonfinite_inputs(apis[i]);
            test_rollback_and_serialization(apis[i]);
            test_restore_into_fresh_instances(apis[i]);
            test_decimal_comma_locale(apis[i]);
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
