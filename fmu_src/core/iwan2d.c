/*
 * iwan2d.c -- the 2D Masing/Iwan element (implementation of iwan2d.h): the exact
 * straight-path update of one slider (stick, then the tractrix at its slip radius)
 * with its exact derivative, the element update with lift-off and re-contact, the
 * outputs and the time series.
 *
 * Symbols (SI). Slider: stiffness k, stretch e = u - z (2-vector), slip radius r.
 * Straight path: u(s) = u0 + s d, r(s) = r0 + s dr (dr = r1 - r0), s in [0, 1];
 * D = |d|, d^ = d / D, n^ = d^ rotated by +90 degrees. Stick phase: e(s) = e0 + s d
 * until h(s) = |e(s)|^2 - r(s)^2 = A s^2 + 2 B s + C reaches zero at s*,
 *     A = D^2 - dr^2,  B = e0 . d - r0 dr,  C = |e0|^2 - r0^2 <= 0           (P1)
 * (one root in [0, 1]: |e| - r is convex). Slip phase: e = r(s) (cos t d^ + sin t n^)
 * with r dt/ds = -D sin t (the component of d across e turns it; the slider moves
 * along e at the rate D cos t - dr >= 0). With x = D int_{s*}^{s} ds'/r(s'),
 *     tan(t / 2) = tan(t* / 2) exp(-x),                                      (P2)
 *     X = x(1) = (1 - s*) D ln(r1 / r*) / (r1 - r*)   (= (1 - s*) D / r at constant r),
 * and, with c = cos t*, s_n = sin t*, E = exp(-X), den = (1 + c) + E^2 (1 - c):
 *     cos t1 = ((1 + c) - E^2 (1 - c)) / den,   sin t1 = 2 E s_n / den.      (P3)
 * Friction work of the slip phase (power k r (D cos t - dr)):
 *     W / k = (1 - s*) (D - dr) (r* + r1) / 2 - K_d,                          (P4)
 *     K_d = D int r (1 - cos t) ds = r*^2 int_0^X 2 (1 - c) e^{2 (beta - 1) x}
 *           / ((1 + c) + (1 - c) e^{-2 x}) dx,   beta = dr / D,               (P5)
 * at constant r (beta = 0) K_d = r^2 ln(1 + (1 - E^2)(1 - c) / den) (closed form);
 * otherwise by 10-point Gauss-Legendre panels of width <= 1 / max(1, |beta - 1|) in x
 * (the integrand is analytic within pi/2 of the real axis: round-off accuracy). On a
 * line (c = 1) K_d = 0 and (P4) is the 1D element's trapezoid. Energy balance per
 * slider: k e . d ds = dW + d(k |e|^2 / 2).
 *
 * Derivative (for the tangent and the periodic Jacobian): with phi the angle of e,
 *     d phi1 = (1 - psi) d phi_d + psi d phi* - sin t1 dX,   psi = 2 E / den    (P6)
 * (psi = d t1 / d t*), d e1 = e1^ dr1 + r1 e1^_perp d phi1, and s* moves with the root
 * of (P1): ds* = -dh / h'(s*). Lift-off and re-contact as in iwan.c.
 */
#include "iwan2d_internal.h"

#include <math.h>
#include <string.h>

/* 10-point Gauss-Legendre rule on [-1, 1]: nodes +-GL_X[i], weights GL_W[i]. */
static const double GL_X[5] = {0.14887433898163121088, 0.43339539412924719080,
                               0.67940956829902440623, 0.86506336668898451073,
                               0.97390652851717172008};
static const double GL_W[5] = {0.29552422471475287017, 0.26926671930999635509,
                               0.21908636251598204400, 0.14945134915058059315,
                               0.06667134430868813759};
/* 5-point Gauss-Legendre rule on [-1, 1] (nodes +-GL5_X[i] and 0). */
static const double GL5_X[2] = {0.53846931010568309104, 0.90617984593866399280};
static const double GL5_W[3] = {0.47862867049936646804, 0.23692688505618908751,
                                0.56888888888888888889};
/* Most panels of (P5): the integrand is cut where it falls below e^-40 of its scale,
 * so X_eff max(1, |beta - 1|) stays below ~60 (this cap is never reached in practice). */
