/* model_point.c -- the model hooks (model.h) on the 3D contact point of the core
 * (fmu_src/core/contact_point.h: the 2D Masing/Iwan element with a normal law N(p)).
 * The FMU adds no physics of its own: fmu_src.contact_point reaches the same core from
 * Python, so both give the same numbers for the same history. The FMU's own guard is
 * the input bound on the slip, as in model_iwan.c (beyond it double precision cannot
 * resolve the smallest slip distance).
 * Variables (point_vr.h): inputs u_x, u_y, p, v_x, v_y, v_n; outputs F_x, F_y, N, W,
 * stored_energy, state, slip and the tangent K_ab = dF_a/dq_b (a, b in x, y, p);
 * parameters scale, N_ref, c_t, c_n. */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "contact_point.h"
#include "fmu_vars.h"
#include "model.h"
#include "model_table.h"

/* Input bound of the slip (as model_iwan.c): a slider force's round-off k eps |u| stays
 * below this fraction of its strength at N_ref; fmu_point.py documents the same number. */
#define U_BOUND_RTOL 1e-6
/* A slider stretch may exceed its slip radius by this much (relative), plus the
 * round-off of u - z at |u| (a deserialized history is checked against it). */
#define STRETCH_RTOL 1e-9
/* Input bound of the penetration: |p| where the normal spring's stored energy int_0^p N dp
 * reaches this [J]. Far beyond any contact, and DBL_MAX / 1e8, which leaves room for the
 * sums and products the outputs form from N(p) (a larger p would overflow them at the
 * next call, so SetReal refuses it). */
#define P_BOUND_ENERGY 1e300

typedef struct {
    cpoint_model m;
    double u_bound;   /* largest |u_x|, |u_y| accepted [m] */
    double p_bound;   /* largest |p| accepted [m] (P_BOUND_ENERGY) */
} point_fmu_model;

/* The penetration where the normal spring's energy reaches P_BOUND_ENERGY: on the law's
 * last segment (extended) E = E_l + N_l d + s d^2 / 2, d = p - p_l, solved for d >= 0. */
static double penetration_bound(const cpoint_model *m)
{
    const int32_t l = m->n_normal - 1;
    const double s = (m->N[l] - m->N[l - 1]) / (m->p[l] - m->p[l - 1]);
    const double room = P_BOUND_ENERGY - m->E_n[l];
    double root;
    if (!(room > 0.0)) return m->p[l];
    root = hypot(m->N[l], sqrt(2.0 * s) * sqrt(room));  /* sqrt(N_l^2 + 2 s room), no overflow */
    return m->p[l] + 2.0 * room / (m->N[l] + root);     /* (root - N_l) / s, without cancellation */
}

/* The outputs' value references, in the order of cpoint_output.K (row-major). */
static const unsigned int VR_K[9] = {VR_K_XX, VR_K_XY, VR_K_XP, VR_K_YX, VR_K_YY, VR_K_YP,
                                     VR_K_PX, VR_K_PY, VR_K_PP};
static const unsigned int VR_Q[3] = {VR_U_X, VR_U_Y, VR_P};
static const unsigned int VR_V[3] = {VR_V_X, VR_V_Y, VR_V_N};
static const unsigned int VR_FORCE[3] = {VR_F_X, VR_F_Y, VR_N};

/* The virgin curve and the normal law (model_table.h). */
const char *model_load(void **res, const char *dir, char *why, size_t why_size)
{
    return model_table_load((model_table **)res, dir, why, why_size);
}

void model_unload(void *res) { model_table_free((model_table *)res); }
size_t model_size(const void *res) { (void)res; return sizeof(point_fmu_model); }
size_t model_history_size(const void *res) { (void)res; return sizeof(cpoint_state); }

