/*
 * iwan.c -- the Masing/Iwan friction element (implementation of iwan.h).
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
 * Exact straight-path update (issue 3, iwan.h): between two committed points
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
#include "iwan.h"

#include <math.h>
#include <string.h>

/* Concavity check of a table in IWAN_FIT_REJECT mode: a slope may exceed the
 * previous one by this fraction of the largest slope (round-off in slopes of
 * collinear points computed from a curve), not more. */
#define IWAN_CONCAVE_RTOL 1e-9
/* Slopes equal to this relative precision count as one segment (round-off of
 * slopes computed from nearly equal differences). */
#define IWAN_COLLINEAR_RTOL 1e-12

/* Anchor codes for the exact periodic Jacobian (see iwan_periodic_jac). A slider
 * stuck since sample a (>= 0) has force k (u(t) - u(a)) + sg * g(N(aN)). */
#define ANCHOR_ORIGIN (-1)               /* stuck since the virgin state at u = 0 */
#define ANCHOR_RECONTACT(t) (-2 - (int32_t)(t)) /* stuck since re-contact in the step to t */
#define ANCHOR_IS_RECONTACT(a) ((a) <= -2)
#define ANCHOR_RECONTACT_STEP(a) ((size_t)(-2 - (a)))

typedef struct {
    int32_t au[IWAN_MAX_SLIDERS];   /* sample fixing the slider position (or code above) */
    int32_t aN[IWAN_MAX_SLIDERS];   /* sample fixing the slip force at the anchor */
    int8_t sg[IWAN_MAX_SLIDERS];    /* sign of the slip force at the anchor */
    int8_t slip[IWAN_MAX_SLIDERS];  /* 1 if the slider slipped in the step just made */
    int32_t res;                    /* residual-spring anchor: ANCHOR_ORIGIN or re-contact */
    int32_t t;                      /* index of the sample being reached */
} anchors;

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

static iwan_status check_model(const iwan_model *m)
{
    if (!m || m->n < 0 || m->n > IWAN_MAX_SLIDERS) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(m->n_ref) || !isfinite(m->scale) || !isfinite(m->k_res))
        return IWAN_ERR_NONFINITE;
    if (!(m->n_ref > 0.0) || !(m->scale >= 0.0) || !(m->k_res >= 0.0)) return IWAN_ERR_BAD_PARAM;
    if (m->n == 0 && m->k_res == 0.0) return IWAN_ERR_BAD_PARAM;
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

static iwan_status check_finite(const double *x, size_t n)
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

iwan_status iwan_model_init(iwan_model *model, const double *u, const double *T, size_t m,
                            double n_ref, iwan_fit fit)
{
    if (!model || !u || !T || (fit != IWAN_FIT_REJECT && fit != IWAN_FIT_CONCAVE))
        return IWAN_ERR_BAD_PARAM;
    if (!isfinite(n_ref)) return IWAN_ERR_NONFINITE;
    if (!(n_ref > 0.0)) return IWAN_ERR_BAD_PARAM;
    if (m < 2) return IWAN_ERR_BAD_TABLE;
    if (check_finite(u, m) || check_finite(T, m)) return IWAN_ERR_NONFINITE;
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
    *model = md;
    return IWAN_OK;
}

iwan_status iwan_model_from_sliders(iwan_model *model, const double *k, const double *fs,
                                    size_t n, double k_res, double n_ref)
{
    if (!model || (n > 0 && (!k || !fs)) || n > IWAN_MAX_SLIDERS) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(k_res) || !isfinite(n_ref)) return IWAN_ERR_NONFINITE;
    if (n > 0 && (check_finite(k, n) || check_finite(fs, n))) return IWAN_ERR_NONFINITE;
    for (size_t j = 0; j < n; ++j)
        if (!(k[j] > 0.0) || !(fs[j] >= 0.0)) return IWAN_ERR_BAD_PARAM;
    iwan_model md;
    memset(&md, 0, sizeof md);
    md.n = (int32_t)n;
    for (size_t j = 0; j < n; ++j) { md.k[j] = k[j]; md.fs[j] = fs[j]; }
    md.k_res = k_res;
    md.n_ref = n_ref;
    md.scale = 1.0;
    iwan_status st = check_model(&md);
    if (st != IWAN_OK) return st;
    *model = md;
    return IWAN_OK;
}

