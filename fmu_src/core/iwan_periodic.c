/*
 * iwan_periodic.c -- periodic steady state of the Masing/Iwan element (iwan.h:
 * iwan_periodic, iwan_periodic_jac). Symbols as in iwan.c: slider j has stiffness
 * k_j, strength g_j(N) = fs_j scale N / n_ref, radius r_j = g_j / k_j, position z_j.
 * At constant N the loop is exact in one pass of the play operator from the
 * maximum of u; with varying N periods are repeated (exact straight-path steps,
 * iwanp_advance) until the state at the sweep start recurs. The Jacobian follows
 * every slider's anchor (the sample where it last slipped).
 */
#include "iwan_internal.h"

#include <math.h>
#include <string.h>

/* ------------------------------------------------------------ periodic loop */

/* Start of the periodic sweep, at the first maximum tM of u (index of the first
 * minimum tm). Convention for the loop's static state (non-unique for sliders
 * that never slip): the element is virgin at u = 0 (residual spring and sliders
 * at rest there) and every slider is shifted by the least amount that keeps it
 * stuck between the loop's extremes, z_j = clamp(0, M - r_j, m + r_j); a slider
 * with M - m >= 2 r_j slips in every cycle and sits at its upper limit at M,
 * z_j = M - r_j, whatever the history. With constant N this state is exactly
 * periodic, so one pass gives the loop (play operator). */
static void periodic_start(const iwan_model *m, size_t n, const double *u, const double *N,
                           iwan_state *s, anchors *an, size_t *tMo)
{
    size_t tM = 0, tm = 0;
    for (size_t i = 1; i < n; ++i) {
        if (u[i] > u[tM]) tM = i;
        if (u[i] < u[tm]) tm = i;
    }
    const double M = u[tM], mn = u[tm], NM = N ? N[tM] : m->n_ref;
    memset(s, 0, sizeof *s);
    memset(an, 0, sizeof *an);
    s->version = IWAN_STATE_VERSION;
    s->u = M;
    s->N = NM;
    s->dir = 1.0;
    an->res = ANCHOR_ORIGIN;
    *tMo = tM;
    if (!(NM > 0.0)) {
        iwanp_release(m, s, M);
        for (int32_t j = 0; j < m->n; ++j) an->au[j] = ANCHOR_ORIGIN;
        return;
    }
    s->in_contact = 1;
    const double f = strength_factor(m, NM);
    for (int32_t j = 0; j < m->n; ++j) {
        const double r = m->rad[j] * f;   /* the sweep's radius: z = M - r is its bound */
        an->aN[j] = (int32_t)tM;
        if (M - mn >= 2.0 * r || 0.0 < M - r) {
            s->z[j] = M - r;
            an->au[j] = (int32_t)tM;
            an->sg[j] = 1;
        } else if (0.0 > mn + r) {
            s->z[j] = mn + r;
            an->au[j] = (int32_t)tm;
            an->sg[j] = -1;
        } else {
            s->z[j] = 0.0;
            an->au[j] = ANCHOR_ORIGIN;
        }
    }
}

/* Force-weighted distance of two states: bounds the change of F over a period. */
static double state_distance(const iwan_model *m, const iwan_state *a, const iwan_state *b)
{
    if (a->in_contact != b->in_contact) return INFINITY;
    double d = m->k_res * fabs(a->u_contact - b->u_contact);
    for (int32_t j = 0; j < m->n; ++j) d += m->k[j] * fabs(a->z[j] - b->z[j]);
    return d;
}

/* Repeat periods from the state s at sample tM until the state at tM recurs
 * within tol times the force range of the period. */
