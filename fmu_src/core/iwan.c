/*
 * iwan.c -- the Masing/Iwan friction element (implementation of iwan.h): model
 * building, the exact straight-path step, outputs and the time series. The periodic
 * loop and its Jacobian are in iwan_periodic.c; shared helpers in iwan_internal.h.
 *
 * Symbols (SI): u tangential displacement [m], N normal load [N], F force [N].
 * Slider j: spring k_j in series with a Coulomb slider of strength
 *     g_j(N) = fs_j * f(N),   f(N) = scale * N / n_ref          (strength factor)
 * position z_j, elastic stretch e_j = u - z_j, force k_j e_j, |e_j| <= r_j,
 *     r_j(N) = g_j(N) / k_j                                       (slip radius)
 * The residual spring carries k_res (u - u_contact) and never slips.
 * Parallel sliders built from a concave table reproduce the virgin curve and
 * Masing's branches F_r + 2 f((x - x_r)/2) (thesis eqs. 2.15-2.16; Iwan 1966)
 * exactly, with the memory of nested loops.
 *
 * Exact straight-path update (iwan.h): between two committed points
 * (u0, N0) -> (u1, N1) both u and r_j are linear in the path parameter s, so the
 * trial stretch e0 + s du and the limits +-r_j(s) are linear too. A slider that
 * ends outside its limit crossed it once, at s* = (r0 - e0) / (du - dr) (upper
 * limit; mirror for the lower), and slips from s* to 1 at the limit; one that
 * ends inside never left it (a linear function inside at both ends stays
 * inside). The friction work of the slip phase, integral of g(s) dz, is exact by
 * the trapezoid rule because g is linear in s and dz/ds is constant:
 *     dW_j = k_j * slip * (r_j(s*) + r_j(1)) / 2,   slip = |e_trial(1)| - r_j(1).
 * Hence results do not depend on how a piecewise-linear (u, N) path is sampled.
 *
 * Lift-off (N <= 0): the path is followed up to N = 0 (every slider has then
 * slipped down to zero force), then the element is released: F = 0, z_j = u,
 * u_contact = u. The stored energy of the residual spring is released, not
 * counted as friction work. Re-contact at N = 0 (inside a step, by the same
 * straight path) restarts the element virgin at the re-contact displacement.
 */
#include "iwan_internal.h"
#include "iwan_sweep.h"

#include <math.h>
#include <string.h>

/* Concavity check of a table in IWAN_FIT_REJECT mode: a slope may exceed the
 * previous one by this fraction of the largest slope (round-off in slopes of
 * collinear points computed from a curve), not more. */
#define IWAN_CONCAVE_RTOL 1e-9
/* Slopes equal to this relative precision count as one segment (round-off of
 * slopes computed from nearly equal differences). */
#define IWAN_COLLINEAR_RTOL 1e-12

const char *iwan_status_text(iwan_status status)
{
    switch (status) {
    case IWAN_OK: return "ok";
    case IWAN_ERR_NONFINITE: return "NaN or infinite input";
    case IWAN_ERR_BAD_TABLE: return "bad curve table";
    case IWAN_ERR_NOT_CONCAVE: return "curve table is not concave";
    case IWAN_ERR_BAD_PARAM: return "bad parameter";
    case IWAN_ERR_NOT_CONVERGED: return "periodic loop did not close";
    case IWAN_ERR_BAD_STATE: return "bad state";
    }
    return "unknown status";
}

/* ------------------------------------------------------------------ checks */

iwan_status iwanp_check_model(const iwan_model *m)
{
    if (!m || m->n < 0 || m->n > IWAN_MAX_SLIDERS) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(m->n_ref) || !isfinite(m->scale) || !isfinite(m->k_res))
        return IWAN_ERR_NONFINITE;
    if (!(m->n_ref > 0.0) || !(m->scale >= 0.0) || !(m->k_res >= 0.0)) return IWAN_ERR_BAD_PARAM;
    if (m->n == 0 && m->k_res == 0.0) return IWAN_ERR_BAD_PARAM;
    if (m->derived_n != m->n) return IWAN_ERR_BAD_PARAM;  /* not built by the init functions */
    return IWAN_OK;
}

