/*
 * contact_point.h -- a 3D contact point: the 2D friction element (iwan2d.h) with a
 * normal law. Plain C99, no heap, no global state, flat fixed-size model and state.
 *
 * Local coordinates q = (u_x, u_y, p): relative tangential displacement (slip) of
 * body 1 against body 2 in the contact plane [m] and penetration p [m] (positive
 * pressed). Local force f = (F_x, F_y, N) conjugate to q: friction force and normal
 * load [N] (the internal force on body 1 is F_x t_x + F_y t_y - N n; virtual work f . dq).
 *
 * Normal law: N(p) piecewise linear through a table (p_i, N_i), p_0 = N_0 = 0, both
 * strictly increasing (the approach curve of a contact computed by `damper normal`,
 * or a penalty spring k_n: the table (0, 0), (1, k_n)); beyond the last point the last
 * slope continues; N = 0 for p <= 0 (lift-off). The slip limits of the friction
 * element follow N(p) (strengths scale with N / n_ref of the tangential curve).
 * Between communication points q moves on a straight line; the step is split where p
 * crosses a table point, so (u, N) is a straight line on each piece and the friction
 * element is exact on the whole step (lift-off where p crosses 0).
 *
 * Dashpots (optional): with relative velocities v = (v_x, v_y, v_n) [m/s], in contact
 * F_t += c_t v_t and N += c_n v_n (clipped at N >= 0: no adhesion). The slip limits
 * follow the elastic N(p) only, and W is the friction work only, so the element stays
 * rate-independent and exact.
 *
 * Tangent: K = d f / d q (3 x 3, row-major), the exact derivative at the end of the
 * step with respect to its end point (committed state fixed), as iwan2d.h; for a zero
 * step the tangent for continued motion (the friction part as iwan2d.h, dN/dp the
 * slope of the table segment below p, d F_t / dp = dF_t/dN dN/dp for decreasing p).
 * C = d f / d v (diagonal): (c_t, c_t, c_n) in contact, 0 when open or clipped.
 */
#ifndef CONTACT_POINT_H
#define CONTACT_POINT_H

#include <stddef.h>
#include <stdint.h>

#include "iwan.h"
#include "iwan2d.h"

#ifdef __cplusplus
extern "C" {
#endif

#define CPOINT_MAX_NORMAL 256    /* largest number of points of the normal law */
#define CPOINT_STATE_VERSION 1   /* bump when cpoint_state changes layout */

/* Contact state codes (cpoint_output.state). */
#define CPOINT_OPEN 0            /* lift-off: N(p) <= 0 */
#define CPOINT_STICK 1           /* in contact, no slider slipping */
#define CPOINT_SLIP 2            /* in contact, at least one slider slipping */

typedef struct {
    iwan_model t;                      /* tangential element (iwan_model_init, at n_ref) */
    int32_t n_normal;                  /* points of the normal law (>= 2) */
    double p[CPOINT_MAX_NORMAL];       /* penetrations [m]: p[0] = 0, strictly increasing */
    double N[CPOINT_MAX_NORMAL];       /* normal loads [N]: N[0] = 0, strictly increasing */
    double E_n[CPOINT_MAX_NORMAL];     /* derived: int_0^p_i N dp [J] */
    double c_t;                        /* tangential dashpot [N s/m] */
    double c_n;                        /* normal dashpot [N s/m] */
} cpoint_model;

/* History of one contact point. The friction element's state comes last, so the part
 * in use is offsetof(cpoint_state, s) + offsetof(iwan2_state, z) + 2 n doubles. */
typedef struct {
    int32_t version;                   /* CPOINT_STATE_VERSION */
    int32_t reserved;                  /* 0 */
    double p;                          /* last committed penetration [m] */
    iwan2_state s;                     /* friction element at N(p) */
} cpoint_state;

typedef struct {
    double f[3];      /* (F_x, F_y, N) [N], dashpots included */
    double K[9];      /* d f / d q, q = (u_x, u_y, p), row-major [N/m] */
    double C[3];      /* d f_i / d v_i (diagonal damping) [N s/m] */
    double W;         /* cumulative friction work [J] */
    double E;         /* stored energy: sliders, residual spring, normal spring [J] */
    double slip;      /* slipping strength / total strength [-] (1 when open) */
    int32_t state;    /* CPOINT_OPEN, CPOINT_STICK or CPOINT_SLIP */
} cpoint_output;

/* Build a contact point from a tangential model (copied) and a normal law table p, N
 * (n >= 2 points with p[0] = N[0] = 0, both strictly increasing: IWAN_ERR_BAD_TABLE
 * otherwise, a table that is not monotone included) and dashpots c_t, c_n >= 0. */
iwan_status cpoint_model_init(cpoint_model *model, const iwan_model *tangential,
                              const double *p, const double *N, size_t n, double c_t,
                              double c_n);

/* Normal load N(p) [N] of the law and its slope dN/dp [N/m] (segment below p). */
double cpoint_normal(const cpoint_model *model, double p, double *slope);

/* Virgin state at u = (0, 0) and penetration p. */
iwan_status cpoint_state_init(const cpoint_model *model, cpoint_state *state, double p);

/* Trial update to q = (u_x, u_y, p) (v: velocities (3) or NULL) from `committed` (not
 * modified); `trial` may be NULL and must not alias `committed`. */
iwan_status cpoint_eval(const cpoint_model *model, const cpoint_state *committed,
                        const double *q, const double *v, cpoint_state *trial,
                        cpoint_output *out);

/* In-place update of `state` to q (v may be NULL); `out` may be NULL. */
iwan_status cpoint_step(const cpoint_model *model, cpoint_state *state, const double *q,
                        const double *v, cpoint_output *out);

/* Header checks of a state (version, the friction element's header, N(p) consistent
 * with its contact flag). */
iwan_status cpoint_check_state(const cpoint_model *model, const cpoint_state *state);

#ifdef __cplusplus
}
#endif

#endif /* CONTACT_POINT_H */