static iwan_status march(const iwan_model *m, size_t n, const double *u, const double *N,
                         size_t tM, iwan_state *s, anchors *an, int max_periods, double tol,
                         double *F, double *kt, double *dFdN, double *W_cycle, int *periods)
{
    for (int p = 1; p <= max_periods; ++p) {
        const iwan_state s0 = *s;
        double fmin = INFINITY, fmax = -INFINITY;
        for (size_t k = 1; k <= n; ++k) {
            const size_t t = (tM + k) % n;
            iwan_output o;
            if (an) an->t = (int32_t)t;
            iwanp_advance(m, s, u[t], N ? N[t] : m->n_ref, an);
            iwanp_outputs(m, s, &o);
            iwanp_store(&o, t, F, kt, dFdN, NULL);
            if (o.F < fmin) fmin = o.F;
            if (o.F > fmax) fmax = o.F;
        }
        *W_cycle = s->w_diss - s0.w_diss;
        *periods = p;
        if (state_distance(m, &s0, s) <= tol * (fmax - fmin)) return IWAN_OK;
    }
    return IWAN_ERR_NOT_CONVERGED;
}

static int all_equal(const double *x, size_t n)
{
    for (size_t i = 1; i < n; ++i)
        if (x[i] != x[0]) return 0;
    return 1;
}

static iwan_status check_periodic(const iwan_model *model, size_t n, const double *u,
                                  const double *N, int max_periods, double tol)
{
    iwan_status st = iwanp_check_model(model);
    if (st != IWAN_OK) return st;
    if (!u || n == 0 || max_periods < 1) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(tol)) return IWAN_ERR_NONFINITE;
    if (!(tol >= 0.0)) return IWAN_ERR_BAD_PARAM;
    if (iwanp_check_finite(u, n) || (N && iwanp_check_finite(N, n))) return IWAN_ERR_NONFINITE;
    return IWAN_OK;
}

iwan_status iwan_periodic(const iwan_model *model, size_t n, const double *u, const double *N,
                          double *F, double *kt, double *dFdN, double *W_cycle,
                          int max_periods, double tol, int *periods_used)
{
    iwan_status st = check_periodic(model, n, u, N, max_periods, tol);
    if (st != IWAN_OK) return st;
    iwan_state s;
    anchors an;
    size_t tM;
    double w = 0.0;
    int p = 0;
    periodic_start(model, n, u, N, &s, &an, &tM);
    if (s.in_contact && (!N || all_equal(N, n))) {
        /* exact in one pass: tM+1 .. n-1, then 0 .. tM (closing the period) */
        iwanp_run_const(model, &s, n - 1 - tM, u + tM + 1, F ? F + tM + 1 : NULL,
                  kt ? kt + tM + 1 : NULL, dFdN ? dFdN + tM + 1 : NULL, NULL);
        iwanp_run_const(model, &s, tM + 1, u, F, kt, dFdN, NULL);
        w = s.w_diss;
        p = 1;
    } else {
        st = march(model, n, u, N, tM, &s, NULL, max_periods, tol, F, kt, dFdN, &w, &p);
    }
    if (W_cycle) *W_cycle = w;
    if (periods_used) *periods_used = p;
    return st;
}

/* ------------------------------------------------- periodic loop Jacobian */

/* Most terms of one Jacobian row (jac_terms): per distinct (anchor, strength anchor)
 * group two (one when both anchors are the same sample), the row's own sample, the two ends of a re-contact step. */
#define JAC_TERMS_MAX (2 * IWAN_MAX_SLIDERS + 3)

/* Row t of dF/dX and dF/dXN as terms: dF(t)/dX = sum_i cX[i] Eu[col[i]] and
 * dF(t)/dXN = sum_i cXN[i] EN[col[i]] (at most JAC_TERMS_MAX). A slider that slipped
 * into t carries sg g(N(t)); one stuck since anchor a carries k (u(t) - u(a)) +
 * sg g(N(aN)); one stuck since the virgin state k u(t); one stuck since re-contact
 * k (u(t) - u_c), u_c = u_p + s_c (u_tc - u_p), s_c = -N_p / (N_tc - N_p) on the step
 * p -> tc (see iwanp_advance()). Sliders sharing an anchor are summed into one term.
 * Returns 0 when the row is structurally zero (lifted off, or every slider slipping
 * with no residual spring and no dF/dXN asked): on a stiff contact in gross slip
 * that is most samples. */