#define KD_MAX_PANELS 128
/* A panel this narrow (in units of the integrand's scale, pi/2 from its poles) is
 * integrated to round-off by 5 points: error ~ (width / pi)^10 < 1e-17. */
#define KD_NARROW 0.05
/* Below this |x| the series of q(x) = ln(1 + x) / x and q'(x) (to x^9) is exact to
 * round-off; above it the closed forms lose at most eps / x. */
#define LOGQ_SERIES 1e-2

/* |(x, y)|: sqrt of the sum of squares (hypot's overflow guard is not needed at the
 * element's scales, |u| <= 1e-6 r / eps, and costs several times more). */
static double norm2(double x, double y)
{
    return sqrt(x * x + y * y);
}

/* q(x) = ln(1 + x) / x and its derivative (x > -1). */
static void logq(double x, double *q, double *dq)
{
    if (fabs(x) < LOGQ_SERIES) {
        double a = 0.0, b = 0.0;
        int k;
        for (k = 9; k >= 1; --k) {  /* q = sum (-x)^k / (k + 1), q' = sum k (-1)^k x^(k-1) / (k + 1) */
            a = (k % 2 ? -1.0 : 1.0) / (k + 1.0) + x * a;
            b = (k % 2 ? -1.0 : 1.0) * k / (k + 1.0) + x * b;
        }
        *q = 1.0 + x * a;
        *dq = b;
        return;
    }
    {
        const double l = log1p(x);
        *q = l / x;
        *dq = (x / (1.0 + x) - l) / (x * x);
    }
}

/* (P5) without the factor r*^2, for beta != 0: Gauss-Legendre panels of equal width.
 * Integrand f(x) = e^{a x} / (c1p + c1m e^{-2 x}), a = 2 (beta - 1). The nodes sit at
 * x_c +- h x_k about each panel's centre, so e^{a x} and e^{-2 x} are the centre's
 * factors (advanced panel by panel) times the offsets' (the same for every panel):
 * 4 + 2 (pairs) exponentials per call instead of 2 per node. */
static double kd_quad(double c1m, double c1p, double beta, double X)
{
    const double a = 2.0 * (beta - 1.0);
    const double *xk = GL_X, *wk = GL_W;
    double cut = X, width, half, wc = 0.0, sum = 0.0, A, B, SA = 1.0, SB = 1.0;
    double ep[5], em[5], fp[5], fm[5];
    int np = 1, npairs = 5, i, k;
    if (beta < 1.0)  /* integrand <= 2 (c1m / c1p) e^{2 (beta - 1) x} and <= 2 e^{2 beta x} */
        cut = fmin(cut, (20.0 + 0.5 * log(fmax(c1m / c1p, 1.0))) / (1.0 - beta));
    if (beta < 0.0) cut = fmin(cut, 20.0 / -beta);
    if (!(cut > 0.0)) return 0.0;
    width = 1.0 / fmax(1.0, fabs(beta - 1.0));
    if (cut <= KD_NARROW * width) {  /* one narrow panel (the common small step): 5 points */
        xk = GL5_X;
        wk = GL5_W;
        npairs = 2;
        wc = GL5_W[2];
    } else {
        np = cut / width < KD_MAX_PANELS ? (int)ceil(cut / width) : KD_MAX_PANELS;
    }
    width = cut / np;
    half = 0.5 * width;
    for (k = 0; k < npairs; ++k) {
        ep[k] = exp(a * half * xk[k]);
        em[k] = 1.0 / ep[k];
        fp[k] = exp(-2.0 * half * xk[k]);
        fm[k] = 1.0 / fp[k];
    }
    A = exp(a * half);       /* e^{a x_c} and e^{-2 x_c} at the first centre */
    B = exp(-2.0 * half);
    if (np > 1) {
        SA = exp(a * width);
        SB = exp(-2.0 * width);
    }
    for (i = 0; i < np; ++i) {
        double s = wc > 0.0 ? wc * A / (c1p + c1m * B) : 0.0;
        for (k = 0; k < npairs; ++k)
            s += wk[k] * (A * em[k] / (c1p + c1m * B * fm[k]) + A * ep[k] / (c1p + c1m * B * fp[k]));
        sum += half * s;
        A *= SA;
        B *= SB;
    }
    return 2.0 * c1m * sum;
}

