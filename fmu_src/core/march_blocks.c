/*
 * march_blocks.c -- the node blocks' kept factorizations and, for blocks of diag_min DOFs
 * and more, their diagonal (Woodbury) updates of kept reference inverses
 * (harmonic_balance/massless.py, FactorCache.solve and solve_diagonal); shared by the
 * node solve (march_step.c) and its sensitivities (march_sens.c).
 */
#include "march_internal.h"

#include <string.h>

msurfp_getrf_t *msurfp_dgetrf;
msurfp_getrs_t *msurfp_dgetrs;
msurfp_gemv_t *msurfp_dgemv;
msurfp_gemm_t *msurfp_dgemm;

int msurf_set_kernels(void *dgetrf, void *dgetrs, void *dgemv, void *dgemm)
{
    msurfp_dgetrf = (msurfp_getrf_t *)dgetrf;
    msurfp_dgetrs = (msurfp_getrs_t *)dgetrs;
    msurfp_dgemv = (msurfp_gemv_t *)dgemv;
    msurfp_dgemm = (msurfp_gemm_t *)dgemm;
    return !(dgetrf && dgetrs && dgemv && dgemm);
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

/* The slot of block b holding the key (klen doubles): a kept one, or the least recently
 * used, emptied (*fresh = 1: the caller factorizes into it). */
int32_t msurfp_find_slot(const msurf_model *m, msurf_cache *cache, int32_t b, size_t klen,
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
size_t msurfp_large_work(const msurf_model *m, size_t R)
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

/* The kept reference of block b closest to d (fewest entries differing: *ne), or -1. */
static int32_t closest_reference(const msurf_model *m, const msurf_refs *refs, int32_t b,
                                 const double *d0, const double *d, int32_t *ne)
{
    const int32_t mb = block_size(m, b), nr = m->n_refs;
    const int64_t *id = refs->id + (size_t)b * nr;
    int32_t best = -1;
    for (int32_t k = 0; k < nr; ++k) {
        if (!id[k]) continue;
        int32_t n = 0;
        for (int32_t j = 0; j < mb; ++j)
            n += d[j] != d0[(size_t)k * mb + j];
        if (best < 0 || n < *ne) {
            best = k;
            *ne = n;
        }
    }
    return best;
}

/* A new reference of block b in its least recently used place: the inverse of
 * A_b + diag(d) (getrf, then getrs on the identity: numpy.linalg.inv's dgesv); J, piv work. */
static int32_t new_reference(const msurf_model *m, msurf_refs *refs, int32_t b, double *inv0,
                             double *d0, const double *d, double *J, int *piv)
{
    const int32_t mb = block_size(m, b), nr = m->n_refs;
    int64_t *id = refs->id + (size_t)b * nr, *used = refs->used + (size_t)b * nr;
    int32_t k = 0;
    for (int32_t q = 1; q < nr; ++q)
        if (used[q] < used[k]) k = q;
    const double *A = block_A(m, b);
    double *inv = inv0 + (size_t)k * mb * mb;
    for (int32_t i = 0; i < mb; ++i)
        for (int32_t j = 0; j < mb; ++j) {
            J[i + (size_t)j * mb] = A[(size_t)i * mb + j] + (i == j ? d[i] : 0.0);
            inv[i + (size_t)j * mb] = i == j ? 1.0 : 0.0;
        }
    int n = mb, info = 0;
    char trans = 'N';
    msurfp_dgetrf(&n, &n, J, &n, piv, &info);
    if (info != 0) {
        id[k] = 0;
        return -1;
    }
    msurfp_dgetrs(&trans, &n, &n, J, &n, piv, inv, &n, &info);
    memcpy(d0 + (size_t)k * mb, d, (size_t)mb * sizeof(double));
    id[k] = ++refs->count;
    return k;
}

/* x -= Z (I + D Z[e])^{-1} D x[e] (Z = inv[:, e], D = diag(delta)): the Woodbury update,
 * its small matrix kept in the cache under key (key[0] the reference's id). */
static int woodbury(const msurf_model *m, msurf_cache *cache, int32_t b, const double *inv,
                    const int *e, const double *delta, int32_t n_e, const double *key, size_t klen,
                    int R, double *x, double *ys, double *Z)
{
    const int32_t mb = block_size(m, b);
    double *S;
    int *spiv, fresh, n = n_e, nrhs = R, info = 0, nm = mb;
    const int32_t slot = msurfp_find_slot(m, cache, b, klen, key, &S, &spiv, &fresh);
    if (fresh) {
        for (int32_t i = 0; i < n_e; ++i)
            for (int32_t j = 0; j < n_e; ++j)
                S[i + (size_t)j * n_e] = (i == j ? 1.0 : 0.0) + delta[i] * inv[e[i] + (size_t)e[j] * mb];
        msurfp_dgetrf(&n, &n, S, &n, spiv, &info);
        if (info != 0) {
            cache->used[(size_t)b * m->n_slots + slot] = 0;
            return MSURF_SINGULAR;
        }
    }
    for (int32_t c = 0; c < R; ++c)
        for (int32_t i = 0; i < n_e; ++i)
            ys[i + (size_t)c * n_e] = delta[i] * x[e[i] + (size_t)c * mb];
    char no = 'N';
    msurfp_dgetrs(&no, &n, &nrhs, S, &n, spiv, ys, &n, &info);
    for (int32_t i = 0; i < n_e; ++i)
        memcpy(Z + (size_t)i * mb, inv + (size_t)e[i] * mb, (size_t)mb * sizeof(double));
    double minus = -1.0, one = 1.0;
    msurfp_dgemm(&no, &no, &nm, &nrhs, &n, &minus, Z, &nm, ys, &n, &one, x, &nm);
    return MSURF_OK;
}

/* x = (A_b + diag(d))^{-1} rhs (m x R, column-major; x may not be rhs) for a large block by
 * the Woodbury identity on a kept reference inverse (massless.FactorCache.solve_diagonal):
 * the reference closest to d, or a new one where more than ref_share of the entries differ;
 * the small matrix I + D Z[e] kept in the cache under (reference, key): key[1 .. klen] the
 * caller's key, key[0] set here to the reference's id. lw: msurfp_large_work(m, R). */
int msurfp_diag_solve(const msurf_model *m, msurf_cache *cache, int32_t b, double *key,
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
    double *J = lw, *delta = J + mm, *ys = delta + mb, *Z = ys + (size_t)changes_max(m, b) * R;
    int *piv = (int *)(Z + (size_t)mb * changes_max(m, b)), *e = piv + mb;
    int32_t ne = 0, best = closest_reference(m, refs, b, d0, d, &ne);
    if (best < 0 || ne > m->ref_share * mb) {     /* a new reference: inverse of A + diag(d) */
        best = new_reference(m, refs, b, inv0, d0, d, J, piv);
        if (best < 0) return MSURF_SINGULAR;
        ne = 0;
    }
    refs->used[(size_t)b * nr + best] = ++refs->clock;
    const double *inv = inv0 + (size_t)best * mm, *dr = d0 + (size_t)best * mb;
    int n = mb, nrhs = R;
    double one = 1.0, zero = 0.0;
    char no = 'N';
    msurfp_dgemm(&no, &no, &n, &nrhs, &n, &one, (double *)inv, &n, (double *)rhs, &n, &zero, x, &n);
    if (ne == 0) return MSURF_OK;
    int32_t n_e = 0;
    for (int32_t j = 0; j < mb; ++j)
        if (d[j] != dr[j]) {
            e[n_e] = j;
            delta[n_e++] = d[j] - dr[j];
        }
    key[0] = (double)refs->id[(size_t)b * nr + best];
    return woodbury(m, cache, b, inv, e, delta, n_e, key, klen + 1, R, x, ys, Z);
}
