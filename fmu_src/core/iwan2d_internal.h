/*
 * iwan2d_internal.h -- private helpers of the 2D element (iwan2d.c) shared with the
 * contact point (contact_point.c) and the periodic loop (iwan2d_periodic.c). Not part
 * of the API (iwan2d.h); symbols and equations in iwan2d.c's header comment.
 *
 * Sensitivities. A caller that needs derivatives of a history with respect to nc
 * parameters X (the end point of a trial step: nc = 3; Fourier coefficients of a
 * periodic path: nc = 3 n_b) carries, for every slider j, S_j = d e_j / dX (2 x nc,
 * row-major) and for the residual spring S_res = d (u - u_contact) / dX, and gives
 * per step the derivatives of its end points: du0/dX, du1/dX (2 x nc), dN0/dX,
 * dN1/dX (nc). The force sensitivity is then sum_j k_j S_j + k_res S_res.
 */
#ifndef IWAN2D_INTERNAL_H
#define IWAN2D_INTERNAL_H

#include "iwan2d.h"
#include "iwan_internal.h"

/* A slider counts as at its limit when |e| >= r (1 - IWAN2_SLIP_RTOL): a slipped
 * slider lands on the circle up to the round-off of r (cos, sin) (a few ulps). */
#define IWAN2_SLIP_RTOL 1e-12

typedef struct {
    size_t nc;            /* number of parameters */
    double *S;            /* 2 nc per slider in use (slider j at S + 2 nc j) */
    double *S_res;        /* 2 nc: residual spring */
    const double *Du0;    /* 2 x nc: d u0 / dX (NULL: zero) */
    const double *Du1;    /* 2 x nc: d u1 / dX (NULL: zero) */
    const double *gN0;    /* nc: d N0 / dX (NULL: zero) */
    const double *gN1;    /* nc: d N1 / dX (NULL: zero) */
    double *scratch;      /* 6 nc doubles of workspace */
} iwan2_sens;

/* One slider along a straight path: stretch e (in: start, out: end), increment d,
 * slip radius r0 -> r1 (>= 0). Returns the friction work divided by k [m^2] and sets
 * *slipped. J (may be NULL): the 2 x 6 derivative (row-major) of the end stretch with
 * respect to (e0x, e0y, dx, dy, r0, r1). */
double iwan2p_slider(double *e, const double *d, double r0, double r1, double *J, int *slipped);

/* Exact update of s along the straight path to (ux, uy, N1), lift-off and re-contact
 * where N crosses zero; sens (may be NULL) carries the sensitivities. */
void iwan2p_advance(const iwan_model *m, iwan2_state *s, double ux, double uy, double N1,
                    iwan2_sens *sens);

/* Outputs of a state. sens (may be NULL): K and dF/dN from sensitivities with respect to
 * (u_x, u_y, N) of the end point (nc = 3); NULL: the tangent for continued motion. */
void iwan2p_outputs(const iwan_model *m, const iwan2_state *s, const iwan2_sens *sens,
                    iwan2_output *o);

/* Header checks of a state (version, flags, finite, dir a unit vector). */
iwan_status iwan2p_check_state(const iwan2_state *s);

/* Copy of the header and the n sliders in use (the rest of z is not read). */
void iwan2p_copy(iwan2_state *dst, const iwan2_state *src, int32_t n);

#endif /* IWAN2D_INTERNAL_H */
