/* The ring's block elimination (ring_lu.py, BlockRingFactor) as one compiled call per
 * factorization and one per refined solve.
 *
 * The loops over the blades, the gathers and scatters of the couplings' rows and columns
 * and the refinement's residual run here; the dense kernels are LAPACK's getrf/getrs and
 * BLAS's gemm, taken at run time as function pointers from scipy
 * (scipy.linalg.cython_lapack / cython_blas, ringlu_set_kernels), so the library links
 * against no LAPACK and uses the one the numpy path of ring_lu.py uses. No Python API:
 * loaded through ctypes by ring_lu_c.py. Plain C99; the caller owns every buffer except
 * the per-call work space.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The pattern of the ring's Jacobian, blade-major (ring_lu.py, BlockRingFactor._analyse):
 * N blades of m unknowns; the upper coupling U_i on ku columns uc and the lower L_i on
 * nlr rows lr and kl columns lc; the border's columns wc (nwc) and rows vr (nvr); w_lc,
 * w_uc: positions of lc and uc in wc; v_lr: of lr in vr. Indices 0-based, sorted. */
typedef struct {
    int N, m, ku, kl, nlr, nvr, nwc;
    const int *uc, *lr, *lc, *wc, *vr, *w_lc, *w_uc, *v_lr;
} ring_pattern;

typedef void getrf_s_t(int *, int *, float *, int *, int *, int *);
typedef void getrs_s_t(char *, int *, int *, float *, int *, int *, float *, int *, int *);
typedef void gemm_s_t(char *, char *, int *, int *, int *, float *, float *, int *, float *,
                      int *, float *, float *, int *);
typedef void getrf_d_t(int *, int *, double *, int *, int *, int *);
typedef void getrs_d_t(char *, int *, int *, double *, int *, int *, double *, int *, int *);
typedef void gemm_d_t(char *, char *, int *, int *, int *, double *, double *, int *,
                      double *, int *, double *, double *, int *);

static getrf_s_t *sgetrf_p;
static getrs_s_t *sgetrs_p;
static gemm_s_t *sgemm_p;
static getrf_d_t *dgetrf_p;
static getrs_d_t *dgetrs_p;
static gemm_d_t *dgemm_p;

/* The LAPACK/BLAS routines (scipy's cython_lapack/cython_blas pointers); 0, or 1 when one
 * is missing. Call once per process before anything else. */
int ringlu_set_kernels(void *sgetrf, void *sgetrs, void *sgemm, void *dgetrf, void *dgetrs,
                       void *dgemm)
{
    sgetrf_p = (getrf_s_t *)sgetrf;
    sgetrs_p = (getrs_s_t *)sgetrs;
    sgemm_p = (gemm_s_t *)sgemm;
    dgetrf_p = (getrf_d_t *)dgetrf;
    dgetrs_p = (getrs_d_t *)dgetrs;
    dgemm_p = (gemm_d_t *)dgemm;
    return !(sgetrf && sgetrs && sgemm && dgetrf && dgetrs && dgemm);
}

static double norm2(const double *v, size_t n)
{
    double s = 0.0;
    for (size_t j = 0; j < n; ++j)
        s += v[j] * v[j];
    return sqrt(s);
}

/* y = A x, A (n x n) CSC: column by column, as scipy.sparse does */
static void csc_matvec(const double *data, const int *indptr, const int *indices, size_t n,
                       const double *x, double *y)
{
    memset(y, 0, n * sizeof(double));
    for (size_t j = 0; j < n; ++j)
        for (int k = indptr[j]; k < indptr[j + 1]; ++k)
            y[indices[k]] += data[k] * x[j];
}

#define REAL float
#define SUFFIX _s
#define GETRF sgetrf_p
#define GETRS sgetrs_p
#define GEMM sgemm_p
#include "ring_lu_body.h"
#undef REAL
#undef SUFFIX
#undef GETRF
#undef GETRS
#undef GEMM

#define REAL double
#define SUFFIX _d
#define GETRF dgetrf_p
#define GETRS dgetrs_p
#define GEMM dgemm_p
#include "ring_lu_body.h"
#undef REAL
#undef SUFFIX
#undef GETRF
#undef GETRS
#undef GEMM