static iwan_status check_state(const iwan_state *s)
{
    if (!s) return IWAN_ERR_BAD_PARAM;
    if (s->version != IWAN_STATE_VERSION || (s->in_contact != 0 && s->in_contact != 1))
        return IWAN_ERR_BAD_STATE;
    if (!isfinite(s->u) || !isfinite(s->N) || !isfinite(s->u_contact) || !isfinite(s->w_diss))
        return IWAN_ERR_BAD_STATE;
    if ((s->in_contact == 1) != (s->N > 0.0) || s->w_diss < 0.0) return IWAN_ERR_BAD_STATE;
    if (s->dir != 1.0 && s->dir != -1.0) return IWAN_ERR_BAD_STATE;
    return IWAN_OK;
}

iwan_status iwanp_check_finite(const double *x, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(x[i])) return IWAN_ERR_NONFINITE;
    return IWAN_OK;
}

/* ------------------------------------------------------------- model build */

static iwan_status slopes_check(const double *u, const double *T, size_t m, iwan_fit fit)
{
    double smax = 0.0;
    for (size_t i = 0; i + 1 < m; ++i) {
        double s = (T[i + 1] - T[i]) / (u[i + 1] - u[i]);
        if (fabs(s) > smax) smax = fabs(s);
    }
    if (fit == IWAN_FIT_CONCAVE) return IWAN_OK;
    double prev = INFINITY;
    for (size_t i = 0; i + 1 < m; ++i) {
        double s = (T[i + 1] - T[i]) / (u[i + 1] - u[i]);
        if (s < 0.0) return IWAN_ERR_BAD_TABLE;  /* T decreasing: negative stiffness */
        if (s > prev + IWAN_CONCAVE_RTOL * smax) return IWAN_ERR_NOT_CONCAVE;
        prev = s;
    }
    return IWAN_OK;
}

/* Upper-hull edge from point i by gift wrapping (O(m) per vertex, no scratch
 * memory): the largest slope to any later point, taken to the farthest point
 * whose slope equals it to IWAN_COLLINEAR_RTOL, so that points collinear up to
 * round-off are merged instead of becoming sliders of stiffness ~1e-16 k. */
static double hull_edge(const double *u, const double *T, size_t m, size_t i, size_t *next)
{
    double best = -INFINITY;
    for (size_t j = i + 1; j < m; ++j) {
        const double s = (T[j] - T[i]) / (u[j] - u[i]);
        if (s > best) best = s;
    }
    const double floor = best - IWAN_COLLINEAR_RTOL * fabs(best);
    for (size_t j = i + 1; j < m; ++j)
        if ((T[j] - T[i]) / (u[j] - u[i]) >= floor) *next = j;
    return (T[*next] - T[i]) / (u[*next] - u[i]);
}

/* Sliders of the least concave non-decreasing majorant of the table: its upper
 * hull, made flat after the first vertex from which no later point is higher
 * (so a noisy plateau at gross slip gives k_res = 0). For a concave table this is
 * the table itself (collinear points merged). */
static iwan_status hull_sliders(iwan_model *md, const double *u, const double *T, size_t m)
{
    size_t i = 0, next = 0;
    double s_prev = hull_edge(u, T, m, 0, &next);
    if (!(s_prev > 0.0)) return IWAN_ERR_BAD_TABLE;  /* no stiffness at all */
    md->n = 0;
    for (i = next; i + 1 < m; i = next) {
        double s = hull_edge(u, T, m, i, &next);
        if (s < 0.0) s = 0.0;                     /* flat after the maximum */
        double k = s_prev - s;
        if (k > 0.0) {                            /* k <= 0 only by round-off: merge */
            if (md->n >= IWAN_MAX_SLIDERS) return IWAN_ERR_BAD_TABLE;
            md->k[md->n] = k;
            md->fs[md->n] = k * u[i];             /* Iwan: fs_j = k_j u_j */
            md->n++;
            s_prev = s;
        }
        if (s == 0.0) break;
    }
    md->k_res = s_prev;
    return IWAN_OK;
}

