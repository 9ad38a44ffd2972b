/*
 * march_step.c -- one quasi-static step of massless node contacts in one call; the
 * equations, the Newton and the line search are stated in march_step.h. Every line
 * mirrors harmonic_balance/massless.py (MasslessContacts.evaluate, _newton_step,
 * _cached_step, _residual, _line_search), which stays the reference a test compares
 * this code with. The blocks' kept factors: march_blocks.c; the sensitivities:
 * march_sens.c.
 */
#include "march_internal.h"

#include <stddef.h>
#include <string.h>

/* One iterate: displacements, contact forces, residual, the slopes (increasing slip,
 * normal, decreasing slip) and the trial states of its friction nodes. */
typedef struct {
    double *w, *fc, *r, *kt, *kp, *ktm;
    iwan_state *trial;
} iterate;

size_t msurf_work_size(const msurf_model *m)
{
    int32_t cb;
    const int32_t mb = largest_block(m, &cb);
    return 7 * (size_t)m->n_b + 10 * (size_t)m->n_c + 3 * (size_t)mb + 2 * (size_t)cb + 1
        + msurfp_large_work(m, 1);
}

size_t msurf_state_work_size(const msurf_model *m)
{
    return 3 * (size_t)m->n_f;
}

/* A state's used part: the header, the n sliders' positions and dir (the rest of z is
 * never read; the buffers start as full copies, so it stays the committed one). */
static void copy_state(iwan_state *dst, const iwan_state *src, int32_t n)
{
    memcpy(dst, src, offsetof(iwan_state, z) + (size_t)n * sizeof(double));
    dst->dir = src->dir;
}

/* Trial forces and slopes at it->w from the committed states (massless.evaluate). */
static int evaluate(const msurf_model *m, const iwan_state *committed, iwan_state *tmp,
                    iterate *it)
{
    const double *w = it->w;
    memset(it->fc, 0, (size_t)m->n_b * sizeof(double));
    for (int32_t i = 0; i < m->n_c; ++i)
        it->kt[i] = it->ktm[i] = 0.0;
    for (int32_t f = 0; f < m->n_f; ++f) {
        const int32_t i = m->f_contact[f], L = m->f_law[f];
        const iwan_model *law = m->laws[L];
        const double c = m->f_c[f];
        const double P = (m->cp[i] >= 0 ? w[m->cp[i]] * m->qp[i] : 0.0) + m->p0[i];
        const double s = (m->cs[i] >= 0 ? w[m->cs[i]] * m->qs[i] : 0.0) - m->s0[i];
        const double n1 = (m->kn[i] * P) / c;
        const double ds = m->fd_rel * (fabs(s) + fabs(n1) * m->law_r0[L] / m->law_r1[L] + 1e-300);
        iwan_output o;
        double F1, F2, F0;
        copy_state(&it->trial[f], &committed[f], law->n);
        if (iwan_step(law, &it->trial[f], s, n1, &o) != IWAN_OK) return MSURF_NONFINITE;
        F1 = o.F;
        copy_state(tmp, &committed[f], law->n);
        if (iwan_step(law, tmp, s + ds, n1, &o) != IWAN_OK) return MSURF_NONFINITE;
        F2 = o.F;
        copy_state(tmp, &committed[f], law->n);
        if (iwan_step(law, tmp, s - ds, n1, &o) != IWAN_OK) return MSURF_NONFINITE;
        F0 = o.F;
        it->kt[i] = c * ((F2 - F1) / ds);
        it->ktm[i] = c * ((F1 - F0) / ds);
        if (m->cs[i] >= 0) it->fc[m->cs[i]] += (c * F1) * m->qs[i];
    }
    for (int32_t i = 0; i < m->n_c; ++i) {
        const double P = (m->cp[i] >= 0 ? w[m->cp[i]] * m->qp[i] : 0.0) + m->p0[i];
        const int on = P > 0.0;
        it->kp[i] = on ? m->kn[i] : 0.0;
        if (m->cp[i] >= 0) it->fc[m->cp[i]] += (m->kn[i] * (on ? P : 0.0)) * m->qp[i];
    }
    for (int32_t j = 0; j < m->n_b; ++j)
        if (!isfinite(it->fc[j])) return MSURF_NONFINITE;
    return MSURF_OK;
}