static size_t jac_terms(const iwan_model *m, const iwan_state *s, const anchors *an, size_t n,
                        const double *u, const double *N, int want_N, size_t *col, double *cX,
                        double *cXN)
{
    if (!s->in_contact) return 0;
    const size_t t = (size_t)an->t;
    const double dgdN = m->scale / m->n_ref;
    int any = m->k_res != 0.0 || ANCHOR_IS_RECONTACT(an->res);
    for (int32_t j = 0; j < m->n && !any; ++j)
        any = !an->slip[j] || (want_N && m->fs[j] != 0.0);
    if (!any) return 0;
    size_t k = 0;
    double kst = m->k_res, krc = ANCHOR_IS_RECONTACT(an->res) ? m->k_res : 0.0, cnow = 0.0;
    double gk = 0.0, gc = 0.0;
    int32_t ga = ANCHOR_ORIGIN, gn = 0;
    for (int32_t j = 0; j <= m->n; ++j) {
        const int last = j == m->n;
        const int32_t a = last ? ANCHOR_ORIGIN : an->au[j];
        if (!last && an->slip[j]) { cnow += an->sg[j] * m->fs[j] * dgdN; continue; }
        if (!last) kst += m->k[j];
        if (!last && ANCHOR_IS_RECONTACT(a)) { krc += m->k[j]; continue; }
        if (ga >= 0 && (last || a != ga || an->aN[j] != gn)) {   /* flush the group */
            col[k] = (size_t)ga; cX[k] = -gk; cXN[k++] = want_N && gn == ga ? gc : 0.0;
            if (want_N && gn != ga) { col[k] = (size_t)gn; cX[k] = 0.0; cXN[k++] = gc; }
            gk = gc = 0.0;
        }
        if (last) break;
        ga = a;
        gn = an->aN[j];
        if (a >= 0) { gk += m->k[j]; gc += an->sg[j] * m->fs[j] * dgdN; }
    }
    col[k] = t; cX[k] = kst; cXN[k++] = want_N ? cnow : 0.0;
    if (krc > 0.0) {
        const size_t tc = ANCHOR_RECONTACT_STEP(an->res), p = (tc + n - 1) % n;
        const double N0 = N[p], N1 = N[tc], D = N1 - N0, sc = -N0 / D, du = u[tc] - u[p];
        col[k] = p; cX[k] = -krc * (1.0 - sc); cXN[k++] = want_N ? -krc * du * (-N1 / (D * D)) : 0.0;
        col[k] = tc; cX[k] = -krc * sc; cXN[k++] = want_N ? -krc * du * (N0 / (D * D)) : 0.0;
    }
    return k;
}

/* Row t of dF/dX (and dF/dXN) written out from its terms (jac_terms) into rX, rXN
 * (nb each). Returns 0, without touching rX, rXN, when the row is structurally zero,
 * so the compact layout (iwan_periodic_jac_rows) skips it: O(stuck samples x nb). */
static int jac_row(const iwan_model *m, const iwan_state *s, const anchors *an, size_t n,
                   size_t nb, const double *u, const double *N, const double *Eu,
                   const double *EN, double *rX, double *rXN)
{
    size_t col[JAC_TERMS_MAX];
    double cX[JAC_TERMS_MAX], cXN[JAC_TERMS_MAX];
    const size_t k = jac_terms(m, s, an, n, u, N, rXN != NULL, col, cX, cXN);
    if (k == 0) return 0;
    for (size_t c = 0; c < nb; ++c) { rX[c] = 0.0; if (rXN) rXN[c] = 0.0; }
    for (size_t i = 0; i < k; ++i) {
        const double *e = Eu + col[i] * nb, *en = rXN ? EN + col[i] * nb : NULL;
        if (cX[i] != 0.0) for (size_t c = 0; c < nb; ++c) rX[c] += cX[i] * e[c];
        if (rXN && cXN[i] != 0.0) for (size_t c = 0; c < nb; ++c) rXN[c] += cXN[i] * en[c];
    }
    return 1;
}

/* The state at the sweep start tM from which the final pass runs: periodic_start,
 * then with varying N periods marched until it recurs (p: periods marched). */
