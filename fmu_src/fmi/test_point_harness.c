/*
 * test_point_harness.c -- our own importer test of the contact-point FMU binaries
 * (model_point.c; variables point_vr.h).
 *
 * Usage: fmu_point_harness <fmi2 contact_point.so> <fmi3 contact_point.so> <scratch dir>
 *
 * Writes a curve and a normal law into the scratch folder, loads both binaries with
 * dlopen and drives them through the FMI C API: start values (p at the start load),
 * refused calls (outputs set, non-finite inputs, negative dashpots) with the instance
 * left as it was; a history with lift-off and re-contact that FMI 2 and FMI 3 give to
 * the bit; rollback and serialization with bit-identical continuations and corrupted
 * states refused; the directional derivatives of F_x, F_y, N against central
 * differences of trial evaluations and equal to the K outputs. Meant to run under
 * valgrind as well (ctest fmu_point_harness_valgrind).
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "harness_api.h"

/* Central differences at 1e-6 of the slip distance away from switches: truncation
 * O(h^2) of the smooth tractrix, round-off ~1e-16 / 1e-6 of the force scale. */
#define FD_RTOL 1e-6
#define P_REF 1.0e-6        /* penetration scale of the normal law [m] */
#define N_STEPS 120          /* samples of the test history */

static const unsigned int Q[3] = {VR_U_X, VR_U_Y, VR_P};
static const unsigned int FORCE[3] = {VR_F_X, VR_F_Y, VR_N};
static const unsigned int KOUT[9] = {VR_K_XX, VR_K_XY, VR_K_XP, VR_K_YX, VR_K_YY, VR_K_YP,
                                     VR_K_PX, VR_K_PY, VR_K_PP};

static void expect_error(inst *x, int status, const char *what)
{
    CHECK(status == 3, "FMI %d: %s returned %d, expected an error", x->a->v, what, status);
}

/* Sample k of the test history: an ellipse in the plane, p through lift-off. */
static void hist(int k, double *q)
{
    const double t = 0.15 * k;
    q[0] = 1.2 * U_SLIP * cos(t);
    q[1] = 0.6 * U_SLIP * sin(1.3 * t);
    q[2] = P_REF * (0.5 + 0.7 * sin(0.4 * t));
}

/* Samples k0 .. k0+n-1: set q, doStep; F_x, F_y, N, W after each into out[4n]. */
static void run(inst *x, int k0, int n, double *out)
{
    int k, i;
    for (k = 0; k < n; k++) {
        double q[3];
        int ok = 1;
        hist(k0 + k, q);
        for (i = 0; i < 3; i++) ok = ok && set(x, Q[i], q[i]) == 0;
        ok = ok && do_step(x, 1e-3) == 0;
        for (i = 0; i < 3; i++) ok = ok && get(x, FORCE[i], &out[4 * k + i]) == 0;
        ok = ok && get(x, VR_W, &out[4 * k + 3]) == 0;
        CHECK(ok, "FMI %d: step %d failed: %s", x->a->v, k0 + k, g_last_log);
        if (!ok) return;
    }
}