/* r = f_c - rhs + A w, block by block (massless._residual); xb, yb (largest block). */
static void residual(const msurf_model *m, const double *rhs, iterate *it, double *xb, double *yb)
{
    const double *A = m->blk_A;
    for (int32_t j = 0; j < m->n_b; ++j)
        it->r[j] = it->fc[j] - rhs[j];
    for (int32_t b = 0; b < m->n_blocks; ++b) {
        const int32_t *dofs = m->blk_dofs + m->blk_ptr[b];
        int mb = block_size(m, b), one = 1;
        double alpha = 1.0, beta = 0.0;
        char trans = 'T';                     /* A row-major: its transpose column-major */
        for (int j = 0; j < mb; ++j)
            xb[j] = it->w[dofs[j]];
        msurfp_dgemv(&trans, &mb, &mb, &alpha, (double *)A, &mb, xb, &one, &beta, yb, &one);
        for (int j = 0; j < mb; ++j)
            it->r[dofs[j]] += yb[j];
        A += (size_t)mb * (size_t)mb;
    }
}

/* Block b's Newton matrix A_b + Q^T diag(k) Q (column-major) into lu and factorized. */
static int factor_block(const msurf_model *m, int32_t b, const double *key, double *lu, int *piv)
{
    const int32_t *ls = m->blk_ls, *lp = m->blk_lp;
    const int32_t mb = block_A_colmajor(m, b, lu), c0 = m->blk_cptr[b], nc = m->blk_cptr[b + 1] - c0;
    for (int32_t k = 0; k < nc; ++k) {          /* slips first, then normals: numpy's order */
        const int32_t i = m->blk_c[c0 + k];
        if (ls[c0 + k] >= 0)
            lu[ls[c0 + k] * ((size_t)mb + 1)] += (key[2 * k] * m->kt_stuck[i]) * (m->qs[i] * m->qs[i]);
    }
    for (int32_t k = 0; k < nc; ++k) {
        const int32_t i = m->blk_c[c0 + k];
        if (lp[c0 + k] >= 0)
            lu[lp[c0 + k] * ((size_t)mb + 1)] += key[2 * k + 1] * (m->qp[i] * m->qp[i]);
    }
    int n = mb, info = 0;
    msurfp_dgetrf(&n, &n, lu, &n, piv, &info);
    return info == 0 ? MSURF_OK : MSURF_SINGULAR;
}

/* dx[dofs of b] = -J_b^{-1} r[dofs], J_b from the kept slot of its key or a new one. */
static int solve_block(const msurf_model *m, msurf_cache *cache, int32_t b, const double *kte,
                       const double *kp, const double *r, double *dx, double *key0, double *xb,
                       double *yb, double *lw)
{
    const int32_t mb = block_size(m, b), c0 = m->blk_cptr[b], nc = m->blk_cptr[b + 1] - c0;
    const int32_t *dofs = m->blk_dofs + m->blk_ptr[b];
    double *key = key0 + 1;
    for (int32_t k = 0; k < nc; ++k) {
        const int32_t i = m->blk_c[c0 + k];
        /* np.round(kt / ks, SLOPE_DIGITS): multiply, rint, divide */
        key[2 * k] = rint((kte[i] / m->kt_stuck[i]) * m->round_scale) / m->round_scale;
        key[2 * k + 1] = kp[i];
    }
    if (is_large(m, b)) {                       /* A_b + diag(d): massless.block_diagonal */
        double *d = lw;
        memset(d, 0, (size_t)mb * sizeof(double));
        for (int32_t k = 0; k < nc; ++k) {
            const int32_t i = m->blk_c[c0 + k];
            if (m->blk_ls[c0 + k] >= 0)
                d[m->blk_ls[c0 + k]] += (key[2 * k] * m->kt_stuck[i]) * (m->qs[i] * m->qs[i]);
        }
        for (int32_t k = 0; k < nc; ++k) {
            const int32_t i = m->blk_c[c0 + k];
            if (m->blk_lp[c0 + k] >= 0) d[m->blk_lp[c0 + k]] += key[2 * k + 1] * (m->qp[i] * m->qp[i]);
        }
        for (int32_t j = 0; j < mb; ++j)
            xb[j] = -r[dofs[j]];
        const int st = msurfp_diag_solve(m, cache, b, key0, 2 * (size_t)nc, d, xb, 1, yb, lw + mb);
        if (st != MSURF_OK) return st;
        for (int32_t j = 0; j < mb; ++j)
            dx[dofs[j]] = yb[j];
        return MSURF_OK;
    }
    double *lu;
    int *piv, fresh;
    const int32_t slot = msurfp_find_slot(m, cache, b, 2 * (size_t)nc, key, &lu, &piv, &fresh);
    if (fresh && factor_block(m, b, key, lu, piv) != MSURF_OK) {
        cache->used[(size_t)b * m->n_slots + slot] = 0;
        return MSURF_SINGULAR;
    }
    for (int32_t j = 0; j < mb; ++j)
        xb[j] = -r[dofs[j]];
    int n = mb, one = 1, info = 0;
    char trans = 'N';
    msurfp_dgetrs(&trans, &n, &one, lu, &n, piv, xb, &n, &info);
    for (int32_t j = 0; j < mb; ++j)
        dx[dofs[j]] = xb[j];
    return MSURF_OK;
}

