/*
 * iwan_fourier.c -- exact Fourier coefficients of the periodic loop for an input given
 * by its own Fourier coefficients (iwan.h: iwan_periodic_fourier).
 *
 * u(theta) = sum_h a_h cos(h theta) + b_h sin(h theta) (+ a_0). Its extrema are the
 * zeros of u' (sign scan on n_scan points, u' and u'' there by one FFT when n_scan is a
 * power of two, then Newton safeguarded by bisection); the
 * loop between them is iwan_periodic_branches (the play operator itself): on interval
 * i, F = c_i + s_i u. Each interval end (a slider reaching its limit) is located in
 * theta (u is monotone between extrema) and the Fourier integrals of c_i + s_i u(theta)
 * are taken in closed form in the interval's local variable t - a (interval_integrals:
 * absolute theta in the arguments loses eps |theta| h of phase, which a stiff slider
 * turns into residual noise). The Jacobian: F is continuous at every interval end and
 * u' = 0 at the extrema, so no boundary terms: dF_p/dU_q = w_p sum_i int psi_p (s_i
 * phi_q + dc_i/dU_q), dc_i/dU = -sum_e A[i][e] phi(theta_e). The first sum is the
 * transform of the piecewise-constant stiffness s(theta) against products of two
 * harmonics, Toeplitz plus Hankel in the orders (built once from its 2 hmax + 1 Fourier
 * coefficients), the second one outer product per extremum that anchors stuck sliders:
 * O(nb^2) per call, not per interval.
 */
#include "iwan_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FOURIER_NEWTON_ITER 80
#define SCAN_SYNC 64
#define TWO_PI 6.283185307179586476925286766559

typedef struct {
    size_t n_h;
    const int32_t *harm;
    int32_t hmax;
    double *c, *s;     /* cos(h t), sin(h t) for h = 0 .. hmax (scratch) */
} tpoly;

/* cos(k t), sin(k t) for k = 0 .. hmax by rotation (4 flops per k). */
static void rot_table(tpoly *p, double t)
{
    const double c1 = cos(t), s1 = sin(t);
    p->c[0] = 1.0;
    p->s[0] = 0.0;
    for (int32_t k = 1; k <= p->hmax; ++k) {
        p->c[k] = p->c[k - 1] * c1 - p->s[k - 1] * s1;
        p->s[k] = p->s[k - 1] * c1 + p->c[k - 1] * s1;
    }
}

/* d-th derivative (0 .. 3) of u at the t of the last rot_table(p, t). */
static double sum_u(const tpoly *p, const double *U, int d)
{
    double v = 0.0;
    size_t q = 0;
    for (size_t k = 0; k < p->n_h; ++k) {
        const int32_t h = p->harm[k];
        if (h == 0) {
            if (d == 0) v += U[q];
            ++q;
            continue;
        }
        const double a = U[q], b = U[q + 1], ch = p->c[h], sh = p->s[h];
        if (d == 0) v += a * ch + b * sh;
        else if (d == 1) v += h * (b * ch - a * sh);
        else if (d == 2) v -= (double)h * h * (a * ch + b * sh);
        else v += (double)h * h * h * (a * sh - b * ch);
        q += 2;
    }
    return v;
}

/* d-th derivative (0 .. 3) of u at t. */
static double eval_u(tpoly *p, const double *U, double t, int d)
{
    rot_table(p, t);
    return sum_u(p, U, d);
}

/* Root of u^(d)(t) - target in [lo, hi] (values of opposite sign at the ends, f_lo at
 * lo): Newton with the derivative, bisection when it leaves the bracket. */
static double root(tpoly *p, const double *U, int d, double target, double lo, double hi,
                   double f_lo, double ftol)
{
    double x = 0.5 * (lo + hi);
    for (int it = 0; it < FOURIER_NEWTON_ITER; ++it) {
        const double f = eval_u(p, U, x, d) - target;
        if (fabs(f) <= ftol) return x;
        if ((f > 0.0) == (f_lo > 0.0)) { lo = x; f_lo = f; } else { hi = x; }
        const double df = sum_u(p, U, d + 1);   /* the same x: the same table */
        double xn = x - f / df;
        if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
        if (fabs(xn - x) <= 4.0 * DBL_EPSILON * fabs(x) || hi - lo <= 4.0 * DBL_EPSILON * hi) return xn;
        x = xn;
    }
    return x;
}

