/*
 * test_iwan_lanes.c -- prints every output of the core for a fixed history as exact
 * hexadecimal doubles (%a). Built twice (CMakeLists.txt): with the vector sweep
 * (GCC/Clang vector extensions) and with the portable scalar sweep
 * (IWAN_SCALAR_SWEEP, what other compilers build); ctest iwan_sweep_lanes runs
 * both and requires identical text, i.e. the same bits from either build.
 */
#include "iwan.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>

#define NS 120

static void put(const char *what, int i, double x)
{
    printf("%s %d %a\n", what, i, x);
}

/* History: random reversals (64-bit LCG, fixed seed), N constant for the first
 * half, then varying with a lift-off, for a model of `n` sliders. */
static int run(const double *k, const double *fs, size_t n, double k_res)
{
    iwan_model m;
    iwan_state s;
    iwan_output o;
    double u[NS], N[NS], F[NS], kt[NS], dFdN[NS], W[NS], x = 0.0, Wc;
    uint64_t seed = 977u;
    if (iwan_model_from_sliders(&m, k, fs, n, k_res, 2.0) != IWAN_OK) return 1;
    m.scale = 0.9;
    for (int i = 0; i < NS; ++i) {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        x += ((double)(seed >> 11) / 9007199254740992.0 - 0.5) * 4e-6;
        u[i] = x;
        N[i] = i < NS / 2 ? 2.0 : 2.0 + 1.5 * sin(0.3 * i);
    }
    iwan_state_init(&m, &s, 2.0);
    for (int i = 0; i < NS; ++i) {
        if (iwan_step(&m, &s, u[i], N[i], &o) != IWAN_OK) return 1;
        put("F", i, o.F); put("kt", i, o.kt); put("dFdN", i, o.dFdN);
        put("W", i, o.W); put("E", i, o.E); put("slip", i, o.slip);
        if (iwan_eval(&m, &s, u[i] + 1e-7, N[i], NULL, &o) != IWAN_OK) return 1;
        put("eval F", i, o.F); put("eval E", i, o.E);
    }
    iwan_state_init(&m, &s, 2.0);
    if (iwan_series(&m, &s, NS, u, N, F, kt, dFdN, W) != IWAN_OK) return 1;
    for (int i = 0; i < NS; ++i) { put("sF", i, F[i]); put("skt", i, kt[i]); put("sW", i, W[i]); }
    if (iwan_periodic(&m, NS / 2, u, NULL, F, kt, dFdN, &Wc, 1, 0.0, NULL) != IWAN_OK) return 1;
    for (int i = 0; i < NS / 2; ++i) { put("pF", i, F[i]); put("pdFdN", i, dFdN[i]); }
    put("pW", 0, Wc);
    return 0;
}

int main(void)
{
    double k[7], fs[7];
    for (int j = 0; j < 7; ++j) {      /* odd count: the pairs and the tail */
        k[j] = 1e6 * (1.0 + 0.3 * j);
        fs[j] = k[j] * 1e-7 * (1.0 + j * j);
    }
    int bad = run(k, fs, 7, 1e4) || run(k, fs, 6, 0.0) || run(k, fs, 1, 0.0);
    if (bad) fprintf(stderr, "test_iwan_lanes: a call failed\n");
    return bad;
}
