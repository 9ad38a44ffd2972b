/*
 * march_sens.c -- the march's forward sensitivities over one committed step (march_step.h,
 * msurf_advance), mirroring harmonic_balance/surface_sensitivity.py (MarchSensitivity.advance,
 * _end_state, _solve_cached), the reference a test compares it with.
 */
#include "march_internal.h"

#include <string.h>

size_t msurf_sens_work_size(const msurf_model *m, const msurf_sens *s)
{
    int32_t cb;
    const size_t mb = (size_t)largest_block(m, &cb), nd = (size_t)s->n_d;
    const size_t nf = (size_t)m->n_f, ns = (size_t)s->ns_max;
    const size_t R = nd > (size_t)s->r ? nd : (size_t)s->r;
    return 3 * (size_t)m->n_c + (size_t)m->n_c * nd + 2 * nf * ns + 2 * nf + nf * ns * nd
        + nf * nd + (size_t)m->n_b * nd + 2 * mb * R + 3 * (size_t)cb + 1 + 2 * nd + mb
        + msurfp_large_work(m, R);
}

/* The end-state coefficients of one node (surface_sensitivity._end_state): a, b per
 * slider, a_c, b_c; returns closed (1/0); *re, *tc, *dtc0, *dstep as there. */
static double end_state(const iwan_model *law, const iwan_state *s0, const iwan_state *s1,
                        double *a, double *b, double *ac, double *bc, int *stick, int *re,
                        double *dtc0, double *tc, double *dstep)
{
    const int closed = s1->in_contact == 1;
    *re = closed && s0->in_contact == 0;
    const double n0 = s0->N, n1 = s1->N, den = *re ? n0 - n1 : 1.0;
    const double t_c = *re ? n0 / den : 0.0, dtc1 = *re ? n0 / (den * den) : 0.0;
    const double ds = s1->u - s0->u;
    *dtc0 = *re ? -n1 / (den * den) : 0.0;
    for (int32_t j = 0; j < law->n; ++j) {
        const double z1 = s1->z[j], e = s1->u - z1;
        const double sigma = (e > 0.0) - (e < 0.0);
        const double r = (law->scale * law->fs[j]) / (law->n_ref * law->k[j]);
        stick[j] = z1 == (*re ? s1->u_contact : s0->z[j]);
        a[j] = stick[j] ? t_c : 1.0;
        b[j] = stick[j] ? ds * dtc1 : -sigma * r;
    }
    *ac = t_c;
    *bc = ds * dtc1;
    *tc = t_c;
    *dstep = ds;
    return closed ? 1.0 : 0.0;
}

/* Block o's sensitivity matrix (surface_sensitivity._solve_cached's build: A_b plus the
 * entries (q_a k) q_b of Q_s^T K_t Q_s, Q_s^T K_N Q_p, Q_p^T k_n Q_p) column-major into lu,
 * factorized; key = (K_t, K_N k_n, k_n [P > 0]) per contact of the block. */
static int factor_sens(const msurf_model *m, int32_t b, const double *key, double *lu, int *piv)
{
    const int32_t *ls = m->blk_ls, *lp = m->blk_lp;
    const int32_t mb = block_A_colmajor(m, b, lu), c0 = m->blk_cptr[b], nc = m->blk_cptr[b + 1] - c0;
    for (int term = 0; term < 3; ++term)          /* numpy's order: ss, sp, pp */
        for (int32_t k = 0; k < nc; ++k) {
            const int32_t i = m->blk_c[c0 + k];
            const int32_t row = term < 2 ? ls[c0 + k] : lp[c0 + k];
            const int32_t col = term == 0 ? ls[c0 + k] : lp[c0 + k];
            const double qa = term < 2 ? m->qs[i] : m->qp[i], qb = term == 0 ? m->qs[i] : m->qp[i];
            if (row >= 0 && col >= 0) lu[row + (size_t)col * mb] += (qa * key[3 * k + term]) * qb;
        }
    int n = mb, info = 0;
    msurfp_dgetrf(&n, &n, lu, &n, piv, &info);
    return info == 0 ? MSURF_OK : MSURF_SINGULAR;
}

