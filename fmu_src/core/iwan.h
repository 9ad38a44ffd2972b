/*
 * iwan.h -- the Masing/Iwan friction element: one plain C99 implementation.
 *
 * A concave piecewise-linear virgin curve T(u) (the tangential force-displacement
 * curve of a contact, loaded monotonically from zero) is represented exactly by
 * m parallel Jenkins elements (spring k_j in series with a Coulomb slider of
 * strength fs_j) plus a residual spring k_res (Iwan). For slopes
 * s_1 > s_2 > ... > s_(m+1) >= 0 between breakpoints u_1 < ... < u_m:
 *     k_j = s_j - s_(j+1),  fs_j = k_j u_j,  k_res = s_(m+1).
 * Such a parallel model obeys Masing's rules exactly for any load history with
 * nested loops (branch after a reversal at (u_r, F_r): F = F_r + 2 g((u-u_r)/2)).
 *
 * Normal load N: every slip strength scales with N / n_ref (same curve shape),
 * so F(u; cN) = c F(u/c; N). N <= 0 is lift-off: force zero, memory released,
 * reloading restarts on the virgin curve from the displacement of re-contact.
 * When u and N change together within one update, each slider is advanced
 * exactly along the straight path (u, N)(s), 0 <= s <= 1 (its stick/slip
 * switches located in closed form), so results do not depend on the step size.
 *
 * Conventions: SI units (u in m, F and N in N, k in N/m, energies in J).
 * No heap use, no global state; model and state are flat fixed-size structs
 * without pointers, so a state is saved and restored by copying it.
 * Every function returns an iwan_status; on failure nothing is written to the
 * committed state.
 */
#ifndef IWAN_H
#define IWAN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define IWAN_MAX_SLIDERS 256   /* largest number of Jenkins elements (table segments) */
#define IWAN_STATE_VERSION 1   /* bump when iwan_state changes layout */

typedef enum {
    IWAN_OK = 0,
    IWAN_ERR_NONFINITE = 1,     /* NaN or infinite input */
    IWAN_ERR_BAD_TABLE = 2,     /* empty, too long, not starting at (0,0), u not increasing */
    IWAN_ERR_NOT_CONCAVE = 3,   /* slopes not non-increasing (and no fit requested) */
    IWAN_ERR_BAD_PARAM = 4,     /* n_ref <= 0, scale < 0, null pointer, size 0, ... */
    IWAN_ERR_NOT_CONVERGED = 5, /* periodic loop did not close within max_periods */
    IWAN_ERR_BAD_STATE = 6      /* state of another version or corrupted */
} iwan_status;

/* Model built from a virgin curve (immutable after iwan_model_init). */
typedef struct {
    int32_t n;                    /* number of Jenkins elements */
    double k[IWAN_MAX_SLIDERS];   /* slider spring stiffnesses [N/m] */
    double fs[IWAN_MAX_SLIDERS];  /* slip strengths at N = n_ref [N] */
    double k_res;                 /* residual (never slipping) spring [N/m] */
    double n_ref;                 /* normal load the curve was computed at [N] */
    double scale;                 /* friction scale: multiplies every fs (1 = as tabulated) */
    /* Derived from k and fs by iwan_model_init / iwan_model_from_sliders (fields
     * appended; do not change k or fs afterwards, build a new model instead): */
    double rad[IWAN_MAX_SLIDERS]; /* slip radius per unit strength factor fs_j / k_j [m] */
    double fs_sum;                /* sum of fs, in the order the step adds them [N] */
    int32_t derived_n;            /* n when derived (a model not built by the init
                                     functions is refused: IWAN_ERR_BAD_PARAM) */
} iwan_model;

/* History of one element (flat, copyable, versioned). */
typedef struct {
    int32_t version;              /* IWAN_STATE_VERSION */
    int32_t in_contact;           /* 0 after lift-off (N <= 0), 1 otherwise */
    double u;                     /* last committed displacement [m] */
    double N;                     /* last committed normal load [N] */
    double u_contact;             /* displacement at (re-)contact: residual spring rest point [m] */
    double w_diss;                /* cumulative dissipated energy [J], never decreasing */
    double z[IWAN_MAX_SLIDERS];   /* slider positions; slider force = k_j (u - z_j) [m] */
    double dir;                   /* sign of the last nonzero increment of u (+1/-1), for tangents */
} iwan_state;

