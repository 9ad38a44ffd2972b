/*
 * test_iwan.c -- unit tests of the Iwan core (iwan.h), plain C99, no framework.
 * Each check compares with a closed form (references.md) or an independent
 * computation; the Python tests (tests/element) cover the rest through the same
 * library. Exit status = number of failed checks.
 */
#include "iwan.h"
#include "iwan_internal.h"   /* the straight-path update, to check the fast path against */
#include "test_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Round-off of sums over a few hundred sliders and samples, relative. */
#define ROUNDOFF 1e-11
#define PI 3.14159265358979323846

/* Concave table: g(u) = 10 (1 - (1 - u/us)^1.5) on [0, us], 24 segments, flat tail. */
#define M_TAB 26
static void sphere_table(double *u, double *T)
{
    const double us = 2e-6;
    for (int i = 0; i <= 24; ++i) {
        T[i] = 10.0 * i / 24.0;
        u[i] = us * (1.0 - pow(1.0 - T[i] / 10.0, 2.0 / 3.0));
    }
    u[25] = 2.0 * us;
    T[25] = 10.0;
}

static double table_g(const double *u, const double *T, double x)
{
    double s = x < 0 ? -1.0 : 1.0, a = fabs(x);
    for (int i = 1; i < M_TAB; ++i)
        if (a <= u[i]) return s * (T[i - 1] + (T[i] - T[i - 1]) * (a - u[i - 1]) / (u[i] - u[i - 1]));
    return s * T[M_TAB - 1];
}

static void test_jenkins_loop_energy(void)
{
    const double k = 2e6, fs = 3.0, kk[1] = {k}, ff[1] = {fs};
    iwan_model m;
    CHECK(iwan_model_from_sliders(&m, kk, ff, 1, 0.0, 1.0) == IWAN_OK, "from_sliders");
    double u[100], F[100], kt[100], dfdn[100], W;
    int p;
    for (int c = 0; c < 3; ++c) {
        const double a = (c + 0.5) * 2.0 * fs / k;
        for (int i = 0; i < 100; ++i) u[i] = a * cos(2.0 * PI * i / 100.0);
        CHECK(iwan_periodic(&m, 100, u, NULL, F, kt, dfdn, &W, 10, 1e-12, &p) == IWAN_OK, "periodic");
        const double want = a > fs / k ? 4.0 * fs * (a - fs / k) : 0.0;
        CHECK(close_to(W, want, ROUNDOFF, 1e-20) && p == 1, "Jenkins W %g vs %g", W, want);
    }
}

static void test_table_and_masing_branches(void)
{
    double ut[M_TAB], Tt[M_TAB];
    sphere_table(ut, Tt);
    iwan_model m;
    CHECK(iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT) == IWAN_OK, "model_init");
    CHECK(m.n == 24 && m.k_res == 0.0, "slider count %d, k_res %g", (int)m.n, m.k_res);
    iwan_state s;
    CHECK(iwan_state_init(&m, &s, 5.0) == IWAN_OK, "state_init");
    double F[M_TAB];
    CHECK(iwan_series(&m, &s, M_TAB, ut, NULL, F, NULL, NULL, NULL) == IWAN_OK, "series");
    for (int i = 0; i < M_TAB; ++i)
        CHECK(close_to(F[i], Tt[i], 0, ROUNDOFF * 10.0), "virgin %d: %g vs %g", i, F[i], Tt[i]);
    /* reversal at u_r = 1.5e-6: branch F_r + 2 g((u - u_r)/2) */
    const double u_r = 1.5e-6, F_r = table_g(ut, Tt, u_r);
    iwan_output o;
    CHECK(iwan_state_init(&m, &s, 5.0) == IWAN_OK && iwan_step(&m, &s, u_r, 5.0, &o) == IWAN_OK, "load");
    for (int i = 1; i <= 20; ++i) {
        const double x = u_r - i * 1.4e-7;
        CHECK(iwan_step(&m, &s, x, 5.0, &o) == IWAN_OK, "step");
        const double want = F_r + 2.0 * table_g(ut, Tt, (x - u_r) / 2.0);
        CHECK(close_to(o.F, want, 0, ROUNDOFF * 10.0), "branch %g vs %g", o.F, want);
    }
}

