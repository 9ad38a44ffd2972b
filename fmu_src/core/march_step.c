/*
 * march_step.c -- one quasi-static step of massless node contacts in one call; the
 * equations, the Newton and the line search are stated in march_step.h. Every line
 * mirrors harmonic_balance/massless.py (MasslessContacts.evaluate, _newton_step,
 * _cached_step, _residual, _line_search), which stays the reference a test compares
 * this code with.
 */
#include "march_step.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

typedef void getrf_t(int *, int *, double *, int *, int *, int *);
typedef void getrs_t(char *, int *, int *, double *, int *, int *, double *, int *, int *);
typedef void gemv_t(char *, int *, int *, double *, double *, int *, double *, int *, double *,
                    double *, int *);
typedef void gemm_t(char *, char *, int *, int *, int *, double *, double *, int *, double *,
                    int *, double *, double *, int *);

static getrf_t *dgetrf_p;
static getrs_t *dgetrs_p;
static gemv_t *dgemv_p;
static gemm_t *dgemm_p;

int msurf_set_kernels(void *dgetrf, void *dgetrs, void *dgemv, void *dgemm)
{
    dgetrf_p = (getrf_t *)dgetrf;
    dgetrs_p = (getrs_t *)dgetrs;
    dgemv_p = (gemv_t *)dgemv;
    dgemm_p = (gemm_t *)dgemm;
    return !(dgetrf && dgetrs && dgemv && dgemm);
}

/* One iterate: displacements, contact forces, residual, the slopes (increasing slip,
 * normal, decreasing slip) and the trial states of its friction nodes. */
typedef struct {
    double *w, *fc, *r, *kt, *kp, *ktm;
    iwan_state *trial;
} iterate;

static int32_t block_size(const msurf_model *m, int32_t b)
{
    return m->blk_ptr[b + 1] - m->blk_ptr[b];
}

static int32_t largest_block(const msurf_model *m, int32_t *contacts)
{
    int32_t mb = 1, cb = 1;
    for (int32_t b = 0; b < m->n_blocks; ++b) {
        if (block_size(m, b) > mb) mb = block_size(m, b);
        if (m->blk_cptr[b + 1] - m->blk_cptr[b] > cb) cb = m->blk_cptr[b + 1] - m->blk_cptr[b];
    }
    if (contacts) *contacts = cb;
    return mb;
}

static size_t large_work(const msurf_model *m, size_t R);

size_t msurf_work_size(const msurf_model *m)
{
    int32_t cb;
    const int32_t mb = largest_block(m, &cb);
    return 7 * (size_t)m->n_b + 10 * (size_t)m->n_c + 3 * (size_t)mb + 2 * (size_t)cb + 1
        + large_work(m, 1);
}

size_t msurf_state_work_size(const msurf_model *m)
{
    return 3 * (size_t)m->n_f;
}

/* A block solved by diagonal updates of kept inverses (march_step.h). */
static int is_large(const msurf_model *m, int32_t b)
{
    return block_size(m, b) >= m->diag_min;
}

/* Most entries a large block's update may change (more: a new reference). */
static int32_t changes_max(const msurf_model *m, int32_t b)
{
    return (int32_t)floor(m->ref_share * block_size(m, b));
}

/* One slot's key (doubles), LU and pivots: the block's own matrix, or a large block's
 * small update matrix (keyed by its reference too). */
static void slot_sizes(const msurf_model *m, int32_t b, size_t *key, size_t *lu, size_t *piv)
{
    const size_t n = (size_t)(is_large(m, b) ? changes_max(m, b) : block_size(m, b));
    *key = 3 * (size_t)(m->blk_cptr[b + 1] - m->blk_cptr[b]) + 1;
    *lu = n * n;
    *piv = n;
}

void msurf_cache_sizes(const msurf_model *m, size_t *n_keys, size_t *n_lu, size_t *n_piv)
{
    size_t k = 0, l = 0, p = 0;
    for (int32_t b = 0; b < m->n_blocks; ++b) {
        size_t kb, lb, pb;
        slot_sizes(m, b, &kb, &lb, &pb);
        k += kb;
        l += lb;
        p += pb;
    }
    *n_keys = k * (size_t)m->n_slots;
    *n_lu = l * (size_t)m->n_slots;
    *n_piv = p * (size_t)m->n_slots;
}

