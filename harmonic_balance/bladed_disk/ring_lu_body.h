/* The block elimination of the ring's Jacobian and its solves, in one precision.
 *
 * Included twice by ring_lu.c, with REAL = float (functions *_s, LAPACK sgetrf/sgetrs,
 * BLAS sgemm) and REAL = double (*_d). It is the arithmetic of
 * harmonic_balance/bladed_disk/ring_lu.py (BlockRingFactor._eliminate and _solve_blocks,
 * whose docstrings state the elimination) step for step; every matrix column-major.
 *
 * Buffers (the caller's, sizes from the ring_pattern p, n_g = kl + ku):
 *   buf  D (N, m, m) | U (N, m, ku) on U's columns | L (N, nlr, kl) row-major, as scattered
 *        from J by ring_lu.py
 *   lus  (N, m, m)   the LU of each eliminated blade block D~_i, the border's S last
 *   piv  (N, m)      their pivots (LAPACK's, 1-based)
 *   g    (N - 2, m, n_g)  D~_i^-1 [W_i | U_i];   gl (m, nwc)   D~_(N-2)^-1 W_(N-2)
 *   vs   (N - 2, nvr, ku) V_i;                   vl (nvr, m)   V_(N-2)
 */

#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
#define FN(name) CAT(name, SUFFIX)

static int FN(getrf_)(int n, REAL *a, int *piv)
{
    int info = 0;
    GETRF(&n, &n, a, &n, piv, &info);
    return info;
}

static void FN(getrs_)(int n, int nrhs, REAL *a, int *piv, REAL *b)
{
    char t = 'N';
    int info = 0;
    GETRS(&t, &n, &nrhs, a, &n, piv, b, &n, &info);
}

/* C (m x n, ld m) = alpha op(A) B + beta C; A (ld lda), B (k x n, ld k). */
static void FN(gemm_)(char ta, int m, int n, int k, REAL alpha, REAL *a, int lda, REAL *b,
                      REAL beta, REAL *c)
{
    char tb = 'N';
    GEMM(&ta, &tb, &m, &n, &k, &alpha, a, &lda, b, &k, &beta, c, &m);
}

/* rows `rows` (n_r of them) of columns c0 .. c0 + n_c - 1 of a (ld lda) into out (n_r x n_c) */
static void FN(gather_)(const REAL *a, int lda, const int *rows, int n_r, int c0, int n_c,
                        REAL *out)
{
    for (int c = 0; c < n_c; ++c)
        for (int r = 0; r < n_r; ++r)
            out[r + (size_t)c * n_r] = a[rows[r] + (size_t)(c0 + c) * lda];
}

/* Work: rhs (m, n_g) | V, V' (nvr, ku) x 2 | SV (nvr, kl) | gathered (max(ku, kl), n_g)
 *       | product (max(nlr, nvr), max(ku, kl, nwc)). */
static size_t FN(factor_work_)(const ring_pattern *p)
{
    int k = p->ku > p->kl ? p->ku : p->kl, r = p->nlr > p->nvr ? p->nlr : p->nvr;
    int c = k > p->nwc ? k : p->nwc;
    return (size_t)p->m * (p->kl + p->ku) + 2 * (size_t)p->nvr * p->ku
           + (size_t)p->nvr * p->kl + (size_t)k * (p->kl + p->ku) + (size_t)r * c;
}

/* Blade N - 2, whose neighbours are both in the border, and the border's Schur complement
 * S (ringlu_factor's last steps): W, V of that blade into gl, vl; 0 or LAPACK's info. */
