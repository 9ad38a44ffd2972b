/*
 * march_step.h -- one quasi-static step of massless node contacts (a contact surface's
 * nodes, harmonic_balance/massless.py) for one history, in one call.
 *
 * The step solves, for the node displacements w (n_b) given the loads r,
 *
 *     A w + f_c(w) = r                                                      (E1)
 *
 * A block-diagonal (independent dense blocks: a face's nodes in x or in z), f_c the node
 * contacts: per contact i a penetration P_i = q_p,i w[c_p,i] + p_0,i, a normal load
 * N_i = k_n,i max(P_i, 0) on its normal coordinate, and (for a contact with friction) a
 * slip s_i = q_s,i w[c_s,i] - s_0,i whose force c_i F(s_i, k_n,i P_i / c_i) comes from the
 * contact's Iwan law (iwan.h, iwan_step: the exact straight-path step from the committed
 * state; the unclamped load, N <= 0 being lift-off there). The laws' sliders are c_i times
 * a reference law's, so one law serves every node of a group.
 *
 * The solve is massless.py's, operation for operation (MasslessContacts.solve with a
 * FactorCache on one history): Newton on the one-sided slopes of each node's trial map
 * (forward and backward differences of the law at fd_rel (|s| + |n| r_0 / r_1) + 1e-300),
 * the slope of the side each node's step moves to (max_sides passes), the slopes rounded
 * to slope_digits of the node's stuck slope (the key of a kept factorization), each block
 * solved by LAPACK getrf/getrs (scipy's, passed once: msurf_set_kernels), the residual's
 * products by BLAS gemv; then the line search: the full step unless it overshoots the
 * minimum of the step's potential along dx (slope g(a) = dx . r(w + a dx) above
 * section_rtol |g(0)|), else a bracket (doubling) and Illinois regula falsi on g. Newton
 * stops when max |r| <= rtol max(max |r|, max |f_c|, 1e-300) and commits the trial states.
 *
 * Each block keeps its last n_slots factorizations (keyed by the rounded slopes and normal
 * stiffnesses of its contacts), so a stick phase solves with factors already made; a kept
 * factorization is the same bits as a new one.
 *
 * Plain C99, no heap: the caller owns every buffer (sizes: msurf_work_size). The step:
 * march_step.c; the sensitivities: march_sens.c; the kept factors: march_blocks.c.
 */
#ifndef MARCH_STEP_H
#define MARCH_STEP_H

#include <stddef.h>
#include <stdint.h>

#include "iwan.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The node contacts and blocks (fixed for a march). Indices 0-based; c_s = -1 for a
 * contact without friction (normal only), c_p = -1 for one without a normal row. */
typedef struct {
    int32_t n_b, n_c, n_f, n_blocks, n_laws;
    const double *kn, *p0, *s0, *kt_stuck;  /* (n_c): k_n [N/m], preload [m], slip ref [m], stuck slope [N/m] */
    const int32_t *cs, *cp;                 /* (n_c): slip / normal coordinate of each contact */
    const double *qs, *qp;                  /* (n_c): its entry in the contact's row */
    const int32_t *f_contact, *f_law;       /* (n_f): friction entry -> contact, law */
    const double *f_c;                      /* (n_f): the factor c of its sliders */
    const iwan_model *const *laws;          /* (n_laws) */
    const double *law_r0, *law_r1;          /* (n_laws): sum fs, N_ref sum k */
    const int32_t *blk_ptr, *blk_dofs;      /* block b: DOFs blk_dofs[blk_ptr[b] .. blk_ptr[b+1]) */
    const int32_t *blk_cptr, *blk_c;        /* its contacts blk_c[blk_cptr[b] .. blk_cptr[b+1]) */
    const int32_t *blk_ls, *blk_lp;         /* (as blk_c): their slip / normal coordinate's
                                               place in the block, -1 if not in it */
    const double *blk_A;                    /* the blocks of A, row-major, one after another */
    double fd_rel, rtol, section_rtol, round_scale;  /* round_scale = 10^slope_digits */
    int32_t max_sides, max_bracket, max_section, n_slots;
    int32_t diag_min, n_refs;   /* blocks of diag_min DOFs and more: diagonal updates of
                                   n_refs kept inverses (rows of one entry: contacts on the
                                   diagonal only) */
    double ref_share;           /* share of changed entries beyond which a new reference */
} msurf_model;