void msurf_refs_sizes(const msurf_model *m, size_t *n_inv, size_t *n_d)
{
    size_t l = 0, d = 0;
    for (int32_t b = 0; b < m->n_blocks; ++b)
        if (is_large(m, b)) {
            l += (size_t)block_size(m, b) * (size_t)block_size(m, b);
            d += (size_t)block_size(m, b);
        }
    *n_inv = l * (size_t)m->n_refs;
    *n_d = d * (size_t)m->n_refs;
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
        dgemv_p(&trans, &mb, &mb, &alpha, (double *)A, &mb, xb, &one, &beta, yb, &one);
        for (int j = 0; j < mb; ++j)
            it->r[dofs[j]] += yb[j];
        A += (size_t)mb * (size_t)mb;
    }
}

/* Offsets of block b's slots in the cache arrays. */
static void slot_offsets(const msurf_model *m, int32_t b, size_t *key, size_t *lu, size_t *piv)
{
    size_t k = 0, l = 0, p = 0;
    for (int32_t a = 0; a < b; ++a) {
        size_t ka, la, pa;
        slot_sizes(m, a, &ka, &la, &pa);
        k += ka;
        l += la;
        p += pa;
    }
    *key = k * (size_t)m->n_slots;
    *lu = l * (size_t)m->n_slots;
    *piv = p * (size_t)m->n_slots;
}

/* Block b's Newton matrix A_b + Q^T diag(k) Q (column-major) into lu and factorized. */
static int factor_block(const msurf_model *m, int32_t b, const double *key, double *lu, int *piv)
{
    const int32_t *ls = m->blk_ls, *lp = m->blk_lp;
    const int32_t mb = block_size(m, b), c0 = m->blk_cptr[b], nc = m->blk_cptr[b + 1] - c0;
    size_t off = 0;
    for (int32_t a = 0; a < b; ++a)
        off += (size_t)block_size(m, a) * (size_t)block_size(m, a);
    const double *A = m->blk_A + off;
    for (int32_t i = 0; i < mb; ++i)
        for (int32_t j = 0; j < mb; ++j)
            lu[i + (size_t)j * mb] = A[(size_t)i * mb + j];
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
    dgetrf_p(&n, &n, lu, &n, piv, &info);
    return info == 0 ? MSURF_OK : MSURF_SINGULAR;
}

/* The slot of block b holding the key (klen doubles): a kept one, or the least recently
 * used, emptied (*fresh = 1: the caller factorizes into it). */
static int32_t find_slot(const msurf_model *m, msurf_cache *cache, int32_t b, size_t klen,
                         const double *key, double **lu, int **piv, int *fresh)
{
    size_t ko, lo, po, kk, mm, pp;
    slot_offsets(m, b, &ko, &lo, &po);
    slot_sizes(m, b, &kk, &mm, &pp);
    int64_t *used = cache->used + (size_t)b * m->n_slots;
    int32_t slot = -1, oldest = 0;
    for (int32_t s = 0; s < m->n_slots; ++s) {
        if (used[s] && !memcmp(cache->keys + ko + s * kk, key, klen * sizeof(double))) {
            slot = s;
            break;
        }
        if (used[s] < used[oldest]) oldest = s;
    }
    *fresh = slot < 0;
    if (slot < 0) {
        slot = oldest;
        memcpy(cache->keys + ko + slot * kk, key, klen * sizeof(double));
    }
    used[slot] = ++cache->clock;
    *lu = cache->lu + lo + slot * mm;
    *piv = (int *)cache->piv + po + (size_t)slot * pp;
    return slot;
}

