/*
 * test_iwan2d.c -- unit tests of the 2D element (iwan2d.h), plain C99, no framework:
 * the 1D element on a line, the steady circle in closed form and its convergence
 * order, independence of how a straight path is sampled, the step tangent against
 * central differences, refused inputs. The Python tests (tests/element/
 * test_element2d.py) add an independent reference and the energy balance.
 * Exit status = number of failed checks.
 */
#include "iwan.h"
#include "iwan2d.h"
#include "test_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Round-off of sums over a few dozen sliders and samples, relative. */
#define ROUNDOFF 1e-12
/* The required accuracy of the circle at 4000 steps a cycle (the polygon's own ~2e-7). */
#define CIRCLE_RTOL 1e-4
/* Central differences at 1e-7 of the slip radius (truncation ~1e-14, round-off ~1e-9). */
#define FD_RTOL 1e-6
#define PI 3.14159265358979323846

/* Deterministic pseudo-random numbers in [-1, 1] (LCG, reproducible everywhere). */
static double rnd(unsigned long *seed)
{
    *seed = (*seed * 6364136223846793005UL + 1442695040888963407UL) & 0xffffffffffffUL;
    return 2.0 * (double)(*seed >> 16) / 4294967295.0 - 1.0;
}

/* Concave table T = 10 (1 - (1 - u/u_s)^2), 8 segments, flat tail: 8 sliders. */
static void make_model(iwan_model *m)
{
    double u[10], T[10];
    int i;
    for (i = 0; i <= 8; ++i) {
        T[i] = 10.0 * i / 8.0;
        u[i] = 2e-6 * (1.0 - sqrt(1.0 - T[i] / 10.0));
    }
    u[9] = 4e-6;
    T[9] = 10.0;
    CHECK(iwan_model_init(m, u, T, 10, 20.0, IWAN_FIT_REJECT) == IWAN_OK, "model");
}

static void test_line_is_the_1d_element(void)
{
    iwan_model m;
    iwan_state s1;
    iwan2_state s2;
    const double c = cos(0.9), sn = sin(0.9);
    unsigned long seed = 7;
    double x = 0.0, Fmax = 0.0, err = 0.0, werr = 0.0;
    int i;
    make_model(&m);
    iwan_state_init(&m, &s1, 20.0);
    iwan2_state_init(&m, &s2, 20.0);
    for (i = 0; i < 200; ++i) {
        iwan_output o1;
        iwan2_output o2;
        const double N = (i % 50 > 45) ? -3.0 : 20.0 * (1.0 + 0.4 * rnd(&seed));
        x += 1e-6 * rnd(&seed);
        CHECK(iwan_step(&m, &s1, x, N, &o1) == IWAN_OK, "1d step");
        CHECK(iwan2_step(&m, &s2, x * c, x * sn, N, &o2) == IWAN_OK, "2d step");
        Fmax = fmax(Fmax, fabs(o1.F));
        err = fmax(err, fabs(o2.F[0] * c + o2.F[1] * sn - o1.F) + fabs(-o2.F[0] * sn + o2.F[1] * c));
        werr = fmax(werr, fabs(o2.W - o1.W));
    }
    CHECK(err <= ROUNDOFF * Fmax, "line: force differs from 1D by %g of %g", err, Fmax);
    CHECK(werr <= ROUNDOFF * s1.w_diss, "line: W differs by %g of %g", werr, s1.w_diss);
}

/* Energy of the last of 6 cycles of a Jenkins slider on a circle of radius a. */
static double circle_cycle_energy(const iwan_model *m, double a, int n)
{
    iwan2_state s;
    double w0 = 0.0;
    int i;
    iwan2_state_init(m, &s, m->n_ref);
    for (i = 0; i <= 6 * n; ++i) {
        const double t = 2.0 * PI * i / n;
        iwan2_step(m, &s, a * cos(t), a * sin(t), m->n_ref, NULL);
        if (i == 5 * n) w0 = s.w_diss;
    }
    return s.w_diss - w0;
}