static void set_stick_jacobian(double *J)
{
    static const double stick[12] = {1, 0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0};
    memcpy(J, stick, sizeof stick);
}

/* D = 0: the radius shrinks below |e0|, the slider slips along e (radially). */
static double slider_radial(double *e, double rho0, double r1, double *J)
{
    const double ex = e[0] / rho0, ey = e[1] / rho0, g = r1 / rho0;
    e[0] = r1 * ex;
    e[1] = r1 * ey;
    if (J) {  /* d e1 = (r1/|e0|)(I - e^ e^T)(de0 + dd) + e^ dr1 (limit of a tiny d) */
        const double a = g * (1.0 - ex * ex), b = -g * ex * ey, c = g * (1.0 - ey * ey);
        const double row[12] = {a, b, a, b, 0, ex, b, c, b, c, 0, ey};
        memcpy(J, row, sizeof row);
    }
    return 0.5 * (rho0 - r1) * (rho0 + r1);
}

/* Derivative (P6) of the slip phase; the quantities of iwan2p_slider in `q`. */
typedef struct {
    double ex, ey, dx, dy, D, dr, s, esx, esy, rs, rho, ux, uy;
    double X, qx, dq, xr, E, omE, den, c1m, c1p, cos1, sin1, r1;
} slip_quantities;

static void slip_jacobian(const slip_quantities *q, double *J)
{
    double gs[6] = {0}, gex[6], gey[6], grs[6], gps[6] = {0}, gX[6] = {0}, gphi[6];
    const double om = 1.0 - q->s;
    const double hp = q->esx * q->dx + q->esy * q->dy - q->rs * q->dr;  /* h'(s*) / 2 */
    const double gD[6] = {0, 0, q->ux, q->uy, 0, 0};
    const double gpd[6] = {0, 0, -q->uy / q->D, q->ux / q->D, 0, 0};
    const double psi = 2.0 * q->E / q->den;
    const double ompsi = q->omE * (q->c1p - q->E * q->c1m) / q->den;
    const double e1x = q->cos1 * q->ux - q->sin1 * q->uy, e1y = q->cos1 * q->uy + q->sin1 * q->ux;
    int i;
    if (hp > 0.0) {  /* the exit point s* moves with the root of (P1) */
        const double dh[6] = {q->esx, q->esy, q->s * q->esx, q->s * q->esy, -q->rs * om,
                              -q->rs * q->s};
        for (i = 0; i < 6; ++i) gs[i] = -dh[i] / hp;
    }
    for (i = 0; i < 6; ++i) {
        gex[i] = (i == 0) + (i == 2) * q->s + q->dx * gs[i];
        gey[i] = (i == 1) + (i == 3) * q->s + q->dy * gs[i];
        grs[i] = (i == 4) * om + (i == 5) * q->s + q->dr * gs[i];
    }
    if (q->rho > 0.0)
        for (i = 0; i < 6; ++i)
            gps[i] = (q->esx * gey[i] - q->esy * gex[i]) / (q->rho * q->rho);
    if (isfinite(q->X)) {  /* X = om D Phi(r*, r1), Phi = q(x) / r*, x = (r1 - r*) / r* */
        const double Phi = q->qx / q->rs, Pa = -(q->qx + (1.0 + q->xr) * q->dq) / (q->rs * q->rs);
        const double Pb = q->dq / (q->rs * q->rs);
        for (i = 0; i < 6; ++i)
            gX[i] = Phi * (om * gD[i] - q->D * gs[i]) + om * q->D * (Pa * grs[i] + Pb * (i == 5));
    }
    for (i = 0; i < 6; ++i) gphi[i] = ompsi * gpd[i] + psi * gps[i] - q->sin1 * gX[i];
    for (i = 0; i < 6; ++i) {
        J[i] = e1x * (i == 5) - q->r1 * e1y * gphi[i];
        J[6 + i] = e1y * (i == 5) + q->r1 * e1x * gphi[i];
    }
}

