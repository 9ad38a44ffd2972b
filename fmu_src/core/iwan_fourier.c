/*
 * iwan_fourier.c -- exact Fourier coefficients of the periodic loop for an input given
 * by its own Fourier coefficients (iwan.h: iwan_periodic_fourier).
 *
 * u(theta) = sum_h a_h cos(h theta) + b_h sin(h theta) (+ a_0). Its extrema are the
 * zeros of u' (sign scan on n_scan points, then Newton safeguarded by bisection); the
 * loop between them is iwan_periodic_branches (the play operator itself): on interval
 * i, F = c_i + s_i u. Each interval end (a slider reaching its limit) is located in
 * theta (u is monotone between extrema) and the Fourier integrals of c_i + s_i u(theta)
 * are taken in closed form in the interval's local variable t - a (interval_integrals:
 * absolute theta in the arguments loses eps |theta| h of phase, which a stiff slider
 * turns into residual noise). The Jacobian: F is continuous at every interval end and
 * u' = 0 at the extrema, so no boundary terms: dF_p/dU_q = w_p sum_i int psi_p (s_i
 * phi_q + dc_i/dU_q), dc_i/dU = -sum_e A[i][e] phi(theta_e).
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

/* d-th derivative (0 .. 3) of u at t. */
static double eval_u(tpoly *p, const double *U, double t, int d)
{
    rot_table(p, t);
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
        const double df = eval_u(p, U, x, d + 1);
        double xn = x - f / df;
        if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
        if (fabs(xn - x) <= 4.0 * DBL_EPSILON * fabs(x) || hi - lo <= 4.0 * DBL_EPSILON * hi) return xn;
        x = xn;
    }
    return x;
}

/* One interval [a, a + L] of the loop, F = c + s u: written F = F_a + s (u - u_a) with
 * F_a = c + s u_a and integrated in the local variable tau = t - a, so that every integral
 * is over small arguments: int psi_p (phi_q(t) - phi_q(a)) is O(L^2) and computed
 * without the cancellation of c int psi + s int u psi (two terms of size s |u| L whose
 * phase rounding eps h t, times k_t, was ~1e-10 of residual noise at 1e6 k). With
 * C(k) = int_0^L cos k tau, S(k) = int_0^L sin k tau (trig scratch of 2K + 2 nb,
 * K = 2 hmax + 1). On a slipping interval (s = 0, every slider at its limit) F = c does
 * not depend on U: no dc (its sliders' anchors), no q loop. The Jacobian's entries are
 * taken per pair of harmonics (p, q): the four integrals A, B, Cc, D below depend on the
 * orders alone and serve the four (cos, sin) x (cos, sin) entries, so the O(nb^2) loop
 * reads them once per pair, not once per entry. */