/* A large block's dw (surface_sensitivity._solve_cached's diagonal updates): its operator
 * A_b + diag(d), d = K_t q_s^2 and k_n [P > 0] q_p^2 on the nodes' coordinates; a block
 * without slip rows solved for the r columns of A R and multiplied by dq1 after, the others
 * for xb (its right-hand side, m x n_d column-major, the coupling subtracted). */
static int large_sens(const msurf_model *m, msurf_cache *cache, msurf_sens *s, int32_t b,
                      const double *K, double *key0, const double *dq1, double *xb, double *x,
                      double *lw)
{
    const int32_t mb = block_size(m, b), c0 = m->blk_cptr[b], nc = m->blk_cptr[b + 1] - c0;
    const int32_t *dofs = m->blk_dofs + m->blk_ptr[b], nd = s->n_d;
    double *d = lw;
    int slips = 0;
    memset(d, 0, (size_t)mb * sizeof(double));
    for (int32_t k = 0; k < nc; ++k) {
        const int32_t i = m->blk_c[c0 + k];
        if (m->blk_ls[c0 + k] >= 0) {
            d[m->blk_ls[c0 + k]] += K[i] * (m->qs[i] * m->qs[i]);
            slips = 1;
        }
    }
    for (int32_t k = 0; k < nc; ++k) {
        const int32_t i = m->blk_c[c0 + k];
        if (m->blk_lp[c0 + k] >= 0) d[m->blk_lp[c0 + k]] += K[2 * m->n_c + i] * (m->qp[i] * m->qp[i]);
    }
    if (slips) {
        const int st = msurfp_diag_solve(m, cache, b, key0, 3 * (size_t)nc, d, xb, nd, x, lw + mb);
        if (st != MSURF_OK) return st;
        for (int32_t j = 0; j < mb; ++j)
            for (int32_t c = 0; c < nd; ++c)
                s->dw[(size_t)dofs[j] * nd + c] = x[j + (size_t)c * mb];
        return MSURF_OK;
    }
    for (int32_t j = 0; j < mb; ++j)
        for (int32_t k = 0; k < s->r; ++k)
            xb[j + (size_t)k * mb] = s->AR[(size_t)dofs[j] * s->r + k];
    const int st = msurfp_diag_solve(m, cache, b, key0, 3 * (size_t)nc, d, xb, s->r, x, lw + mb);
    if (st != MSURF_OK) return st;
    for (int32_t j = 0; j < mb; ++j)
        for (int32_t c = 0; c < nd; ++c) {
            double v = 0.0;
            for (int32_t k = 0; k < s->r; ++k)
                v += x[j + (size_t)k * mb] * dq1[(size_t)k * nd + c];
            s->dw[(size_t)dofs[j] * nd + c] = v;
        }
    return MSURF_OK;
}

/* dw of (M2), block by block in s->order (surface_sensitivity._solve_cached); rhs (n_b,
 * n_d) row-major, K (3 n_c): K_t, K_N k_n, k_n [P > 0]; dw zero on entry. */
static int solve_sens(const msurf_model *m, msurf_cache *cache, msurf_sens *s, const double *K,
                      const double *rhs, const double *dq1, double *xb, double *key0, double *x,
                      double *lw)
{
    double *key = key0 + 1;
    const int32_t nd = s->n_d;
    for (int32_t o = 0; o < m->n_blocks; ++o) {
        const int32_t b = s->order[o], mb = block_size(m, b);
        const int32_t c0 = m->blk_cptr[b], nc = m->blk_cptr[b + 1] - c0;
        const int32_t *dofs = m->blk_dofs + m->blk_ptr[b];
        for (int32_t k = 0; k < nc; ++k)
            for (int t = 0; t < 3; ++t)
                key[3 * k + t] = K[t * m->n_c + m->blk_c[c0 + k]];
        for (int32_t j = 0; j < mb; ++j)
            for (int32_t d = 0; d < nd; ++d)
                xb[j + (size_t)d * mb] = rhs[(size_t)dofs[j] * nd + d];
        for (int32_t k = 0; k < nc; ++k) {        /* the solved normals' Coulomb coupling */
            const int32_t i = m->blk_c[c0 + k], l = m->blk_ls[c0 + k];
            if (l < 0 || m->cp[i] < 0) continue;
            for (int32_t d = 0; d < nd; ++d)
                xb[l + (size_t)d * mb] -= (K[m->n_c + i] * (s->dw[(size_t)m->cp[i] * nd + d] * m->qp[i]))
                                          * m->qs[i];
        }
        if (is_large(m, b)) {
            const int st = large_sens(m, cache, s, b, K, key0, dq1, xb, x, lw);
            if (st != MSURF_OK) return st;
            continue;
        }
        double *lu;
        int *piv, fresh;
        const int32_t slot = msurfp_find_slot(m, cache, b, 3 * (size_t)nc, key, &lu, &piv, &fresh);
        if (fresh && factor_sens(m, b, key, lu, piv) != MSURF_OK) {
            cache->used[(size_t)b * m->n_slots + slot] = 0;
            return MSURF_SINGULAR;
        }
        int n = mb, nrhs = nd, info = 0;
        char trans = 'N';
        msurfp_dgetrs(&trans, &n, &nrhs, lu, &n, piv, xb, &n, &info);
        for (int32_t j = 0; j < mb; ++j)
            for (int32_t d = 0; d < nd; ++d)
                s->dw[(size_t)dofs[j] * nd + d] = xb[j + (size_t)d * mb];
    }
    return MSURF_OK;
}