static void test_bad_inputs(void)
{
    double ut[M_TAB], Tt[M_TAB];
    sphere_table(ut, Tt);
    iwan_model m, keep;
    CHECK(iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT) == IWAN_OK, "init");
    keep = m;
    Tt[4] -= 0.2;   /* dent (still increasing) */
    CHECK(iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT) == IWAN_ERR_NOT_CONCAVE, "concave");
    CHECK(memcmp(&m, &keep, sizeof m) == 0, "model untouched on failure");
    CHECK(iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_CONCAVE) == IWAN_OK && m.n < 24, "fit");
    Tt[4] += 0.2;
    ut[3] = NAN;
    CHECK(iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT) == IWAN_ERR_NONFINITE, "nan");
    ut[3] = ut[2];
    CHECK(iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT) == IWAN_ERR_BAD_TABLE, "u order");
    sphere_table(ut, Tt);
    CHECK(iwan_model_init(&m, ut, Tt, 1, 5.0, IWAN_FIT_REJECT) == IWAN_ERR_BAD_TABLE, "short");
    CHECK(iwan_model_init(&m, ut, Tt, M_TAB, 0.0, IWAN_FIT_REJECT) == IWAN_ERR_BAD_PARAM, "n_ref");
    CHECK(iwan_model_init(NULL, ut, Tt, M_TAB, 1.0, IWAN_FIT_REJECT) == IWAN_ERR_BAD_PARAM, "null");
    CHECK(iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT) == IWAN_OK, "init again");
    iwan_state s, s0;
    iwan_output o;
    iwan_state_init(&m, &s, 5.0);
    iwan_step(&m, &s, 1e-6, 5.0, &o);
    s0 = s;
    CHECK(iwan_step(&m, &s, NAN, 5.0, &o) == IWAN_ERR_NONFINITE, "nan u");
    CHECK(iwan_step(&m, &s, 1e-6, INFINITY, &o) == IWAN_ERR_NONFINITE, "inf N");
    CHECK(memcmp(&s, &s0, sizeof s) == 0, "state untouched on failure");
    s.version = 99;
    CHECK(iwan_step(&m, &s, 1e-6, 5.0, &o) == IWAN_ERR_BAD_STATE, "version");
    m.scale = -1.0;
    CHECK(iwan_step(&m, &s0, 1e-6, 5.0, &o) == IWAN_ERR_BAD_PARAM, "scale");
    CHECK(strlen(iwan_status_text(IWAN_ERR_NOT_CONCAVE)) > 0, "text");
}

/* Piecewise-linear (u, N) path: vertices only vs refined samples give the same
 * force at the vertices (exact straight-path update), with a lift-off on the way. */
