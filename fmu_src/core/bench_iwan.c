/*
 * bench_iwan.c -- C driver timing iwan_series (run by examples/bench_element.py).
 *
 *     bench_iwan N_SLIDERS N_SAMPLES REPEATS
 *
 * History: u = a (0.8 sin t + 0.3 sin 3.7 t) over 10 periods, amplitude such that
 * about half the sliders slip in each cycle (the realistic, branchy case).
 * Prints one line: n_sliders n_samples ns_per_sample ns_per_slider_update checksum.
 */
#define _POSIX_C_SOURCE 199309L
#include "iwan.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: bench_iwan N_SLIDERS N_SAMPLES REPEATS\n");
        return 2;
    }
    const int ns = atoi(argv[1]), n = atoi(argv[2]), reps = atoi(argv[3]);
    if (ns < 1 || ns > IWAN_MAX_SLIDERS || n < 1 || reps < 1) {
        fprintf(stderr, "bench_iwan: bad sizes\n");
        return 2;
    }
    double k[IWAN_MAX_SLIDERS], fs[IWAN_MAX_SLIDERS];
    for (int j = 0; j < ns; ++j) {       /* slip radii 1e-7 .. 2e-6 m */
        k[j] = 1e6 / ns;
        fs[j] = k[j] * (1e-7 + 1.9e-6 * j / (ns > 1 ? ns - 1 : 1));
    }
    iwan_model m;
    iwan_state s;
    if (iwan_model_from_sliders(&m, k, fs, (size_t)ns, 1e5, 1.0) != IWAN_OK) return 1;
    double *u = malloc(sizeof(double) * n), *F = malloc(sizeof(double) * n);
    double *kt = malloc(sizeof(double) * n), *dFdN = malloc(sizeof(double) * n);
    double *W = malloc(sizeof(double) * n);
    if (!u || !F || !kt || !dFdN || !W) return 1;
    for (int i = 0; i < n; ++i) {
        const double t = 20.0 * 3.141592653589793 * i / n;
        u[i] = 2e-6 * (0.8 * sin(t) + 0.3 * sin(3.7 * t));
    }
    double best = INFINITY, checksum = 0.0;
    for (int r = 0; r < reps; ++r) {
        iwan_state_init(&m, &s, 1.0);
        const double t0 = now();
        if (iwan_series(&m, &s, (size_t)n, u, NULL, F, kt, dFdN, W) != IWAN_OK) return 1;
        const double dt = now() - t0;
        if (dt < best) best = dt;
        checksum += F[n - 1] + W[n - 1];
    }
    printf("%d %d %.4f %.4f %.17g\n", ns, n, 1e9 * best / n, 1e9 * best / ((double)n * ns), checksum);
    free(u); free(F); free(kt); free(dFdN); free(W);
    return 0;
}
