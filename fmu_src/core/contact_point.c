/*
 * contact_point.c -- the 3D contact point of contact_point.h: normal law, the step
 * split at the normal table's points, outputs with the 3 x 3 tangent.
 *
 * Symbols: q = (u, p), u slip (2) [m], p penetration [m]; N(p) the normal law; the
 * step moves q0 -> q1 on a straight line, q(s) = q0 + s (q1 - q0). Where p crosses a
 * table point p_b, at s_b = (p_b - p0) / (p1 - p0), the friction element is advanced
 * to (u(s_b), N_b): on each piece N is linear in s, so iwan2d's straight-path update
 * is exact there. Sensitivities to X = (u1_x, u1_y, p1) move the breakpoints:
 *     d u(s_b) / dX = [s_b I, -s_b / (p1 - p0) (u1 - u0)],   d N_b / dX = 0,
 * and at the end d u1 / dX = [I, 0], d N1 / dX = [0, 0, N'(p1)].
 */
#include "contact_point.h"

#include <math.h>
#include <string.h>

#include "iwan2d_internal.h"

static iwan_status check_table(const double *p, const double *N, size_t n)
{
    size_t i;
    if (n < 2 || n > CPOINT_MAX_NORMAL) return IWAN_ERR_BAD_TABLE;
    if (iwanp_check_finite(p, n) || iwanp_check_finite(N, n)) return IWAN_ERR_NONFINITE;
    if (p[0] != 0.0 || N[0] != 0.0) return IWAN_ERR_BAD_TABLE;
    for (i = 1; i < n; ++i)  /* monotone: N strictly increasing with p */
        if (!(p[i] > p[i - 1]) || !(N[i] > N[i - 1])) return IWAN_ERR_BAD_TABLE;
    return IWAN_OK;
}

iwan_status cpoint_model_init(cpoint_model *model, const iwan_model *tangential,
                              const double *p, const double *N, size_t n, double c_t,
                              double c_n)
{
    iwan_status st;
    size_t i;
    if (!model || !tangential || !p || !N) return IWAN_ERR_BAD_PARAM;
    st = iwanp_check_model(tangential);
    if (st != IWAN_OK) return st;
    st = check_table(p, N, n);
    if (st != IWAN_OK) return st;
    if (!isfinite(c_t) || !isfinite(c_n)) return IWAN_ERR_NONFINITE;
    if (c_t < 0.0 || c_n < 0.0) return IWAN_ERR_BAD_PARAM;
    memset(model, 0, sizeof *model);
    model->t = *tangential;
    model->n_normal = (int32_t)n;
    for (i = 0; i < n; ++i) {
        model->p[i] = p[i];
        model->N[i] = N[i];
        model->E_n[i] = i == 0 ? 0.0
                        : model->E_n[i - 1] + 0.5 * (p[i] - p[i - 1]) * (N[i] + N[i - 1]);
    }
    model->c_t = c_t;
    model->c_n = c_n;
    return IWAN_OK;
}