/* The work space's arrays of msurf_advance (msurf_sens_work_size). */
typedef struct {
    double *K, *G, *a, *b, *ac, *bc, *gz, *gc, *rhs, *xb, *key, *ds0, *dn0, *x, *lw;
} sens_work;

static sens_work sens_layout(const msurf_model *m, const msurf_sens *s, double *work)
{
    const size_t nd = (size_t)s->n_d, ns = (size_t)s->ns_max, nf = (size_t)m->n_f;
    const size_t nc = (size_t)m->n_c, nb = (size_t)m->n_b;
    const size_t R = nd > (size_t)s->r ? nd : (size_t)s->r;
    int32_t cb;
    const size_t mb = (size_t)largest_block(m, &cb);
    sens_work v;
    v.K = work;
    v.G = v.K + 3 * nc;
    v.a = v.G + nc * nd;
    v.b = v.a + nf * ns;
    v.ac = v.b + nf * ns;
    v.bc = v.ac + nf;
    v.gz = v.bc + nf;
    v.gc = v.gz + nf * ns * nd;
    v.rhs = v.gc + nf * nd;
    v.xb = v.rhs + nb * nd;
    v.key = v.xb + mb * R;
    v.ds0 = v.key + 3 * (size_t)cb + 1;
    v.dn0 = v.ds0 + nd;
    v.x = v.dn0 + nd;
    v.lw = v.x + mb * R;
    return v;
}

/* Friction entry f's end state, its row of K (K_t, K_N k_n) and G, and its sliders' g
 * (surface_sensitivity.MarchSensitivity.advance, before the solve). */
static void node_terms(const msurf_model *m, const msurf_sens *s, const iwan_state *before,
                       const iwan_state *after, size_t f, sens_work *v)
{
    const size_t nd = (size_t)s->n_d, ns = (size_t)s->ns_max, nc = (size_t)m->n_c;
    const int32_t i = m->f_contact[f];
    const iwan_model *law = m->laws[m->f_law[f]];
    const double c = m->f_c[f], n_scale = m->kn[i] / c;
    int re, stick[IWAN_MAX_SLIDERS];
    double dtc0, t_c, dstep;
    const double closed = end_state(law, &before[f], &after[f], v->a + f * ns, v->b + f * ns,
                                    v->ac + f, v->bc + f, stick, &re, &dtc0, &t_c, &dstep);
    for (size_t d = 0; d < nd; ++d) {
        v->ds0[d] = m->cs[i] >= 0 ? s->dw[(size_t)m->cs[i] * nd + d] * m->qs[i] : 0.0;
        v->dn0[d] = (m->cp[i] >= 0 ? s->dw[(size_t)m->cp[i] * nd + d] * m->qp[i] : 0.0) * n_scale;
    }
    double sum_a = 0.0, sum_b = 0.0;
    for (int32_t j = 0; j < law->n; ++j) {
        sum_a += (1.0 - v->a[f * ns + j]) * law->k[j];
        sum_b += v->b[f * ns + j] * law->k[j];
    }
    v->K[i] = (c * closed) * (sum_a + law->k_res * (1.0 - v->ac[f]));
    v->K[nc + i] = (closed * (-sum_b - law->k_res * v->bc[f])) * m->kn[i];
    for (size_t d = 0; d < nd; ++d) {
        const double g_re = (1.0 - t_c) * v->ds0[d] + (dstep * dtc0) * v->dn0[d];
        double gk = 0.0;
        for (int32_t j = 0; j < law->n; ++j) {
            const size_t o = (f * ns + (size_t)j) * nd + d;
            v->gz[o] = (stick[j] && re ? g_re : 0.0) + (stick[j] && !re ? s->dz[o] : 0.0);
            gk += law->k[j] * v->gz[o];
        }
        v->gc[f * nd + d] = re ? g_re : s->duc[f * nd + d];
        v->G[(size_t)i * nd + d] = -(c * closed) * (gk + law->k_res * v->gc[f * nd + d]);
    }
}