static iwan_status closed_start(const iwan_model *model, size_t n, const double *u,
                                const double *N, iwan_state *s, anchors *an, size_t *tM,
                                int max_periods, double tol, int *p)
{
    double w = 0.0;
    *p = 0;
    periodic_start(model, n, u, N, s, an, tM);
    if (N && !all_equal(N, n))
        return march(model, n, u, N, *tM, s, an, max_periods, tol, NULL, NULL, NULL, &w, p);
    return IWAN_OK;
}

/* Shared body of iwan_periodic_jac (rows == NULL: dense rows, t * nb) and
 * iwan_periodic_jac_rows (rows != NULL: only the non-zero rows, packed, their
 * samples in rows[0 .. *n_rows - 1]). */
static iwan_status periodic_jac_impl(const iwan_model *model, size_t n, const double *u,
                                     const double *N, const double *Eu, const double *EN,
                                     size_t nb, double *F, size_t *rows, size_t *n_rows,
                                     double *dFdX, double *dFdXN, double *W_cycle,
                                     int max_periods, double tol, int *periods_used)
{
    iwan_status st = check_periodic(model, n, u, N, max_periods, tol);
    if (st != IWAN_OK) return st;
    /* anchors hold sample indices as int32; n * nb must not overflow */
    if (!Eu || nb == 0 || n > (size_t)INT32_MAX / 2 || nb > SIZE_MAX / n) return IWAN_ERR_BAD_PARAM;
    /* Dense rows: every entry of Eu, EN is checked. Packed rows: only the rows the
     * Jacobian is made of, through its (non-finite where they are) rows at the end;
     * checking all n x nb inputs cost as much as the whole sweep on a stiff contact. */
    if (!rows && (iwanp_check_finite(Eu, n * nb) || (EN && iwanp_check_finite(EN, n * nb))))
        return IWAN_ERR_NONFINITE;
    iwan_state s;
    anchors an;
    size_t tM, k_row = 0;
    int p = 0;
    st = closed_start(model, n, u, N, &s, &an, &tM, max_periods, tol, &p);
    if (st != IWAN_OK) {
        if (periods_used) *periods_used = p;
        return st;
    }
    double *dXN = (EN && dFdXN) ? dFdXN : NULL;
    const double w0 = s.w_diss;
    for (size_t k = 1; k <= n; ++k) {       /* final pass from the closed state */
        const size_t t = (tM + k) % n;
        an.t = (int32_t)t;
        iwanp_advance(model, &s, u[t], N ? N[t] : model->n_ref, &an);
        if (F) F[t] = iwanp_force(model, &s);
        if (!dFdX) continue;
        const size_t r = rows ? k_row : t;
        if (jac_row(model, &s, &an, n, nb, u, N, Eu, EN, dFdX + r * nb, dXN ? dXN + r * nb : NULL)) {
            if (rows) rows[k_row++] = t;
        } else if (!rows) {
            memset(dFdX + t * nb, 0, nb * sizeof *dFdX);
            if (dXN) memset(dXN + t * nb, 0, nb * sizeof *dXN);
        }
    }
    if (rows && (iwanp_check_finite(dFdX, k_row * nb) || (dXN && iwanp_check_finite(dXN, k_row * nb))))
        return IWAN_ERR_NONFINITE;
    if (n_rows) *n_rows = k_row;
    if (W_cycle) *W_cycle = s.w_diss - w0;
    if (periods_used) *periods_used = p + 1;
    return IWAN_OK;
}

iwan_status iwan_periodic_jac(const iwan_model *model, size_t n, const double *u, const double *N,
                              const double *Eu, const double *EN, size_t nb,
                              double *F, double *dFdX, double *dFdXN, double *W_cycle,
                              int max_periods, double tol, int *periods_used)
{
    return periodic_jac_impl(model, n, u, N, Eu, EN, nb, F, NULL, NULL, dFdX, dFdXN, W_cycle,
                             max_periods, tol, periods_used);
}

iwan_status iwan_periodic_jac_rows(const iwan_model *model, size_t n, const double *u,
                                   const double *N, const double *Eu, const double *EN, size_t nb,
                                   double *F, size_t *rows, size_t *n_rows, double *dFdX,
                                   double *dFdXN, double *W_cycle, int max_periods, double tol,
                                   int *periods_used)
{
    if (!rows || !n_rows || !dFdX) return IWAN_ERR_BAD_PARAM;
    return periodic_jac_impl(model, n, u, N, Eu, EN, nb, F, rows, n_rows, dFdX, dFdXN, W_cycle,
                             max_periods, tol, periods_used);
}