/* Doubles of the work space of a large block's update solve with R right-hand sides. */
static size_t large_work(const msurf_model *m, size_t R)
{
    size_t most = 0;
    for (int32_t b = 0; b < m->n_blocks; ++b)
        if (is_large(m, b)) {
            const size_t mb = (size_t)block_size(m, b), ne = (size_t)changes_max(m, b);
            const size_t need = mb * mb + 4 * mb + mb * R + ne * R + mb * ne;
            if (need > most) most = need;
        }
    return most;
}

/* x = (A_b + diag(d))^{-1} rhs (m x R, column-major; x may not be rhs) for a large block by
 * the Woodbury identity on a kept reference inverse (massless.FactorCache.solve_diagonal):
 * the reference closest to d, or a new one where more than ref_share of the entries differ;
 * the small matrix I + D Z[e] kept in the cache under (reference, key): key[1 .. klen] the
 * caller's key, key[0] set here to the reference's id. */
static int diag_solve(const msurf_model *m, msurf_cache *cache, int32_t b, double *key,
                      size_t klen, const double *d, const double *rhs, int R, double *x, double *lw)
{
    msurf_refs *refs = cache->refs;
    const int32_t mb = block_size(m, b), nr = m->n_refs;
    size_t io = 0, dof = 0;
    for (int32_t a = 0; a < b; ++a)
        if (is_large(m, a)) {
            io += (size_t)block_size(m, a) * (size_t)block_size(m, a);
            dof += (size_t)block_size(m, a);
        }
    const size_t mm = (size_t)mb * (size_t)mb;
    double *inv0 = refs->inv + io * nr, *d0 = refs->dref + dof * nr;
    int64_t *id = refs->id + (size_t)b * nr, *used = refs->used + (size_t)b * nr;
    int32_t best = -1, ne = 0;
    for (int32_t k = 0; k < nr; ++k) {
        if (!id[k]) continue;
        int32_t n = 0;
        for (int32_t j = 0; j < mb; ++j)
            n += d[j] != d0[(size_t)k * mb + j];
        if (best < 0 || n < ne) {
            best = k;
            ne = n;
        }
    }
    double *J = lw, *x0 = J + mm, *delta = x0 + (size_t)mb * R, *ys = delta + mb;
    double *Z = ys + (size_t)changes_max(m, b) * R;
    int *piv = (int *)(Z + (size_t)mb * changes_max(m, b)), *e = piv + mb;
    if (best < 0 || ne > m->ref_share * mb) {     /* a new reference: inverse of A + diag(d) */
        int32_t k = 0;
        for (int32_t q = 1; q < nr; ++q)
            if (used[q] < used[k]) k = q;
        size_t off = 0;
        for (int32_t a = 0; a < b; ++a)
            off += (size_t)block_size(m, a) * (size_t)block_size(m, a);
        const double *A = m->blk_A + off;
        double *inv = inv0 + (size_t)k * mm;
        for (int32_t i = 0; i < mb; ++i)
            for (int32_t j = 0; j < mb; ++j) {
                J[i + (size_t)j * mb] = A[(size_t)i * mb + j] + (i == j ? d[i] : 0.0);
                inv[i + (size_t)j * mb] = i == j ? 1.0 : 0.0;
            }
        int n = mb, info = 0;
        char trans = 'N';
        dgetrf_p(&n, &n, J, &n, piv, &info);
        if (info != 0) {
            id[k] = 0;
            return MSURF_SINGULAR;
        }
        dgetrs_p(&trans, &n, &n, J, &n, piv, inv, &n, &info);
        memcpy(d0 + (size_t)k * mb, d, (size_t)mb * sizeof(double));
        id[k] = ++refs->count;
        best = k;
        ne = 0;
    }
    used[best] = ++refs->clock;
    const double *inv = inv0 + (size_t)best * mm, *dr = d0 + (size_t)best * mb;
    {
        int n = mb, nrhs = R;
        double one = 1.0, zero = 0.0;
        char no = 'N';
        dgemm_p(&no, &no, &n, &nrhs, &n, &one, (double *)inv, &n, (double *)rhs, &n, &zero, x, &n);
    }
    if (ne == 0) return MSURF_OK;
    int32_t n_e = 0;
    for (int32_t j = 0; j < mb; ++j)
        if (d[j] != dr[j]) {
            e[n_e] = j;
            delta[n_e++] = d[j] - dr[j];
        }
    key[0] = (double)id[best];                 /* the small matrix: keyed by (reference, key) */
    double *S;
    int *spiv, fresh;
    const int32_t slot = find_slot(m, cache, b, klen + 1, key, &S, &spiv, &fresh);
    int n = n_e, nrhs = R, info = 0;
    if (fresh) {
        for (int32_t i = 0; i < n_e; ++i)
            for (int32_t j = 0; j < n_e; ++j)
                S[i + (size_t)j * n_e] = (i == j ? 1.0 : 0.0) + delta[i] * inv[e[i] + (size_t)e[j] * mb];
        dgetrf_p(&n, &n, S, &n, spiv, &info);
        if (info != 0) {
            cache->used[(size_t)b * m->n_slots + slot] = 0;
            return MSURF_SINGULAR;
        }
    }
    for (int32_t c = 0; c < R; ++c)
        for (int32_t i = 0; i < n_e; ++i)
            ys[i + (size_t)c * n_e] = delta[i] * x[e[i] + (size_t)c * mb];
    char no = 'N';
    dgetrs_p(&no, &n, &nrhs, S, &n, spiv, ys, &n, &info);
    for (int32_t i = 0; i < n_e; ++i)
        memcpy(Z + (size_t)i * mb, inv + (size_t)e[i] * mb, (size_t)mb * sizeof(double));
    int nm = mb;
    double minus = -1.0, one = 1.0;
    dgemm_p(&no, &no, &nm, &nrhs, &n, &minus, Z, &nm, ys, &n, &one, x, &nm);
    return MSURF_OK;
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
        const int st = diag_solve(m, cache, b, key0, 2 * (size_t)nc, d, xb, 1, yb, lw + mb);
        if (st != MSURF_OK) return st;
        for (int32_t j = 0; j < mb; ++j)
            dx[dofs[j]] = yb[j];
        return MSURF_OK;
    }
    double *lu;
    int *piv, fresh;
    const int32_t slot = find_slot(m, cache, b, 2 * (size_t)nc, key, &lu, &piv, &fresh);
    if (fresh && factor_block(m, b, key, lu, piv) != MSURF_OK) {
        cache->used[(size_t)b * m->n_slots + slot] = 0;
        return MSURF_SINGULAR;
    }
    for (int32_t j = 0; j < mb; ++j)
        xb[j] = -r[dofs[j]];
    int n = mb, one = 1, info = 0;
    char trans = 'N';
    dgetrs_p(&trans, &n, &one, lu, &n, piv, xb, &n, &info);
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
    s->lw = s->key + 2 * (size_t)cb + 1;   /* mb + large_work(m, 1) */
}