/* The work space's arrays. */
typedef struct {
    double *dx, *kte, *side, *ds, *xb, *yb, *key, *lw;
} scratch;

/* Newton's dx with each node's slope on the side it moves to (massless._newton_step). */
static int newton_step(const msurf_model *m, msurf_cache *cache, const iterate *it, scratch *s)
{
    for (int32_t i = 0; i < m->n_c; ++i)
        s->side[i] = 1.0;
    for (int32_t pass = 0; pass < m->max_sides; ++pass) {
        for (int32_t i = 0; i < m->n_c; ++i)
            s->kte[i] = s->side[i] != 0.0 ? it->kt[i] : it->ktm[i];
        for (int32_t b = 0; b < m->n_blocks; ++b)
            if (solve_block(m, cache, b, s->kte, it->kp, it->r, s->dx, s->key, s->xb, s->yb, s->lw) != MSURF_OK)
                return MSURF_SINGULAR;
        int changed = 0;
        for (int32_t i = 0; i < m->n_c; ++i) {
            const double ds = m->cs[i] >= 0 ? s->dx[m->cs[i]] * m->qs[i] : 0.0;
            const double side = ds != 0.0 ? (double)(ds > 0.0) : s->side[i];
            s->ds[i] = side;
            changed |= it->kt[i] != it->ktm[i] && side != s->side[i];
        }
        if (!changed) break;
        for (int32_t i = 0; i < m->n_c; ++i)
            if (it->kt[i] != it->ktm[i]) s->side[i] = s->ds[i];
    }
    return MSURF_OK;
}

static double dot(const double *a, const double *b, int32_t n)
{
    double g = 0.0;
    for (int32_t j = 0; j < n; ++j)
        g += a[j] * b[j];
    return g;
}

/* The trial iterate w + alpha dx into *t; its slope g = dx . r there. */
static int trial_at(const msurf_model *m, const iwan_state *committed, iwan_state *tmp,
                    const double *rhs, const iterate *cur, iterate *t, double alpha, scratch *s,
                    double *g)
{
    for (int32_t j = 0; j < m->n_b; ++j)
        t->w[j] = cur->w[j] + alpha * s->dx[j];
    const int st = evaluate(m, committed, tmp, t);
    if (st != MSURF_OK) return st;
    residual(m, rhs, t, s->xb, s->yb);
    *g = dot(s->dx, t->r, m->n_b);
    return MSURF_OK;
}

static void swap(iterate *a, iterate *b)
{
    const iterate t = *a;
    *a = *b;
    *b = t;
}