/* In-place inverse DFT z_j = sum_k Z_k exp(+2 pi i j k / n) of n complex values
 * (interleaved re, im), n a power of two: iterative radix-2 (bit reversal, then
 * butterflies). tw: scratch of n doubles for the n/2 twiddles exp(+2 pi i k / n), made
 * by rotation re-synchronised every SCAN_SYNC steps (only the scan's brackets use it). */
static void inverse_fft(size_t n, double *z, double *tw)
{
    const double c1 = cos(TWO_PI / (double)n), s1 = sin(TWO_PI / (double)n);
    for (size_t k = 0; k < n / 2; ++k) {
        if (k % SCAN_SYNC == 0) {
            tw[2 * k] = cos(TWO_PI * (double)k / (double)n);
            tw[2 * k + 1] = sin(TWO_PI * (double)k / (double)n);
        } else {
            tw[2 * k] = tw[2 * k - 2] * c1 - tw[2 * k - 1] * s1;
            tw[2 * k + 1] = tw[2 * k - 1] * c1 + tw[2 * k - 2] * s1;
        }
    }
    for (size_t i = 1, j = 0; i < n; ++i) {
        size_t bit = n >> 1;
        for (; j & bit; bit >>= 1) j ^= bit;
        j |= bit;
        if (i < j) {
            const double re = z[2 * i], im = z[2 * i + 1];
            z[2 * i] = z[2 * j];
            z[2 * i + 1] = z[2 * j + 1];
            z[2 * j] = re;
            z[2 * j + 1] = im;
        }
    }
    for (size_t len = 2; len <= n; len <<= 1) {
        const size_t half = len / 2, step = n / len;
        for (size_t i = 0; i < n; i += len)
            for (size_t k = 0; k < half; ++k) {
                const double wr = tw[2 * k * step], wi = tw[2 * k * step + 1];
                double *x = z + 2 * (i + k), *y = z + 2 * (i + k + half);
                const double yr = y[0] * wr - y[1] * wi, yi = y[0] * wi + y[1] * wr;
                y[0] = x[0] - yr;
                y[1] = x[1] - yi;
                x[0] += yr;
                x[1] += yi;
            }
    }
}

/* u' and u'' at t_j = 2 pi j / n_scan, j = 0 .. n_scan - 1, into gs[2j], gs[2j + 1].
 * n_scan a power of two: one complex inverse FFT of z = u' + i u'' (O(n log n); the
 * per-point sums cost O(n H), the larger part of a call at H = 31), whose coefficient
 * at +h is (alpha_1 + beta_2 + i (alpha_2 - beta_1)) / 2 and at -h (index n - h)
 * (alpha_1 - beta_2 + i (alpha_2 + beta_1)) / 2, for u' = alpha_1 cos + beta_1 sin and
 * u'' = alpha_2 cos + beta_2 sin (2 h < n_scan: no aliasing). Otherwise per-harmonic
 * phasors rotated by h dt (no libm call per point), re-synchronised every SCAN_SYNC
 * points. Both carry round-off of a few eps |u'|: they only decide the brackets, the
 * roots are refined with exact evaluations. scratch: n_scan + 4 n_h doubles. */