double iwan2p_slider(double *e, const double *d, double r0, double r1, double *J, int *slipped)
{
    slip_quantities q;
    double rho0, A, B, C, sq, c, sn, Kd = 0.0, w;
    q.ex = e[0];
    q.ey = e[1];
    q.dx = d[0];
    q.dy = d[1];
    q.r1 = r1;
    rho0 = norm2(q.ex, q.ey);
    if (rho0 > r0) {  /* outside only by round-off: onto the circle */
        const double f = r0 > 0.0 ? r0 / rho0 : 0.0;
        q.ex *= f;
        q.ey *= f;
        rho0 = r0;
    }
    if ((q.ex + q.dx) * (q.ex + q.dx) + (q.ey + q.dy) * (q.ey + q.dy) <= r1 * r1) {  /* sticks */
        e[0] = q.ex + q.dx;
        e[1] = q.ey + q.dy;
        if (J) set_stick_jacobian(J);
        *slipped = 0;
        return 0.0;
    }
    *slipped = 1;
    q.D = norm2(q.dx, q.dy);
    if (q.D == 0.0) {
        e[0] = q.ex;
        e[1] = q.ey;
        return slider_radial(e, rho0, r1, J);
    }
    q.dr = r1 - r0;
    A = (q.D - q.dr) * (q.D + q.dr);                       /* (P1) */
    B = q.ex * q.dx + q.ey * q.dy - r0 * q.dr;
    C = fmin((rho0 - r0) * (rho0 + r0), 0.0);
    sq = sqrt(fmax(B * B - A * C, 0.0));
    q.s = B > 0.0 ? -C / (B + sq) : (A > 0.0 ? (sq - B) / A : 0.0);
    q.s = fmin(fmax(q.s, 0.0), 1.0);
    q.esx = q.ex + q.s * q.dx;
    q.esy = q.ey + q.s * q.dy;
    q.rs = r0 + q.s * q.dr;
    q.ux = q.dx / q.D;
    q.uy = q.dy / q.D;
    q.rho = norm2(q.esx, q.esy);
    c = 1.0;
    sn = 0.0;
    if (q.rho > 0.0) {  /* angle t* of e* to d (re-contact from r* = 0: along d) */
        c = fmin(fmax((q.esx * q.ux + q.esy * q.uy) / q.rho, -1.0), 1.0);
        sn = (q.esy * q.ux - q.esx * q.uy) / q.rho;
    }
    q.c1m = c > 0.0 ? sn * sn / (1.0 + c) : 1.0 - c;       /* 1 - c and 1 + c without */
    q.c1p = c < 0.0 ? sn * sn / (1.0 - c) : 1.0 + c;       /* cancellation */
    q.X = INFINITY;
    q.qx = q.dq = q.xr = 0.0;
    if (q.rs > 0.0 && r1 > 0.0) {                           /* (P2) */
        q.xr = (1.0 - q.s) * q.dr / q.rs;
        if (q.dr == 0.0) {  /* constant radius: q(0) = 1, q'(0) = -1/2 */
            q.qx = 1.0;
            q.dq = -0.5;
        } else {
            logq(q.xr, &q.qx, &q.dq);
        }
        q.X = (1.0 - q.s) * q.D * q.qx / q.rs;
    }
    q.E = exp(-q.X);
    q.omE = -expm1(-q.X);
    q.den = q.c1p + q.E * q.E * q.c1m;                      /* (P3) */
    if (q.den > 0.0) {
        q.cos1 = (q.c1p - q.E * q.E * q.c1m) / q.den;
        q.sin1 = 2.0 * q.E * sn / q.den;
    } else {  /* t* = pi and E = 0: only with r1 = 0, where e1 = 0 anyway */
        q.cos1 = 1.0;
        q.sin1 = 0.0;
        q.den = 1.0;
    }
    e[0] = r1 * (q.cos1 * q.ux - q.sin1 * q.uy);
    e[1] = r1 * (q.cos1 * q.uy + q.sin1 * q.ux);
    if (q.c1m > 0.0 && q.rs > 0.0) {                        /* (P5) */
        Kd = q.dr == 0.0 ? log1p(-expm1(-2.0 * q.X) * q.c1m / q.den)
                         : kd_quad(q.c1m, q.c1p, q.dr / q.D, q.X);
        Kd *= q.rs * q.rs;
    }
    w = 0.5 * (1.0 - q.s) * (q.D - q.dr) * (q.rs + r1) - Kd;  /* (P4) */
    if (J) slip_jacobian(&q, J);
    return w > 0.0 ? w : 0.0;
}