static int FN(border_)(const ring_pattern *p, const REAL *D, const REAL *U, const REAL *L,
                       const REAL *rhs, const REAL *V, const REAL *SV, REAL *prod, REAL *lus,
                       int *piv, REAL *gl, REAL *vl)
{
    const int N = p->N, m = p->m, ku = p->ku, kl = p->kl, nlr = p->nlr, nvr = p->nvr;
    const int nwc = p->nwc;
    const size_t mm = (size_t)m * m;
    int info;
    REAL *lu = lus + (size_t)(N - 2) * mm, *S = lu + mm;
    const REAL *UN2 = U + (size_t)(N - 2) * m * ku, *LN1 = L + (size_t)(N - 1) * nlr * kl;
    memset(gl, 0, (size_t)m * nwc * sizeof(REAL));
    memset(vl, 0, (size_t)nvr * m * sizeof(REAL));
    for (int c = 0; c < kl; ++c)
        memcpy(gl + (size_t)p->w_lc[c] * m, rhs + (size_t)c * m, m * sizeof(REAL));
    for (int c = 0; c < ku; ++c)
        for (int r = 0; r < m; ++r)
            gl[r + (size_t)p->w_uc[c] * m] += UN2[r + (size_t)c * m];
    for (int c = 0; c < ku; ++c)
        memcpy(vl + (size_t)p->uc[c] * nvr, V + (size_t)c * nvr, nvr * sizeof(REAL));
    for (int a = 0; a < nlr; ++a)
        for (int c = 0; c < kl; ++c)
            vl[p->v_lr[a] + (size_t)p->lc[c] * nvr] += LN1[(size_t)a * kl + c];
    info = FN(getrf_)(m, lu, piv + (size_t)(N - 2) * m);
    if (!info) {
        FN(getrs_)(m, nwc, lu, piv + (size_t)(N - 2) * m, gl);
        memcpy(S, D + (N - 1) * mm, mm * sizeof(REAL));
        for (int c = 0; c < kl; ++c)
            for (int a = 0; a < nvr; ++a)
                S[p->vr[a] + (size_t)p->lc[c] * m] -= SV[a + (size_t)c * nvr];
        FN(gemm_)('N', nvr, nwc, m, 1, vl, nvr, gl, 0, prod);
        for (int c = 0; c < nwc; ++c)
            for (int a = 0; a < nvr; ++a)
                S[p->vr[a] + (size_t)p->wc[c] * m] -= prod[a + (size_t)c * nvr];
        info = FN(getrf_)(m, S, piv + (size_t)(N - 1) * m);
    }
    return info;
}

/* The factors of the ring (the buffers above) from J's nnz stored values `data`, entry k
 * scattered to buf[dest[k]] first (buf's other entries stay zero); 0, 1 at a singular
 * block, -1 no memory. */