static void test_sampling_independence_and_lift_off(void)
{
    double ut[M_TAB], Tt[M_TAB];
    sphere_table(ut, Tt);
    iwan_model m;
    iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT);
    enum { NV = 9, R = 7 };
    const double vu[NV] = {0, 1.2e-6, -0.4e-6, 0.9e-6, 3e-6, -1e-6, 0.2e-6, 0.5e-6, -2e-6};
    const double vN[NV] = {5, 6, 3, 8, -1, 2, 5, 9, 4};
    double cu[NV], cN[NV], Fc[NV], Wc[NV], fu[(NV - 1) * R + 1], fN[(NV - 1) * R + 1];
    double Ff[(NV - 1) * R + 1], Wf[(NV - 1) * R + 1];
    memcpy(cu, vu, sizeof cu);
    memcpy(cN, vN, sizeof cN);
    fu[0] = vu[0];
    fN[0] = vN[0];
    for (int i = 0; i + 1 < NV; ++i)
        for (int r = 1; r <= R; ++r) {
            fu[i * R + r] = vu[i] + (vu[i + 1] - vu[i]) * r / R;
            fN[i * R + r] = vN[i] + (vN[i + 1] - vN[i]) * r / R;
        }
    iwan_state a, b;
    iwan_state_init(&m, &a, 5.0);
    iwan_state_init(&m, &b, 5.0);
    CHECK(iwan_series(&m, &a, NV, cu, cN, Fc, NULL, NULL, Wc) == IWAN_OK, "coarse");
    CHECK(iwan_series(&m, &b, (NV - 1) * R + 1, fu, fN, Ff, NULL, NULL, Wf) == IWAN_OK, "fine");
    for (int i = 0; i < NV; ++i) {
        CHECK(close_to(Ff[i * R], Fc[i], 0, ROUNDOFF * 20.0), "F at vertex %d: %g vs %g", i, Ff[i * R], Fc[i]);
        CHECK(close_to(Wf[i * R], Wc[i], 1e-10, 0), "W at vertex %d", i);
    }
    CHECK(Fc[4] == 0.0, "lift-off force %g", Fc[4]);
    for (int i = 1; i < (NV - 1) * R + 1; ++i) CHECK(Wf[i] >= Wf[i - 1], "W decreasing at %d", i);
}

/* dF/dX of the periodic loop vs central differences, u = c0 + c1 cos + c2 sin 2t, N varying. */
static void test_periodic_jacobian(void)
{
    double ut[M_TAB], Tt[M_TAB];
    sphere_table(ut, Tt);
    iwan_model m;
    iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT);
    enum { NT = 48, NB = 3 };
    double E[NT * NB], X[NB] = {0.2e-6, 1.5e-6, 0.4e-6}, XN[NB] = {5.0, 2.0, 1.0};
    double u[NT], N[NT], F[NT], J[NT * NB], JN[NT * NB], W, Fp[NT], Fm[NT], Wp;
    int p;
    for (int t = 0; t < NT; ++t) {
        const double th = 2.0 * PI * t / NT;
        E[t * NB] = 1.0; E[t * NB + 1] = cos(th); E[t * NB + 2] = sin(2.0 * th);
    }
    for (int t = 0; t < NT; ++t) {
        u[t] = N[t] = 0.0;
        for (int c = 0; c < NB; ++c) { u[t] += E[t * NB + c] * X[c]; N[t] += E[t * NB + c] * XN[c]; }
    }
    CHECK(iwan_periodic_jac(&m, NT, u, N, E, E, NB, F, J, JN, &W, 50, 1e-12, &p) == IWAN_OK, "jac");
    double jmax = 0.0;   /* FD round-off ~ eps F / h: tolerance relative to the largest entry */
    for (int i = 0; i < NT * NB; ++i) jmax = fmax(jmax, fabs(J[i]));
    for (int c = 0; c < NB; ++c) {
        const double h = 1e-7 * X[1];
        double up[NT], um[NT];
        for (int t = 0; t < NT; ++t) { up[t] = u[t] + h * E[t * NB + c]; um[t] = u[t] - h * E[t * NB + c]; }
        iwan_periodic(&m, NT, up, N, Fp, NULL, NULL, &Wp, 50, 1e-12, NULL);
        iwan_periodic(&m, NT, um, N, Fm, NULL, NULL, &Wp, 50, 1e-12, NULL);
        for (int t = 0; t < NT; ++t) {
            const double fd = (Fp[t] - Fm[t]) / (2.0 * h);
            CHECK(close_to(J[t * NB + c], fd, 0, 1e-6 * jmax), "dF[%d]/dX[%d] %g vs %g", t, c, J[t * NB + c], fd);
        }
    }
    /* not converged within one period (N varies) */
    CHECK(iwan_periodic(&m, NT, u, N, F, NULL, NULL, &W, 1, 1e-12, &p) == IWAN_ERR_NOT_CONVERGED,
          "closure status");
    /* two elements in one call (the second at half the amplitude): each its own call's bits;
     * a NaN in the second one's samples is reported with its index */
    const iwan_model *ms[2] = {&m, &m};
    const double *ens[2] = {E, E};
    double u2[2 * NT], N2[2 * NT], F2[2 * NT], J2[2 * NT * NB], JN2[2 * NT * NB], W2[2];
    double Fb[NT], Jb[NT * NB], JNb[NT * NB], Wb;
    size_t failed = 0;
    for (int t = 0; t < NT; ++t) {
        u2[t] = u[t]; N2[t] = N[t]; u2[NT + t] = 0.5 * u[t]; N2[NT + t] = N[t];
    }
    CHECK(iwan_periodic_jac_many(ms, 2, NT, u2, N2, E, ens, NB, F2, J2, JN2, W2, 50, 1e-12,
                                 &failed) == IWAN_OK && failed == 2, "jac_many");
    for (int e = 0; e < 2; ++e) {
        CHECK(iwan_periodic_jac(&m, NT, u2 + e * NT, N, E, E, NB, Fb, Jb, JNb, &Wb, 50, 1e-12, &p)
              == IWAN_OK, "jac of element %d", e);
        CHECK(memcmp(F2 + e * NT, Fb, sizeof Fb) == 0 && memcmp(J2 + e * NT * NB, Jb, sizeof Jb) == 0
              && memcmp(JN2 + e * NT * NB, JNb, sizeof JNb) == 0 && W2[e] == Wb,
              "jac_many: element %d differs from its own call", e);
    }
    u2[NT + 3] = NAN;
    CHECK(iwan_periodic_jac_many(ms, 2, NT, u2, N2, E, ens, NB, F2, J2, JN2, W2, 50, 1e-12,
                                 &failed) == IWAN_ERR_NONFINITE && failed == 1, "jac_many NaN");
}