/* ----------------------------------------------------------- element update */

/* S <- J_e S + J_d Dd + J_r0 g0 + J_r1 g1 for one slider (2 x nc, row-major). */
static void sens_update(const double *J, double *S, const double *Dd, const double *g0,
                        const double *g1, size_t nc)
{
    size_t c;
    for (c = 0; c < nc; ++c) {
        const double sx = S[c], sy = S[nc + c], ddx = Dd[c], ddy = Dd[nc + c];
        S[c] = J[0] * sx + J[1] * sy + J[2] * ddx + J[3] * ddy + J[4] * g0[c] + J[5] * g1[c];
        S[nc + c] = J[6] * sx + J[7] * sy + J[8] * ddx + J[9] * ddy + J[10] * g0[c]
                    + J[11] * g1[c];
    }
}

/* Scratch layout of a step with sensitivities: Dd = d(u1 - u0)/dX (2 nc), g0, g1 =
 * d f(N0)/dX, d f(N1)/dX (nc each), then rad_j g0, rad_j g1 of the slider at hand. */
#define SCR_DD(sn) ((sn)->scratch)
#define SCR_G0(sn) ((sn)->scratch + 2 * (sn)->nc)
#define SCR_G1(sn) ((sn)->scratch + 3 * (sn)->nc)
#define SCR_R0(sn) ((sn)->scratch + 4 * (sn)->nc)
#define SCR_R1(sn) ((sn)->scratch + 5 * (sn)->nc)

/* Every slider along the straight path from u0 by d to u1 (= u0 + d, given exactly),
 * strength factor f0 -> f1; sens (may be NULL) with Dd, g0, g1 in its scratch. Returns
 * the friction work. */
static double sliders_path(const iwan_model *m, iwan2_state *s, const double *u0,
                           const double *d, const double *u1, double f0, double f1,
                           iwan2_sens *sens)
{
    double w = 0.0, J[12];
    int32_t j;
    for (j = 0; j < m->n; ++j) {
        double e[2];
        int slipped;
        e[0] = u0[0] - s->z[2 * j];
        e[1] = u0[1] - s->z[2 * j + 1];
        w += m->k[j] * iwan2p_slider(e, d, m->rad[j] * f0, m->rad[j] * f1, sens ? J : NULL,
                                     &slipped);
        s->z[2 * j] = u1[0] - e[0];
        s->z[2 * j + 1] = u1[1] - e[1];
        if (sens) {
            double *gr0 = SCR_R0(sens), *gr1 = SCR_R1(sens);
            size_t c;
            for (c = 0; c < sens->nc; ++c) {
                gr0[c] = m->rad[j] * SCR_G0(sens)[c];
                gr1[c] = m->rad[j] * SCR_G1(sens)[c];
            }
            sens_update(J, sens->S + 2 * sens->nc * (size_t)j, SCR_DD(sens), gr0, gr1, sens->nc);
        }
    }
    return w;
}

static void release(const iwan_model *m, iwan2_state *s, double ux, double uy, iwan2_sens *sens)
{
    int32_t j;
    for (j = 0; j < m->n; ++j) {
        s->z[2 * j] = ux;
        s->z[2 * j + 1] = uy;
    }
    s->u_contact[0] = ux;
    s->u_contact[1] = uy;
    s->in_contact = 0;
    if (sens) {
        memset(sens->S, 0, 2 * sens->nc * (size_t)m->n * sizeof(double));
        memset(sens->S_res, 0, 2 * sens->nc * sizeof(double));
    }
}

/* v[c] of an optional array (NULL: 0). */
static double at(const double *v, size_t c)
{
    return v ? v[c] : 0.0;
}

/* Re-contact in the step (N0 <= 0 < N1) at s_c = -N0 / (N1 - N0): virgin at
 * u_c = u0 + s_c d, then the rest of the path with the radius growing from 0. With
 * sensitivities, d u_c = du0 + s_c (du1 - du0) + d ds_c, ds_c = (N0 dN1 - N1 dN0) /
 * (N1 - N0)^2; the remaining path moves with du1 - du_c. */