int FN(ringlu_factor)(const ring_pattern *p, size_t nnz, const long long *dest,
                      const double *data, REAL *buf, REAL *lus, int *piv, REAL *g, REAL *gl,
                      REAL *vs, REAL *vl)
{
    const int N = p->N, m = p->m, ku = p->ku, kl = p->kl, nlr = p->nlr, nvr = p->nvr;
    const int ng = kl + ku;
    const size_t mm = (size_t)m * m;
    const REAL *D = buf, *U = buf + N * mm, *L = U + (size_t)N * m * ku;
    REAL *work = calloc(FN(factor_work_)(p), sizeof(REAL));
    if (!work)
        return -1;
    REAL *rhs = work, *V = rhs + (size_t)m * ng, *V2 = V + (size_t)nvr * ku;
    REAL *SV = V2 + (size_t)nvr * ku, *gat = SV + (size_t)nvr * kl;
    REAL *prod = gat + (size_t)(ku > kl ? ku : kl) * ng;
    int info = 0;

    for (size_t k = 0; k < nnz; ++k)
        buf[dest[k]] = (REAL)data[k];
    for (int a = 0; a < nlr; ++a)                   /* W_0 = J_0,N-1 on rows lr */
        for (int c = 0; c < kl; ++c)
            rhs[p->lr[a] + (size_t)c * m] = L[(size_t)a * kl + c];
    FN(gather_)(U + (size_t)(N - 1) * m * ku, m, p->vr, nvr, 0, ku, V);   /* V_0 = J_N-1,0 */
    memcpy(lus, D, mm * sizeof(REAL));
    for (int i = 0; i < N - 2 && !info; ++i) {
        REAL *lu = lus + i * mm, *gi = g + (size_t)i * m * ng;
        const REAL *Li1 = L + (size_t)(i + 1) * nlr * kl;
        memcpy(rhs + (size_t)m * kl, U + (size_t)i * m * ku, (size_t)m * ku * sizeof(REAL));
        if ((info = FN(getrf_)(m, lu, piv + (size_t)i * m)) != 0)
            break;
        memcpy(gi, rhs, (size_t)m * ng * sizeof(REAL));
        FN(getrs_)(m, ng, lu, piv + (size_t)i * m, gi);       /* D~_i^-1 [W_i | U_i] */
        FN(gather_)(gi, m, p->uc, ku, 0, kl, gat);              /* SV += V_i gw[uc] */
        FN(gemm_)('N', nvr, kl, ku, 1, V, nvr, gat, 1, SV);
        memcpy(vs + (size_t)i * nvr * ku, V, (size_t)nvr * ku * sizeof(REAL));
        /* D~_(i+1) = D_(i+1) - L_(i+1) gu[lc] on (lr, uc) */
        memcpy(lu + mm, D + (i + 1) * mm, mm * sizeof(REAL));
        FN(gather_)(gi, m, p->lc, kl, kl, ku, gat);
        FN(gemm_)('T', nlr, ku, kl, 1, (REAL *)Li1, kl, gat, 0, prod);
        for (int b = 0; b < ku; ++b)
            for (int a = 0; a < nlr; ++a)
                lu[mm + p->lr[a] + (size_t)p->uc[b] * m] -= prod[a + (size_t)b * nlr];
        FN(gather_)(gi, m, p->lc, kl, 0, kl, gat);              /* W_(i+1) = -L_(i+1) gw[lc] */
        FN(gemm_)('T', nlr, kl, kl, -1, (REAL *)Li1, kl, gat, 0, prod);
        for (int c = 0; c < kl; ++c)
            for (int a = 0; a < nlr; ++a)
                rhs[p->lr[a] + (size_t)c * m] = prod[a + (size_t)c * nlr];
        FN(gather_)(gi, m, p->uc, ku, kl, ku, gat);             /* V_(i+1) = -V_i gu[uc] */
        FN(gemm_)('N', nvr, ku, ku, -1, V, nvr, gat, 0, V2);
        REAL *t = V; V = V2; V2 = t;
    }
    if (!info)
        info = FN(border_)(p, D, U, L, rhs, V, SV, prod, lus, piv, gl, vl);
    free(work);
    return info ? 1 : 0;
}

/* y -= A x[cols], the product summed first (A (n_r x n_c), ld lda; x read at cols, or
 * 0 .. n_c - 1 when cols is NULL; y (n_r), or y[rows] when rows is given); acc: n_r work */
static void FN(submv_)(const REAL *a, int lda, int n_r, const int *cols, int n_c,
                       const REAL *x, REAL *y, const int *rows, REAL *acc)
{
    memset(acc, 0, n_r * sizeof(REAL));
    for (int c = 0; c < n_c; ++c) {
        const REAL xc = x[cols ? cols[c] : c];
        const REAL *ac = a + (size_t)c * lda;
        for (int r = 0; r < n_r; ++r)   /* contiguous, no branch: vectorised */
            acc[r] += ac[r] * xc;
    }
    if (rows)
        for (int r = 0; r < n_r; ++r)
            y[rows[r]] -= acc[r];
    else
        for (int r = 0; r < n_r; ++r)
            y[r] -= acc[r];
}

/* x (N m, blade-major) from y (overwritten): the forward and backward sweeps of
 * _solve_blocks. z: work (N m); acc: work (m). */