/* Outputs at one point of the history. */
typedef struct {
    double F;      /* friction force [N] */
    double kt;     /* tangent stiffness dF/du for continued motion in direction `dir` [N/m] */
    double dFdN;   /* dF/dN at fixed u (slipping sliders only) [-] */
    double W;      /* cumulative dissipated energy [J] */
    double E;      /* stored elastic energy [J] */
    double slip;   /* slip fraction: slipping strength / total strength, in [0, 1] */
    /* "Slipping" = at its slip limit on the side of `dir` (it slips on continued
     * motion in that direction): such a slider adds 0 to kt and +-fs*scale/n_ref to
     * dFdN (the derivative when N decreases; when N grows it sticks). After lift-off
     * F = kt = dFdN = E = 0 and slip = 1 (also slip = 1 if the total strength is 0). */
} iwan_output;

/* Curve-table handling for iwan_model_init. */
typedef enum {
    IWAN_FIT_REJECT = 0,  /* a non-concave table is an error (IWAN_ERR_NOT_CONCAVE) */
    IWAN_FIT_CONCAVE = 1  /* replace the table by its least concave majorant (upper hull) */
} iwan_fit;

/* Build a model from a virgin-curve table u[0..m-1], T[0..m-1], u[0] = T[0] = 0,
 * u strictly increasing. The last segment's slope continues as the residual spring
 * unless the table ends flat (gross slip). IWAN_FIT_REJECT accepts slope increases
 * up to 1e-9 of the largest slope (round-off of collinear points) and refuses a
 * decreasing T (IWAN_ERR_BAD_TABLE); IWAN_FIT_CONCAVE takes the least concave
 * non-decreasing majorant (upper hull, flat after the largest T). Collinear points
 * are merged; more than IWAN_MAX_SLIDERS slope changes is IWAN_ERR_BAD_TABLE.
 * model->scale is set to 1 (change it afterwards to scale every slip strength). */
iwan_status iwan_model_init(iwan_model *model, const double *u, const double *T, size_t m,
                            double n_ref, iwan_fit fit);

/* Build a model directly from sliders (k_j, fs_j at n_ref) and a residual spring. */
iwan_status iwan_model_from_sliders(iwan_model *model, const double *k, const double *fs,
                                    size_t n, double k_res, double n_ref);

/* Virgin state at u = 0 with normal load N (pass model->n_ref for the curve's own load). */
iwan_status iwan_state_init(const iwan_model *model, iwan_state *state, double N);

/* Trial update: advance a copy of `committed` along the straight path to (u, N) and
 * report the outputs there. `committed` is not modified; `trial` may be NULL (outputs
 * only) and must not alias `committed` (iwan_step updates in place). */
iwan_status iwan_eval(const iwan_model *model, const iwan_state *committed, double u, double N,
                      iwan_state *trial, iwan_output *out);

/* In-place update of `state` to (u, N); `out` may be NULL.
 * At constant N in contact (N equal to the committed N) the exact update is the
 * play operator and one pass over the sliders gives the new state and every
 * output; iwan_series and iwan_eval run the same code, so a history gives the
 * same bits through iwan_step, iwan_eval + commit or iwan_series. */
iwan_status iwan_step(const iwan_model *model, iwan_state *state, double u, double N,
                      iwan_output *out);

/* Whole history in one call: n samples of u (and N, or NULL for constant model->n_ref).
 * Any output pointer may be NULL. `state` is advanced to the last sample. */
iwan_status iwan_series(const iwan_model *model, iwan_state *state, size_t n,
                        const double *u, const double *N,
                        double *F, double *kt, double *dFdN, double *W);

/* Many independent states of one model, each advanced by one sample: state i to
 * (u[i], N[i]) (N == NULL: model->n_ref for all), writing F[i] and, when kt is not
 * NULL, kt[i]. The same bits as iwan_step on each state separately (it runs the
 * same code). Every state and input is checked before any state moves: on failure
 * no state is modified. For vectorised time integration (one call per element per
 * time step for all frequencies or parameter variants). */
iwan_status iwan_step_batch(const iwan_model *model, iwan_state *states, size_t n_states,
                            const double *u, const double *N, double *F, double *kt);

