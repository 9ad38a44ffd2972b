/*
 * iwan_internal.h -- private helpers shared by the two halves of the core:
 * iwan.c (model building, exact straight-path step, time series) and
 * iwan_periodic.c (periodic loop and its Jacobian). Not part of the API (iwan.h);
 * symbols and equations are defined in iwan.c's header comment.
 */
#ifndef IWAN_INTERNAL_H
#define IWAN_INTERNAL_H

#include "iwan.h"

/* Anchor codes for the exact periodic Jacobian (see iwan_periodic_jac). A slider
 * stuck since sample a (>= 0) has force k (u(t) - u(a)) + sg * g(N(aN)). */
#define ANCHOR_ORIGIN (-1)               /* stuck since the virgin state at u = 0 */
#define ANCHOR_RECONTACT(t) (-2 - (int32_t)(t)) /* stuck since re-contact in the step to t */
#define ANCHOR_IS_RECONTACT(a) ((a) <= -2)
#define ANCHOR_RECONTACT_STEP(a) ((size_t)(-2 - (a)))

typedef struct {
    int32_t au[IWAN_MAX_SLIDERS];   /* sample fixing the slider position (or code above) */
    int32_t aN[IWAN_MAX_SLIDERS];   /* sample fixing the slip force at the anchor */
    int8_t sg[IWAN_MAX_SLIDERS];    /* sign of the slip force at the anchor */
    int8_t slip[IWAN_MAX_SLIDERS];  /* 1 if the slider slipped in the step just made */
    int32_t res;                    /* residual-spring anchor: ANCHOR_ORIGIN or re-contact */
    int32_t t;                      /* index of the sample being reached */
} anchors;

/* Strength factor f(N) = scale N / n_ref: slip strength g_j = fs_j f, radius r_j = g_j / k_j. */
static inline double strength_factor(const iwan_model *m, double N)
{
    return m->scale * (N / m->n_ref);
}

/* Parameter checks (IWAN_OK or the status to return). */
iwan_status iwanp_check_model(const iwan_model *m);
iwan_status iwanp_check_finite(const double *x, size_t n);

/* Exact update of s along the straight path to (u1, N1), with lift-off and
 * re-contact where N crosses zero; `an` (may be NULL) records the anchors. */
void iwanp_advance(const iwan_model *m, iwan_state *s, double u1, double N1, anchors *an);

/* Release every slider and the residual spring at u (lift-off). */
void iwanp_release(const iwan_model *m, iwan_state *s, double u);

/* Outputs of a state; its force alone. */
void iwanp_outputs(const iwan_model *m, const iwan_state *s, iwan_output *o);
double iwanp_force(const iwan_model *m, const iwan_state *s);

/* n samples of u at the committed constant N > 0 (play operator); outputs may be NULL. */
void iwanp_run_const(const iwan_model *m, iwan_state *s, size_t n, const double *u,
                     double *F, double *kt, double *dFdN, double *W);

/* Store the outputs o at index i of the arrays that are not NULL. */
void iwanp_store(const iwan_output *o, size_t i, double *F, double *kt, double *dFdN, double *W);

#endif /* IWAN_INTERNAL_H */