static void test_start_and_refusals(const api *a)
{
    inst x = start(a, "start");
    double p, N, before, after;
    const double bad[2] = {NAN, INFINITY};
    int i, j, logs;
    if (!x.c) return;
    CHECK(get(&x, VR_P, &p) == 0 && get(&x, VR_N, &N) == 0 && fabs(N - N_CURVE) < 1e-9 * N_CURVE
          && p > 0.0, "FMI %d: start p = %g should carry N_ref, N = %g", a->v, p, N);
    expect_error(&x, set(&x, VR_F_X, 1.0), "setting an output");
    expect_error(&x, set(&x, VR_C_T, 1.0), "a fixed parameter in step mode");
    for (i = 0; i < 2; i++)
        for (j = 0; j < 3; j++) {
            get(&x, Q[j], &before);
            logs = g_log_count;
            expect_error(&x, set(&x, Q[j], bad[i]), "a non-finite input");
            CHECK(g_log_count > logs && strstr(g_last_log, "NaN or infinite"),
                  "FMI %d: non-finite input not logged clearly: '%s'", a->v, g_last_log);
            get(&x, Q[j], &after);
            CHECK(memcmp(&before, &after, sizeof before) == 0, "FMI %d: bad input stored", a->v);
        }
    expect_error(&x, set(&x, VR_U_X, 1e12), "u_x beyond the bound");
    /* a penetration whose normal energy would overflow: refused at SetReal (not at the
     * next call), the input unchanged; a deep but representable one is accepted */
    get(&x, VR_P, &before);
    expect_error(&x, set(&x, VR_P, 1e300), "p beyond the bound");
    CHECK(strstr(g_last_log, "beyond the bound") != NULL, "FMI %d: p bound not logged: '%s'",
          a->v, g_last_log);
    get(&x, VR_P, &after);
    CHECK(before == after, "FMI %d: p beyond the bound stored", a->v);
    CHECK(set(&x, VR_P, 1e3 * P_REF) == 0 && do_step(&x, 1e-3) == 0 && get(&x, VR_N, &N) == 0
          && isfinite(N) && N > N_CURVE, "FMI %d: a deep penetration refused: %s", a->v, g_last_log);
    CHECK(set(&x, VR_P, p) == 0, "FMI %d: p back to the start", a->v);
    /* a step whose end t + h is not a finite number: refused, the time unchanged */
    CHECK(do_step(&x, 1e308) == 0, "FMI %d: a step of 1e308 s: %s", a->v, g_last_log);
    expect_error(&x, do_step(&x, 1e308), "t + h = inf");
    CHECK(strstr(g_last_log, "overflows") != NULL, "FMI %d: t + h overflow not logged: '%s'",
          a->v, g_last_log);
    CHECK(do_step(&x, 1.0) == 0, "FMI %d: a finite step after the refusal: %s", a->v, g_last_log);
    release(&x);
    x.t = 0.0;
    x.c = instantiate(a, "neg", DAMPER_TOKEN, a->resources);
    if (!x.c) return;
    CHECK(enter_init(&x) == 0, "FMI %d: enter init", a->v);
    expect_error(&x, set(&x, VR_C_N, -1.0), "a negative dashpot");
    release(&x);
}

/* FMI 2 and FMI 3 binaries give the same bits; save, continue, restore, continue
 * again: bit-identical, also through serialized bytes into another instance;
 * corrupted bytes refused. */
static void test_history_and_states(const api *a2, const api *a3)
{
    static double first[4 * N_STEPS], again[4 * N_STEPS], other[4 * N_STEPS];
    inst x = start(a2, "two"), y = start(a3, "three"), z = start(a2, "other");
    void *s = NULL, *s2 = NULL;
    unsigned char *bytes = NULL;
    size_t size = 0, pos;
    int refused = 0;
    if (!x.c || !y.c || !z.c) return;
    run(&x, 0, N_STEPS, first);
    run(&y, 0, N_STEPS, again);
    CHECK(memcmp(first, again, sizeof first) == 0, "FMI 2 and 3 differ");
    CHECK(first[4 * (N_STEPS - 1) + 3] > 0.0, "no friction work in the history");
    CHECK(get_state(&x, &s) == 0 && serialize(&x, s, &bytes, &size) == 0,
          "get/serialize state: %s", g_last_log);
    run(&x, N_STEPS, N_STEPS, first);
    x.t -= N_STEPS * 1e-3;
    CHECK(set_state(&x, s) == 0, "SetFMUState");
    run(&x, N_STEPS, N_STEPS, again);
    CHECK(memcmp(first, again, sizeof first) == 0, "rollback not bit-identical");
    CHECK(bytes && deserialize(&z, bytes, size, &s2) == 0 && set_state(&z, s2) == 0,
          "deserialize into another instance: %s", g_last_log);
    z.t = N_STEPS * 1e-3;
    run(&z, N_STEPS, N_STEPS, other);
    CHECK(memcmp(first, other, sizeof first) == 0, "deserialized continuation not bit-identical");
    for (pos = 0; bytes && pos < size; pos += size / 97 + 1) {  /* one byte changed: refused */
        void *s3 = NULL;
        bytes[pos] ^= 0x5a;
        refused += deserialize(&z, bytes, size, &s3) == 3;
        bytes[pos] ^= 0x5a;
    }
    CHECK(bytes && refused == (int)(size / (size / 97 + 1) + (size % (size / 97 + 1) != 0)),
          "a corrupted state was accepted (%d refused)", refused);
    free_state(&x, &s);
    free_state(&z, &s2);
    free(bytes);
    release(&x);
    release(&y);
    release(&z);
}

/* d f / d q at trial inputs (set, not stepped) against central differences of the
 * getters; the K outputs carry the same numbers. */