int msurf_solve(const msurf_model *m, msurf_cache *cache, iwan_state *states, const double *rhs,
                double *w, int32_t max_iter, double *work, iwan_state *swork, int32_t *iterations)
{
    if (!dgetrf_p || !dgetrs_p || !dgemv_p) return MSURF_NO_KERNELS;
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

/* ------------------------------------------------------------ sensitivities */

size_t msurf_sens_work_size(const msurf_model *m, const msurf_sens *s)
{
    int32_t cb;
    const size_t mb = (size_t)largest_block(m, &cb), nd = (size_t)s->n_d;
    const size_t nf = (size_t)m->n_f, ns = (size_t)s->ns_max;
    const size_t R = nd > (size_t)s->r ? nd : (size_t)s->r;
    return 3 * (size_t)m->n_c + (size_t)m->n_c * nd + 2 * nf * ns + 2 * nf + nf * ns * nd
        + nf * nd + (size_t)m->n_b * nd + 2 * mb * R + 3 * (size_t)cb + 1 + 2 * nd + mb
        + large_work(m, R);
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
    const int32_t mb = block_size(m, b), c0 = m->blk_cptr[b], nc = m->blk_cptr[b + 1] - c0;
    size_t off = 0;
    for (int32_t a = 0; a < b; ++a)
        off += (size_t)block_size(m, a) * (size_t)block_size(m, a);
    const double *A = m->blk_A + off;
    for (int32_t i = 0; i < mb; ++i)
        for (int32_t j = 0; j < mb; ++j)
            lu[i + (size_t)j * mb] = A[(size_t)i * mb + j];
    for (int term = 0; term < 3; ++term)          /* numpy's order: ss, sp, pp */
        for (int32_t k = 0; k < nc; ++k) {
            const int32_t i = m->blk_c[c0 + k];
            const int32_t row = term < 2 ? ls[c0 + k] : lp[c0 + k];
            const int32_t col = term == 0 ? ls[c0 + k] : lp[c0 + k];
            const double qa = term < 2 ? m->qs[i] : m->qp[i], qb = term == 0 ? m->qs[i] : m->qp[i];
            if (row >= 0 && col >= 0) lu[row + (size_t)col * mb] += (qa * key[3 * k + term]) * qb;
        }
    int n = mb, info = 0;
    dgetrf_p(&n, &n, lu, &n, piv, &info);
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
        const int st = diag_solve(m, cache, b, key0, 3 * (size_t)nc, d, xb, nd, x, lw + mb);
        if (st != MSURF_OK) return st;
        for (int32_t j = 0; j < mb; ++j)
            for (int32_t c = 0; c < nd; ++c)
                s->dw[(size_t)dofs[j] * nd + c] = x[j + (size_t)c * mb];
        return MSURF_OK;
    }
    for (int32_t j = 0; j < mb; ++j)
        for (int32_t k = 0; k < s->r; ++k)
            xb[j + (size_t)k * mb] = s->AR[(size_t)dofs[j] * s->r + k];
    const int st = diag_solve(m, cache, b, key0, 3 * (size_t)nc, d, xb, s->r, x, lw + mb);
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
        const int32_t slot = find_slot(m, cache, b, 3 * (size_t)nc, key, &lu, &piv, &fresh);
        if (fresh && factor_sens(m, b, key, lu, piv) != MSURF_OK) {
            cache->used[(size_t)b * m->n_slots + slot] = 0;
            return MSURF_SINGULAR;
        }
        int n = mb, nrhs = nd, info = 0;
        char trans = 'N';
        dgetrs_p(&trans, &n, &nrhs, lu, &n, piv, xb, &n, &info);
        for (int32_t j = 0; j < mb; ++j)
            for (int32_t d = 0; d < nd; ++d)
                s->dw[(size_t)dofs[j] * nd + d] = xb[j + (size_t)d * mb];
    }
    return MSURF_OK;
}