/* Header and the sliders in use (the rest of z stays zero in every history). */
void model_copy_history(const void *model, void *dst, const void *src)
{
    const int32_t n = ((const point_fmu_model *)model)->m.t.n;
    memcpy(dst, src, offsetof(cpoint_state, s) + offsetof(iwan2_state, z)
                         + 2 * (size_t)n * sizeof(double));
}

const char *model_build(void *model, const void *res, const double *value)
{
    const model_table *t = (const model_table *)res;
    point_fmu_model *md = (point_fmu_model *)model;
    iwan_model tm;
    double rmin = HUGE_VAL;
    int32_t j;
    iwan_status st = iwan_model_init(&tm, t->u, t->T, t->n, value[VR_N_REF],
                                     t->fit ? IWAN_FIT_CONCAVE : IWAN_FIT_REJECT);
    if (st != IWAN_OK) return iwan_status_text(st);
    if (!(value[VR_SCALE] >= 0.0)) return "scale must be >= 0";
    tm.scale = value[VR_SCALE];
    if (t->n_normal < 2) return "no normal law in the resources (normal.txt)";
    st = cpoint_model_init(&md->m, &tm, t->p, t->N, t->n_normal, value[VR_C_T], value[VR_C_N]);
    if (st == IWAN_ERR_BAD_TABLE)
        return "bad normal law: it must start at (0, 0) with p and N strictly increasing";
    if (st != IWAN_OK) return iwan_status_text(st);
    for (j = 0; j < tm.n; j++) rmin = fmin(rmin, tm.rad[j]);
    md->u_bound = tm.n > 0 ? U_BOUND_RTOL * rmin / DBL_EPSILON : HUGE_VAL;
    md->p_bound = penetration_bound(&md->m);
    return NULL;
}

const char *model_reset(const void *model, void *history, const double *value)
{
    iwan_status st = cpoint_state_init(&((const point_fmu_model *)model)->m,
                                       (cpoint_state *)history, value[VR_P]);
    return st == IWAN_OK ? NULL : iwan_status_text(st);
}

static void inputs(const double *value, double *q, double *v)
{
    int i;
    for (i = 0; i < 3; i++) {
        q[i] = value[VR_Q[i]];
        v[i] = value[VR_V[i]];
    }
}

static void store(const cpoint_output *o, double *out)
{
    int i;
    for (i = 0; i < 3; i++) out[VR_FORCE[i]] = o->f[i];
    for (i = 0; i < 9; i++) out[VR_K[i]] = o->K[i];
    out[VR_W] = o->W;
    out[VR_STORED_ENERGY] = o->E;
    out[VR_STATE] = (double)o->state;
    out[VR_SLIP] = o->slip;
}

const char *model_eval(const void *model, const void *history, const double *value, double *out)
{
    double q[3], v[3];
    cpoint_output o;
    iwan_status st;
    inputs(value, q, v);
    st = cpoint_eval(&((const point_fmu_model *)model)->m, (const cpoint_state *)history, q, v,
                     NULL, &o);
    if (st != IWAN_OK) return iwan_status_text(st);
    store(&o, out);
    return NULL;
}

static const char *commit(const void *model, void *history, const double *value, double *out)
{
    double q[3], v[3];
    cpoint_output o;
    iwan_status st;
    inputs(value, q, v);
    st = cpoint_step(&((const point_fmu_model *)model)->m, (cpoint_state *)history, q, v, &o);
    if (st != IWAN_OK) return iwan_status_text(st);
    store(&o, out);
    return NULL;
}

/* The path to the inputs at t, then along their straight lines to t + h (the core is
 * exact along straight paths: h itself does not enter). */
const char *model_step(const void *model, void *history, const double *start,
                       const double *end, double t, double h, double *out)
{
    const char *why = commit(model, history, start, out);
    int i, moves = 0;
    (void)t; (void)h;
    for (i = 0; i < DAMPER_N_INPUTS; i++) moves |= end[damper_inputs[i]] != start[damper_inputs[i]];
    if (!why && moves) why = commit(model, history, end, out);
    return why;
}