/* Kept reference inverses of the large blocks: per large block n_refs column-major
 * inverses (m^2) and their diagonals (m); per block and reference its id (0: empty) and
 * last use. Zero the arrays to start; one store serves both caches below. */
typedef struct {
    double *inv, *dref;
    int64_t *id, *used;
    int64_t clock, count;
} msurf_refs;

/* Kept factorizations: per block n_slots slots of its key (3 n_cb + 1 doubles), column-major
 * LU (m^2; a large block's update matrix: floor(ref_share m)^2) and pivots, each slot's
 * last use (0: empty). Zero the arrays to start. */
typedef struct {
    double *keys, *lu;
    int32_t *piv;
    int64_t *used;
    int64_t clock;
    msurf_refs *refs;
} msurf_cache;

/* Status codes. */
#define MSURF_OK 0
#define MSURF_NOT_SETTLED 1     /* no equilibrium within max_iter Newton iterations */
#define MSURF_NONFINITE 2       /* NaN or infinite displacement or force */
#define MSURF_SINGULAR 3        /* a block's Newton matrix is singular */
#define MSURF_NO_KERNELS 4      /* msurf_set_kernels not called */

/* The LAPACK / BLAS routines (Fortran dgetrf, dgetrs, dgemv, dgemm); 0, or 1 if one is NULL. */
int msurf_set_kernels(void *dgetrf, void *dgetrs, void *dgemv, void *dgemm);

/* Doubles and states of the work space msurf_solve needs. */
size_t msurf_work_size(const msurf_model *m);
size_t msurf_state_work_size(const msurf_model *m);
/* Doubles of keys and LU, and ints of pivots, of a cache of m->n_slots slots per block. */
void msurf_cache_sizes(const msurf_model *m, size_t *n_keys, size_t *n_lu, size_t *n_piv);
/* Doubles of inverses and of diagonals of a reference store (msurf_refs). */
void msurf_refs_sizes(const msurf_model *m, size_t *n_inv, size_t *n_d);

/* Solve (E1) from the guess w (n_b, overwritten with the solution) and the committed
 * states (n_f, replaced by the solution's on MSURF_OK, untouched otherwise); rhs (n_b);
 * *iterations gets the Newton iterations made. */
int msurf_solve(const msurf_model *m, msurf_cache *cache, iwan_state *states, const double *rhs,
                double *w, int32_t max_iter, double *work, iwan_state *swork, int32_t *iterations);

/* The march's forward sensitivities along n_d directions (harmonic_balance/
 * surface_sensitivity.py, equations M1-M2 there): dw (n_b, n_d) of the last committed
 * displacements, the sliders' dz (n_f, ns_max, n_d) and residual rest points' du_c (n_f,
 * n_d), all row-major and carried in place; A R (n_b, r); the blocks in the order they are
 * solved (normal blocks first: the system is block-triangular in it). */
typedef struct {
    int32_t n_d, ns_max, r;
    double *dw, *dz, *duc;
    const double *AR;
    const int32_t *order;
} msurf_sens;

/* Doubles of the work space msurf_advance needs. */
size_t msurf_sens_work_size(const msurf_model *m, const msurf_sens *s);

/* Carry s over the step just committed: before / after the states of its start and end
 * (n_f), w1 its displacements (n_b), dq1 (r, n_d) its inputs' sensitivity; the block
 * factorizations kept in cache (a cache of its own: its keys are the consistent tangents). */
int msurf_advance(const msurf_model *m, msurf_cache *cache, msurf_sens *s,
                  const iwan_state *before, const iwan_state *after, const double *w1,
                  const double *dq1, double *work);

#ifdef __cplusplus
}
#endif

#endif /* MARCH_STEP_H */