static void scan_derivatives(size_t n_h, const int32_t *harm, const double *U, size_t n_scan,
                             double *gs, double *scratch)
{
    if ((n_scan & (n_scan - 1)) == 0) {
        memset(gs, 0, 2 * n_scan * sizeof *gs);
        for (size_t k = 0, q = 0; k < n_h; ++k) {
            const double h = harm[k];
            if (h == 0.0) { ++q; continue; }
            const double a = U[q], b = U[q + 1];
            const double al1 = h * b, be1 = -h * a, al2 = -h * h * a, be2 = -h * h * b;
            const size_t ip = (size_t)harm[k], im = n_scan - ip;
            gs[2 * ip] = 0.5 * (al1 + be2);
            gs[2 * ip + 1] = 0.5 * (al2 - be1);
            gs[2 * im] = 0.5 * (al1 - be2);
            gs[2 * im + 1] = 0.5 * (al2 + be1);
            q += 2;
        }
        inverse_fft(n_scan, gs, scratch);
        return;
    }
    const double dt = TWO_PI / (double)n_scan;
    double *zc = scratch, *zs = scratch + n_h, *rc = scratch + 2 * n_h, *rs = scratch + 3 * n_h;
    for (size_t k = 0; k < n_h; ++k) {
        rc[k] = cos(harm[k] * dt);
        rs[k] = sin(harm[k] * dt);
    }
    for (size_t j = 0; j < n_scan; ++j) {
        if (j % SCAN_SYNC == 0)
            for (size_t k = 0; k < n_h; ++k) {
                zc[k] = cos(harm[k] * dt * (double)j);
                zs[k] = sin(harm[k] * dt * (double)j);
            }
        double d1v = 0.0, d2v = 0.0;
        for (size_t k = 0, q = 0; k < n_h; ++k) {
            const double h = harm[k];
            if (h == 0.0) { ++q; continue; }
            const double a = U[q], b = U[q + 1];
            d1v += h * (b * zc[k] - a * zs[k]);
            d2v -= h * h * (a * zc[k] + b * zs[k]);
            q += 2;
        }
        gs[2 * j] = d1v;
        gs[2 * j + 1] = d2v;
        for (size_t k = 0; k < n_h; ++k) {
            const double c1 = zc[k] * rc[k] - zs[k] * rs[k];
            zs[k] = zs[k] * rc[k] + zc[k] * rs[k];
            zc[k] = c1;
        }
    }
}

/* One interval [a, a + L] of the loop, F = c + s u, into Fh: written F = F_a + s (u - u_a)
 * with F_a = c + s u_a and integrated in the local variable tau = t - a, so that every
 * integral is over small arguments: int psi_p (u(a + tau) - u_a) is O(L^2) and computed
 * without the cancellation of c int psi + s int u psi (two terms of size s |u| L whose
 * phase rounding eps h t, times k_t, was ~1e-10 of residual noise at 1e6 k). In tau,
 * u(a + tau) - u_a = sum_q V_q^c (cos q tau - 1) + V_q^s sin q tau with the coefficients
 * rotated by q a, and psi_p(a + tau) is a rotation by p a of cos p tau, sin p tau, so the
 * O(nb^2) part per interval is the four integrals A, B, Cc, D of the orders p, q alone
 * (C(k) = int_0^L cos k tau, S(k) = int_0^L sin k tau: trig scratch of 2K + 4 n_h,
 * K = 2 hmax + 1). A slipping interval (s = 0, every slider at its limit) has F = c:
 * no q loop. Also returns ip[p] = int_a^(a+L) psi_p (nb) and, for s != 0, adds
 * s int_a^(a+L) (cos k t, sin k t) to kc[k], ks[k] (k < K): the Fourier coefficients of
 * the piecewise-constant stiffness, from which the Jacobian is built once (stiffness_jacobian). */
