/*
 * iwan2d_periodic.c -- periodic steady state of the 2D element and its exact Jacobian
 * with respect to the basis coefficients of the path (iwan2d.h: iwan2_periodic_jac).
 *
 * The path (u_x, u_y, N) over one period is given, so the sliders do not interact:
 * each slider (and the residual spring) is marched on its own, with its own number of
 * periods, as a one-slider model through the exact straight-path update (iwan2d.c).
 *
 * Convention for the start: the element is virgin at u = 0 under N(0) (residual spring
 * at rest there), moves along the straight path to the first sample (u(0), N(0)), and
 * periods are repeated until the slider's position at sample 0 recurs to tol r_max
 * (r_max its largest slip radius over the period); one more period gives the outputs.
 * A slider that slips every cycle forgets the start. One that never slips in the steady
 * loop keeps where the first period left it: on a line at constant N that is the nearest
 * point to 0 of the interval it may occupy, the 1D element's convention (iwan_periodic),
 * whatever the first sample; the result is continuous in the path (a start at an
 * extreme sample would jump when the extreme moves to another sample). With lift-off in
 * the period every slider restarts virgin at re-contact, so one period settles it.
 *
 * Jacobian: every marched period carries the sensitivities S = d e / dX of the stretch
 * (X = the coefficients of u_x, u_y and N, e = u - z) from the start convention on
 * (iwan2d_internal.h), so the derivative is exact for the computed loop, including a
 * slider that stuck after slipping in an earlier period.
 */
#include "iwan2d_internal.h"

#include <math.h>
#include <string.h>

size_t iwan2_periodic_work_size(size_t nb)
{
    return 16 * 3 * nb;
}

/* Workspace of one march (nc = 3 nb): S, S_res (2 nc each), scratch (6 nc), Du0, Du1
 * (2 nc each), gN0, gN1 (nc each). */
typedef struct {
    size_t n, nb, nc;
    const double *ux, *uy, *N, *E, *EN;
    double *S, *S_res, *scratch, *Du0, *Du1, *gN0, *gN1;
} path;

/* The rows of sample t: du/dX (2 x nc) and dN/dX (nc). */
static void rows(const path *P, size_t t, double *Du, double *gN)
{
    memset(Du, 0, 2 * P->nc * sizeof(double));
    memset(gN, 0, P->nc * sizeof(double));
    memcpy(Du, P->E + t * P->nb, P->nb * sizeof(double));
    memcpy(Du + P->nc + P->nb, P->E + t * P->nb, P->nb * sizeof(double));
    if (P->EN) memcpy(gN + 2 * P->nb, P->EN + t * P->nb, P->nb * sizeof(double));
}

static double load(const iwan_model *m, const path *P, size_t t)
{
    return P->N ? P->N[t] : m->n_ref;
}

/* A model of slider j alone (j < 0: the residual spring alone). */
static void component(const iwan_model *m, int32_t j, iwan_model *one)
{
    memset(one, 0, offsetof(iwan_model, k) + sizeof(double));
    one->n = j < 0 ? 0 : 1;
    if (j >= 0) {
        one->k[0] = m->k[j];
        one->fs[0] = m->fs[j];
        one->rad[0] = m->rad[j];
    }
    one->k_res = j < 0 ? m->k_res : 0.0;
    one->n_ref = m->n_ref;
    one->scale = m->scale;
    one->fs_sum = j < 0 ? 0.0 : m->fs[j];
    one->derived_n = one->n;
}

/* The start convention (module comment): virgin at the origin under N(0), then the
 * straight path to (u(0), N(0)), with its sensitivities. */
static void start(const iwan_model *one, path *P, iwan2_state *s, int sens)
{
    const double N0 = load(one, P, 0);
    iwan2_sens sn;
    memset(s, 0, offsetof(iwan2_state, z) + 2 * sizeof(double));
    s->version = IWAN2_STATE_VERSION;
    s->N = N0;
    s->in_contact = N0 > 0.0;
    s->dir[0] = 1.0;
    if (sens) {
        memset(P->S, 0, 2 * P->nc * sizeof(double));
        memset(P->S_res, 0, 2 * P->nc * sizeof(double));
        memset(P->Du0, 0, 2 * P->nc * sizeof(double));   /* the origin does not move */
        rows(P, 0, P->Du1, P->gN1);
        sn.nc = P->nc;
        sn.S = P->S;
        sn.S_res = P->S_res;
        sn.scratch = P->scratch;
        sn.Du0 = P->Du0;
        sn.Du1 = P->Du1;
        sn.gN0 = P->gN1;                                 /* N(0) at both ends */
        sn.gN1 = P->gN1;
    }
    iwan2p_advance(one, s, P->ux[0], P->uy[0], N0, sens ? &sn : NULL);
}

/* One period from sample 0 (samples 1 .. n, sample n = 0); with F, the component's force
 * k e (and k S) is added to F (and dF) at every sample. Returns the friction work. */