static double recontact(const iwan_model *m, iwan2_state *s, const double *u0, const double *d,
                        const double *u1, double N0, double N1, iwan2_sens *sens)
{
    const double sc = -N0 / (N1 - N0);
    const double uc[2] = {u0[0] + sc * d[0], u0[1] + sc * d[1]};
    const double rest[2] = {u1[0] - uc[0], u1[1] - uc[1]};
    int32_t j;
    for (j = 0; j < m->n; ++j) {
        s->z[2 * j] = uc[0];
        s->z[2 * j + 1] = uc[1];
    }
    s->u_contact[0] = uc[0];
    s->u_contact[1] = uc[1];
    s->in_contact = 1;
    if (sens) {
        const size_t nc = sens->nc;
        size_t c;
        int r;
        memset(sens->S, 0, 2 * nc * (size_t)m->n * sizeof(double));
        for (c = 0; c < nc; ++c) {
            const double dsc = (N0 * at(sens->gN1, c) - N1 * at(sens->gN0, c))
                               / ((N1 - N0) * (N1 - N0));
            for (r = 0; r < 2; ++r) {
                const double du0 = at(sens->Du0, r * nc + c), du1 = at(sens->Du1, r * nc + c);
                const double duc = du0 + sc * (du1 - du0) + d[r] * dsc;
                SCR_DD(sens)[r * nc + c] = du1 - duc;
                sens->S_res[r * nc + c] = du1 - duc;
            }
            SCR_G0(sens)[c] = 0.0;
        }
    }
    return sliders_path(m, s, uc, rest, u1, 0.0, strength_factor(m, N1), sens);
}

void iwan2p_advance(const iwan_model *m, iwan2_state *s, double ux, double uy, double N1,
                    iwan2_sens *sens)
{
    const double u0[2] = {s->u[0], s->u[1]}, u1[2] = {ux, uy};
    const double d[2] = {ux - u0[0], uy - u0[1]}, N0 = s->N, dfdN = m->scale / m->n_ref;
    if (sens) {  /* the step's derivative inputs, in the scratch */
        const size_t nc = sens->nc;
        size_t c;
        for (c = 0; c < 2 * nc; ++c) SCR_DD(sens)[c] = at(sens->Du1, c) - at(sens->Du0, c);
        for (c = 0; c < nc; ++c) {
            SCR_G0(sens)[c] = dfdN * at(sens->gN0, c);
            SCR_G1(sens)[c] = dfdN * at(sens->gN1, c);
        }
    }
    if (N0 > 0.0 && N1 > 0.0) {
        s->w_diss += sliders_path(m, s, u0, d, u1, strength_factor(m, N0),
                                  strength_factor(m, N1), sens);
        if (sens) {
            size_t c;
            for (c = 0; c < 2 * sens->nc; ++c) sens->S_res[c] += SCR_DD(sens)[c];
        }
    } else if (N0 > 0.0) {                 /* lift-off where N = 0, then released */
        const double sl = N0 / (N0 - N1);
        const double dl[2] = {sl * d[0], sl * d[1]}, ul[2] = {u0[0] + dl[0], u0[1] + dl[1]};
        s->w_diss += sliders_path(m, s, u0, dl, ul, strength_factor(m, N0), 0.0, NULL);
        release(m, s, ux, uy, sens);
    } else if (N1 > 0.0) {
        s->w_diss += recontact(m, s, u0, d, u1, N0, N1, sens);
    } else {
        release(m, s, ux, uy, sens);
    }
    if (d[0] != 0.0 || d[1] != 0.0) {
        const double D = norm2(d[0], d[1]);
        s->dir[0] = d[0] / D;
        s->dir[1] = d[1] / D;
    }
    s->u[0] = ux;
    s->u[1] = uy;
    s->N = N1;
}

/* ----------------------------------------------------------------- outputs */

/* Tangent for continued motion along dir of one slider with stretch (ex, ey) and
 * radius r, added to K and dFdN; returns 1 if it counts as slipping. */