static void interval_integrals(size_t n_h, const int32_t *harm, const double *U, double a,
                               double L, double c, double s, const double *dc, double u_a,
                               double *trig, size_t K, size_t nb, double *Fh, double *dFh)
{
    /* a slipping interval needs orders up to hmax only (no products of two harmonics) */
    const size_t kn = s == 0.0 ? (K + 1) / 2 : K;
    for (size_t k = 0; k < kn; ++k) {
        const double h = sin(0.5 * (double)k * L);
        trig[k] = k ? sin((double)k * L) / (double)k : L;
        trig[K + k] = k ? 2.0 * h * h / (double)k : 0.0;
    }
    /* cos, sin of (order x a) per harmonic, once (scratch after the 2K above) */
    double *ca = trig + 2 * K, *sa = ca + n_h;
    for (size_t k = 0; k < n_h; ++k) {
        ca[k] = cos(harm[k] * a);
        sa[k] = sin(harm[k] * a);
    }
#define C_(k) trig[(size_t)abs(k)]
#define S_(k) ((k) < 0 ? -trig[K + (size_t)(-(k))] : trig[K + (size_t)(k)])
    const double Fa = c + s * u_a;
    for (size_t kp = 0, pc = 0; kp < n_h; ++kp) {
        const int32_t op = harm[kp];
        const double cp = ca[kp], sp = sa[kp], wp = op == 0 ? 1.0 / TWO_PI : 2.0 / TWO_PI;
        const size_t ps = pc + 1;   /* the sine row (none for the mean) */
        const double ipc = cp * C_(op) - sp * S_(op), ips = sp * C_(op) + cp * S_(op);
        double acc_c = Fa * ipc, acc_s = Fa * ips;
        if (s != 0.0) {
            double *rc = dFh + pc * nb, *rs = dFh + ps * nb;
            for (size_t kq = 0, q = 0; kq < n_h; ++kq) {
                const int32_t oq = harm[kq];
                if (oq == 0) {   /* the mean does not vary over the interval */
                    rc[q] += wp * ipc * (dc[q] + s);
                    if (op) rs[q] += wp * ips * (dc[q] + s);
                    ++q;
                    continue;
                }
                const double cq = ca[kq], sq = sa[kq];
                const double A = 0.5 * (C_(op - oq) + C_(op + oq)) - C_(op);     /* cos p (cos q - 1) */
                const double B = 0.5 * (S_(oq + op) + S_(oq - op));              /* cos p sin q */
                const double Cc = 0.5 * (S_(op + oq) + S_(op - oq)) - S_(op);    /* sin p (cos q - 1) */
                const double D = 0.5 * (C_(op - oq) - C_(op + oq));              /* sin p sin q */
                const double cc = cp * cq, cs = cp * sq, sc = sp * cq, ss = sp * sq;
                /* int psi_p(a + tau) (phi_q(a + tau) - phi_q(a)), p and q cos or sin */
                const double Icc = cc * A - cs * B - sc * Cc + ss * D;
                const double Ics = cs * A + cc * B - ss * Cc - sc * D;
                acc_c += s * Icc * U[q];
                rc[q] += wp * (s * Icc + ipc * (dc[q] + s * cq));
                acc_c += s * Ics * U[q + 1];
                rc[q + 1] += wp * (s * Ics + ipc * (dc[q + 1] + s * sq));
                if (op) {
                    const double Isc = sc * A - ss * B + cc * Cc - cs * D;
                    const double Iss = ss * A + sc * B + cs * Cc + cc * D;
                    acc_s += s * Isc * U[q];
                    rs[q] += wp * (s * Isc + ips * (dc[q] + s * cq));
                    acc_s += s * Iss * U[q + 1];
                    rs[q + 1] += wp * (s * Iss + ips * (dc[q + 1] + s * sq));
                }
                q += 2;
            }
        }
        Fh[pc] += wp * acc_c;
        if (op) Fh[ps] += wp * acc_s;
        pc += op ? 2 : 1;
    }
#undef S_
#undef C_
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
    double *trig = malloc((2 * K + 2 * nb) * sizeof *trig);
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
    /* u' and u'' on the scan grid from per-harmonic phasors rotated by h dt (no libm
     * call per point), re-synchronised every SCAN_SYNC points (drift ~ steps x eps: it
     * only decides the brackets, the roots are refined with exact evaluations) */
    double *gs_scan = malloc(2 * (n_scan + 1) * sizeof *gs_scan);
    double *pz = malloc(4 * n_h * sizeof *pz);
    if (!gs_scan || !pz) {
        free(gs_scan); free(pz);
        st = IWAN_ERR_BAD_PARAM;
        goto done;
    }
    {
        double *zc = pz, *zs = pz + n_h, *rc = pz + 2 * n_h, *rs = pz + 3 * n_h;
        for (size_t k = 0; k < n_h; ++k) {
            rc[k] = cos(harm[k] * dt);
            rs[k] = sin(harm[k] * dt);
        }
        for (size_t j = 0; j <= n_scan; ++j) {
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
            gs_scan[2 * j] = d1v;
            gs_scan[2 * j + 1] = d2v;
            for (size_t k = 0; k < n_h; ++k) {
                const double c1 = zc[k] * rc[k] - zs[k] * rs[k];
                zs[k] = zs[k] * rc[k] + zc[k] * rs[k];
                zc[k] = c1;
            }
        }
    }
    /* the period closes exactly (the phasors' 2 pi carries round-off: a zero of u' at
     * t = 0 would be lost between a tiny value at 2 pi and the exact 0 at 0) */
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
    double *phie = malloc(ne * nb * sizeof *phie), *dc = malloc(nb * sizeof *dc);
    double W = 0.0;
    if (!seg || !lo || !hi || !sl || !ic || !A || !tl || !phie || !dc) {
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

    /* 4. closed-form integrals, interval by interval */
    for (size_t i = 0; i < m; ++i) {
        const size_t e1 = (seg[i] + 1) % ne;
        const double a = tl[i];
        const double b = (i + 1 < m && seg[i + 1] == seg[i]) ? tl[i + 1]
                         : (e1 ? th_e[e1] : th_e[0] + TWO_PI);
        if (!(b > a)) continue;
        /* d c / dU: the stuck sliders' positions follow their anchors (a slipping
         * interval has none: every slider has k_j > 0, so s = 0 means none is stuck) */
        for (size_t q = 0; q < nb && sl[i] != 0.0; ++q) {
            double v = 0.0;
            for (size_t e = 0; e < ne; ++e) v -= A[i * ne + e] * phie[e * nb + q];
            dc[q] = v;
        }
        const double u_a = sl[i] != 0.0 ? eval_u(&p, U, a, 0) : 0.0;
        interval_integrals(n_h, harm, U, a, b - a, ic[i], sl[i], dc, u_a, trig, K, nb, Fh, dFh);
    }
    *n_ext_out = ne;
    if (W_cycle) *W_cycle = W;
    if (iwanp_check_finite(Fh, nb) || iwanp_check_finite(dFh, nb * nb)) st = IWAN_ERR_NONFINITE;
free_loop:
    free(seg); free(lo); free(hi); free(sl); free(ic); free(A); free(tl); free(phie); free(dc);
done:
    free(tab); free(th_e); free(u_e); free(ord); free(kind); free(trig);
    return st;
}