/* Segment i of the law with p in (p_i, p_(i+1)] (the last one extended), for p > 0. */
static int32_t segment(const cpoint_model *m, double p)
{
    int32_t lo = 0, hi = m->n_normal - 2;
    while (lo < hi) {
        const int32_t mid = (lo + hi + 1) / 2;
        if (p > m->p[mid]) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

double cpoint_normal(const cpoint_model *m, double p, double *slope)
{
    int32_t i;
    double s;
    if (!(p > 0.0)) {
        if (slope) *slope = 0.0;
        return 0.0;
    }
    i = segment(m, p);
    s = (m->N[i + 1] - m->N[i]) / (m->p[i + 1] - m->p[i]);
    if (slope) *slope = s;
    return m->N[i] + s * (p - m->p[i]);
}

/* Stored energy of the normal spring, int_0^p N dp (exact: N linear on each segment). */
static double normal_energy(const cpoint_model *m, double p)
{
    int32_t i;
    if (!(p > 0.0)) return 0.0;
    i = segment(m, p);
    return m->E_n[i] + 0.5 * (p - m->p[i]) * (m->N[i] + cpoint_normal(m, p, NULL));
}

iwan_status cpoint_check_state(const cpoint_model *m, const cpoint_state *st)
{
    iwan_status s;
    if (!m || !st) return IWAN_ERR_BAD_PARAM;
    if (st->version != CPOINT_STATE_VERSION || st->reserved != 0) return IWAN_ERR_BAD_STATE;
    if (!isfinite(st->p)) return IWAN_ERR_BAD_STATE;
    s = iwan2p_check_state(&st->s);
    if (s != IWAN_OK) return s;
    if (st->s.N != cpoint_normal(m, st->p, NULL)) return IWAN_ERR_BAD_STATE;
    return IWAN_OK;
}

iwan_status cpoint_state_init(const cpoint_model *model, cpoint_state *state, double p)
{
    iwan_status st;
    if (!model || !state) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(p)) return IWAN_ERR_NONFINITE;
    memset(state, 0, sizeof *state);
    st = iwan2_state_init(&model->t, &state->s, cpoint_normal(model, p, NULL));
    if (st != IWAN_OK) return st;
    state->version = CPOINT_STATE_VERSION;
    state->p = p;
    return IWAN_OK;
}

/* Index of the next table point strictly between p and p1 in the direction of travel,
 * or -1 when there is none (the piece ends at p1). */
static int32_t next_break(const cpoint_model *m, double p, double p1)
{
    int32_t i;
    if (p1 > p) {
        for (i = 0; i < m->n_normal; ++i)
            if (m->p[i] > p) return m->p[i] < p1 ? i : -1;
    } else {
        for (i = m->n_normal - 1; i >= 0; --i)
            if (m->p[i] < p) return m->p[i] > p1 ? i : -1;
    }
    return -1;
}

/* The straight step q0 -> q1 in pieces between table points; sens (nc = 3, zeroed by
 * the caller) carries d/d(u1_x, u1_y, p1). Returns dN1/dp1 along the last piece. */
static double advance(const cpoint_model *m, cpoint_state *st, const double *q,
                      iwan2_sens *sens)
{
    const double u0[2] = {st->s.u[0], st->s.u[1]}, p0 = st->p, p1 = q[2];
    const double d[2] = {q[0] - u0[0], q[1] - u0[1]};
    double Du0[6] = {0}, Du1[6], gN0[3] = {0}, gN1[3] = {0}, p = p0, slope = 0.0;
    for (;;) {
        const int32_t b = next_break(m, p, p1);
        const int last = b < 0;
        const double pb = last ? p1 : m->p[b];
        double ux = q[0], uy = q[1], Nb;
        if (last) {  /* slope of the last piece (inside one segment), or below p1 */
            Nb = cpoint_normal(m, p1, &slope);
            if (p1 != p) cpoint_normal(m, 0.5 * (p + p1), &slope);
        } else {
            const double sb = (pb - p0) / (p1 - p0);
            ux = u0[0] + sb * d[0];
            uy = u0[1] + sb * d[1];
            Nb = m->N[b];  /* the table value (0 at p = 0: lift-off or re-contact there) */
        }
        if (sens) {
            if (last) {
                static const double I3[6] = {1, 0, 0, 0, 1, 0};
                memcpy(Du1, I3, sizeof Du1);
                gN1[2] = slope;
            } else {
                const double sb = (pb - p0) / (p1 - p0), g = -sb / (p1 - p0);
                const double row[6] = {sb, 0, g * d[0], 0, sb, g * d[1]};
                memcpy(Du1, row, sizeof Du1);
                gN1[2] = 0.0;
            }
            sens->Du0 = Du0;
            sens->Du1 = Du1;
            sens->gN0 = gN0;
            sens->gN1 = gN1;
        }
        iwan2p_advance(&m->t, &st->s, ux, uy, Nb, sens);
        p = pb;
        if (last) break;
        memcpy(Du0, Du1, sizeof Du0);
        memcpy(gN0, gN1, sizeof gN0);
    }
    st->p = p1;
    return slope;
}

/* Outputs of a state from the friction element's outputs o2 (K, dFdN w.r.t. (u, p) when
 * `exact`, else w.r.t. (u, N) for continued motion) and the normal slope. */
static void point_outputs(const cpoint_model *m, const cpoint_state *st, const iwan2_output *o2,
                          int exact, double slope, const double *v, cpoint_output *out)
{
    const int on = st->s.in_contact;
    const double dpN = exact ? 1.0 : slope;  /* dF_t/dp = dF_t/dN dN/dp for continued motion */
    memset(out, 0, sizeof *out);
    out->f[0] = o2->F[0];
    out->f[1] = o2->F[1];
    out->f[2] = st->s.N > 0.0 ? st->s.N : 0.0;
    out->K[0] = o2->K[0];
    out->K[1] = o2->K[1];
    out->K[2] = o2->dFdN[0] * dpN;
    out->K[3] = o2->K[2];
    out->K[4] = o2->K[3];
    out->K[5] = o2->dFdN[1] * dpN;
    out->K[8] = on ? slope : 0.0;
    out->W = o2->W;
    out->E = o2->E + normal_energy(m, st->p);
    out->slip = o2->slip;
    out->state = !on ? CPOINT_OPEN : (o2->slip > 0.0 ? CPOINT_SLIP : CPOINT_STICK);
    if (on && v) {  /* dashpots, in contact only; N >= 0 (no adhesion) */
        out->f[0] += m->c_t * v[0];
        out->f[1] += m->c_t * v[1];
        out->f[2] += m->c_n * v[2];
        out->C[0] = out->C[1] = m->c_t;
        out->C[2] = m->c_n;
        if (out->f[2] < 0.0) {
            out->f[2] = 0.0;
            out->C[2] = 0.0;
            out->K[8] = 0.0;
        }
    }
}

/* Update of a checked state; with `out`, the outputs and their exact tangent. */
static void step_checked(const cpoint_model *m, cpoint_state *st, const double *q,
                         const double *v, cpoint_output *out)
{
    double S[6 * IWAN_MAX_SLIDERS], S_res[6] = {0}, scratch[18], slope;
    iwan2_sens sens;
    iwan2_output o2;
    if (!out) {
        advance(m, st, q, NULL);
        return;
    }
    if (q[0] == st->s.u[0] && q[1] == st->s.u[1] && q[2] == st->p) {  /* continued motion */
        cpoint_normal(m, st->p, &slope);
        iwan2p_outputs(&m->t, &st->s, NULL, &o2);
        point_outputs(m, st, &o2, 0, slope, v, out);
        return;
    }
    memset(S, 0, 6 * (size_t)m->t.n * sizeof(double));
    sens.nc = 3;
    sens.S = S;
    sens.S_res = S_res;
    sens.scratch = scratch;
    slope = advance(m, st, q, &sens);
    iwan2p_outputs(&m->t, &st->s, &sens, &o2);  /* its dFdN column is d F_t / d p1 */
    point_outputs(m, st, &o2, 1, slope, v, out);
}

static iwan_status check_call(const cpoint_model *m, const cpoint_state *st, const double *q,
                              const double *v)
{
    iwan_status s;
    if (!m || !q) return IWAN_ERR_BAD_PARAM;
    s = iwanp_check_model(&m->t);
    if (s != IWAN_OK) return s;
    s = cpoint_check_state(m, st);
    if (s != IWAN_OK) return s;
    if (iwanp_check_finite(q, 3) || (v && iwanp_check_finite(v, 3))) return IWAN_ERR_NONFINITE;
    return IWAN_OK;
}

iwan_status cpoint_eval(const cpoint_model *model, const cpoint_state *committed,
                        const double *q, const double *v, cpoint_state *trial,
                        cpoint_output *out)
{
    cpoint_state local;
    iwan_status s = check_call(model, committed, q, v);
    if (s != IWAN_OK) return s;
    if (trial == committed) return IWAN_ERR_BAD_PARAM;
    if (!trial) trial = &local;
    else memset(trial, 0, sizeof *trial);  /* unused sliders stay zero */
    memcpy(trial, committed, offsetof(cpoint_state, s));
    iwan2p_copy(&trial->s, &committed->s, model->t.n);
    step_checked(model, trial, q, v, out);
    return IWAN_OK;
}

iwan_status cpoint_step(const cpoint_model *model, cpoint_state *state, const double *q,
                        const double *v, cpoint_output *out)
{
    iwan_status s = check_call(model, state, q, v);
    if (s != IWAN_OK) return s;
    step_checked(model, state, q, v, out);
    return IWAN_OK;
}