static int continued_tangent(const iwan_model *m, int32_t j, double ex, double ey, double r,
                             const double *dir, double *K, double *dFdN, int want)
{
    const double k = m->k[j], rho = norm2(ex, ey);
    const int slipping = r == 0.0 || (rho >= r * (1.0 - IWAN2_SLIP_RTOL)
                                      && ex * dir[0] + ey * dir[1] > 0.0);
    if (!want) return slipping;
    if (!slipping) {
        K[0] += k;
        K[3] += k;
    } else if (rho > 0.0) {  /* k (I - e e^T / |e|^2); dF/dN when N decreases */
        const double nx = ex / rho, ny = ey / rho, g = m->fs[j] * (m->scale / m->n_ref);
        K[0] += k * (1.0 - nx * nx);
        K[1] -= k * nx * ny;
        K[2] -= k * nx * ny;
        K[3] += k * (1.0 - ny * ny);
        dFdN[0] += g * nx;
        dFdN[1] += g * ny;
    }
    return slipping;
}

void iwan2p_outputs(const iwan_model *m, const iwan2_state *s, const iwan2_sens *sens,
                    iwan2_output *o)
{
    const double f = strength_factor(m, s->N);
    const double rx = s->u[0] - s->u_contact[0], ry = s->u[1] - s->u_contact[1];
    double fsl = 0.0;
    int32_t j;
    memset(o, 0, sizeof *o);
    o->W = s->w_diss;
    if (!s->in_contact) {
        o->slip = 1.0;
        return;
    }
    o->F[0] = m->k_res * rx;
    o->F[1] = m->k_res * ry;
    o->E = 0.5 * m->k_res * (rx * rx + ry * ry);
    if (!sens) {
        o->K[0] = o->K[3] = m->k_res;
    }
    for (j = 0; j < m->n; ++j) {
        const double ex = s->u[0] - s->z[2 * j], ey = s->u[1] - s->z[2 * j + 1], k = m->k[j];
        o->F[0] += k * ex;
        o->F[1] += k * ey;
        o->E += 0.5 * k * (ex * ex + ey * ey);
        if (continued_tangent(m, j, ex, ey, m->rad[j] * f, s->dir, o->K, o->dFdN, !sens))
            fsl += m->fs[j];
    }
    if (sens) {  /* exact tangent of the step: dF/dX = sum k_j S_j + k_res S_res, X = (ux, uy, N) */
        int r, c;
        for (r = 0; r < 2; ++r)
            for (c = 0; c < 3; ++c) {
                double v = m->k_res * sens->S_res[3 * r + c];
                for (j = 0; j < m->n; ++j) v += m->k[j] * sens->S[6 * j + 3 * r + c];
                if (c < 2) o->K[2 * r + c] = v;
                else o->dFdN[r] = v;
            }
    }
    o->slip = (m->fs_sum > 0.0 && f > 0.0) ? fsl / m->fs_sum : 1.0;
}

/* ------------------------------------------------------------ checks, API */

iwan_status iwan2p_check_state(const iwan2_state *s)
{
    if (!s) return IWAN_ERR_BAD_PARAM;
    if (s->version != IWAN2_STATE_VERSION || (s->in_contact != 0 && s->in_contact != 1))
        return IWAN_ERR_BAD_STATE;
    if (!isfinite(s->u[0]) || !isfinite(s->u[1]) || !isfinite(s->N) || !isfinite(s->w_diss)
        || !isfinite(s->u_contact[0]) || !isfinite(s->u_contact[1]))
        return IWAN_ERR_BAD_STATE;
    if ((s->in_contact == 1) != (s->N > 0.0) || s->w_diss < 0.0) return IWAN_ERR_BAD_STATE;
    if (!(fabs(norm2(s->dir[0], s->dir[1]) - 1.0) <= 1e-12)) return IWAN_ERR_BAD_STATE;
    return IWAN_OK;
}

void iwan2p_copy(iwan2_state *dst, const iwan2_state *src, int32_t n)
{
    memcpy(dst, src, offsetof(iwan2_state, z) + 2 * (size_t)n * sizeof(double));
}

