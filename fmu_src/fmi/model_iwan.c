/* model_iwan.c -- the model hooks (model.h) on the Masing/Iwan core (fmu_src/core/iwan.h).
 * The FMU adds no physics of its own: the same core is reached from Python through
 * fmu_src.element, so both give the same numbers for the same history. Two guards
 * belong to the FMU: the input bound (beyond it double precision cannot resolve the
 * smallest slip distance) and |F| <= the gross-slip force exactly (round-off of
 * k (u - z) at large |u| could exceed it by a few ulps of k |u|). */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "fmu_vars.h"
#include "iwan.h"
#include "model.h"
#include "model_table.h"

/* Input bound: the force error of a slider, about k_j * eps * |u|, stays below this
 * fraction of its slip strength k_j r_j: |u| <= U_BOUND_RTOL * min_j r_j / eps, with
 * r_j the slip distances of the curve (at N = N_ref, scale 1). fmu_build.py states
 * the same number in the FMU's documentation (input_bound there). */
#define U_BOUND_RTOL 1e-6
/* A slider stretch may exceed its slip distance by this much (relative), plus the
 * round-off of u - z at |u| (a deserialized history is checked against it). */
#define STRETCH_RTOL 1e-9

typedef struct {
    iwan_model m;
    double u_bound;   /* largest |u| accepted [m] */
    double T_top;     /* largest force of the table [N]: |F| <= T_top f(N) when k_res = 0 */
} iwan_fmu_model;

void model_unload(void *res) { model_table_free((model_table *)res); }

const char *model_load(void **res, const char *dir, char *why, size_t why_size)
{
    return model_table_load((model_table **)res, dir, why, why_size);
}

size_t model_size(const void *res) { (void)res; return sizeof(iwan_fmu_model); }
size_t model_history_size(const void *res) { (void)res; return sizeof(iwan_state); }

/* N and N_ref start at the curve's normal load. */
double model_start(const void *res, unsigned int vr)
{
    (void)vr;
    return ((const model_table *)res)->n_ref;
}

const char *model_check_parameter(const void *res, unsigned int vr, double v)
{
    (void)res;
    if (vr == VR_SCALE && !(v >= 0.0)) return "scale must be >= 0";
    if (vr == VR_N_REF && !(v > 0.0)) return "N_ref must be > 0";
    return NULL;
}

/* Header, the n sliders in use and dir: the rest of z stays zero in every history. */
void model_copy_history(const void *model, void *dst, const void *src)
{
    const int32_t n = ((const iwan_fmu_model *)model)->m.n;
    iwan_state *d = (iwan_state *)dst;
    const iwan_state *s = (const iwan_state *)src;
    memcpy(d, s, offsetof(iwan_state, z) + (size_t)n * sizeof(double));
    d->dir = s->dir;
}

const char *model_build(void *model, const void *res, const double *value)
{
    const model_table *t = (const model_table *)res;
    iwan_fmu_model *md = (iwan_fmu_model *)model;
    double rmin = HUGE_VAL;
    size_t i;
    int32_t j;
    iwan_status st = iwan_model_init(&md->m, t->u, t->T, t->n, value[VR_N_REF],
                                     t->fit ? IWAN_FIT_CONCAVE : IWAN_FIT_REJECT);
    if (st != IWAN_OK) return iwan_status_text(st);
    if (!(value[VR_SCALE] >= 0.0)) return "scale must be >= 0";
    md->m.scale = value[VR_SCALE];
    for (j = 0; j < md->m.n; j++) rmin = fmin(rmin, md->m.rad[j]);
    md->u_bound = md->m.n > 0 ? U_BOUND_RTOL * rmin / DBL_EPSILON : HUGE_VAL;
    md->T_top = 0.0;
    for (i = 0; i < t->n; i++) md->T_top = fmax(md->T_top, t->T[i]);
    return NULL;
}

const char *model_reset(const void *model, void *history, const double *value)
{
    iwan_status st = iwan_state_init(&((const iwan_fmu_model *)model)->m, (iwan_state *)history,
                                     value[VR_N]);
    return st == IWAN_OK ? NULL : iwan_status_text(st);
}