static void interval_integrals(size_t n_h, const int32_t *harm, const double *U, double a,
                               double L, double c, double s, double u_a, double *trig, size_t K,
                               double *Fh, double *ip, double *kc, double *ks)
{
    /* a slipping interval needs orders up to hmax only (no products of two harmonics) */
    const size_t kn = s == 0.0 ? (K + 1) / 2 : K;
    for (size_t k = 0; k < kn; ++k) {
        const double h = sin(0.5 * (double)k * L);
        trig[k] = k ? sin((double)k * L) / (double)k : L;
        trig[K + k] = k ? 2.0 * h * h / (double)k : 0.0;
    }
    /* cos, sin of (order x a) per harmonic, and the rotated coefficients V (scratch after
     * the 2K above; the stiffness's rotation table after them) */
    double *ca = trig + 2 * K, *sa = ca + n_h, *vc = sa + n_h, *vs = vc + n_h;
    for (size_t k = 0, q = 0; k < n_h; ++k) {
        ca[k] = cos(harm[k] * a);
        sa[k] = sin(harm[k] * a);
        if (harm[k] == 0) { vc[k] = vs[k] = 0.0; ++q; continue; }
        vc[k] = U[q] * ca[k] + U[q + 1] * sa[k];
        vs[k] = U[q + 1] * ca[k] - U[q] * sa[k];
        q += 2;
    }
#define C_(k) trig[(size_t)abs(k)]
#define S_(k) ((k) < 0 ? -trig[K + (size_t)(-(k))] : trig[K + (size_t)(k)])
    const double Fa = c + s * u_a;
    for (size_t kp = 0, pc = 0; kp < n_h; ++kp) {
        const int32_t op = harm[kp];
        const double cp = ca[kp], sp = sa[kp], wp = op == 0 ? 1.0 / TWO_PI : 2.0 / TWO_PI;
        const double ipc = cp * C_(op) - sp * S_(op), ips = sp * C_(op) + cp * S_(op);
        double gc = 0.0, gsn = 0.0;   /* int cos p tau w, int sin p tau w, w = u(a + tau) - u_a */
        for (size_t kq = 0; kq < n_h && s != 0.0; ++kq) {
            const int32_t oq = harm[kq];
            if (oq == 0) continue;   /* the mean does not vary over the interval */
            const double A = 0.5 * (C_(op - oq) + C_(op + oq)) - C_(op);     /* cos p (cos q - 1) */
            const double B = 0.5 * (S_(oq + op) + S_(oq - op));              /* cos p sin q */
            const double Cc = 0.5 * (S_(op + oq) + S_(op - oq)) - S_(op);    /* sin p (cos q - 1) */
            const double D = 0.5 * (C_(op - oq) - C_(op + oq));              /* sin p sin q */
            gc += A * vc[kq] + B * vs[kq];
            gsn += Cc * vc[kq] + D * vs[kq];
        }
        Fh[pc] += wp * (Fa * ipc + s * (cp * gc - sp * gsn));
        ip[pc] = ipc;
        if (op) {
            Fh[pc + 1] += wp * (Fa * ips + s * (sp * gc + cp * gsn));
            ip[pc + 1] = ips;
        }
        pc += op ? 2 : 1;
    }
    if (s != 0.0) {   /* s int cos k t, s int sin k t over [a, a + L], k < K */
        const double c1 = cos(a), s1 = sin(a);
        double ck = 1.0, sk = 0.0;
        for (size_t k = 0; k < K; ++k) {
            if (k % SCAN_SYNC == 0) {   /* the rotation re-synchronised (drift ~ k eps) */
                ck = cos((double)k * a);
                sk = sin((double)k * a);
            }
            kc[k] += s * (ck * trig[k] - sk * trig[K + k]);
            ks[k] += s * (sk * trig[k] + ck * trig[K + k]);
            const double cn = ck * c1 - sk * s1;
            sk = sk * c1 + ck * s1;
            ck = cn;
        }
    }
#undef S_
#undef C_
}

/* dFh[p*nb + q] = w_p int K psi_p phi_q dt for the piecewise-constant stiffness K(t) of
 * Fourier coefficients kc, ks (k < K): products of two harmonics are the orders p +- q, so
 * the (nb, nb) matrix is Toeplitz plus Hankel in the orders, one pass of O(nb^2) (the
 * anchors' terms w_p ip dc^T are added by the caller). */