/* Derived model fields (iwan.h): radii per unit strength factor, rad_j = fs_j / k_j,
 * so r_j(N) = rad_j f(N) is one multiplication in every path (straight path,
 * constant-N sweep, periodic start: the same bits everywhere); fs_sum added in
 * the sweep's two-lane order, so that slip = 1 exactly when every slider slips. */
static void derive(iwan_model *md)
{
    double lane[2] = {0.0, 0.0};
    for (int32_t j = 0; j < md->n; ++j) {
        md->rad[j] = md->fs[j] / md->k[j];
        lane[j & 1] += md->fs[j];
    }
    md->fs_sum = lane[0] + lane[1];
    md->derived_n = md->n;
}

iwan_status iwan_model_init(iwan_model *model, const double *u, const double *T, size_t m,
                            double n_ref, iwan_fit fit)
{
    if (!model || !u || !T || (fit != IWAN_FIT_REJECT && fit != IWAN_FIT_CONCAVE))
        return IWAN_ERR_BAD_PARAM;
    if (!isfinite(n_ref)) return IWAN_ERR_NONFINITE;
    if (!(n_ref > 0.0)) return IWAN_ERR_BAD_PARAM;
    if (m < 2) return IWAN_ERR_BAD_TABLE;
    if (iwanp_check_finite(u, m) || iwanp_check_finite(T, m)) return IWAN_ERR_NONFINITE;
    if (u[0] != 0.0 || T[0] != 0.0) return IWAN_ERR_BAD_TABLE;
    for (size_t i = 1; i < m; ++i)
        if (!(u[i] > u[i - 1])) return IWAN_ERR_BAD_TABLE;
    iwan_status st = slopes_check(u, T, m, fit);
    if (st != IWAN_OK) return st;
    iwan_model md;
    memset(&md, 0, sizeof md);
    st = hull_sliders(&md, u, T, m);
    if (st != IWAN_OK) return st;
    md.n_ref = n_ref;
    md.scale = 1.0;
    derive(&md);
    *model = md;
    return IWAN_OK;
}

iwan_status iwan_model_from_sliders(iwan_model *model, const double *k, const double *fs,
                                    size_t n, double k_res, double n_ref)
{
    if (!model || (n > 0 && (!k || !fs)) || n > IWAN_MAX_SLIDERS) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(k_res) || !isfinite(n_ref)) return IWAN_ERR_NONFINITE;
    if (n > 0 && (iwanp_check_finite(k, n) || iwanp_check_finite(fs, n))) return IWAN_ERR_NONFINITE;
    for (size_t j = 0; j < n; ++j)
        if (!(k[j] > 0.0) || !(fs[j] >= 0.0)) return IWAN_ERR_BAD_PARAM;
    iwan_model md;
    memset(&md, 0, sizeof md);
    md.n = (int32_t)n;
    for (size_t j = 0; j < n; ++j) { md.k[j] = k[j]; md.fs[j] = fs[j]; }
    md.k_res = k_res;
    md.n_ref = n_ref;
    md.scale = 1.0;
    derive(&md);
    iwan_status st = iwanp_check_model(&md);
    if (st != IWAN_OK) return st;
    *model = md;
    return IWAN_OK;
}

iwan_status iwan_state_init(const iwan_model *model, iwan_state *state, double N)
{
    iwan_status st = iwanp_check_model(model);
    if (st != IWAN_OK) return st;
    if (!state) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(N)) return IWAN_ERR_NONFINITE;
    memset(state, 0, sizeof *state);
    state->version = IWAN_STATE_VERSION;
    state->in_contact = N > 0.0;
    state->N = N;
    state->dir = 1.0;
    return IWAN_OK;
}

/* ------------------------------------------------------------------ update */

/* Advance every slider along the straight path (u0, f0) -> (u1, f1) of
 * displacement and strength factor (f0, f1 >= 0); return the friction work. */