/* d f / d q = K and d f / d v = diag(C) (the core's exact tangent of the step to the
 * current inputs); state and slip are piecewise constant (zero derivative). K changes
 * along a tractrix, W and stored_energy depend on the sign of the motion: refused. */
const char *model_partial(const void *model, const void *history, const double *value,
                          unsigned int unknown, unsigned int known, double *d)
{
    double q[3], v[3];
    cpoint_output o;
    iwan_status st;
    int row = -1, i;
    if (unknown == VR_STATE || unknown == VR_SLIP) {
        *d = 0.0;
        return NULL;
    }
    for (i = 0; i < 3; i++)
        if (unknown == VR_FORCE[i]) row = i;
    if (row < 0) return "provided for F_x, F_y, N, state and slip only";
    inputs(value, q, v);
    st = cpoint_eval(&((const point_fmu_model *)model)->m, (const cpoint_state *)history, q, v,
                     NULL, &o);
    if (st != IWAN_OK) return iwan_status_text(st);
    *d = 0.0;
    for (i = 0; i < 3; i++) {
        if (known == VR_Q[i]) *d = o.K[3 * row + i];
        if (known == VR_V[i] && i == row) *d = o.C[i];
    }
    return NULL;
}

const char *model_check_history(const void *model, const void *history)
{
    const point_fmu_model *md = (const point_fmu_model *)model;
    const cpoint_state *h = (const cpoint_state *)history;
    const iwan2_state *s = &h->s;
    double f;
    int32_t j;
    /* header invariants: versions, contact flag vs N(p), finite, W >= 0, |dir| = 1 */
    if (cpoint_check_state(&md->m, h) != IWAN_OK) return "bad contact-point history";
    for (j = 0; j < 2; j++)
        if (fabs(s->u[j]) > md->u_bound || fabs(s->u_contact[j]) > md->u_bound)
            return "history displacement beyond the input bound";
    f = md->m.t.scale * (s->N / md->m.t.n_ref);
    for (j = 0; j < IWAN_MAX_SLIDERS; j++) {
        const double zx = s->z[2 * j], zy = s->z[2 * j + 1];
        if (!isfinite(zx) || !isfinite(zy)) return "slider position not finite";
        if (j >= md->m.t.n) {
            if (zx != 0.0 || zy != 0.0) return "unused slider moved";
            continue;
        }
        if (!s->in_contact) {
            if (zx != s->u_contact[0] || zy != s->u_contact[1])
                return "slider not released after lift-off";
            continue;
        }
        if (hypot(s->u[0] - zx, s->u[1] - zy)
            > md->m.t.rad[j] * f * (1.0 + STRETCH_RTOL)
                  + 4.0 * DBL_EPSILON * (fabs(s->u[0]) + fabs(s->u[1])))
            return "slider force beyond its slip strength";
    }
    return NULL;
}

double model_input_bound(const void *model, unsigned int vr)
{
    const point_fmu_model *md = (const point_fmu_model *)model;
    if (vr == VR_P) return md->p_bound;
    return (vr == VR_U_X || vr == VR_U_Y) ? md->u_bound : HUGE_VAL;
}

const char *model_check_parameter(const void *res, unsigned int vr, double v)
{
    (void)res;
    if (vr == VR_SCALE && !(v >= 0.0)) return "scale must be >= 0";
    if (vr == VR_N_REF && !(v > 0.0)) return "N_ref must be > 0";
    if ((vr == VR_C_T || vr == VR_C_N) && !(v >= 0.0)) return "dashpots must be >= 0";
    return NULL;
}

/* The start penetration (rule normal_p) comes with the normal law (normal.txt); N_ref
 * (rule curve_n) is the curve's load. */
double model_start(const void *res, unsigned int vr)
{
    const model_table *t = (const model_table *)res;
    return vr == VR_P ? t->p_start : t->n_ref;
}