/* Reproducible uniform numbers in [0, 1) (64-bit LCG, Knuth's MMIX constants). */
static double lcg(uint64_t *x)
{
    *x = *x * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*x >> 11) / 9007199254740992.0;
}

/* Outputs of an in-contact state written out slider by slider (independent of the
 * core's sweep): slipping = at the limit on the side of the last motion. */
static void ref_outputs(const iwan_model *m, const iwan_state *s, iwan_output *o)
{
    const double f = m->scale * s->N / m->n_ref, ur = s->u - s->u_contact;
    double g_all = 0.0, g_slip = 0.0;
    o->F = m->k_res * ur;
    o->kt = m->k_res;
    o->dFdN = 0.0;
    o->E = 0.5 * m->k_res * ur * ur;
    o->W = s->w_diss;
    for (int j = 0; j < m->n; ++j) {
        const double e = s->u - s->z[j], r = m->fs[j] * f / m->k[j];
        const int slipping = s->dir > 0 ? e >= r * (1.0 - 1e-12) : e <= -r * (1.0 - 1e-12);
        o->F += m->k[j] * e;
        o->E += 0.5 * m->k[j] * e * e;
        g_all += m->fs[j];
        if (slipping) {
            o->dFdN += s->dir * m->fs[j] * m->scale / m->n_ref;
            g_slip += m->fs[j];
        } else {
            o->kt += m->k[j];
        }
    }
    o->slip = g_slip / g_all;
}

/* The one-pass constant-N step (iwan_step, iwan_eval) against the general exact
 * straight-path update (iwanp_advance, an independent code path; outputs of its
 * state by ref_outputs)
 * over random reversals with gross slip, at a friction scale != 1. */