static double sliders_path(const iwan_model *m, double *z, double u0, double f0,
                           double u1, double f1, anchors *an)
{
    const double du = u1 - u0;
    double dw = 0.0;
    for (int32_t j = 0; j < m->n; ++j) {
        const double k = m->k[j];
        const double r0 = m->rad[j] * f0, r1 = m->rad[j] * f1;
        const double dr = r1 - r0;
        double e0 = u0 - z[j];
        if (e0 > r0 || e0 < -r0) {        /* outside only by round-off: project */
            e0 = e0 > r0 ? r0 : -r0;
            z[j] = u0 - e0;
        }
        const double e1 = e0 + du;
        int8_t sg = 0;
        if (e1 > r1) {                    /* stick to s*, slip at +r to s = 1 */
            const double s = (r0 - e0) / (du - dr);
            dw += k * (e1 - r1) * 0.5 * (r0 + s * dr + r1);
            z[j] = u1 - r1;
            sg = 1;
        } else if (e1 < -r1) {            /* mirror: lower limit */
            const double s = (r0 + e0) / (-(du + dr));
            dw += k * (-r1 - e1) * 0.5 * (r0 + s * dr + r1);
            z[j] = u1 + r1;
            sg = -1;
        }
        if (an) {
            an->slip[j] = sg != 0;
            if (sg) { an->au[j] = an->t; an->aN[j] = an->t; an->sg[j] = sg; }
        }
    }
    return dw;
}

/* Force of a state (the F of iwanp_outputs(), without the rest). */
double iwanp_force(const iwan_model *m, const iwan_state *s)
{
    if (!s->in_contact) return 0.0;
    double F = m->k_res * (s->u - s->u_contact);
    for (int32_t j = 0; j < m->n; ++j) F += m->k[j] * (s->u - s->z[j]);
    return F;
}

void iwanp_release(const iwan_model *m, iwan_state *s, double u)
{
    for (int32_t j = 0; j < m->n; ++j) s->z[j] = u;
    s->u_contact = u;
    s->in_contact = 0;
}

/* Exact update of s along the straight path to (u1, N1), with lift-off and
 * re-contact at the point where N crosses zero. */
void iwanp_advance(const iwan_model *m, iwan_state *s, double u1, double N1, anchors *an)
{
    const double u0 = s->u, N0 = s->N, du = u1 - u0;
    if (N0 > 0.0 && N1 > 0.0) {
        s->w_diss += sliders_path(m, s->z, u0, strength_factor(m, N0), u1,
                                  strength_factor(m, N1), an);
    } else if (N0 > 0.0) {                 /* lift-off where N = 0 */
        const double sl = N0 / (N0 - N1);
        s->w_diss += sliders_path(m, s->z, u0, strength_factor(m, N0), u0 + sl * du, 0.0, an);
        iwanp_release(m, s, u1);
    } else if (N1 > 0.0) {                 /* re-contact where N = 0: virgin there */
        const double sc = -N0 / (N1 - N0);
        const double uc = u0 + sc * du;
        for (int32_t j = 0; j < m->n; ++j) s->z[j] = uc;
        s->u_contact = uc;
        s->in_contact = 1;
        if (an) {
            for (int32_t j = 0; j < m->n; ++j) an->au[j] = ANCHOR_RECONTACT(an->t);
            an->res = ANCHOR_RECONTACT(an->t);
        }
        s->w_diss += sliders_path(m, s->z, uc, 0.0, u1, strength_factor(m, N1), an);
    } else {
        iwanp_release(m, s, u1);
    }
    if (du > 0.0) s->dir = 1.0;
    else if (du < 0.0) s->dir = -1.0;
    s->u = u1;
    s->N = N1;
}

/* Direction of the motion to u (unchanged when u does not move). */
static double new_dir(const iwan_state *s, double u)
{
    return u > s->u ? 1.0 : (u < s->u ? -1.0 : s->dir);
}

/* Outputs of an in-contact state at strength factor f from its sweep sums. A slider
 * counts as slipping at its limit on the side of the last motion (it would slip on
 * continued motion): it adds nothing to kt and +-dg/dN to dF/dN. */