static double period(const iwan_model *one, path *P, iwan2_state *s, int sens,
                     double *F, double *dF)
{
    const size_t nc = P->nc;
    const double k = one->n ? one->k[0] : one->k_res;
    const double w0 = s->w_diss;
    iwan2_sens sn;
    size_t i, c;
    sn.nc = nc;
    sn.S = P->S;
    sn.S_res = P->S_res;
    sn.scratch = P->scratch;
    if (sens) rows(P, 0, P->Du1, P->gN1);
    for (i = 1; i <= P->n; ++i) {
        const size_t t = i % P->n;
        if (sens) {  /* the previous sample's rows become the step's start */
            double *tmp = P->Du0;
            P->Du0 = P->Du1;
            P->Du1 = tmp;
            tmp = P->gN0;
            P->gN0 = P->gN1;
            P->gN1 = tmp;
            rows(P, t, P->Du1, P->gN1);
            sn.Du0 = P->Du0;
            sn.Du1 = P->Du1;
            sn.gN0 = P->gN0;
            sn.gN1 = P->gN1;
        }
        iwan2p_advance(one, s, P->ux[t], P->uy[t], load(one, P, t), sens ? &sn : NULL);
        if (F && s->in_contact) {
            const double *z = one->n ? s->z : s->u_contact;
            const double *S = one->n ? P->S : P->S_res;
            F[2 * t] += k * (s->u[0] - z[0]);
            F[2 * t + 1] += k * (s->u[1] - z[1]);
            for (c = 0; dF && c < nc; ++c) {
                dF[(2 * t) * nc + c] += k * S[c];
                dF[(2 * t + 1) * nc + c] += k * S[nc + c];
            }
        }
    }
    return s->w_diss - w0;
}

/* March one component until its state at sample 0 recurs (to tol of `scale`), then one more
 * period adding its outputs. Returns the periods used (negative: not converged). */
static int march_component(const iwan_model *one, path *P, double scale, int max_periods,
                           double tol, double *F, double *dF, double *W)
{
    iwan2_state s;
    const int sens = dF != NULL;
    int p;
    start(one, P, &s, sens);
    for (p = 1; p <= max_periods; ++p) {
        const double *z = one->n ? s.z : s.u_contact;
        const double before[2] = {z[0], z[1]};
        period(one, P, &s, sens, NULL, NULL);
        z = one->n ? s.z : s.u_contact;
        if (hypot(z[0] - before[0], z[1] - before[1]) <= tol * scale) break;
    }
    *W += period(one, P, &s, sens, F, dF);
    return p <= max_periods ? p + 1 : -(max_periods + 1);
}

iwan_status iwan2_periodic_jac(const iwan_model *model, size_t n, const double *ux,
                               const double *uy, const double *N, const double *E,
                               const double *EN, size_t nb, double *F, double *dF,
                               double *W_cycle, int max_periods, double tol, int *periods_used,
                               double *work)
{
    iwan_status st = iwanp_check_model(model);
    path P;
    iwan_model one;
    double amax = 0.0, W = 0.0;
    int used = 0, ok = 1;
    int32_t j;
    size_t t;
    if (st != IWAN_OK) return st;
    if (!ux || !uy || !F || !W_cycle || n < 2 || max_periods < 1) return IWAN_ERR_BAD_PARAM;
    if (dF && (!E || !work || nb == 0)) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(tol)) return IWAN_ERR_NONFINITE;
    if (!(tol >= 0.0)) return IWAN_ERR_BAD_PARAM;
    if (iwanp_check_finite(ux, n) || iwanp_check_finite(uy, n) || (N && iwanp_check_finite(N, n))
        || (dF && iwanp_check_finite(E, n * nb)) || (dF && EN && iwanp_check_finite(EN, n * nb)))
        return IWAN_ERR_NONFINITE;
    memset(&P, 0, sizeof P);
    P.n = n;
    P.nb = dF ? nb : 0;
    P.nc = 3 * P.nb;
    P.ux = ux;
    P.uy = uy;
    P.N = N;
    P.E = E;
    P.EN = EN;
    if (dF) {
        P.S = work;
        P.S_res = P.S + 2 * P.nc;
        P.scratch = P.S_res + 2 * P.nc;
        P.Du0 = P.scratch + 6 * P.nc;
        P.Du1 = P.Du0 + 2 * P.nc;
        P.gN0 = P.Du1 + 2 * P.nc;
        P.gN1 = P.gN0 + P.nc;
        memset(dF, 0, 2 * n * P.nc * sizeof(double));
    }
    for (t = 0; t < n; ++t) amax = fmax(amax, hypot(ux[t], uy[t]));
    memset(F, 0, 2 * n * sizeof(double));
    for (j = -1; j < model->n; ++j) {
        double rmax = 0.0, scale;
        int p;
        component(model, j, &one);
        if (j < 0 && model->k_res == 0.0) continue;
        for (t = 0; j >= 0 && t < n; ++t)
            rmax = fmax(rmax, model->rad[j] * strength_factor(model, fmax(load(model, &P, t), 0.0)));
        if (j >= 0 && rmax == 0.0) continue;  /* never any force */
        scale = j < 0 ? amax : rmax;
        p = march_component(&one, &P, scale, max_periods, tol, F, dF, &W);
        ok = ok && p > 0;
        used = p > 0 ? (p > used ? p : used) : (-p > used ? -p : used);
    }
    *W_cycle = W;
    if (periods_used) *periods_used = used;
    return ok ? IWAN_OK : IWAN_ERR_NOT_CONVERGED;
}