static void test_directional_derivatives(const api *a)
{
    inst x = start(a, "dd");
    double out[4 * 30];
    int k, checked = 0;
    if (!x.c) return;
    run(&x, 0, 30, out);                            /* into slip, p varying */
    for (k = 0; k < 6; k++) {
        double q[3], d[9], fd[9], K[9], scale = 0.0, err = 0.0;
        int i, j;
        hist(30 + k, q);
        q[2] += 0.03 * P_REF;                       /* trial point off the history */
        for (i = 0; i < 3; i++) set(&x, Q[i], q[i]);
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++) {
                const double h = j < 2 ? 1e-6 * U_SLIP : 1e-6 * P_REF;
                double fp, fm;
                CHECK(dir_deriv(&x, FORCE[i], Q[j], 1.0, &d[3 * i + j]) == 0,
                      "FMI %d: directional derivative: %s", a->v, g_last_log);
                set(&x, Q[j], q[j] + h);
                get(&x, FORCE[i], &fp);
                set(&x, Q[j], q[j] - h);
                get(&x, FORCE[i], &fm);
                set(&x, Q[j], q[j]);
                fd[3 * i + j] = (fp - fm) / (2 * h);
                get(&x, KOUT[3 * i + j], &K[3 * i + j]);
                scale = fmax(scale, fabs(d[3 * i + j]));
            }
        for (i = 0; i < 9; i++) {
            err = fmax(err, fabs(fd[i] - d[i]));
            CHECK(K[i] == d[i], "FMI %d: K output %d = %g, directional derivative %g", a->v, i,
                  K[i], d[i]);
        }
        checked += err <= FD_RTOL * scale;          /* no slider switch within +-h */
        do_step(&x, 1e-3);
    }
    CHECK(checked >= 5, "FMI %d: directional derivatives vs differences: %d of 6", a->v, checked);
    {
        double dv;
        CHECK(dir_deriv(&x, VR_F_X, VR_V_X, 1.0, &dv) == 0 && dv == 0.0, "dF_x/dv_x (c_t = 0)");
        expect_error(&x, dir_deriv(&x, VR_W, VR_U_X, 1.0, &dv), "dW/du_x (not provided)");
    }
    release(&x);
}

static int write_resources(const char *dir)
{
    char path[1100];
    FILE *f;
    int i;
    mkdir(dir, 0755);
    snprintf(path, sizeof path, "%s/curve.txt", dir);
    f = fopen(path, "w");
    if (!f) return 0;
    /* Cattaneo-Mindlin: T = mu N (1 - (1 - u/u_s)^(3/2)), mu = 0.5, 21 points, flat tail */
    fprintf(f, "damper-curve 1\nn_ref %.17g\nfit 0\npoints 22\n", N_CURVE);
    for (i = 0; i <= 20; i++) {
        double u = U_SLIP * i / 20.0;
        fprintf(f, "%.17g %.17g\n", u, 0.5 * N_CURVE * (1.0 - pow(1.0 - u / U_SLIP, 1.5)));
    }
    fprintf(f, "%.17g %.17g\n", 2.0 * U_SLIP, 0.5 * N_CURVE);
    if (fclose(f) != 0) return 0;
    snprintf(path, sizeof path, "%s/normal.txt", dir);
    f = fopen(path, "w");
    if (!f) return 0;
    /* Hertz-like N = N_CURVE (p / P_REF)^1.5 at 7 points; N_CURVE at p = P_REF */
    fprintf(f, "damper-normal 1\np_start %.17g\npoints 7\n", P_REF);
    for (i = 0; i <= 6; i++)
        fprintf(f, "%.17g %.17g\n", i * P_REF / 3.0, N_CURVE * pow(i / 3.0, 1.5));
    return fclose(f) == 0;
}

int main(int argc, char **argv)
{
    static api a2, a3;
    if (argc != 4) {
        fprintf(stderr, "usage: %s <fmi2 contact_point.so> <fmi3 contact_point.so> <dir>\n",
                argv[0]);
        return 2;
    }
    if (!write_resources(argv[3])) {
        fprintf(stderr, "cannot write the resources into %s\n", argv[3]);
        return 2;
    }
    if (load(&a2, 2, argv[1], argv[3]) && load(&a3, 3, argv[2], argv[3])) {
        test_start_and_refusals(&a2);
        test_start_and_refusals(&a3);
        test_history_and_states(&a2, &a3);
        test_directional_derivatives(&a2);
        test_directional_derivatives(&a3);
    }
    if (a2.lib) dlclose(a2.lib);
    if (a3.lib) dlclose(a3.lib);
    printf("fmu_point_harness: %d checks, %d failures\n", g_checks, g_failures);
    return g_failures ? 1 : 0;
}