static void FN(sweep_)(const ring_pattern *p, REAL *lus, int *piv, const REAL *buf,
                       const REAL *g, const REAL *gl, const REAL *vs, const REAL *vl,
                       REAL *y, REAL *z, REAL *x, REAL *acc)
{
    const int N = p->N, m = p->m, ku = p->ku, kl = p->kl, nlr = p->nlr, nvr = p->nvr;
    const size_t mm = (size_t)m * m;
    const int ng = kl + ku;
    const REAL *L = buf + N * mm + (size_t)N * m * ku;
    REAL *yb = y + (size_t)(N - 1) * m;
    for (int i = 0; i < N - 2; ++i) {          /* forward: L^-1 b, blade by blade */
        REAL *zi = z + (size_t)i * m;
        memcpy(zi, y + (size_t)i * m, m * sizeof(REAL));
        FN(getrs_)(m, 1, lus + i * mm, piv + (size_t)i * m, zi);
        /* y_(i+1)[lr] -= L_(i+1) z_i[lc]: L row-major (nlr, kl) = column-major (kl, nlr) */
        const REAL *Li1 = L + (size_t)(i + 1) * nlr * kl;
        REAL *yi1 = y + (size_t)(i + 1) * m;
        for (int a = 0; a < nlr; ++a) {
            REAL s = 0;
            for (int c = 0; c < kl; ++c)
                s += Li1[(size_t)a * kl + c] * zi[p->lc[c]];
            yi1[p->lr[a]] -= s;
        }
        FN(submv_)(vs + (size_t)i * nvr * ku, nvr, nvr, p->uc, ku, zi, yb, p->vr, acc);
    }
    REAL *zl = z + (size_t)(N - 2) * m;
    memcpy(zl, y + (size_t)(N - 2) * m, m * sizeof(REAL));
    FN(getrs_)(m, 1, lus + (size_t)(N - 2) * mm, piv + (size_t)(N - 2) * m, zl);
    FN(submv_)(vl, nvr, nvr, NULL, m, zl, yb, p->vr, acc);
    REAL *xb = x + (size_t)(N - 1) * m, *xl = x + (size_t)(N - 2) * m;
    memcpy(xb, yb, m * sizeof(REAL));
    FN(getrs_)(m, 1, lus + (size_t)(N - 1) * mm, piv + (size_t)(N - 1) * m, xb);
    memcpy(xl, zl, m * sizeof(REAL));
    FN(submv_)(gl, m, m, p->wc, p->nwc, xb, xl, NULL, acc);
    for (int i = N - 3; i >= 0; --i) {         /* backward: x_i = z_i - D~_i^-1 (W_i x_b + U_i x_i+1) */
        const REAL *gi = g + (size_t)i * m * ng;
        REAL *xi = x + (size_t)i * m;
        memcpy(xi, z + (size_t)i * m, m * sizeof(REAL));
        FN(submv_)(gi, m, m, p->lc, kl, xb, xi, NULL, acc);
        FN(submv_)(gi + (size_t)m * kl, m, m, p->uc, ku, x + (size_t)(i + 1) * m, xi, NULL, acc);
    }
}

/* x with J x = b: the block solve refined in double against J (CSC, double) until
 * |b - J x| <= rtol |b|, at most `refine` steps (BlockRingFactor.solve). perm: blade-major
 * index -> ring index. 0 converged, 1 not (the caller falls back), -1 no memory. */
int FN(ringlu_solve)(const ring_pattern *p, REAL *lus, int *piv, const REAL *buf,
                     const REAL *g, const REAL *gl, const REAL *vs, const REAL *vl,
                     const int *perm, const double *Jx, const int *indptr, const int *indices,
                     const double *b, int refine, double rtol, double *x)
{
    const size_t n = (size_t)p->N * p->m;
    REAL *w = malloc((3 * n + (size_t)p->m) * sizeof(REAL));
    double *r = malloc(n * sizeof(double)), *Ax = malloc(n * sizeof(double));
    int status = 1;
    if (!w || !r || !Ax) {
        status = -1;
        goto done;
    }
    const double nb = norm2(b, n);
    const double *rhs = b;
    for (int k = 0; k <= refine + 1; ++k) {
        if (k > 0) {   /* r = b - J x, as scipy's CSC product then the difference */
            csc_matvec(Jx, indptr, indices, n, x, Ax);
            for (size_t j = 0; j < n; ++j)
                r[j] = b[j] - Ax[j];
            if (norm2(r, n) <= rtol * nb) {
                status = 0;
                break;
            }
            if (k > refine)
                break;
            rhs = r;
        }
        for (size_t j = 0; j < n; ++j)
            w[j] = (REAL)rhs[perm[j]];
        FN(sweep_)(p, lus, piv, buf, g, gl, vs, vl, w, w + n, w + 2 * n, w + 3 * n);
        for (size_t j = 0; j < n; ++j)
            x[perm[j]] = k ? x[perm[j]] + (double)w[2 * n + j] : (double)w[2 * n + j];
    }
done:
    free(w);
    free(r);
    free(Ax);
    return status;
}

#undef FN
#undef CAT
#undef CAT_