iwan_status iwan2_state_init(const iwan_model *model, iwan2_state *state, double N)
{
    iwan_status st = iwanp_check_model(model);
    if (st != IWAN_OK) return st;
    if (!state) return IWAN_ERR_BAD_PARAM;
    if (!isfinite(N)) return IWAN_ERR_NONFINITE;
    memset(state, 0, sizeof *state);
    state->version = IWAN2_STATE_VERSION;
    state->in_contact = N > 0.0;
    state->N = N;
    state->dir[0] = 1.0;
    return IWAN_OK;
}

/* The update of iwan2_step / iwan2_eval on checked arguments: with an output, the
 * step's exact tangent (sensitivities to the end point; a zero step: continued motion). */
static void step_checked(const iwan_model *m, iwan2_state *s, double ux, double uy, double N,
                         iwan2_output *out)
{
    static const double DU1[6] = {1, 0, 0, 0, 1, 0}, GN1[3] = {0, 0, 1};
    double S[6 * IWAN_MAX_SLIDERS], S_res[6] = {0}, scratch[18];
    iwan2_sens sens;
    if (!out) {
        iwan2p_advance(m, s, ux, uy, N, NULL);
        return;
    }
    if (ux == s->u[0] && uy == s->u[1] && N == s->N) {  /* zero step: continued motion */
        iwan2p_outputs(m, s, NULL, out);
        return;
    }
    memset(S, 0, 6 * (size_t)m->n * sizeof(double));
    sens.nc = 3;
    sens.S = S;
    sens.S_res = S_res;
    sens.Du0 = NULL;
    sens.Du1 = DU1;
    sens.gN0 = NULL;
    sens.gN1 = GN1;
    sens.scratch = scratch;
    iwan2p_advance(m, s, ux, uy, N, &sens);
    iwan2p_outputs(m, s, &sens, out);
}

static iwan_status check_call(const iwan_model *m, const iwan2_state *s, double ux, double uy,
                              double N)
{
    iwan_status st = iwanp_check_model(m);
    if (st != IWAN_OK) return st;
    st = iwan2p_check_state(s);
    if (st != IWAN_OK) return st;
    if (!isfinite(ux) || !isfinite(uy) || !isfinite(N)) return IWAN_ERR_NONFINITE;
    return IWAN_OK;
}

iwan_status iwan2_eval(const iwan_model *model, const iwan2_state *committed, double ux,
                       double uy, double N, iwan2_state *trial, iwan2_output *out)
{
    iwan2_state local;
    iwan_status st = check_call(model, committed, ux, uy, N);
    if (st != IWAN_OK) return st;
    if (trial == committed) return IWAN_ERR_BAD_PARAM;
    if (!trial) trial = &local;
    if (trial != &local) memset(trial, 0, sizeof *trial);  /* unused sliders stay zero */
    iwan2p_copy(trial, committed, model->n);
    step_checked(model, trial, ux, uy, N, out);
    return IWAN_OK;
}

iwan_status iwan2_step(const iwan_model *model, iwan2_state *state, double ux, double uy,
                       double N, iwan2_output *out)
{
    iwan_status st = check_call(model, state, ux, uy, N);
    if (st != IWAN_OK) return st;
    step_checked(model, state, ux, uy, N, out);
    return IWAN_OK;
}

iwan_status iwan2_series(const iwan_model *model, iwan2_state *state, size_t n,
                         const double *ux, const double *uy, const double *N,
                         double *F, double *W)
{
    size_t i;
    iwan_status st = check_call(model, state, 0.0, 0.0, 0.0);
    if (st != IWAN_OK) return st;
    if (!ux || !uy || n == 0) return IWAN_ERR_BAD_PARAM;
    if (iwanp_check_finite(ux, n) || iwanp_check_finite(uy, n) || (N && iwanp_check_finite(N, n)))
        return IWAN_ERR_NONFINITE;
    for (i = 0; i < n; ++i) {
        iwan2p_advance(model, state, ux[i], uy[i], N ? N[i] : model->n_ref, NULL);
        if (F) {
            iwan2_output o;
            iwan2p_outputs(model, state, NULL, &o);
            F[2 * i] = o.F[0];
            F[2 * i + 1] = o.F[1];
        }
        if (W) W[i] = state->w_diss;
    }
    return IWAN_OK;
}