static void test_fast_step_equals_straight_path(void)
{
    double ut[M_TAB], Tt[M_TAB];
    sphere_table(ut, Tt);
    iwan_model m;
    iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT);
    m.scale = 0.7;
    iwan_state a, b, c;
    iwan_output oa, ob, oc;
    uint64_t seed = 20261122u;
    double u = 0.0;
    iwan_state_init(&m, &a, 4.0);
    b = a;
    for (int i = 0; i < 400; ++i) {
        u += (lcg(&seed) - 0.5) * 3e-6 * (i % 7 == 0 ? 3.0 : 0.3);
        CHECK(iwan_eval(&m, &a, u, 4.0, NULL, &oc) == IWAN_OK, "eval");
        CHECK(iwan_eval(&m, &a, u, 4.0, &c, NULL) == IWAN_OK, "eval trial");
        CHECK(iwan_step(&m, &a, u, 4.0, &oa) == IWAN_OK, "step");
        iwanp_advance(&m, &b, u, 4.0, NULL);
        ref_outputs(&m, &b, &ob);
        CHECK(memcmp(&oa, &oc, sizeof oa) == 0 && memcmp(&a, &c, sizeof a) == 0,
              "eval differs from step at %d", i);
        CHECK(close_to(oa.F, ob.F, 0, ROUNDOFF * 10.0), "F %d: %g vs %g", i, oa.F, ob.F);
        CHECK(close_to(oa.W, ob.W, ROUNDOFF, 1e-20), "W %d: %g vs %g", i, oa.W, ob.W);
        CHECK(close_to(oa.E, ob.E, ROUNDOFF, 1e-20), "E %d: %g vs %g", i, oa.E, ob.E);
        CHECK(close_to(oa.kt, ob.kt, ROUNDOFF, 0) && close_to(oa.dFdN, ob.dFdN, ROUNDOFF, 1e-15)
              && close_to(oa.slip, ob.slip, ROUNDOFF, 0), "kt, dF/dN, slip %d", i);
        for (int j = 0; j < m.n; ++j) CHECK(close_to(a.z[j], b.z[j], 0, 1e-20), "z[%d] at %d", j, i);
    }
    /* a model not made by the init functions (derived fields missing) is refused */
    iwan_model bad;
    memset(&bad, 0, sizeof bad);
    bad.n = 1; bad.k[0] = 1.0; bad.fs[0] = 1.0; bad.n_ref = 1.0; bad.scale = 1.0;
    CHECK(iwan_state_init(&bad, &c, 1.0) == IWAN_ERR_BAD_PARAM, "hand-made model accepted");
}

/* iwan_step_batch: each of NB states takes the bits iwan_step gives it alone, over
 * random (u, N) histories with constant-N runs and lift-off; a NaN or a bad state
 * anywhere leaves every state untouched. */