/* The sliders' dz and the rest points' du_c at the step's end from the solved dw. */
static void update_states(const msurf_model *m, msurf_sens *s, const sens_work *v)
{
    const size_t nd = (size_t)s->n_d, ns = (size_t)s->ns_max;
    for (size_t f = 0; f < (size_t)m->n_f; ++f) {
        const int32_t i = m->f_contact[f];
        const iwan_model *law = m->laws[m->f_law[f]];
        const double n_scale = m->kn[i] / m->f_c[f];
        for (size_t d = 0; d < nd; ++d) {
            const double ds1 = m->cs[i] >= 0 ? s->dw[(size_t)m->cs[i] * nd + d] * m->qs[i] : 0.0;
            const double dn1 = (m->cp[i] >= 0 ? s->dw[(size_t)m->cp[i] * nd + d] * m->qp[i] : 0.0) * n_scale;
            for (int32_t j = 0; j < law->n; ++j) {
                const size_t o = f * ns + (size_t)j;
                s->dz[o * nd + d] = (v->a[o] * ds1 + v->b[o] * dn1) + v->gz[o * nd + d];
            }
            s->duc[f * nd + d] = (v->ac[f] * ds1 + v->bc[f] * dn1) + v->gc[f * nd + d];
        }
    }
}

int msurf_advance(const msurf_model *m, msurf_cache *cache, msurf_sens *s,
                  const iwan_state *before, const iwan_state *after, const double *w1,
                  const double *dq1, double *work)
{
    if (!msurfp_dgetrf || !msurfp_dgetrs || !msurfp_dgemm) return MSURF_NO_KERNELS;
    const size_t nd = (size_t)s->n_d, nc = (size_t)m->n_c, nb = (size_t)m->n_b;
    sens_work v = sens_layout(m, s, work);
    memset(v.K, 0, (3 * nc + nc * nd) * sizeof(double));
    for (size_t f = 0; f < (size_t)m->n_f; ++f)
        node_terms(m, s, before, after, f, &v);
    for (size_t i = 0; i < nc; ++i) {
        const double P = (m->cp[i] >= 0 ? w1[m->cp[i]] * m->qp[i] : 0.0) + m->p0[i];
        v.K[2 * nc + i] = m->kn[i] * (P > 0.0 ? 1.0 : 0.0);
    }
    for (size_t j = 0; j < nb; ++j)               /* A R dq1 */
        for (size_t d = 0; d < nd; ++d) {
            double r = 0.0;
            for (int32_t k = 0; k < s->r; ++k)
                r += s->AR[j * (size_t)s->r + (size_t)k] * dq1[(size_t)k * nd + d];
            v.rhs[j * nd + d] = r;
        }
    for (size_t i = 0; i < nc; ++i)               /* - Q_s^T G */
        if (m->cs[i] >= 0)
            for (size_t d = 0; d < nd; ++d)
                v.rhs[(size_t)m->cs[i] * nd + d] -= v.G[i * nd + d] * m->qs[i];
    memset(s->dw, 0, nb * nd * sizeof(double));
    const int st = solve_sens(m, cache, s, v.K, v.rhs, dq1, v.xb, v.key, v.x, v.lw);
    if (st != MSURF_OK) return st;
    update_states(m, s, &v);
    return MSURF_OK;
}
