/*
 * iwan2d.h -- the two-dimensional Masing/Iwan friction element: the 1D element of
 * iwan.h with the slip u = (u_x, u_y) in the contact plane. Plain C99, no heap, no
 * global state; model and state are flat fixed-size structs (copy to save/restore).
 *
 * Model: the same iwan_model as the 1D element (iwan_model_init from the isotropic
 * virgin curve, or iwan_model_from_sliders): sliders (k_j, fs_j at n_ref), a residual
 * spring k_res, the friction scale. Slider j is a 2D Jenkins element: spring k_j in
 * series with a Coulomb slider at z_j (a point of the plane), elastic stretch
 * e_j = u - z_j, force k_j e_j, with the circular slip limit
 *     |e_j| <= r_j(N) = rad_j f(N),   f(N) = scale N / n_ref,   rad_j = fs_j / k_j.
 * While it slips, the slider moves along its stretch (maximal dissipation): dz/ds is
 * parallel to e. Along a straight line the element is exactly the 1D element; the
 * virgin curve is the same in every direction (isotropy).
 *
 * Exact straight path. Between two committed points (u, N) moves on a straight line,
 * u(s) = u0 + s d, r(s) = r0 + s (r1 - r0), s in [0, 1] (as the 1D element). A slider
 * sticks until its stretch e0 + s d reaches the circle (one crossing at most: |e| - r
 * is convex in s), then slips to s = 1. While it slips its stretch keeps |e| = r(s)
 * and its angle theta to d obeys r dtheta/ds = -|d| sin(theta): with
 * tau(s) = int ds / r the closed form is the tractrix
 *     tan(theta(s) / 2) = tan(theta* / 2) exp(-|d| (tau(s) - tau(s*))),
 * (for constant r: a slider dragged at its slip radius). The work of the slip phase
 * is exact in closed form at constant N,
 *     W_j = k_j [ (1 - s*) |d| r - r^2 ln((1 + cos theta_1) / (1 + cos theta*)) ],
 * and, when N varies within the step, its one term without an elementary primitive
 * (the turning stretch against the changing radius) is integrated by Gauss-Legendre
 * panels in the variable |d| tau, on which the integrand is analytic in a strip of
 * half-width pi/2: round-off accuracy. Results do not depend on how a piecewise-linear
 * path is sampled. Lift-off (N <= 0) and re-contact as in the 1D element (iwan.h):
 * the path is followed to N = 0 (every slider then carries zero force), the element
 * is released (z_j = u, residual spring at rest at u); re-contact restarts it virgin
 * at the point of the straight path where N crosses zero.
 *
 * Tangent. iwan2_eval / iwan2_step report the exact derivative of the outputs at the
 * end of the step with respect to the end point (u_x, u_y, N), the committed state
 * fixed: the 2x2 stiffness K and dF/dN (for an importer iterating on a step, and what
 * central differences of iwan2_eval give). For a zero step (the end point equals the
 * committed one) they report the tangent for continued motion in the direction of the
 * last motion `dir`, the limit of the former: a slider at its limit with e . dir > 0
 * adds k (I - e e^T / |e|^2) to K and fs * scale / n_ref * e / |e| to dF/dN (the
 * derivative when N decreases, as the 1D element), every other slider k I and 0.
 *
 * Conventions: SI units (u in m, F and N in N, K in N/m, energies in J); functions
 * return an iwan_status (iwan.h) and write nothing on failure.
 */
#ifndef IWAN2D_H
#define IWAN2D_H

#include <stddef.h>
#include <stdint.h>

#include "iwan.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IWAN2_STATE_VERSION 1   /* bump when iwan2_state changes layout */

/* History of one 2D element (flat, copyable, versioned). The sliders come last, so
 * a copy of the sliders in use is offsetof(iwan2_state, z) + 2 n doubles. */
typedef struct {
    int32_t version;              /* IWAN2_STATE_VERSION */
    int32_t in_contact;           /* 0 after lift-off (N <= 0), 1 otherwise */
    double u[2];                  /* last committed slip (u_x, u_y) [m] */
    double N;                     /* last committed normal load [N] */
    double u_contact[2];          /* (re-)contact point: rest point of the residual spring [m] */
    double w_diss;                /* cumulative dissipated energy [J], never decreasing */
    double dir[2];                /* unit direction of the last nonzero slip increment */
    double z[2 * IWAN_MAX_SLIDERS]; /* slider j at (z[2j], z[2j+1]); its force k_j (u - z_j) [m] */
} iwan2_state;

