/*
 * bench_driver.c -- a minimal C co-simulation master for timing one doStep.
 *
 * Usage: fmu_bench_driver <damper.so (FMI 2)> <resource URI> <steps> <amplitude [m]>
 *                         <points per cycle> <repeats>
 *
 * Loads the FMI 2 binary with dlopen, then per step: fmi2SetReal(u), fmi2DoStep,
 * fmi2GetReal(F, W), with u = amplitude sin(2 pi k / points) (one cycle tabulated
 * before timing, so libm is not timed). Built against the variable table of fmu_vars.h:
 * for the contact point (point_vr.h) a step sets u_x = amplitude cos, u_y = amplitude
 * sin and p = p0 (1 + 0.2 sin 3 t) (p0 its start value) and gets F_x and W. Prints the
 * best (over
 * `repeats` fresh instances) wall time per step in ns, F and W of the last step (so
 * the caller can check the numbers against the array API) and the peak RSS in KiB.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "fmi2FunctionTypes.h"
#include "fmu_vars.h"

#ifdef VR_U_X  /* the contact point: an orbit in the plane, the penetration varying */
#define N_IN 3
#define N_TAB 3
static const fmi2ValueReference VR_IN[N_IN] = {VR_U_X, VR_U_Y, VR_P}, VR_OUT[2] = {VR_F_X, VR_W};
#else          /* the 1D element (and the pass-through baseline): u */
#define N_IN 1
#define N_TAB 1
static const fmi2ValueReference VR_IN[N_IN] = {VR_U}, VR_OUT[2] = {VR_F, VR_W};
#endif

static void quiet_logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                         fmi2String category, fmi2String message, ...)
{
    (void)env; (void)name; (void)category;
    if (status >= fmi2Error) fprintf(stderr, "FMU: %s\n", message);
}

typedef struct {
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2SetRealTYPE *set;
    fmi2GetRealTYPE *get;
    fmi2DoStepTYPE *step;
} api;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* One fresh instance, `steps` steps; returns seconds per step (or -1 on error). */
static double run(const api *f, const char *uri, long steps, double amp, long points,
                  double out[2])
{
    static const fmi2CallbackFunctions cb = {quiet_logger, NULL, NULL, NULL, NULL};
    const double h = 1e-3, w = 2.0 * acos(-1.0) / (double)points;
    double t0, t1, *cycle = (double *)malloc((size_t)points * N_TAB * sizeof(double));
    long k;
    int bad = 0;
    fmi2Component c;
    if (!cycle) return -1.0;
    c = f->instantiate("bench", fmi2CoSimulation, DAMPER_TOKEN, uri, &cb,
                                     fmi2False, fmi2False);
    if (!c || f->setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) || f->enter(c) || f->exit_init(c)) {
        free(cycle);
        return -1.0;
    }
    for (k = 0; k < points; k++) {
#ifdef VR_U_X
        double p0 = 0.0;
        f->get(c, &VR_IN[2], 1, &p0);
        cycle[3 * k] = amp * cos(w * (double)k);
        cycle[3 * k + 1] = amp * sin(w * (double)k);
        cycle[3 * k + 2] = p0 * (1.0 + 0.2 * sin(3.0 * w * (double)k));
#else
        cycle[k] = amp * sin(w * (double)k);
#endif
    }
    t0 = now();
    for (k = 0; k < steps; k++) {
        bad |= f->set(c, VR_IN, N_IN, &cycle[N_TAB * (k % points)]);
        bad |= f->step(c, (double)k * h, h, fmi2True);
        bad |= f->get(c, VR_OUT, 2, out);
    }
    t1 = now();
    f->free_instance(c);
    free(cycle);
    return bad ? -1.0 : (t1 - t0) / (double)steps;
}

/* Peak resident memory of this process [KiB] (Linux /proc), or -1. */
static long peak_rss_kib(void)
{
    char line[256];
    long kib = -1;
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return -1;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %ld", &kib) == 1) break;
    fclose(f);
    return kib;
}

#define SYM(field, name) (*(void **)(&f.field) = dlsym(lib, name))

int main(int argc, char **argv)
{
    api f;
    void *lib;
    double best = -1.0, out[2] = {0.0, 0.0};
    long steps, points, repeats, r;
    if (argc != 7) {
        fprintf(stderr, "usage: %s <damper.so> <resource URI> <steps> <amplitude> "
                "<points per cycle> <repeats>\n", argv[0]);
        return 2;
    }
    lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    SYM(instantiate, "fmi2Instantiate"); SYM(free_instance, "fmi2FreeInstance");
    SYM(setup, "fmi2SetupExperiment"); SYM(enter, "fmi2EnterInitializationMode");
    SYM(exit_init, "fmi2ExitInitializationMode"); SYM(set, "fmi2SetReal");
    SYM(get, "fmi2GetReal"); SYM(step, "fmi2DoStep");
    steps = atol(argv[3]);
    points = atol(argv[5]);
    repeats = atol(argv[6]);
    for (r = 0; r < repeats; r++) {
        double s = run(&f, argv[2], steps, atof(argv[4]), points, out);
        if (s < 0.0) {
            fprintf(stderr, "the FMU refused a call\n");
            return 1;
        }
        if (best < 0.0 || s < best) best = s;
    }
    printf("%.6f %.17g %.17g %ld\n", best * 1e9, out[0], out[1], peak_rss_kib());
    dlclose(lib);
    return 0;
}