/* Converged periodic loop of a periodic input sampled at n points per period
 * (sample n would equal sample 0). With constant N (N == NULL or all equal) the loop
 * is exact in one pass (the sweep starts at the maximum of u); otherwise periods are
 * repeated until the loop closes to `tol` (relative to the force range), at most
 * `max_periods`. Outputs per sample; W_cycle = energy dissipated per period [J];
 * periods_used may be NULL.
 * Static-state convention (sliders that never slip are not fixed by the loop): the
 * element is virgin at u = 0 (residual spring at rest there) and each slider is
 * shifted by the least amount that keeps it between its limits over the loop,
 * z_j = clamp(0, M - r_j, m + r_j) at the maximum M (minimum m) of u; a slider
 * with M - m >= 2 r_j slips every cycle and z_j = M - r_j. Closure check: the state
 * at the sweep start recurs to tol * (force range) in sum_j k_j |dz_j| + k_res |du_c|.
 * On IWAN_ERR_NOT_CONVERGED the outputs hold the last (unconverged) period. */
iwan_status iwan_periodic(const iwan_model *model, size_t n, const double *u, const double *N,
                          double *F, double *kt, double *dFdN, double *W_cycle,
                          int max_periods, double tol, int *periods_used);

/* Periodic loop plus its exact sensitivities with respect to basis coefficients:
 * u[t] = sum_c Eu[t*nb + c] X[c] (and N[t] = sum_c EN[t*nb + c] XN[c] when EN != NULL).
 * Writes dFdX[t*nb + c] = dF[t]/dX[c], including the dependence of every sticking
 * slider on the sample where it last stuck (its reversal point), and, when EN and
 * dFdXN are not NULL, dFdXN[t*nb + c] = dF[t]/dXN[c]. Same F, W_cycle as iwan_periodic
 * (to round-off). A slider stuck since sample a has F_j = k_j (u(t) - u(a)) +- g_j(N(a)),
 * one stuck since re-contact depends on the re-contact point of the straight path,
 * one that slipped into t has F_j = +-g_j(N(t)); the derivative is one-sided where a
 * slider sits exactly on a switch. With varying N, periods_used counts the closure
 * periods plus the final pass. Eu, EN are row-major (n, nb). */
iwan_status iwan_periodic_jac(const iwan_model *model, size_t n, const double *u, const double *N,
                              const double *Eu, const double *EN, size_t nb,
                              double *F, double *dFdX, double *dFdXN, double *W_cycle,
                              int max_periods, double tol, int *periods_used);

/* iwan_periodic_jac with the Jacobian's non-zero rows only (same numbers): the
 * samples whose row may be non-zero go to rows[0 .. *n_rows - 1] (ascending in the
 * sweep order, each once) and their rows, packed, to dFdX[r*nb + c] (and dFdXN) for
 * r < *n_rows; every other row is exactly zero (lifted off, or all sliders slipping
 * without a residual spring and, with EN, without strength). rows and dFdX need room
 * for n rows. On a stiff contact in gross slip a few per cent of the samples stick,
 * so this costs O(n + stuck samples x nb) instead of O(n x nb). Eu and EN are checked
 * through the result: IWAN_ERR_NONFINITE when a non-finite entry reaches a row (a
 * row of Eu that no Jacobian row uses is not read). */
iwan_status iwan_periodic_jac_rows(const iwan_model *model, size_t n, const double *u,
                                   const double *N, const double *Eu, const double *EN, size_t nb,
                                   double *F, size_t *rows, size_t *n_rows, double *dFdX,
                                   double *dFdXN, double *W_cycle, int max_periods, double tol,
                                   int *periods_used);

/* iwan_periodic_jac of n_el independent elements in one call (each its own model and
 * samples, one shared basis Eu (n, nb), the normal load's basis EN[e] (n, nb) per
 * element): element e reads u[e*n ..], N[e*n ..] and writes F[e*n ..],
 * dFdX[e*n*nb ..], dFdXN[e*n*nb ..], W_cycle[e], the same numbers as its own call.
 * Stops at the first element whose call fails: its status, its index in *failed (n_el
 * when all succeed). For a ring of many contacts evaluated together. */
iwan_status iwan_periodic_jac_many(const iwan_model *const *models, size_t n_el, size_t n,
                                   const double *u, const double *N, const double *Eu,
                                   const double *const *EN, size_t nb, double *F, double *dFdX,
                                   double *dFdXN, double *W_cycle, int max_periods, double tol,
                                   size_t *failed);

