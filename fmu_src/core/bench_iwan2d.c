/*
 * bench_iwan2d.c -- C driver timing one step of the 1D element, the 2D element and the
 * contact point, side by side in one process (run by examples/bench_contact2d.py).
 *
 *     bench_iwan2d N_SLIDERS SAMPLES_PER_CYCLE CYCLES REPEATS [CASE]
 *
 * Sliders: k_j = 1e6 / n N/m, slip radii 1e-7 .. 2e-6 m at N_ref = 1 N, k_res = 0.
 * Cases (each a step with its outputs and tangent, best of REPEATS fresh states):
 *   line1d    iwan_step,   u = a cos t                     (the 1D element)
 *   line2d    iwan2_step,  u = (a cos t, 0)                (the same path in 2D)
 *   circle    iwan2_step,  u = a (cos t, sin t), N = 1     (tractrix at constant N)
 *   circleN   iwan2_step,  the circle, N = 1 + 0.3 sin 3t  (varying N: quadrature)
 *   point     cpoint_step, the circle, p with N(p) = 1 + 0.3 sin 3t (penalty law)
 * with a = 1.5e-6 m (most sliders slip). Prints one line per case:
 *   case n_sliders samples ns_per_step ns_per_slider_update W_last_cycle
 * (only CASE when given: for instruction counts of one case).
 */
#define _POSIX_C_SOURCE 199309L
#include "contact_point.h"
#include "iwan.h"
#include "iwan2d.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define AMP 1.5e-6
#define K_N 1e6   /* penalty normal stiffness of the contact point [N/m] */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

typedef struct {
    const iwan_model *m;
    const cpoint_model *cp;
    const double *ux, *uy, *N;
    long n, per_cycle;
} bench;

/* Seconds per step of one case over the whole history; *W: work of the last cycle. */
static double run_case(const bench *b, int which, double *W)
{
    iwan_state s1;
    iwan2_state s2;
    cpoint_state sc;
    iwan_output o1;
    iwan2_output o2;
    cpoint_output oc;
    double t0, t1, w_before = 0.0, w_end = 0.0;
    long i;
    iwan_state_init(b->m, &s1, 1.0);
    iwan2_state_init(b->m, &s2, 1.0);
    cpoint_state_init(b->cp, &sc, 1.0 / K_N);
    t0 = now();
    for (i = 0; i < b->n; ++i) {
        const double N = which >= 3 ? b->N[i] : 1.0;
        if (i == b->n - b->per_cycle)
            w_before = which == 0 ? s1.w_diss : (which == 4 ? sc.s.w_diss : s2.w_diss);
        switch (which) {
        case 0: iwan_step(b->m, &s1, b->ux[i], 1.0, &o1); break;
        case 1: iwan2_step(b->m, &s2, b->ux[i], 0.0, 1.0, &o2); break;
        case 2: iwan2_step(b->m, &s2, b->ux[i], b->uy[i], 1.0, &o2); break;
        case 3: iwan2_step(b->m, &s2, b->ux[i], b->uy[i], N, &o2); break;
        default: {
            const double q[3] = {b->ux[i], b->uy[i], N / K_N};
            cpoint_step(b->cp, &sc, q, NULL, &oc);
        }
        }
    }
    t1 = now();
    w_end = which == 0 ? s1.w_diss : (which == 4 ? sc.s.w_diss : s2.w_diss);
    *W = w_end - w_before;
    return (t1 - t0) / (double)b->n;
}

int main(int argc, char **argv)
{
    static const char *names[5] = {"line1d", "line2d", "circle", "circleN", "point"};
    static const double pen[2] = {0.0, 1.0}, law[2] = {0.0, K_N};
    double k[IWAN_MAX_SLIDERS], fs[IWAN_MAX_SLIDERS];
    iwan_model m;
    cpoint_model cp;
    bench b;
    double *ux, *uy, *N;
    int ns, reps, c, r, j;
    long per, cycles, i;
    if (argc != 5 && argc != 6) {
        fprintf(stderr, "usage: bench_iwan2d N_SLIDERS SAMPLES_PER_CYCLE CYCLES REPEATS [CASE]\n");
        return 2;
    }
    ns = atoi(argv[1]);
    per = atol(argv[2]);
    cycles = atol(argv[3]);
    reps = atoi(argv[4]);
    if (ns < 1 || ns > IWAN_MAX_SLIDERS || per < 2 || cycles < 1 || reps < 1) {
        fprintf(stderr, "bench_iwan2d: bad sizes\n");
        return 2;
    }
    for (j = 0; j < ns; ++j) {
        k[j] = 1e6 / ns;
        fs[j] = k[j] * (1e-7 + 1.9e-6 * j / (ns > 1 ? ns - 1 : 1));
    }
    if (iwan_model_from_sliders(&m, k, fs, (size_t)ns, 0.0, 1.0) != IWAN_OK
        || cpoint_model_init(&cp, &m, pen, law, 2, 0.0, 0.0) != IWAN_OK)
        return 1;
    b.m = &m;
    b.cp = &cp;
    b.n = per * cycles;
    b.per_cycle = per;
    ux = malloc(sizeof(double) * (size_t)b.n);
    uy = malloc(sizeof(double) * (size_t)b.n);
    N = malloc(sizeof(double) * (size_t)b.n);
    if (!ux || !uy || !N) return 1;
    for (i = 0; i < b.n; ++i) {
        const double t = 2.0 * 3.141592653589793 * (double)i / (double)per;
        ux[i] = AMP * cos(t);
        uy[i] = AMP * sin(t);
        N[i] = 1.0 + 0.3 * sin(3.0 * t);
    }
    b.ux = ux;
    b.uy = uy;
    b.N = N;
    for (c = 0; c < 5; ++c) {
        double best = INFINITY, W = 0.0;
        if (argc == 6 && strcmp(argv[5], names[c]) != 0) continue;
        for (r = 0; r < reps; ++r) {
            const double s = run_case(&b, c, &W);
            if (s < best) best = s;
        }
        printf("%s %d %ld %.4f %.4f %.17g\n", names[c], ns, b.n, 1e9 * best, 1e9 * best / ns, W);
    }
    free(ux);
    free(uy);
    free(N);
    return 0;
}