#define NB 5
static void test_step_batch_equals_step(void)
{
    double ut[M_TAB], Tt[M_TAB];
    sphere_table(ut, Tt);
    iwan_model m;
    iwan_model_init(&m, ut, Tt, M_TAB, 5.0, IWAN_FIT_REJECT);
    iwan_state sb[NB], ss[NB], keep[NB];
    double u[NB] = {0}, N[NB], F[NB], kt[NB];
    uint64_t seed = 20261123u;
    for (int i = 0; i < NB; ++i) {
        N[i] = 5.0;
        iwan_state_init(&m, &sb[i], N[i]);
        ss[i] = sb[i];
    }
    int lifted = 0;
    for (int t = 0; t < 300; ++t) {
        for (int i = 0; i < NB; ++i) {
            u[i] += (lcg(&seed) - 0.5) * 2e-6;
            const double r = lcg(&seed);
            if (r < 0.1) N[i] = -1.0;                 /* lift-off */
            else if (r < 0.5) N[i] = 5.0 * (0.3 + lcg(&seed));
        }                                             /* else: N held (fast path) */
        CHECK(iwan_step_batch(&m, sb, NB, u, N, F, kt) == IWAN_OK, "batch at %d", t);
        for (int i = 0; i < NB; ++i) {
            iwan_output o;
            CHECK(iwan_step(&m, &ss[i], u[i], N[i], &o) == IWAN_OK, "step");
            CHECK(memcmp(&ss[i], &sb[i], sizeof ss[i]) == 0 && F[i] == o.F && kt[i] == o.kt,
                  "batch differs from step: state %d at %d", i, t);
            lifted += !sb[i].in_contact;
        }
    }
    CHECK(lifted > 0, "no lift-off reached");
    memcpy(keep, sb, sizeof sb);
    u[NB - 1] = NAN;
    CHECK(iwan_step_batch(&m, sb, NB, u, NULL, F, NULL) == IWAN_ERR_NONFINITE, "nan u");
    u[NB - 1] = 0.0;
    sb[NB - 1].version = 99;
    CHECK(iwan_step_batch(&m, sb, NB, u, N, F, kt) == IWAN_ERR_BAD_STATE, "bad state");
    sb[NB - 1].version = IWAN_STATE_VERSION;
    CHECK(memcmp(keep, sb, sizeof sb) == 0, "states moved on failure");
    CHECK(iwan_step_batch(&m, sb, 0, u, N, F, kt) == IWAN_ERR_BAD_PARAM, "empty batch");
    CHECK(iwan_step_batch(&m, sb, NB, u, N, NULL, kt) == IWAN_ERR_BAD_PARAM, "null F");
}

/* iwan_periodic_fourier: the Jenkins describing function exactly (references.md),
 * a constant input (no extrema) and refused arguments. */
static void test_periodic_fourier(void)
{
    const double k = 2e6, fs = 3.0, a = 4e-6;
    iwan_model m;
    CHECK(iwan_model_from_sliders(&m, &k, &fs, 1, 0.0, 1.0) == IWAN_OK, "jenkins model");
    const int32_t harm[3] = {1, 2, 3};
    double U[6] = {a, 0, 0, 0, 0, 0}, Fh[6], J[36], W;
    size_t ne;
    CHECK(iwan_periodic_fourier(&m, 3, harm, U, 64, Fh, J, &W, &ne) == IWAN_OK && ne == 2, "fourier");
    const double th = acos(1.0 - 2.0 * fs / (k * a));
    const double a1 = k * a / PI * (th - sin(2.0 * th) / 2.0), b1 = -k * a / PI * sin(th) * sin(th);
    CHECK(close_to(Fh[0], a1, 1e-13, 0.0) && close_to(Fh[1], b1, 1e-13, 0.0), "DF %g %g vs %g %g",
          Fh[0], Fh[1], a1, b1);
    CHECK(close_to(W, -PI * a * b1, 1e-13, 0.0), "fourier W %g", W);
    const int32_t h01[2] = {0, 1};
    double C[3] = {0.5, 0.0, 0.0};
    CHECK(iwan_periodic_fourier(&m, 2, h01, C, 16, Fh, J, &W, &ne) == IWAN_OK && ne == 0, "constant");
    const int32_t bad[2] = {2, 1};
    CHECK(iwan_periodic_fourier(&m, 2, bad, U, 16, Fh, J, &W, &ne) == IWAN_ERR_BAD_PARAM, "order");
    CHECK(iwan_periodic_fourier(&m, 3, harm, U, 6, Fh, J, &W, &ne) == IWAN_ERR_BAD_PARAM, "scan");
}

int main(void)
{
    test_step_batch_equals_step();
    test_jenkins_loop_energy();
    test_table_and_masing_branches();
    test_bad_inputs();
    test_sampling_independence_and_lift_off();
    test_periodic_jacobian();
    test_periodic_fourier();
    test_fast_step_equals_straight_path();
    if (failures == 0) printf("test_iwan: all checks passed\n");
    return failures;
}