static void sums_to_outputs(const iwan_model *m, const iwan_state *s, double f,
                            const sweep_sums *a, iwan_output *o)
{
    const double ur = s->u - s->u_contact;
    o->F = a->F + m->k_res * ur;
    o->kt = m->k_res + a->ks;
    o->dFdN = s->dir * a->fsl * (m->scale / m->n_ref);
    o->W = s->w_diss;
    o->E = 0.5 * (a->E2 + m->k_res * ur * ur);
    o->slip = (m->fs_sum > 0.0 && f > 0.0) ? a->fsl / m->fs_sum : 1.0;
}

/* Outputs of a state: the sweep at its own point (positions unchanged). */
void iwanp_outputs(const iwan_model *m, const iwan_state *s, iwan_output *o)
{
    if (!s->in_contact) {
        o->W = s->w_diss;
        o->F = o->kt = o->dFdN = o->E = 0.0;
        o->slip = 1.0;
        return;
    }
    const double f = strength_factor(m, s->N);
    sweep_sums a;
    sweep_dir(m, s->z, NULL, f, s->u, s->dir, 0, 1, &a);
    sums_to_outputs(m, s, f, &a, o);
}

/* Step to u at the constant N > 0 of the state s (the fast path of iwan_step and
 * iwan_eval): one pass reads the positions from z, writes them to zout (may be z, or
 * NULL for outputs only), updates the header of s (u, dir, w_diss) and the outputs. */
static void step_const(const iwan_model *m, iwan_state *s, const double *z, double *zout,
                       double u, iwan_output *o)
{
    const double f = strength_factor(m, s->N);
    sweep_sums a;
    s->dir = new_dir(s, u);
    s->u = u;
    if (zout) sweep_dir(m, z, zout, f, u, s->dir, 1, 1, &a);
    else sweep_dir(m, z, NULL, f, u, s->dir, 0, 1, &a);
    s->w_diss += f * a.w;
    if (o) sums_to_outputs(m, s, f, &a, o);
}

/* The constant-N fast path applies: in contact and N unchanged. */
static int constant_n(const iwan_state *s, double N)
{
    return s->in_contact && N == s->N;
}

iwan_status iwan_eval(const iwan_model *model, const iwan_state *committed, double u, double N,
                      iwan_state *trial, iwan_output *out)
{
    iwan_status st = iwanp_check_model(model);
    if (st != IWAN_OK) return st;
    st = check_state(committed);
    if (st != IWAN_OK) return st;
    if (!isfinite(u) || !isfinite(N)) return IWAN_ERR_NONFINITE;
    if (trial == committed) return IWAN_ERR_BAD_PARAM;
    if (trial) {
        *trial = *committed;
        return iwan_step(model, trial, u, N, out);
    }
    iwan_state s;
    if (constant_n(committed, N)) {        /* outputs only: copy the header, not z */
        memcpy(&s, committed, offsetof(iwan_state, z));
        s.dir = committed->dir;
        step_const(model, &s, committed->z, NULL, u, out);
        return IWAN_OK;
    }
    s = *committed;
    iwanp_advance(model, &s, u, N, NULL);
    if (out) iwanp_outputs(model, &s, out);
    return IWAN_OK;
}

iwan_status iwan_step(const iwan_model *model, iwan_state *state, double u, double N,
                      iwan_output *out)
{
    iwan_status st = iwanp_check_model(model);
    if (st != IWAN_OK) return st;
    st = check_state(state);
    if (st != IWAN_OK) return st;
    if (!isfinite(u) || !isfinite(N)) return IWAN_ERR_NONFINITE;
    if (constant_n(state, N)) {
        step_const(model, state, state->z, state->z, u, out);
    } else {
        iwanp_advance(model, state, u, N, NULL);
        if (out) iwanp_outputs(model, state, out);
    }
    return IWAN_OK;
}

/* ------------------------------------------------------------- time series */

/* n samples at the committed constant N > 0: the step's own pass per sample
 * (step_const), outputs stored per sample. */