iwan_status iwan_periodic_jac_many(const iwan_model *const *models, size_t n_el, size_t n,
                                   const double *u, const double *N, const double *Eu,
                                   const double *const *EN, size_t nb, double *F, double *dFdX,
                                   double *dFdXN, double *W_cycle, int max_periods, double tol,
                                   size_t *failed)
{
    if (!models || !u || !N || !EN || !F || !dFdX || !dFdXN || !W_cycle || !failed || n == 0
        || nb == 0 || n > SIZE_MAX / nb)
        return IWAN_ERR_BAD_PARAM;
    const size_t m = n * nb;
    for (size_t e = 0; e < n_el; ++e) {
        int used;
        iwan_status st = iwan_periodic_jac(models[e], n, u + e * n, N + e * n, Eu, EN[e], nb,
                                           F + e * n, dFdX + e * m, dFdXN + e * m, W_cycle + e,
                                           max_periods, tol, &used);
        if (st != IWAN_OK) {
            *failed = e;
            return st;
        }
    }
    *failed = n_el;
    return IWAN_OK;
}

iwan_status iwan_periodic_many(const iwan_model *const *models, size_t n_el, size_t n,
                               const double *u, const double *N, double *F, double *W_cycle,
                               int max_periods, double tol, size_t *failed)
{
    if (!models || !u || !N || !F || !W_cycle || !failed || n == 0 || n > (size_t)INT32_MAX / 2)
        return IWAN_ERR_BAD_PARAM;
    for (size_t e = 0; e < n_el; ++e) {
        const iwan_model *m = models[e];
        const double *ue = u + e * n, *Ne = N + e * n;
        double *Fe = F + e * n;
        iwan_state s;
        anchors an;
        size_t tM;
        int p = 0;
        iwan_status st = check_periodic(m, n, ue, Ne, max_periods, tol);
        if (st == IWAN_OK)
            st = closed_start(m, n, ue, Ne, &s, &an, &tM, max_periods, tol, &p);
        if (st != IWAN_OK) {
            *failed = e;
            return st;
        }
        /* the final pass of iwan_periodic_jac_terms without its Jacobian terms (the
         * anchors are kept as there: the same steps, the same bits) */
        const double w0 = s.w_diss;
        for (size_t k = 1; k <= n; ++k) {
            const size_t t = (tM + k) % n;
            an.t = (int32_t)t;
            iwanp_advance(m, &s, ue[t], Ne[t], &an);
            Fe[t] = iwanp_force(m, &s);
        }
        W_cycle[e] = s.w_diss - w0;
    }
    *failed = n_el;
    return IWAN_OK;
}

/* ------------------------------------------- exact loop of a monotone-piecewise input */