/* The step along dx (massless._line_search): *cur becomes the accepted iterate. */
static int line_search(const msurf_model *m, const iwan_state *committed, iwan_state *tmp,
                       const double *rhs, iterate *cur, iterate *cand, scratch *s)
{
    const double g0 = dot(s->dx, cur->r, m->n_b), stop = m->section_rtol * fabs(g0);
    double lo = 0.0, glo = g0, hi = 1.0, ghi, g;
    int st = trial_at(m, committed, tmp, rhs, cur, cand, 1.0, s, &ghi);
    if (st != MSURF_OK) return st;
    if (ghi <= stop) {                         /* no overshoot of the minimum */
        swap(cur, cand);
        return MSURF_OK;
    }
    for (int32_t k = 0; k < m->max_bracket && ghi < 0.0; ++k) {   /* bracket the zero of g */
        lo = hi;
        glo = ghi;
        hi = 2.0 * hi;
        if ((st = trial_at(m, committed, tmp, rhs, cur, cand, hi, s, &ghi)) != MSURF_OK) return st;
    }
    int side = 0;
    for (int32_t k = 0; k < m->max_section; ++k) {                 /* Illinois regula falsi */
        const double a = lo - glo * (hi - lo) / (ghi != glo ? ghi - glo : 1.0);
        if ((st = trial_at(m, committed, tmp, rhs, cur, cand, a, s, &g)) != MSURF_OK) return st;
        if (fabs(g) <= stop) {
            swap(cur, cand);
            return MSURF_OK;
        }
        const int up = g > 0.0;
        if (up) {
            hi = a;
            ghi = g;
        } else {
            lo = a;
            glo = g;
        }
        if (up && side == 1) glo *= 0.5;
        if (!up && side == -1) ghi *= 0.5;
        side = up ? 1 : -1;
    }
    if ((st = trial_at(m, committed, tmp, rhs, cur, cand, lo, s, &g)) != MSURF_OK) return st;
    swap(cur, cand);
    return MSURF_OK;
}

static double max_abs(const double *x, int32_t n)
{
    double a = 0.0;
    for (int32_t j = 0; j < n; ++j)
        if (fabs(x[j]) > a) a = fabs(x[j]);
    return a;
}

/* The two iterates and the scratch arrays laid out in work (msurf_work_size). */
static void layout(const msurf_model *m, double *work, iwan_state *swork, double *w,
                   iterate *cur, iterate *cand, scratch *s)
{
    const size_t nb = (size_t)m->n_b, nc = (size_t)m->n_c;
    int32_t cb;
    const int32_t mb = largest_block(m, &cb);
    iterate *its[2] = {cur, cand};
    for (int k = 0; k < 2; ++k) {
        its[k]->fc = work;
        its[k]->r = work + nb;
        its[k]->kt = work + 2 * nb;
        its[k]->kp = work + 2 * nb + nc;
        its[k]->ktm = work + 2 * nb + 2 * nc;
        its[k]->trial = swork + (size_t)k * m->n_f;
        work += 2 * nb + 3 * nc;
    }
    cur->w = w;
    cand->w = work;
    s->dx = work + nb;
    s->kte = work + 2 * nb;
    s->side = s->kte + nc;
    s->ds = s->side + nc;
    s->xb = s->ds + nc;
    s->yb = s->xb + mb;
    s->key = s->yb + mb;   /* 2 cb + 1 */
    s->lw = s->key + 2 * (size_t)cb + 1;   /* mb + msurfp_large_work(m, 1) */
}

int msurf_solve(const msurf_model *m, msurf_cache *cache, iwan_state *states, const double *rhs,
                double *w, int32_t max_iter, double *work, iwan_state *swork, int32_t *iterations)
{
    if (!msurfp_dgetrf || !msurfp_dgetrs || !msurfp_dgemv) return MSURF_NO_KERNELS;
    iterate cur, cand;
    scratch s;
    layout(m, work, swork, w, &cur, &cand, &s);
    iwan_state *tmp = swork + 2 * (size_t)m->n_f;
    for (int32_t f = 0; f < m->n_f; ++f)       /* full copies once: see copy_state */
        cur.trial[f] = cand.trial[f] = tmp[f] = states[f];
    *iterations = 0;
    int st = evaluate(m, states, tmp, &cur);
    if (st != MSURF_OK) return st;
    residual(m, rhs, &cur, s.xb, s.yb);
    const double load = max_abs(rhs, m->n_b);
    for (int32_t k = 0; k < max_iter; ++k) {
        const double f = max_abs(cur.fc, m->n_b), scale = load > f ? load : f;
        if (!(max_abs(cur.r, m->n_b) > m->rtol * (scale > 1e-300 ? scale : 1e-300))) {
            memcpy(states, cur.trial, (size_t)m->n_f * sizeof *states);
            if (cur.w != w) memcpy(w, cur.w, (size_t)m->n_b * sizeof *w);
            return MSURF_OK;
        }
        ++*iterations;
        if ((st = newton_step(m, cache, &cur, &s)) != MSURF_OK) return st;
        if ((st = line_search(m, states, tmp, rhs, &cur, &cand, &s)) != MSURF_OK) return st;
    }
    return MSURF_NOT_SETTLED;
}