void iwanp_run_const(const iwan_model *m, iwan_state *s, size_t n, const double *u,
                     double *F, double *kt, double *dFdN, double *W)
{
    const double f = strength_factor(m, s->N), dgdN = m->scale / m->n_ref;
    for (size_t i = 0; i < n; ++i) {
        sweep_sums a;
        s->dir = new_dir(s, u[i]);
        s->u = u[i];
        sweep_dir(m, s->z, s->z, f, u[i], s->dir, 1, 0, &a);
        s->w_diss += f * a.w;
        /* the expressions of sums_to_outputs: the same bits as iwan_step */
        if (F) F[i] = a.F + m->k_res * (u[i] - s->u_contact);
        if (kt) kt[i] = m->k_res + a.ks;
        if (dFdN) dFdN[i] = s->dir * a.fsl * dgdN;
        if (W) W[i] = s->w_diss;
    }
}

void iwanp_store(const iwan_output *o, size_t i, double *F, double *kt, double *dFdN, double *W)
{
    if (F) F[i] = o->F;
    if (kt) kt[i] = o->kt;
    if (dFdN) dFdN[i] = o->dFdN;
    if (W) W[i] = o->W;
}

/* The body of iwan_series on checked arguments (also one sample of iwan_step_batch). */
static void series_run(const iwan_model *model, iwan_state *state, size_t n,
                       const double *u, const double *N,
                       double *F, double *kt, double *dFdN, double *W)
{
    size_t i = 0;
    while (i < n) {
        const double Ni = N ? N[i] : model->n_ref;
        if (state->in_contact && Ni == state->N) {   /* run of constant N: fast sweep */
            size_t j = i + 1;
            if (N) while (j < n && N[j] == Ni) ++j;
            else j = n;
            iwanp_run_const(model, state, j - i, u + i, F ? F + i : NULL, kt ? kt + i : NULL,
                      dFdN ? dFdN + i : NULL, W ? W + i : NULL);
            i = j;
        } else {
            iwan_output o;
            iwanp_advance(model, state, u[i], Ni, NULL);
            iwanp_outputs(model, state, &o);
            iwanp_store(&o, i, F, kt, dFdN, W);
            ++i;
        }
    }
}

iwan_status iwan_series(const iwan_model *model, iwan_state *state, size_t n,
                        const double *u, const double *N,
                        double *F, double *kt, double *dFdN, double *W)
{
    iwan_status st = iwanp_check_model(model);
    if (st != IWAN_OK) return st;
    st = check_state(state);
    if (st != IWAN_OK) return st;
    if (!u || n == 0) return IWAN_ERR_BAD_PARAM;
    if (iwanp_check_finite(u, n) || (N && iwanp_check_finite(N, n))) return IWAN_ERR_NONFINITE;
    series_run(model, state, n, u, N, F, kt, dFdN, W);
    return IWAN_OK;
}

/* ------------------------------------------------------------ batch of states */

/* Every check first (model, each state, each input), so that a failure leaves all
 * states untouched; then state i takes one sample of the time series (series_run
 * with n = 1): at constant N the step's own pass (iwanp_run_const), otherwise the
 * straight-path update and the outputs of the state, i.e. the code of iwan_step, so
 * the bits are those of iwan_step on each state separately. */
iwan_status iwan_step_batch(const iwan_model *model, iwan_state *states, size_t n_states,
                            const double *u, const double *N, double *F, double *kt)
{
    iwan_status st = iwanp_check_model(model);
    if (st != IWAN_OK) return st;
    if (!states || !u || !F || n_states == 0) return IWAN_ERR_BAD_PARAM;
    if (iwanp_check_finite(u, n_states) || (N && iwanp_check_finite(N, n_states)))
        return IWAN_ERR_NONFINITE;
    for (size_t i = 0; i < n_states; ++i) {
        st = check_state(&states[i]);
        if (st != IWAN_OK) return st;
    }
    for (size_t i = 0; i < n_states; ++i)
        series_run(model, &states[i], 1, u + i, N ? N + i : NULL, F + i,
                   kt ? kt + i : NULL, NULL, NULL);
    return IWAN_OK;
}