iwan_status iwan_periodic_branches(const iwan_model *model, size_t n, const double *u_ext,
                                   size_t cap, size_t *n_int, size_t *seg, double *u_lo,
                                   double *u_hi, double *slope, double *icpt, double *A,
                                   double *W_cycle)
{
    iwan_status st = check_periodic(model, n, u_ext, NULL, 1, 0.0);
    if (st != IWAN_OK) return st;
    const size_t ns = (size_t)model->n;
    if (n < 2 || !n_int || !seg || !u_lo || !u_hi || !slope || !icpt || !A
        || n > (size_t)INT32_MAX / 2 || cap < n * (ns + 1) || cap > SIZE_MAX / n)
        return IWAN_ERR_BAD_PARAM;
    iwan_state s;
    anchors an;
    size_t tM, m = 0;
    periodic_start(model, n, u_ext, NULL, &s, &an, &tM);
    const double f = strength_factor(model, model->n_ref), w0 = s.w_diss;
    memset(A, 0, cap * n * sizeof *A);
    for (size_t k = 1; k <= n; ++k) {
        const size_t e0 = (tM + k - 1) % n, e1 = (tM + k) % n;
        const double ua = s.u, ub = u_ext[e1], sg = ub >= ua ? 1.0 : -1.0, len = sg * (ub - ua);
        /* travel at which each slider reaches its limit (0: already there) */
        double d[IWAN_MAX_SLIDERS];
        for (size_t j = 0; j < ns; ++j) {
            const double r = model->rad[j] * f, t = sg * (s.z[j] + sg * r - ua);
            d[j] = t > 0.0 ? t : 0.0;
        }
        double at = 0.0;   /* travel at the start of the current interval */
        while (at < len) {
            double next = len;
            for (size_t j = 0; j < ns; ++j)
                if (d[j] > at && d[j] < next) next = d[j];
            double sl = model->k_res, c = -model->k_res * s.u_contact;
            for (size_t j = 0; j < ns; ++j) {
                if (d[j] > at) {                  /* stuck on this interval */
                    sl += model->k[j];
                    c -= model->k[j] * s.z[j];
                    if (an.au[j] >= 0) A[m * n + (size_t)an.au[j]] += model->k[j];
                } else {                          /* at its limit: carries +-g_j */
                    c += sg * model->k[j] * model->rad[j] * f;
                }
            }
            seg[m] = e0;
            u_lo[m] = ua + sg * at;
            u_hi[m] = next >= len ? ub : ua + sg * next;   /* the extremum exactly */
            slope[m] = sl;
            icpt[m] = c;
            ++m;
            at = next;
        }
        an.t = (int32_t)e1;
        iwanp_advance(model, &s, ub, model->n_ref, &an);
    }
    *n_int = m;
    if (W_cycle) *W_cycle = s.w_diss - w0;
    return IWAN_OK;
}

iwan_status iwan_periodic_jac_terms(const iwan_model *model, size_t n, const double *u,
                                    const double *N, int with_N, double *F, double *dX,
                                    double *dXN, size_t cap, size_t *n_terms, size_t *row,
                                    size_t *col, double *cX, double *cXN, double *W_cycle,
                                    int max_periods, double tol, int *periods_used)
{
    iwan_status st = check_periodic(model, n, u, N, max_periods, tol);
    if (st != IWAN_OK) return st;
    if (!dX || !dXN || !n_terms || !row || !col || !cX || !cXN || n > (size_t)INT32_MAX / 2
        || cap < n * (size_t)(2 * model->n + 2))
        return IWAN_ERR_BAD_PARAM;
    iwan_state s;
    anchors an;
    size_t tM, k = 0;
    int p = 0;
    st = closed_start(model, n, u, N, &s, &an, &tM, max_periods, tol, &p);
    if (st != IWAN_OK) {
        if (periods_used) *periods_used = p;
        return st;
    }
    const double w0 = s.w_diss;
    size_t tcol[JAC_TERMS_MAX];
    double tX[JAC_TERMS_MAX], tXN[JAC_TERMS_MAX];
    for (size_t i = 1; i <= n; ++i) {       /* final pass from the closed state */
        const size_t t = (tM + i) % n;
        an.t = (int32_t)t;
        iwanp_advance(model, &s, u[t], N ? N[t] : model->n_ref, &an);
        if (F) F[t] = iwanp_force(model, &s);
        const size_t r = jac_terms(model, &s, &an, n, u, N, with_N && N, tcol, tX, tXN);
        dX[t] = dXN[t] = 0.0;
        for (size_t j = 0; j < r; ++j) {
            if (tcol[j] == t) { dX[t] += tX[j]; dXN[t] += tXN[j]; continue; }
            row[k] = t; col[k] = tcol[j]; cX[k] = tX[j]; cXN[k++] = tXN[j];
        }
    }
    if (iwanp_check_finite(dX, n) || iwanp_check_finite(dXN, n) || iwanp_check_finite(cX, k)
        || iwanp_check_finite(cXN, k))
        return IWAN_ERR_NONFINITE;
    *n_terms = k;
    if (W_cycle) *W_cycle = s.w_diss - w0;
    if (periods_used) *periods_used = p + 1;
    return IWAN_OK;
}