/* Outputs at one point of the history. */
typedef struct {
    double F[2];      /* friction force (F_x, F_y) [N] */
    double K[4];      /* tangent stiffness dF_i/du_j, row-major: [dFx/dux, dFx/duy, dFy/dux, dFy/duy] [N/m] */
    double dFdN[2];   /* dF_i/dN [-] */
    double W;         /* cumulative dissipated energy [J] */
    double E;         /* stored elastic energy (sliders and residual spring) [J] */
    double slip;      /* slipping strength / total strength in [0, 1]; 1 after lift-off */
    /* "Slipping" = at its limit (to SLIP_RTOL) with e . dir > 0, dir the direction of
     * the step (or the last motion for a zero step). After lift-off F = K = dFdN =
     * E = 0 and slip = 1 (also slip = 1 if the total strength is 0). */
} iwan2_output;

/* Virgin state at u = (0, 0) with normal load N (model->n_ref for the curve's own). */
iwan_status iwan2_state_init(const iwan_model *model, iwan2_state *state, double N);

/* Trial update: advance a copy of `committed` along the straight path to (ux, uy, N)
 * and report the outputs there (with the exact tangent of that step). `committed` is
 * not modified; `trial` may be NULL (outputs only) and must not alias `committed`. */
iwan_status iwan2_eval(const iwan_model *model, const iwan2_state *committed, double ux,
                       double uy, double N, iwan2_state *trial, iwan2_output *out);

/* In-place update of `state` to (ux, uy, N); `out` may be NULL. Same numbers as
 * iwan2_eval followed by a commit of its trial. */
iwan_status iwan2_step(const iwan_model *model, iwan2_state *state, double ux, double uy,
                       double N, iwan2_output *out);

/* Whole history in one call: n samples of (ux, uy) and N (NULL: model->n_ref). Any
 * output array may be NULL (F: 2n values, (F_x, F_y) per sample). `state` is advanced
 * to the last sample. */
iwan_status iwan2_series(const iwan_model *model, iwan2_state *state, size_t n,
                         const double *ux, const double *uy, const double *N,
                         double *F, double *W);

/* Doubles of workspace iwan2_periodic_jac needs for nb basis functions (48 nb). */
size_t iwan2_periodic_work_size(size_t nb);

/* Periodic steady state of a periodic path sampled at n >= 2 points (sample n would
 * equal sample 0), straight lines between samples, and its exact Jacobian with respect
 * to basis coefficients: u_x[t] = sum_c E[t*nb + c] X_x[c], u_y[t] = sum_c E[t*nb + c]
 * X_y[c], N[t] = sum_c EN[t*nb + c] X_N[c] (EN NULL: N does not depend on X; N NULL:
 * constant model->n_ref). Outputs: F[2t + i] = F_i(t) (i = 0: x, 1: y); when dF is not
 * NULL, dF[(2t + i) * 3nb + c] = dF_i(t)/d(X_x, X_y, X_N)[c] (E and a workspace of
 * iwan2_periodic_work_size(nb) doubles needed); W_cycle = energy dissipated per period.
 * Convention: virgin at u = 0 under N[0], the straight path to sample 0, then each
 * slider is marched on its own until its position at sample 0 recurs to tol times its
 * largest slip radius (max_periods at most); one more period gives the outputs. On a
 * line at constant N this is the 1D element's iwan_periodic (a slider that never slips
 * sits at the point nearest to 0 it may occupy); the loop is continuous in the path.
 * periods_used (may be NULL): the most periods any
 * slider needed, the final one included. IWAN_ERR_NOT_CONVERGED: a slider did not
 * close (the outputs hold its last period). */
iwan_status iwan2_periodic_jac(const iwan_model *model, size_t n, const double *ux,
                               const double *uy, const double *N, const double *E,
                               const double *EN, size_t nb, double *F, double *dF,
                               double *W_cycle, int max_periods, double tol, int *periods_used,
                               double *work);

#ifdef __cplusplus
}
#endif

#endif /* IWAN2D_H */