/* The periodic loops of n_el independent elements without their Jacobians, in one call
 * (each its own model and samples): element e reads u[e*n ..], N[e*n ..] (N required)
 * and writes F[e*n ..] and W_cycle[e], the same numbers as the F and W_cycle of its own
 * iwan_periodic_jac, iwan_periodic_jac_rows or iwan_periodic_jac_terms call (the same
 * closure and final pass). Stops at the first element that fails: its status, its
 * index in *failed (n_el when all succeed). For a ring's residual without its Jacobian. */
iwan_status iwan_periodic_many(const iwan_model *const *models, size_t n_el, size_t n,
                               const double *u, const double *N, double *F, double *W_cycle,
                               int max_periods, double tol, size_t *failed);

/* iwan_periodic_jac's Jacobian as sparse terms in the samples, for any basis (same
 * numbers as the dense rows to round-off): row t of dF/dX is
 *   dX[t] Eu[t, :] + sum_i cX[i] Eu[col[i], :]     over the terms i with row[i] == t,
 * and of dF/dXN (with_N != 0 and N given; else dXN and cXN are zero)
 *   dXN[t] EN[t, :] + sum_i cXN[i] EN[col[i], :].
 * The diagonal dX, dXN (n) is a stuck slider's stiffness and a slipping one's strength
 * slope; the *n_terms off-diagonal terms (col != row, sweep order) are the samples
 * where stuck sliders stuck and the ends of a re-contact step, few distinct columns.
 * So a projection D dF/dX onto a Fourier basis costs O(n log n) for the diagonal
 * (D diag(dX) E from the FFT of dX) plus O(n nb) per distinct column, not O(n nb^2).
 * row, col, cX, cXN need room for cap >= n (2 n_sliders + 2) terms. */
iwan_status iwan_periodic_jac_terms(const iwan_model *model, size_t n, const double *u,
                                    const double *N, int with_N, double *F, double *dX,
                                    double *dXN, size_t cap, size_t *n_terms, size_t *row,
                                    size_t *col, double *cX, double *cXN, double *W_cycle,
                                    int max_periods, double tol, int *periods_used);

/* Exact periodic loop of an input that is monotone between its n >= 2 extrema u_ext
 * (alternating maxima and minima; after u_ext[n-1] comes u_ext[0]) at N = n_ref, the
 * convention of iwan_periodic. Between two extrema the force is piecewise linear in
 * u: interval i of segment seg[i] (from extremum seg[i] to the next) runs from u_lo[i]
 * to u_hi[i] in travel order with F = icpt[i] + slope[i] u; at most n * (n_sliders + 1)
 * intervals (cap, the rows of A). A[i*n + e] = summed stiffness of the sliders stuck on
 * interval i since extremum e (position u_ext[e] -+ r_j), so d icpt[i] / d u_ext[e] =
 * -A[i*n + e]; sliders stuck since the virgin state carry no such term. With the
 * extrema of a smooth input this gives the exact Fourier coefficients of the loop (no
 * sampling error). W_cycle (may be NULL) = energy dissipated per period [J]. */
iwan_status iwan_periodic_branches(const iwan_model *model, size_t n, const double *u_ext,
                                   size_t cap, size_t *n_int, size_t *seg, double *u_lo,
                                   double *u_hi, double *slope, double *icpt, double *A,
                                   double *W_cycle);

/* Exact Fourier coefficients of the periodic loop at N = n_ref for the input
 * u(t) = sum over harm[k] of a cos(h t) + b sin(h t) (a alone for h = 0), coefficients
 * U in that order (nb of them): Fh[p] = (1/pi) int F cos / sin (1/(2 pi) for the mean)
 * and dFh[p*nb + q] = dFh[p]/dU[q], with no sampling error: the extrema of u are found
 * by a sign scan of u' on n_scan points (> 2 max h) and Newton, the loop between them
 * is iwan_periodic_branches and its pieces are integrated in closed form. n_ext = the
 * extrema found; 0 for a constant input and an odd number when the scan lost one (a
 * root on a scan point counted twice or an unresolved cell): then the outputs are zero
 * and the caller decides (harmonic balance falls back to the sampled loop). */
iwan_status iwan_periodic_fourier(const iwan_model *model, size_t n_h, const int32_t *harm,
                                  const double *U, size_t n_scan, double *Fh, double *dFh,
                                  double *W_cycle, size_t *n_ext);

/* Human-readable text of a status code (static string). */
const char *iwan_status_text(iwan_status status);

#ifdef __cplusplus
}
#endif

#endif /* IWAN_H */
