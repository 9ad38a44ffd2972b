/*
 * iwan_sweep.h -- the constant-N one-pass sweep of the Iwan core (private; included
 * by iwan.c only): static inline code, specialised by the compiler for each
 * direction of motion and each use (step with outputs, time series, outputs of a
 * state). Symbols as in iwan.c.
 */
#ifndef IWAN_SWEEP_H
#define IWAN_SWEEP_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "iwan.h"

/* At constant N > 0 the exact update of a slider reduces to the play operator
 * z <- clamp(z, u - r, u + r) and its friction work to g |dz| = f fs |dz|. Moving
 * up, only the lower bound can bind for a state within its limits (z <= u0 + r <=
 * u + r): z <- max(z, u - r), and the slider slips iff it binds, i.e. it is
 * "slipping" in the sense of the outputs (at its limit on the side of the motion);
 * mirror for down. Every path of the core leaves the states within their limits.
 * The same pass gives every output, so a step at constant N, the time series and
 * the outputs of any state run this one code and agree to the bit (iwan.h).
 * Lane L sums sliders j = L mod 2 (two short add chains; fs_sum uses the same order). */
typedef struct {
    double F;    /* sum k_j (u - z_j) [N] */
    double ks;   /* sum of k_j over sticking sliders [N/m] */
    double fsl;  /* sum of fs_j over slipping sliders [N] */
    double w;    /* sum fs_j |dz_j| (work / f) [N m] */
    double E2;   /* sum k_j (u - z_j)^2 (twice the sliders' stored energy) [J] */
} sweep_sums;

#if defined(__GNUC__)
#define IWAN_INLINE static inline __attribute__((always_inline))
#else
#define IWAN_INLINE static inline
#endif

/* Slider J in lane L; SIDE = +1.0 (moving up) or -1.0 (down), a constant. The
 * selections multiply by exact 0.0 / 1.0 (or take a max/min) so that no branch
 * depends on the data. */
#define SWEEP_SLIDER(J, L)                                                      \
    do {                                                                        \
        const double z0 = z[J], r = m->rad[J] * f;                              \
        const double bind = u - SIDE * r;                                       \
        const double sl = (SIDE > 0.0 ? z0 <= bind : z0 >= bind) ? 1.0 : 0.0;   \
        const double zn = SIDE > 0.0 ? (z0 > bind ? z0 : bind)                  \
                                     : (z0 < bind ? z0 : bind);                 \
        const double e = u - zn, Fj = m->k[J] * e;                              \
        if (STORE) zout[J] = zn;                                                \
        w##L += m->fs[J] * (SIDE * (zn - z0));                                  \
        F##L += Fj;                                                             \
        if (WANT_E) E##L += Fj * e;                                             \
        ks##L += m->k[J] * (1.0 - sl);                                          \
        fsl##L += m->fs[J] * sl;                                                \
    } while (0)

#if defined(__GNUC__) && !defined(IWAN_SCALAR_SWEEP)
/* Two sliders per instruction (GCC/Clang vector extensions, SSE2 on x86-64): lane
 * L of a vector is lane L of the scalar code (sliders j = L mod 2) and every lane
 * does the same IEEE operations, so both give the same bits (ctest
 * iwan_sweep_lanes compares them). The selections by mask equal the scalar
 * code's multiplications by 0.0 / 1.0. */
#define IWAN_VECTOR_SWEEP 1
typedef double iwan_v2 __attribute__((vector_size(16)));
typedef int64_t iwan_m2 __attribute__((vector_size(16)));

static inline iwan_v2 load2(const double *p)
{
    iwan_v2 v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* mask ? a : b, lane by lane (mask lanes all ones or all zeros). */
static inline iwan_v2 select2(iwan_m2 mask, iwan_v2 a, iwan_v2 b)
{
    return (iwan_v2)(((iwan_m2)a & mask) | ((iwan_m2)b & ~mask));
}

/* Sliders 0 .. 2 floor(n/2) - 1 in pairs; returns the index of the first left over. */
IWAN_INLINE int32_t sweep_pairs(const iwan_model *m, const double *z, double *zout, double f,
                                double u, const double SIDE, const int STORE,
                                const int WANT_E, double lanes[5][2])
{
    const iwan_v2 zero = {0.0, 0.0}, uv = {u, u}, fv = {f, f}, sv = {SIDE, SIDE};
    iwan_v2 F = zero, ks = zero, fsl = zero, w = zero, E = zero;
    int32_t j = 0;
    for (; j + 1 < m->n; j += 2) {
        const iwan_v2 z0 = load2(z + j), k = load2(m->k + j), fs = load2(m->fs + j);
        const iwan_v2 bind = uv - sv * (load2(m->rad + j) * fv);
        const iwan_m2 sl = SIDE > 0.0 ? (iwan_m2)(z0 <= bind) : (iwan_m2)(z0 >= bind);
        const iwan_v2 zn = select2(sl, bind, z0);
        const iwan_v2 e = uv - zn, Fj = k * e;
        if (STORE) memcpy(zout + j, &zn, sizeof zn);
        w += fs * (sv * (zn - z0));
        F += Fj;
        if (WANT_E) E += Fj * e;
        ks += select2(sl, zero, k);
        fsl += select2(sl, fs, zero);
    }
    for (int L = 0; L < 2; ++L) {
        lanes[0][L] = F[L]; lanes[1][L] = ks[L]; lanes[2][L] = fsl[L];
        lanes[3][L] = w[L]; lanes[4][L] = E[L];
    }
    return j;
}
#endif

/* One pass over the sliders at displacement u and strength factor f, motion on
 * SIDE; writes the new positions to zout when STORE (zout may equal z). */
IWAN_INLINE void sweep(const iwan_model *m, const double *z, double *zout, double f,
                       double u, const double SIDE, const int STORE, const int WANT_E,
                       sweep_sums *acc)
{
    double F0 = 0.0, F1 = 0.0, ks0 = 0.0, ks1 = 0.0, fsl0 = 0.0, fsl1 = 0.0;
    double w0 = 0.0, w1 = 0.0, E0 = 0.0, E1 = 0.0;
    int32_t j = 0;
#ifdef IWAN_VECTOR_SWEEP
    double lanes[5][2];
    j = sweep_pairs(m, z, zout, f, u, SIDE, STORE, WANT_E, lanes);
    F0 = lanes[0][0]; F1 = lanes[0][1]; ks0 = lanes[1][0]; ks1 = lanes[1][1];
    fsl0 = lanes[2][0]; fsl1 = lanes[2][1]; w0 = lanes[3][0]; w1 = lanes[3][1];
    E0 = lanes[4][0]; E1 = lanes[4][1];
#endif
    for (; j + 1 < m->n; j += 2) {
        SWEEP_SLIDER(j, 0);
        SWEEP_SLIDER(j + 1, 1);
    }
    if (j < m->n) SWEEP_SLIDER(j, 0);
    acc->F = F0 + F1;
    acc->ks = ks0 + ks1;
    acc->fsl = fsl0 + fsl1;
    acc->w = w0 + w1;
    acc->E2 = E0 + E1;
}

/* The pass in the direction dir (+1 or -1), specialised for both (constant SIDE). */
IWAN_INLINE void sweep_dir(const iwan_model *m, const double *z, double *zout, double f,
                           double u, double dir, const int STORE, const int WANT_E,
                           sweep_sums *acc)
{
    if (dir > 0.0) sweep(m, z, zout, f, u, 1.0, STORE, WANT_E, acc);
    else sweep(m, z, zout, f, u, -1.0, STORE, WANT_E, acc);
}

#endif /* IWAN_SWEEP_H */