static void test_circle_energy_and_order(void)
{
    const double k = 2e6, fs = 3.0, r = fs / k, a = 3.0 * r;
    const double want = 2.0 * PI * fs * sqrt(a * a - r * r);
    iwan_model m;
    double e1, e2, e4;
    CHECK(iwan_model_from_sliders(&m, &k, &fs, 1, 0.0, 1.0) == IWAN_OK, "jenkins");
    e1 = fabs(circle_cycle_energy(&m, a, 1000) / want - 1.0);
    e2 = fabs(circle_cycle_energy(&m, a, 2000) / want - 1.0);
    e4 = fabs(circle_cycle_energy(&m, a, 4000) / want - 1.0);
    CHECK(e4 < CIRCLE_RTOL, "circle at 4000 steps: relative error %g", e4);
    CHECK(fabs(log2(e1 / e2) - 2.0) < 0.05 && fabs(log2(e2 / e4) - 2.0) < 0.05,
          "circle: convergence order %g, %g (want 2)", log2(e1 / e2), log2(e2 / e4));
}

static void test_straight_path_sampling(void)
{
    iwan_model m;
    iwan2_state a, b;
    unsigned long seed = 11;
    double ux = 0.0, uy = 0.0, N = 20.0;
    int i, j, p;
    make_model(&m);
    iwan2_state_init(&m, &a, N);
    iwan2_state_init(&m, &b, N);
    for (i = 0; i < 40; ++i) {
        const double vx = ux + 1.5e-6 * rnd(&seed), vy = uy + 1.5e-6 * rnd(&seed);
        const double M = (i == 20) ? -4.0 : 20.0 * (1.0 + 0.5 * rnd(&seed));
        const double cuts[4] = {0.21, 0.5, 0.64, 1.0};
        double zerr = 0.0;
        iwan2_step(&m, &a, vx, vy, M, NULL);
        for (p = 0; p < 4; ++p)
            iwan2_step(&m, &b, ux + cuts[p] * (vx - ux), uy + cuts[p] * (vy - uy),
                       N + cuts[p] * (M - N), NULL);
        for (j = 0; j < 2 * m.n; ++j) zerr = fmax(zerr, fabs(a.z[j] - b.z[j]));
        CHECK(zerr <= ROUNDOFF * 1e-5 && fabs(a.w_diss - b.w_diss) <= 10 * ROUNDOFF * a.w_diss,
              "sampling changes the result: dz %g, W %g vs %g", zerr, a.w_diss, b.w_diss);
        ux = vx;
        uy = vy;
        N = M;
    }
}

static void test_tangent_central_differences(void)
{
    iwan_model m;
    iwan2_state s;
    unsigned long seed = 5;
    const double h = 1e-7 * 1e-6, hN = 1e-7 * 20.0;
    int i, checked = 0;
    make_model(&m);
    iwan2_state_init(&m, &s, 20.0);
    for (i = 0; i < 30; ++i) {
        const double ux = s.u[0] + 1e-6 * rnd(&seed), uy = s.u[1] + 1e-6 * rnd(&seed);
        const double N = 20.0 * (1.0 + 0.3 * rnd(&seed));
        iwan2_output o, p, q;
        double fd[6], err = 0.0, scale;
        int c;
        iwan2_eval(&m, &s, ux, uy, N, NULL, &o);
        for (c = 0; c < 3; ++c) {
            const double dx = c == 0 ? h : 0.0, dy = c == 1 ? h : 0.0, dN = c == 2 ? hN : 0.0;
            const double step = c == 2 ? hN : h;
            iwan2_eval(&m, &s, ux + dx, uy + dy, N + dN, NULL, &p);
            iwan2_eval(&m, &s, ux - dx, uy - dy, N - dN, NULL, &q);
            fd[c] = (p.F[0] - q.F[0]) / (2 * step);
            fd[3 + c] = (p.F[1] - q.F[1]) / (2 * step);
        }
        scale = fabs(o.K[0]) + fabs(o.K[3]);
        err = fmax(fmax(fabs(fd[0] - o.K[0]), fabs(fd[1] - o.K[1])),
                   fmax(fabs(fd[3] - o.K[2]), fabs(fd[4] - o.K[3])));
        if (err <= FD_RTOL * scale) {  /* no slider switch inside the difference */
            ++checked;
            CHECK(fabs(fd[2] - o.dFdN[0]) + fabs(fd[5] - o.dFdN[1])
                      <= FD_RTOL * (fabs(o.dFdN[0]) + fabs(o.dFdN[1])) + 1e-12,
                  "dF/dN %g %g vs %g %g", o.dFdN[0], o.dFdN[1], fd[2], fd[5]);
        }
        iwan2_step(&m, &s, ux, uy, N, NULL);
    }
    CHECK(checked >= 26, "tangent: only %d of 30 steps without a switch", checked);
}