iwan_status iwan_state_init(const iwan_model *model, iwan_state *state, double N)
{
    iwan_status st = check_model(model);
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

static double strength_factor(const iwan_model *m, double N)
{
    return m->scale * (N / m->n_ref);
}

/* Advance every slider along the straight path (u0, f0) -> (u1, f1) of
 * displacement and strength factor (f0, f1 >= 0); return the friction work. */
static double sliders_path(const iwan_model *m, double *z, double u0, double f0,
                           double u1, double f1, anchors *an)
{
    const double du = u1 - u0;
    double dw = 0.0;
    for (int32_t j = 0; j < m->n; ++j) {
        const double k = m->k[j];
        const double r0 = m->fs[j] * f0 / k, r1 = f1 == f0 ? r0 : m->fs[j] * f1 / k;
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

/* Force of a state (the F of outputs(), without the rest). */
static double force(const iwan_model *m, const iwan_state *s)
{
    if (!s->in_contact) return 0.0;
    double F = m->k_res * (s->u - s->u_contact);
    for (int32_t j = 0; j < m->n; ++j) F += m->k[j] * (s->u - s->z[j]);
    return F;
}

static void release(const iwan_model *m, iwan_state *s, double u)
{
    for (int32_t j = 0; j < m->n; ++j) s->z[j] = u;
    s->u_contact = u;
    s->in_contact = 0;
}

/* Exact update of s along the straight path to (u1, N1), with lift-off and
 * re-contact at the point where N crosses zero. */
static void advance(const iwan_model *m, iwan_state *s, double u1, double N1, anchors *an)
{
    const double u0 = s->u, N0 = s->N, du = u1 - u0;
    if (N0 > 0.0 && N1 > 0.0) {
        s->w_diss += sliders_path(m, s->z, u0, strength_factor(m, N0), u1,
                                  strength_factor(m, N1), an);
    } else if (N0 > 0.0) {                 /* lift-off where N = 0 */
        const double sl = N0 / (N0 - N1);
        s->w_diss += sliders_path(m, s->z, u0, strength_factor(m, N0), u0 + sl * du, 0.0, an);
        release(m, s, u1);
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
        release(m, s, u1);
    }
    if (du > 0.0) s->dir = 1.0;
    else if (du < 0.0) s->dir = -1.0;
    s->u = u1;
    s->N = N1;
}

/* Outputs of a state. A slider counts as slipping when it sits at its limit on
 * the side of the last motion (it would slip on continued motion): it adds
 * nothing to kt and +-dg/dN to dF/dN. */
static void outputs(const iwan_model *m, const iwan_state *s, iwan_output *o)
{
    o->W = s->w_diss;
    if (!s->in_contact) {
        o->F = o->kt = o->dFdN = o->E = 0.0;
        o->slip = 1.0;
        return;
    }
    const double f = strength_factor(m, s->N), u = s->u, ur = u - s->u_contact;
    const double dgdN = m->scale / m->n_ref;
    double F = m->k_res * ur, kt = m->k_res, dfdn = 0.0, E = 0.5 * m->k_res * ur * ur;
    double g_slip = 0.0, g_all = 0.0;
    for (int32_t j = 0; j < m->n; ++j) {
        const double k = m->k[j], r = m->fs[j] * f / k, e = u - s->z[j];
        const int slipping = s->dir > 0.0 ? s->z[j] <= u - r : s->z[j] >= u + r;
        F += k * e;
        E += 0.5 * k * e * e;
        g_all += m->fs[j];
        if (slipping) {
            dfdn += s->dir * m->fs[j] * dgdN;
            g_slip += m->fs[j];
        } else {
            kt += k;
        }
    }
    o->F = F;
    o->kt = kt;
    o->dFdN = dfdn;
    o->E = E;
    o->slip = (g_all > 0.0 && f > 0.0) ? g_slip / g_all : 1.0;
}

iwan_status iwan_eval(const iwan_model *model, const iwan_state *committed, double u, double N,
                      iwan_state *trial, iwan_output *out)
{
    iwan_status st = check_model(model);
    if (st != IWAN_OK) return st;
    st = check_state(committed);
    if (st != IWAN_OK) return st;
    if (!isfinite(u) || !isfinite(N)) return IWAN_ERR_NONFINITE;
    if (trial == committed) return IWAN_ERR_BAD_PARAM;
    iwan_state s = *committed;
    advance(model, &s, u, N, NULL);
    if (out) outputs(model, &s, out);
    if (trial) *trial = s;
    return IWAN_OK;
}

iwan_status iwan_step(const iwan_model *model, iwan_state *state, double u, double N,
                      iwan_output *out)
{
    iwan_status st = check_model(model);
    if (st != IWAN_OK) return st;
    st = check_state(state);
    if (st != IWAN_OK) return st;
    if (!isfinite(u) || !isfinite(N)) return IWAN_ERR_NONFINITE;
    advance(model, state, u, N, NULL);
    if (out) outputs(model, state, out);
    return IWAN_OK;
}


/* ------------------------------------------------------------- time series */

/* One sample at constant committed N > 0 for every slider. For constant N the
 * exact update reduces to the play operator z <- clamp(z, u - r, u + r) and the
 * friction work to g |dz|. Moving up (u >= previous u), z <= u + r
 * holds already, so only the lower bound can bind: z <- max(z, u - r), and the
 * slider slips iff it binds (mirror for down). Two partial sums per quantity
 * shorten the add-latency chains.
 * acc = {sum k (u - z), sum of k over sticking, sum of fs over slipping, work}. */
/* Body of one slider update in lane L (written once, expanded for both
 * directions and both lanes so that -O2 needs no unrolling or inlining). */
#define SWEEP_SLIDER(J, L, BOUND, SLIPS, WORK)                                   \
    do {                                                                        \
        const double z0 = z[J], bound = (BOUND);                                \
        const int slipping = (SLIPS);                                           \
        const double zn = slipping ? bound : z0;                                \
        w##L += g[J] * (WORK);                                                  \
        z[J] = zn;                                                              \
        Fa##L += k[J] * (u - zn);                                               \
        ks##L += slipping ? 0.0 : k[J];                                         \
        fsl##L += slipping ? fs[J] : 0.0;                                       \
    } while (0)

#define SWEEP_FUNCTION(NAME, BOUND, SLIPS, WORK)                                \
    static void NAME(int32_t n, double *restrict z, const double *restrict r,  \
                     const double *restrict g, const double *restrict k,        \
                     const double *restrict fs, double u, double acc[4])        \
    {                                                                           \
        double Fa0 = 0.0, Fa1 = 0.0, ks0 = 0.0, ks1 = 0.0;                      \
        double fsl0 = 0.0, fsl1 = 0.0, w0 = 0.0, w1 = 0.0;                      \
        int32_t j = 0;                                                          \
        for (; j + 1 < n; j += 2) {                                             \
            SWEEP_SLIDER(j, 0, BOUND(j), SLIPS, WORK);                          \
            SWEEP_SLIDER(j + 1, 1, BOUND(j + 1), SLIPS, WORK);                  \
        }                                                                       \
        if (j < n) SWEEP_SLIDER(j, 0, BOUND(j), SLIPS, WORK);                   \
        acc[0] = Fa0 + Fa1;                                                     \
        acc[1] = ks0 + ks1;                                                     \
        acc[2] = fsl0 + fsl1;                                                   \
        acc[3] = w0 + w1;                                                       \
    }

#define BOUND_UP(J) (u - r[J])
#define BOUND_DOWN(J) (u + r[J])
SWEEP_FUNCTION(sweep_up, BOUND_UP, z0 <= bound, zn - z0)
SWEEP_FUNCTION(sweep_down, BOUND_DOWN, z0 >= bound, z0 - zn)

static void run_const(const iwan_model *m, iwan_state *s, size_t n, const double *u,
                      double *F, double *kt, double *dFdN, double *W)
{
    double r[IWAN_MAX_SLIDERS], g[IWAN_MAX_SLIDERS];
    const double f = strength_factor(m, s->N), dgdN = m->scale / m->n_ref;
    for (int32_t j = 0; j < m->n; ++j) {
        r[j] = m->fs[j] * f / m->k[j];   /* same expression as outputs(): same limits */
        g[j] = m->fs[j] * f;
    }
    for (size_t i = 0; i < n; ++i) {
        const double ui = u[i];
        double acc[4];
        if (ui > s->u) s->dir = 1.0;
        else if (ui < s->u) s->dir = -1.0;
        if (s->dir > 0.0) sweep_up(m->n, s->z, r, g, m->k, m->fs, ui, acc);
        else sweep_down(m->n, s->z, r, g, m->k, m->fs, ui, acc);
        s->u = ui;
        s->w_diss += acc[3];
        if (F) F[i] = acc[0] + m->k_res * (ui - s->u_contact);
        if (kt) kt[i] = m->k_res + acc[1];
        if (dFdN) dFdN[i] = s->dir * acc[2] * dgdN;
        if (W) W[i] = s->w_diss;
    }
}

static void store(const iwan_output *o, size_t i, double *F, double *kt, double *dFdN, double *W)
{
    if (F) F[i] = o->F;
    if (kt) kt[i] = o->kt;
    if (dFdN) dFdN[i] = o->dFdN;
    if (W) W[i] = o->W;
}

iwan_status iwan_series(const iwan_model *model, iwan_state *state, size_t n,
                        const double *u, const double *N,
                        double *F, double *kt, double *dFdN, double *W)
{
    iwan_status st = check_model(model);
    if (st != IWAN_OK) return st;
    st = check_state(state);
    if (st != IWAN_OK) return st;
    if (!u || n == 0) return IWAN_ERR_BAD_PARAM;
    if (check_finite(u, n) || (N && check_finite(N, n))) return IWAN_ERR_NONFINITE;
    size_t i = 0;
    while (i < n) {
        const double Ni = N ? N[i] : model->n_ref;
        if (state->in_contact && Ni == state->N) {   /* run of constant N: fast sweep */
            size_t j = i + 1;
            if (N) while (j < n && N[j] == Ni) ++j;
            else j = n;
            run_const(model, state, j - i, u + i, F ? F + i : NULL, kt ? kt + i : NULL,
                      dFdN ? dFdN + i : NULL, W ? W + i : NULL);
            i = j;
        } else {
            iwan_output o;
            advance(model, state, u[i], Ni, NULL);
            outputs(model, state, &o);
            store(&o, i, F, kt, dFdN, W);
            ++i;
        }
    }
    return IWAN_OK;
}

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
        release(m, s, M);
        for (int32_t j = 0; j < m->n; ++j) an->au[j] = ANCHOR_ORIGIN;
        return;
    }
    s->in_contact = 1;
    const double f = strength_factor(m, NM);
    for (int32_t j = 0; j < m->n; ++j) {
        const double r = m->fs[j] * f / m->k[j];
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
            advance(m, s, u[t], N ? N[t] : m->n_ref, an);
            outputs(m, s, &o);
            store(&o, t, F, kt, dFdN, NULL);
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
    iwan_status st = check_model(model);
    if (st != IWAN_OK) return st;
    if (!u || n == 0 || max_periods < 1) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(tol)) return IWAN_ERR_NONFINITE;
    if (!(tol >= 0.0)) return IWAN_ERR_BAD_PARAM;
    if (check_finite(u, n) || (N && check_finite(N, n))) return IWAN_ERR_NONFINITE;
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
        run_const(model, &s, n - 1 - tM, u + tM + 1, F ? F + tM + 1 : NULL,
                  kt ? kt + tM + 1 : NULL, dFdN ? dFdN + tM + 1 : NULL, NULL);
        run_const(model, &s, tM + 1, u, F, kt, dFdN, NULL);
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

/* d u_c / dX and d u_c / dXN of the re-contact point in the step p -> tc,
 * u_c = u_p + s_c (u_tc - u_p), s_c = -N_p / (N_tc - N_p) (see advance()). */
static void recontact_grad(size_t n, size_t nb, const double *u, const double *N,
                           const double *Eu, const double *EN, size_t tc, double w,
                           double *rX, double *rXN)
{
    const size_t p = (tc + n - 1) % n;
    const double N0 = N[p], N1 = N[tc], D = N1 - N0, sc = -N0 / D, du = u[tc] - u[p];
    const double ds0 = -N1 / (D * D), ds1 = N0 / (D * D);
    for (size_t c = 0; c < nb; ++c) {
        rX[c] -= w * ((1.0 - sc) * Eu[p * nb + c] + sc * Eu[tc * nb + c]);
        if (rXN) rXN[c] -= w * du * (ds0 * EN[p * nb + c] + ds1 * EN[tc * nb + c]);
    }
}

/* Row t of dF/dX (and dF/dXN): a slider that slipped into t carries
 * sg g(N(t)); one stuck since anchor a carries k (u(t) - u(a)) + sg g(N(aN));
 * one stuck since the virgin state k u(t); one stuck since re-contact
 * k (u(t) - u_c). Sliders sharing an anchor are summed before the axpy. */
static void jac_row(const iwan_model *m, const iwan_state *s, const anchors *an, size_t n,
                    size_t nb, const double *u, const double *N, const double *Eu,
                    const double *EN, double *rX, double *rXN)
{
    const size_t t = (size_t)an->t;
    const double dgdN = m->scale / m->n_ref;
    for (size_t c = 0; c < nb; ++c) { rX[c] = 0.0; if (rXN) rXN[c] = 0.0; }
    if (!s->in_contact) return;
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
            for (size_t c = 0; c < nb; ++c) {
                rX[c] -= gk * Eu[(size_t)ga * nb + c];
                if (rXN) rXN[c] += gc * EN[(size_t)gn * nb + c];
            }
            gk = gc = 0.0;
        }
        if (last) break;
        ga = a;
        gn = an->aN[j];
        if (a >= 0) { gk += m->k[j]; gc += an->sg[j] * m->fs[j] * dgdN; }
    }
    for (size_t c = 0; c < nb; ++c) {
        rX[c] += kst * Eu[t * nb + c];
        if (rXN) rXN[c] += cnow * EN[t * nb + c];
    }
    if (krc > 0.0) recontact_grad(n, nb, u, N, Eu, EN, ANCHOR_RECONTACT_STEP(an->res), krc, rX, rXN);
}