int msurf_advance(const msurf_model *m, msurf_cache *cache, msurf_sens *s,
                  const iwan_state *before, const iwan_state *after, const double *w1,
                  const double *dq1, double *work)
{
    if (!dgetrf_p || !dgetrs_p) return MSURF_NO_KERNELS;
    const size_t nd = (size_t)s->n_d, ns = (size_t)s->ns_max, nf = (size_t)m->n_f;
    const size_t nc = (size_t)m->n_c, nb = (size_t)m->n_b;
    int32_t cb;
    const size_t mb = (size_t)largest_block(m, &cb);
    double *K = work, *G = K + 3 * nc, *a = G + nc * nd, *bco = a + nf * ns, *ac = bco + nf * ns;
    double *bc = ac + nf, *gz = bc + nf, *gc = gz + nf * ns * nd, *rhs = gc + nf * nd;
    const size_t R = nd > (size_t)s->r ? nd : (size_t)s->r;
    double *xb = rhs + nb * nd, *key = xb + mb * R, *ds0 = key + 3 * (size_t)cb + 1, *dn0 = ds0 + nd;
    double *x = dn0 + nd, *lw = x + mb * R;
    int stick[IWAN_MAX_SLIDERS];
    memset(K, 0, (3 * nc + nc * nd) * sizeof(double));
    for (size_t f = 0; f < nf; ++f) {
        const int32_t i = m->f_contact[f];
        const iwan_model *law = m->laws[m->f_law[f]];
        const double c = m->f_c[f], n_scale = m->kn[i] / c;
        int re;
        double dtc0, t_c, dstep;
        const double closed = end_state(law, &before[f], &after[f], a + f * ns, bco + f * ns,
                                        ac + f, bc + f, stick, &re, &dtc0, &t_c, &dstep);
        for (size_t d = 0; d < nd; ++d) {
            ds0[d] = m->cs[i] >= 0 ? s->dw[(size_t)m->cs[i] * nd + d] * m->qs[i] : 0.0;
            dn0[d] = (m->cp[i] >= 0 ? s->dw[(size_t)m->cp[i] * nd + d] * m->qp[i] : 0.0) * n_scale;
        }
        double sum_a = 0.0, sum_b = 0.0;
        for (int32_t j = 0; j < law->n; ++j) {
            sum_a += (1.0 - a[f * ns + j]) * law->k[j];
            sum_b += bco[f * ns + j] * law->k[j];
        }
        K[i] = (c * closed) * (sum_a + law->k_res * (1.0 - ac[f]));
        K[nc + i] = (closed * (-sum_b - law->k_res * bc[f])) * m->kn[i];
        for (size_t d = 0; d < nd; ++d) {
            const double g_re = (1.0 - t_c) * ds0[d] + (dstep * dtc0) * dn0[d];
            double gk = 0.0;
            for (int32_t j = 0; j < law->n; ++j) {
                double *g = gz + (f * ns + (size_t)j) * nd + d;
                *g = (stick[j] && re ? g_re : 0.0) + (stick[j] && !re ? s->dz[(f * ns + (size_t)j) * nd + d] : 0.0);
                gk += law->k[j] * *g;
            }
            gc[f * nd + d] = re ? g_re : s->duc[f * nd + d];
            G[(size_t)i * nd + d] = -(c * closed) * (gk + law->k_res * gc[f * nd + d]);
        }
    }
    for (size_t i = 0; i < nc; ++i) {
        const double P = (m->cp[i] >= 0 ? w1[m->cp[i]] * m->qp[i] : 0.0) + m->p0[i];
        K[2 * nc + i] = m->kn[i] * (P > 0.0 ? 1.0 : 0.0);
    }
    for (size_t j = 0; j < nb; ++j)               /* A R dq1 */
        for (size_t d = 0; d < nd; ++d) {
            double v = 0.0;
            for (int32_t k = 0; k < s->r; ++k)
                v += s->AR[j * (size_t)s->r + (size_t)k] * dq1[(size_t)k * nd + d];
            rhs[j * nd + d] = v;
        }
    for (size_t i = 0; i < nc; ++i)               /* - Q_s^T G */
        if (m->cs[i] >= 0)
            for (size_t d = 0; d < nd; ++d)
                rhs[(size_t)m->cs[i] * nd + d] -= G[i * nd + d] * m->qs[i];
    memset(s->dw, 0, nb * nd * sizeof(double));
    const int st = solve_sens(m, cache, s, K, rhs, dq1, xb, key, x, lw);
    if (st != MSURF_OK) return st;
    for (size_t f = 0; f < nf; ++f) {
        const int32_t i = m->f_contact[f];
        const iwan_model *law = m->laws[m->f_law[f]];
        const double n_scale = m->kn[i] / m->f_c[f];
        for (size_t d = 0; d < nd; ++d) {
            const double ds1 = m->cs[i] >= 0 ? s->dw[(size_t)m->cs[i] * nd + d] * m->qs[i] : 0.0;
            const double dn1 = (m->cp[i] >= 0 ? s->dw[(size_t)m->cp[i] * nd + d] * m->qp[i] : 0.0) * n_scale;
            for (int32_t j = 0; j < law->n; ++j) {
                const size_t o = f * ns + (size_t)j;
                s->dz[o * nd + d] = (a[o] * ds1 + bco[o] * dn1) + gz[o * nd + d];
            }
            s->duc[f * nd + d] = (ac[f] * ds1 + bc[f] * dn1) + gc[f * nd + d];
        }
    }
    return MSURF_OK;
}
