/*
 * march_internal.h -- private helpers shared by march_step.c (the node solve),
 * march_sens.c (its sensitivities) and march_blocks.c (the blocks' kept factors and
 * reference inverses). Not part of the API (march_step.h).
 */
#ifndef MARCH_INTERNAL_H
#define MARCH_INTERNAL_H

#include <math.h>

#include "march_step.h"

typedef void msurfp_getrf_t(int *, int *, double *, int *, int *, int *);
typedef void msurfp_getrs_t(char *, int *, int *, double *, int *, int *, double *, int *, int *);
typedef void msurfp_gemv_t(char *, int *, int *, double *, double *, int *, double *, int *,
                           double *, double *, int *);
typedef void msurfp_gemm_t(char *, char *, int *, int *, int *, double *, double *, int *,
                           double *, int *, double *, double *, int *);

/* scipy's LAPACK / BLAS (msurf_set_kernels). */
extern msurfp_getrf_t *msurfp_dgetrf;
extern msurfp_getrs_t *msurfp_dgetrs;
extern msurfp_gemv_t *msurfp_dgemv;
extern msurfp_gemm_t *msurfp_dgemm;

static inline int32_t block_size(const msurf_model *m, int32_t b)
{
    return m->blk_ptr[b + 1] - m->blk_ptr[b];
}

static inline int32_t largest_block(const msurf_model *m, int32_t *contacts)
{
    int32_t mb = 1, cb = 1;
    for (int32_t b = 0; b < m->n_blocks; ++b) {
        if (block_size(m, b) > mb) mb = block_size(m, b);
        if (m->blk_cptr[b + 1] - m->blk_cptr[b] > cb) cb = m->blk_cptr[b + 1] - m->blk_cptr[b];
    }
    if (contacts) *contacts = cb;
    return mb;
}

/* A block solved by diagonal updates of kept inverses (march_step.h). */
static inline int is_large(const msurf_model *m, int32_t b)
{
    return block_size(m, b) >= m->diag_min;
}

/* Most entries a large block's update may change (more: a new reference). */
static inline int32_t changes_max(const msurf_model *m, int32_t b)
{
    return (int32_t)floor(m->ref_share * block_size(m, b));
}

/* Block b of A (row-major m x m). */
static inline const double *block_A(const msurf_model *m, int32_t b)
{
    size_t off = 0;
    for (int32_t a = 0; a < b; ++a)
        off += (size_t)block_size(m, a) * (size_t)block_size(m, a);
    return m->blk_A + off;
}

/* Block b of A copied column-major into lu (LAPACK's layout), the start of a Newton or a
 * sensitivity matrix; returns the block's size. */
static inline int32_t block_A_colmajor(const msurf_model *m, int32_t b, double *lu)
{
    const int32_t mb = block_size(m, b);
    const double *A = block_A(m, b);
    for (int32_t i = 0; i < mb; ++i)
        for (int32_t j = 0; j < mb; ++j)
            lu[i + (size_t)j * mb] = A[(size_t)i * mb + j];
    return mb;
}

/* The cache slot of block b holding key (klen doubles), or the least recently used one
 * emptied for it (*fresh = 1: the caller factorizes into *lu, *piv); returns the slot. */
int32_t msurfp_find_slot(const msurf_model *m, msurf_cache *cache, int32_t b, size_t klen,
                         const double *key, double **lu, int **piv, int *fresh);

/* Doubles of work space of msurfp_diag_solve with R right-hand sides. */
size_t msurfp_large_work(const msurf_model *m, size_t R);

/* x = (A_b + diag(d))^{-1} rhs for a large block (march_blocks.c). */
int msurfp_diag_solve(const msurf_model *m, msurf_cache *cache, int32_t b, double *key,
                      size_t klen, const double *d, const double *rhs, int R, double *x, double *lw);

#endif /* MARCH_INTERNAL_H */