static void stiffness_jacobian(size_t nb, const int32_t *ord, const int8_t *kind,
                               const double *kc, const double *ks, double *dFh)
{
#define KS_(k) ((k) < 0 ? -ks[-(k)] : ks[(k)])
    for (size_t P = 0; P < nb; ++P) {
        const int32_t op = ord[P];
        const double wp = op == 0 ? 1.0 / TWO_PI : 2.0 / TWO_PI;
        double *row = dFh + P * nb;
        for (size_t Q = 0; Q < nb; ++Q) {
            const int32_t oq = ord[Q], dm = abs(op - oq), sm = op + oq;
            double v;
            if (!kind[P]) v = kind[Q] ? KS_(oq - op) + ks[sm] : kc[dm] + kc[sm];
            else v = kind[Q] ? kc[dm] - kc[sm] : ks[sm] + KS_(op - oq);
            row[Q] = 0.5 * wp * v;
        }
    }
#undef KS_
}

iwan_status iwan_periodic_fourier(const iwan_model *model, size_t n_h, const int32_t *harm,
                                  const double *U, size_t n_scan, double *Fh, double *dFh,
                                  double *W_cycle, size_t *n_ext_out)
{
    iwan_status st = iwanp_check_model(model);
    if (st != IWAN_OK) return st;
    if (!harm || !U || !Fh || !dFh || !n_ext_out || n_h == 0 || n_scan < 4) return IWAN_ERR_BAD_PARAM;
    size_t nb = 0;
    int32_t hmax = 0;
    for (size_t k = 0; k < n_h; ++k) {
        if (harm[k] < 0 || (k > 0 && harm[k] <= harm[k - 1])) return IWAN_ERR_BAD_PARAM;
        nb += harm[k] == 0 ? 1 : 2;
        if (harm[k] > hmax) hmax = harm[k];
    }
    if ((size_t)(2 * hmax) >= n_scan) return IWAN_ERR_BAD_PARAM;  /* the scan must resolve u' */
    if (iwanp_check_finite(U, nb)) return IWAN_ERR_NONFINITE;
    memset(Fh, 0, nb * sizeof *Fh);
    memset(dFh, 0, nb * nb * sizeof *dFh);
    *n_ext_out = 0;
    if (W_cycle) *W_cycle = 0.0;

    const size_t K = (size_t)(2 * hmax) + 1;   /* frequencies 0 .. 2 hmax */
    const size_t ns = (size_t)model->n;
    double *tab = malloc(2 * (size_t)(hmax + 1) * sizeof *tab);
    double *th_e = malloc(n_scan * sizeof *th_e);
    double *u_e = malloc(n_scan * sizeof *u_e);
    int32_t *ord = malloc(nb * sizeof *ord);
    int8_t *kind = malloc(nb);
    double *trig = malloc((2 * K + 4 * n_h) * sizeof *trig);
    if (!tab || !th_e || !u_e || !ord || !kind || !trig) {
        free(tab); free(th_e); free(u_e); free(ord); free(kind); free(trig);
        return IWAN_ERR_BAD_PARAM;
    }
    tpoly p = {n_h, harm, hmax, tab, tab + hmax + 1};
    for (size_t k = 0, q = 0; k < n_h; ++k) {
        ord[q] = harm[k];
        kind[q++] = 0;
        if (harm[k] > 0) { ord[q] = harm[k]; kind[q++] = 1; }
    }
    double usum = 0.0;
    for (size_t q = 0; q < nb; ++q) usum += fabs(U[q]) * (ord[q] > 0 ? ord[q] : 1);

    /* 1. extrema: sign changes of u' on the scan grid, refined */
    size_t ne = 0;
    const double dt = TWO_PI / (double)n_scan;
    /* A pair of zeros of u' closer than a scan step (a wiggle of u being born: a minor
     * loop) leaves u' of one sign at both ends of its cell; it is found from the
     * extremum of u' inside the cell (a sign change of u''), so that the loop's pieces
     * appear continuously, from zero size, as the input changes. */
    const double ftol1 = 8.0 * DBL_EPSILON * usum * hmax;
    /* |u''| <= B = sum h^2 |U_h|: a cell where |u'| exceeds B dt at both ends cannot hold
     * a zero of u', and u'' (the test for a pair) is evaluated only in the others */
    double B = 0.0;
    for (size_t q = 0; q < nb; ++q) B += fabs(U[q]) * (double)ord[q] * ord[q];
    const double gmin = B * dt;
    /* u' and u'' on the scan grid (scan_derivatives: one FFT, or phasors) */
    double *gs_scan = malloc(2 * (n_scan + 1) * sizeof *gs_scan);
    double *pz = malloc((n_scan + 4 * n_h) * sizeof *pz);
    if (!gs_scan || !pz) {
        free(gs_scan); free(pz);
        st = IWAN_ERR_BAD_PARAM;
        goto done;
    }
    scan_derivatives(n_h, harm, U, n_scan, gs_scan, pz);
    /* the period closes exactly (the value at 2 pi is the one at 0, not a second one with
     * its own round-off: a zero of u' at t = 0 would be lost between a tiny value at 2 pi
     * and the exact 0 at 0) */
    gs_scan[2 * n_scan] = gs_scan[0];
    gs_scan[2 * n_scan + 1] = gs_scan[1];
    double g = gs_scan[0], c = gs_scan[1];
    for (size_t j = 0; j < n_scan && ne + 2 <= n_scan; ++j) {
        const double t = dt * (double)j;
        const double gn = gs_scan[2 * (j + 1)], cn = gs_scan[2 * (j + 1) + 1];
        const int near = fabs(g) <= gmin || fabs(gn) <= gmin;
        if ((g > 0.0 && gn <= 0.0) || (g < 0.0 && gn >= 0.0)) {
            const double r = root(&p, U, 1, 0.0, t, t + dt, g, ftol1);
            th_e[ne++] = r >= TWO_PI ? r - TWO_PI : r;
        } else if (near && ((g > 0.0 && c < 0.0 && cn > 0.0) || (g < 0.0 && c > 0.0 && cn < 0.0))) {
            const double ts = root(&p, U, 2, 0.0, t, t + dt, c, ftol1 * hmax);
            const double gs = eval_u(&p, U, ts, 1);
            if ((g > 0.0 && gs <= 0.0) || (g < 0.0 && gs >= 0.0)) {
                const double r1 = gs == 0.0 ? ts : root(&p, U, 1, 0.0, t, ts, g, ftol1);
                const double r2 = gs == 0.0 ? ts : root(&p, U, 1, 0.0, ts, t + dt, gs, ftol1);
                th_e[ne++] = r1 >= TWO_PI ? r1 - TWO_PI : r1;
                th_e[ne++] = r2 >= TWO_PI ? r2 - TWO_PI : r2;
            }
        }
        g = gn;
        c = cn;
    }
    free(gs_scan);
    free(pz);
    /* roots of the last cell that wrapped past 2 pi go first */
    while (ne >= 2 && th_e[ne - 1] < th_e[0]) {
        const double r = th_e[ne - 1];
        memmove(th_e + 1, th_e, (ne - 1) * sizeof *th_e);
        th_e[0] = r;
    }
    if (ne < 2 || ne % 2) {   /* constant input, or a scan that lost a root: no integrals */
        *n_ext_out = ne;
        goto done;
    }
    for (size_t e = 0; e < ne; ++e) u_e[e] = eval_u(&p, U, th_e[e], 0);

    /* 2. the loop between the extrema */
    const size_t cap = ne * (ns + 1);
    size_t m = 0, *seg = malloc(cap * sizeof *seg);
    double *lo = malloc(cap * sizeof *lo), *hi = malloc(cap * sizeof *hi);
    double *sl = malloc(cap * sizeof *sl), *ic = malloc(cap * sizeof *ic);
    double *A = malloc(cap * ne * sizeof *A), *tl = malloc(cap * sizeof *tl);
    double *phie = malloc(ne * nb * sizeof *phie);
    double W = 0.0;
    if (!seg || !lo || !hi || !sl || !ic || !A || !tl || !phie) {
        st = IWAN_ERR_BAD_PARAM;
        goto free_loop;
    }
    st = iwan_periodic_branches(model, ne, u_e, cap, &m, seg, lo, hi, sl, ic, A, &W);
    if (st != IWAN_OK) goto free_loop;
    for (size_t e = 0; e < ne; ++e) {
        rot_table(&p, th_e[e]);
        for (size_t q = 0; q < nb; ++q)
            phie[e * nb + q] = kind[q] ? p.s[ord[q]] : p.c[ord[q]];
    }

    /* 3. interval starts in theta (each knot once; a segment starts at its extremum) */
    for (size_t i = 0; i < m; ++i) {
        const size_t e0 = seg[i], e1 = (seg[i] + 1) % ne;
        const double t0 = th_e[e0], t1 = e1 ? th_e[e1] : th_e[0] + TWO_PI;
        if (lo[i] == u_e[e0]) { tl[i] = t0; continue; }
        const double f0 = u_e[e0] - lo[i];
        tl[i] = root(&p, U, 0, lo[i], t0, t1, f0, 4.0 * DBL_EPSILON * usum);
    }

    /* 4. closed-form integrals, interval by interval: Fh, the stiffness's Fourier
     * coefficients and the anchors' terms of the Jacobian. On interval i the stuck
     * sliders follow their anchors: dc_i/dU = -sum_e A[i][e] phi(theta_e) (a slipping
     * interval has none: every slider has k_j > 0, so s = 0 means none is stuck), so
     * the anchors add -sum_e g_e phi(theta_e)^T with g_e (ga) = sum_i A[i][e] w ip_i: one
     * outer product per extremum, however many intervals it anchors. */
    double *kc = calloc(2 * K, sizeof *kc), *ks = kc ? kc + K : NULL;
    double *ip = malloc(nb * sizeof *ip), *ga = calloc(ne * nb, sizeof *ga);
    if (!kc || !ip || !ga) {
        st = IWAN_ERR_BAD_PARAM;
        free(kc); free(ip); free(ga);
        goto free_loop;
    }
    for (size_t i = 0; i < m; ++i) {
        const size_t e1 = (seg[i] + 1) % ne;
        const double a = tl[i];
        const double b = (i + 1 < m && seg[i + 1] == seg[i]) ? tl[i + 1]
                         : (e1 ? th_e[e1] : th_e[0] + TWO_PI);
        if (!(b > a)) continue;
        const double u_a = sl[i] != 0.0 ? eval_u(&p, U, a, 0) : 0.0;
        interval_integrals(n_h, harm, U, a, b - a, ic[i], sl[i], u_a, trig, K, Fh, ip, kc, ks);
        for (size_t e = 0; e < ne && sl[i] != 0.0; ++e) {
            const double Ae = A[i * ne + e];
            if (Ae == 0.0) continue;
            for (size_t q = 0; q < nb; ++q)
                ga[e * nb + q] += Ae * (ord[q] == 0 ? 1.0 / TWO_PI : 2.0 / TWO_PI) * ip[q];
        }
    }
    stiffness_jacobian(nb, ord, kind, kc, ks, dFh);
    for (size_t e = 0; e < ne; ++e)
        for (size_t P = 0; P < nb; ++P) {
            const double f = ga[e * nb + P];
            const double *ph = phie + e * nb;
            double *row = dFh + P * nb;
            if (f != 0.0)
                for (size_t Q = 0; Q < nb; ++Q) row[Q] -= f * ph[Q];
        }
    free(kc); free(ip); free(ga);
    *n_ext_out = ne;
    if (W_cycle) *W_cycle = W;
    if (iwanp_check_finite(Fh, nb) || iwanp_check_finite(dFh, nb * nb)) st = IWAN_ERR_NONFINITE;
free_loop:
    free(seg); free(lo); free(hi); free(sl); free(ic); free(A); free(tl); free(phie);
done:
    free(tab); free(th_e); free(u_e); free(ord); free(kind); free(trig);
    return st;
}