iwan_status iwan_periodic_jac(const iwan_model *model, size_t n, const double *u, const double *N,
                              const double *Eu, const double *EN, size_t nb,
                              double *F, double *dFdX, double *dFdXN, double *W_cycle,
                              int max_periods, double tol, int *periods_used)
{
    iwan_status st = check_periodic(model, n, u, N, max_periods, tol);
    if (st != IWAN_OK) return st;
    /* anchors hold sample indices as int32; n * nb must not overflow */
    if (!Eu || nb == 0 || n > (size_t)INT32_MAX / 2 || nb > SIZE_MAX / n) return IWAN_ERR_BAD_PARAM;
    if (check_finite(Eu, n * nb) || (EN && check_finite(EN, n * nb))) return IWAN_ERR_NONFINITE;
    iwan_state s;
    anchors an;
    size_t tM;
    double w = 0.0;
    int p = 0;
    periodic_start(model, n, u, N, &s, &an, &tM);
    if (N && !all_equal(N, n)) {
        st = march(model, n, u, N, tM, &s, &an, max_periods, tol, NULL, NULL, NULL, &w, &p);
        if (st != IWAN_OK) {
            if (periods_used) *periods_used = p;
            return st;
        }
    }
    const double w0 = s.w_diss;
    for (size_t k = 1; k <= n; ++k) {       /* final pass from the closed state */
        const size_t t = (tM + k) % n;
        an.t = (int32_t)t;
        advance(model, &s, u[t], N ? N[t] : model->n_ref, &an);
        if (F) F[t] = force(model, &s);
        if (dFdX) {
            jac_row(model, &s, &an, n, nb, u, N, Eu, EN, dFdX + t * nb,
                    (EN && dFdXN) ? dFdXN + t * nb : NULL);
        }
    }
    if (W_cycle) *W_cycle = s.w_diss - w0;
    if (periods_used) *periods_used = p + 1;
    return IWAN_OK;
}