/* Outputs by value reference; |F| clamped to the gross-slip force (k_res = 0 only). */
static void store(const iwan_fmu_model *md, const iwan_output *o, double N, double *out)
{
    double F = o->F;
    if (md->m.k_res == 0.0) {
        double top = fmin(md->m.fs_sum, md->T_top) * (md->m.scale * (fmax(N, 0.0) / md->m.n_ref));
        F = fmax(-top, fmin(top, F));
    }
    out[VR_F] = F;
    out[VR_KT] = o->kt;
    out[VR_W] = o->W;
    out[VR_SLIP] = o->slip;
    out[VR_STORED_ENERGY] = o->E;
}

const char *model_eval(const void *model, const void *history, const double *value, double *out)
{
    const iwan_fmu_model *md = (const iwan_fmu_model *)model;
    iwan_output o;
    iwan_status st = iwan_eval(&md->m, (const iwan_state *)history, value[VR_U], value[VR_N],
                               NULL, &o);
    if (st != IWAN_OK) return iwan_status_text(st);
    store(md, &o, value[VR_N], out);
    return NULL;
}

static const char *commit(const iwan_fmu_model *md, void *history, const double *value,
                          double *out)
{
    iwan_output o;
    iwan_status st = iwan_step(&md->m, (iwan_state *)history, value[VR_U], value[VR_N], &o);
    if (st != IWAN_OK) return iwan_status_text(st);
    store(md, &o, value[VR_N], out);
    return NULL;
}

/* The path to the inputs at t, then along their straight lines to t + h: the core is
 * exact along straight (u, N) paths, so h itself does not enter (rate independence). */
const char *model_step(const void *model, void *history, const double *start,
                       const double *end, double t, double h, double *out)
{
    const iwan_fmu_model *md = (const iwan_fmu_model *)model;
    const char *why = commit(md, history, start, out);
    (void)t; (void)h;
    if (!why && (end[VR_U] != start[VR_U] || end[VR_N] != start[VR_N]))
        why = commit(md, history, end, out);
    return why;
}

/* dF = kt du + dF/dN dN; kt, slip are piecewise constant in (u, N) (zero derivative);
 * W and the stored energy are not linear in the direction of motion (they depend on
 * its sign), so they are refused rather than approximated. */
const char *model_partial(const void *model, const void *history, const double *value,
                          unsigned int unknown, unsigned int known, double *d)
{
    const iwan_fmu_model *md = (const iwan_fmu_model *)model;
    iwan_output o;
    iwan_status st;
    if (unknown == VR_KT || unknown == VR_SLIP) {
        *d = 0.0;
        return NULL;
    }
    if (unknown != VR_F) return "provided for F, kt and slip only";
    st = iwan_eval(&md->m, (const iwan_state *)history, value[VR_U], value[VR_N], NULL, &o);
    if (st != IWAN_OK) return iwan_status_text(st);
    *d = known == VR_U ? o.kt : o.dFdN;
    return NULL;
}

const char *model_check_history(const void *model, const void *history)
{
    const iwan_fmu_model *md = (const iwan_fmu_model *)model;
    const iwan_state *s = (const iwan_state *)history;
    iwan_output o;
    double f;
    int32_t j;
    /* header invariants (version, contact flag vs N, finite, W >= 0, dir = +-1) */
    if (iwan_eval(&md->m, s, s->u, s->N, NULL, &o) != IWAN_OK) return "bad element history";
    if (fabs(s->u) > md->u_bound || fabs(s->u_contact) > md->u_bound)
        return "history displacement beyond the input bound";
    f = md->m.scale * (s->N / md->m.n_ref);
    for (j = 0; j < IWAN_MAX_SLIDERS; j++) {
        double stretch;
        if (!isfinite(s->z[j])) return "slider position not finite";
        if (j >= md->m.n) {
            if (s->z[j] != 0.0) return "unused slider moved";
            continue;
        }
        if (!s->in_contact) {
            if (s->z[j] != s->u_contact) return "slider not released after lift-off";
            continue;
        }
        stretch = fabs(s->u - s->z[j]);
        if (stretch > md->m.rad[j] * f * (1.0 + STRETCH_RTOL) + 4.0 * DBL_EPSILON * fabs(s->u))
            return "slider force beyond its slip strength";
    }
    if (!(o.slip >= 0.0 && o.slip <= 1.0)) return "slip fraction outside [0, 1]";
    return NULL;
}

double model_input_bound(const void *model, unsigned int vr)
{
    return vr == VR_U ? ((const iwan_fmu_model *)model)->u_bound : HUGE_VAL;
}