static void test_refused_inputs(void)
{
    iwan_model m;
    iwan2_state s, before;
    iwan2_output o;
    make_model(&m);
    iwan2_state_init(&m, &s, 20.0);
    iwan2_step(&m, &s, 1e-6, -2e-7, 20.0, NULL);
    memcpy(&before, &s, sizeof s);
    CHECK(iwan2_step(&m, &s, NAN, 0.0, 20.0, &o) == IWAN_ERR_NONFINITE, "NaN u accepted");
    CHECK(iwan2_step(&m, &s, 0.0, INFINITY, 20.0, &o) == IWAN_ERR_NONFINITE, "inf u accepted");
    CHECK(iwan2_step(&m, &s, 0.0, 0.0, NAN, &o) == IWAN_ERR_NONFINITE, "NaN N accepted");
    CHECK(iwan2_eval(&m, &s, 0.0, 0.0, 1.0, &s, &o) == IWAN_ERR_BAD_PARAM, "aliased trial");
    CHECK(memcmp(&before, &s, sizeof s) == 0, "a refused call changed the state");
    s.version = 99;
    CHECK(iwan2_step(&m, &s, 0.0, 0.0, 20.0, &o) == IWAN_ERR_BAD_STATE, "bad version accepted");
    s.version = IWAN2_STATE_VERSION;
    s.N = -1.0;  /* in contact but N <= 0 */
    CHECK(iwan2_step(&m, &s, 0.0, 0.0, 20.0, &o) == IWAN_ERR_BAD_STATE, "inconsistent state");
}

/* The periodic loop (with its Jacobian workspace) on a line equals the 1D loop; on a
 * circle its energy is the steady circles' sum. */
static void test_periodic_loop(void)
{
    enum { NT = 128, NB = 3 };
    iwan_model m;
    double u[NT], ux[NT], uy[NT], E[NT * NB], F1[NT], kt[NT], dfdn[NT], F2[2 * NT];
    double dF[2 * NT * 3 * NB], work[48 * NB], W1, W2, err = 0.0, Fmax = 0.0, want = 0.0;
    const double c = cos(0.4), sn = sin(0.4);
    int i, j, p;
    make_model(&m);
    CHECK(iwan2_periodic_work_size(NB) <= 48 * NB, "workspace size");
    for (i = 0; i < NT; ++i) {
        const double t = 2.0 * PI * i / NT;
        u[i] = 1e-7 + 1.5e-6 * cos(t) + 0.4e-6 * sin(t);
        ux[i] = c * u[i];
        uy[i] = sn * u[i];
        E[NB * i] = 1.0;
        E[NB * i + 1] = cos(t);
        E[NB * i + 2] = sin(t);
    }
    CHECK(iwan_periodic(&m, NT, u, NULL, F1, kt, dfdn, &W1, 10, 1e-12, &p) == IWAN_OK, "1D loop");
    CHECK(iwan2_periodic_jac(&m, NT, ux, uy, NULL, E, NULL, NB, F2, dF, &W2, 100, 1e-12, &p, work)
              == IWAN_OK, "2D loop");
    for (i = 0; i < NT; ++i) {
        Fmax = fmax(Fmax, fabs(F1[i]));
        err = fmax(err, fabs(c * F2[2 * i] + sn * F2[2 * i + 1] - F1[i]));
    }
    CHECK(err <= ROUNDOFF * Fmax && fabs(W2 - W1) <= ROUNDOFF * W1,
          "periodic loop on a line: force %g of %g, W %g vs %g", err, Fmax, W2, W1);
    for (i = 0; i < NT; ++i) {  /* a circle: the 128-gon's own error is a few 1e-4 */
        const double t = 2.0 * PI * i / NT;
        ux[i] = 1.5e-6 * cos(t);
        uy[i] = 1.5e-6 * sin(t);
    }
    CHECK(iwan2_periodic_jac(&m, NT, ux, uy, NULL, NULL, NULL, 0, F2, NULL, &W2, 200, 1e-12, &p,
                             NULL) == IWAN_OK, "circle loop");
    for (j = 0; j < m.n; ++j) {
        const double r = m.rad[j] * m.scale;
        if (r < 1.5e-6) want += 2.0 * PI * m.fs[j] * sqrt(1.5e-6 * 1.5e-6 - r * r);
    }
    CHECK(fabs(W2 / want - 1.0) < 1e-3, "circle loop energy %g vs %g", W2, want);
}

int main(void)
{
    test_line_is_the_1d_element();
    test_circle_energy_and_order();
    test_straight_path_sampling();
    test_tangent_central_differences();
    test_refused_inputs();
    test_periodic_loop();
    if (failures == 0) printf("iwan2d: all tests passed\n");
    return failures;
}
