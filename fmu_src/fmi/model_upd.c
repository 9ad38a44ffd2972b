/* model_upd.c -- the model hooks (model.h) of an underplatform damper between two platforms.
 *
 * A rigid planar damper q = (x_d, y_d, theta_d) with its mass M = diag(m_d, m_d, I_d),
 * the centrifugal load CF on y_d, and n_c contact points (fmu_src/upd_fmu.py writes them
 * from the same UPD description as `damper upd`: harmonic_balance.bladed_disk). Contact
 * c touches one platform point P (side 0: blade j's, side 1: blade j+1's), whose (u, v)
 * displacement is an input. Its slip and penetration are rows of the sector's contact
 * kinematics, s = Qs_d . q + Qs_p . P, p = Qp_d . q + Qp_p . P; its law is that of
 * harmonic_balance.contact.ContactElement:
 *     N = k_n max(p, 0)                                                  (C1)
 *     f_t = Iwan element (the C core) at slip s - s_0, normal load k_n p  (C2)
 *           (unclamped: the core treats N <= 0 as lift-off)
 *     + dashpots beta_c k_t s' and beta_c k_n p' (always on)             (C3)
 * The local force f = [f_t + c_t s', N + c_n p'] acts as -Qd^T f on the damper and
 * -Qp^T f on the platform point (virtual work of the contact's energy).
 *
 * Over a communication step [t, t + h] each platform point moves on the straight line
 * P + P' (s - t) of its inputs (their values and velocities at t). The damper is
 * integrated by velocity Verlet (central differences) in substeps dt = h / ceil(h /
 * dt_max), dt_max below the stability limit of the damper on its stuck contacts
 * (written by the builder), the dashpots implicit (linear):
 *     v+ = v + dt/2 a;  q' = q + dt v+;  contacts at q' (one core step each);
 *     (M + dt/2 C_dd) v' = M v+ + dt/2 (f_ext - Qd^T f_el - C_dp P');  a' = 2 (v' - v+) / dt.
 * Outputs at t + h: the forces on the two platform points and their rates over the step
 * (secant: (F(t + h) - F(t)) / h, the first-order hold the blades use on the next
 * step), the damper's position, the normal loads, and the energies: friction W (the
 * core's), dashpots (trapezoid per substep), the work of the platforms on the damper
 * (trapezoid of f . Qp P'), and its energy (kinetic + contact springs + the core's
 * stored energy - CF (y_d - y_d,0)), so W_platforms = W_friction + W_dashpots +
 * (energy - energy at the start) up to the O(dt^2) of the trapezoids.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_vars.h"
#include "iwan.h"
#include "model.h"
#include "model_table.h"

#define UPD_FILE "upd.txt"
#define MAX_CONTACTS 8
#define MAX_SUBSTEPS 1000000   /* a step needing more substeps is refused */
#define N_FORCES 8             /* F_left_x, rate, F_left_y, rate, F_right_x, ... */
/* Output positions after the forces: x_d, y_d, theta_d, N per contact, then energies. */
#define OUT_Q 8
#define OUT_N 11

typedef struct {
    int side;                  /* 0: blade j's platform point (left), 1: blade j+1's */
    double Qs_d[3], Qs_p[2];   /* slip row [m/m, m/rad] */
    double Qp_d[3], Qp_p[2];   /* penetration row */
    double kn, kt, beta_c;     /* [N/m], [N/m], [s] */
    double s0;                 /* slip where the sliders are virgin (prestress) [m] */
    iwan_model law;
} upd_contact;

typedef struct {
    double M[3];               /* m_d, m_d, I_d [kg, kg, kg m^2] */
    double dt_max;             /* largest substep [s] */
    int nc;
    upd_contact c[MAX_CONTACTS];
    double q0[3];              /* initial (prestress) position [m, m, rad] */
} upd_res;

typedef struct {
    const upd_res *r;
    double cf;                 /* centrifugal load on y_d [N] */
} upd_model;

typedef struct {
    double q[3], v[3], a[3];   /* damper position, velocity, acceleration */
    double F[4];               /* forces on the platform points at the last point [N] */
    double Fdot[4];            /* their rates over the last step [N/s] */
    double N[MAX_CONTACTS];    /* normal loads at the last point [N] */
    double W_dash, W_plat;     /* cumulative [J] */
    double P_dash, P_plat;     /* dashpot and platform power at the last point [W] */
    double E0;                 /* energy at the start [J] */
    double y0;                 /* y_d at the start [m] */
    iwan_state s[MAX_CONTACTS];
} upd_history;

/* ------------------------------------------------------------ resources */
static int read_n(FILE *f, double *v, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (fscanf(f, "%lf", &v[i]) != 1 || !isfinite(v[i])) return 0;
    return 1;
}

static const char *read_contact(FILE *f, upd_contact *c)
{
    double k[IWAN_MAX_SLIDERS], fs[IWAN_MAX_SLIDERS], k_res, n_ref, scale;
    int n, j;
    if (fscanf(f, " contact %d", &c->side) != 1 || (c->side != 0 && c->side != 1)
        || !read_n(f, c->Qs_d, 3) || !read_n(f, c->Qs_p, 2) || !read_n(f, c->Qp_d, 3)
        || !read_n(f, c->Qp_p, 2) || !read_n(f, &c->kn, 1) || !read_n(f, &c->kt, 1)
        || !read_n(f, &c->beta_c, 1) || !read_n(f, &c->s0, 1))
        return "bad contact line";
    if (!(c->kn > 0.0) || !(c->kt >= 0.0) || !(c->beta_c >= 0.0)) return "contact stiffness <= 0";
    if (fscanf(f, " law %d", &n) != 1 || n < 0 || n > IWAN_MAX_SLIDERS || !read_n(f, &k_res, 1)
        || !read_n(f, &n_ref, 1) || !read_n(f, &scale, 1))
        return "bad friction law line";
    for (j = 0; j < n; j++)
        if (!read_n(f, &k[j], 1) || !read_n(f, &fs[j], 1)) return "bad slider line";
    if (iwan_model_from_sliders(&c->law, k, fs, (size_t)n, k_res, n_ref) != IWAN_OK)
        return "friction law refused by the core";
    if (!(scale >= 0.0)) return "friction scale < 0";
    c->law.scale = scale;
    return NULL;
}

static const char *read_upd(upd_res *r, FILE *f, char *why, size_t nw)
{
    int version = 0, i;
    const char *err;
    if (fscanf(f, " damper-upd %d mass", &version) != 1 || version != 1 || !read_n(f, r->M, 3)
        || fscanf(f, " dt_max") != 0 || !read_n(f, &r->dt_max, 1)
        || fscanf(f, " q0") != 0 || !read_n(f, r->q0, 3)
        || fscanf(f, " contacts %d", &r->nc) != 1)
        return "not a damper-upd 1 file";
    if (!(r->M[0] > 0.0 && r->M[1] > 0.0 && r->M[2] > 0.0) || !(r->dt_max > 0.0))
        return "mass or dt_max not > 0";
    if (r->nc < 1 || r->nc > MAX_CONTACTS || OUT_N + r->nc + 4 != DAMPER_N_OUTPUTS) {
        snprintf(why, nw, "%d contacts do not fit this interface (%d outputs)", r->nc,
                 DAMPER_N_OUTPUTS);
        return why;
    }
    for (i = 0; i < r->nc; i++)
        if ((err = read_contact(f, &r->c[i])) != NULL) {
            snprintf(why, nw, "contact %d: %s", i, err);
            return why;
        }
    return NULL;
}

void model_unload(void *res) { free(res); }

const char *model_load(void **res, const char *dir, char *why, size_t why_size)
{
    upd_res *r = (upd_res *)calloc(1, sizeof(upd_res));
    const char *err;
    FILE *f;
    *res = NULL;
    if (!r) return "out of memory reading the damper";
    f = model_open_resource(dir, UPD_FILE, "damper", why, why_size);
    err = f ? read_upd(r, f, why, why_size) : why;
    if (f) fclose(f);
    if (err) {
        free(r);
        return err;
    }
    *res = r;
    return NULL;
}

size_t model_size(const void *res) { (void)res; return sizeof(upd_model); }
size_t model_history_size(const void *res) { (void)res; return sizeof(upd_history); }

double model_start(const void *res, unsigned int vr)
{
    (void)res;
    return damper_start_value[vr];  /* rule "value": the variable table's number */
}

const char *model_check_parameter(const void *res, unsigned int vr, double v)
{
    (void)res;
    if (vr == VR_CF && !(v >= 0.0)) return "CF must be >= 0";
    return isfinite(v) ? NULL : "parameter not finite";
}

/* The header and, per contact, the sliders in use (the rest of z stays zero). */
void model_copy_history(const void *model, void *dst, const void *src)
{
    const upd_res *r = ((const upd_model *)model)->r;
    upd_history *d = (upd_history *)dst;
    const upd_history *s = (const upd_history *)src;
    int i;
    memcpy(d, s, offsetof(upd_history, s));
    for (i = 0; i < r->nc; i++) {
        memcpy(&d->s[i], &s->s[i],
               offsetof(iwan_state, z) + (size_t)r->c[i].law.n * sizeof(double));
        d->s[i].dir = s->s[i].dir;
    }
}

const char *model_build(void *model, const void *res, const double *value)
{
    upd_model *md = (upd_model *)model;
    md->r = (const upd_res *)res;
    md->cf = value[VR_CF];
    return NULL;
}

/* ------------------------------------------------------------ physics */
typedef struct {
    double P[2][2];            /* platform point positions (u, v) per side */
    double V[2][2];            /* their velocities */
} platforms;

static void platforms_at(const double *value, platforms *p)
{
    p->P[0][0] = value[VR_Q_LEFT_X]; p->P[0][1] = value[VR_Q_LEFT_Y];
    p->P[1][0] = value[VR_Q_RIGHT_X]; p->P[1][1] = value[VR_Q_RIGHT_Y];
    p->V[0][0] = value[VR_V_LEFT_X]; p->V[0][1] = value[VR_V_LEFT_Y];
    p->V[1][0] = value[VR_V_RIGHT_X]; p->V[1][1] = value[VR_V_RIGHT_Y];
}

static double dot(const double *a, const double *b, int n)
{
    double s = 0.0;
    int i;
    for (i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

/* The contacts at a point: the elastic part (one core update of each element, committed
 * or evaluated), then the forces with the dashpots at the velocities v, V. */
typedef struct {
    double ft[MAX_CONTACTS], N[MAX_CONTACTS];  /* friction and normal forces [N] */
    double f_el[3];            /* elastic generalized force on the damper (Qd^T [f_t, N]) */
    double E_el;               /* contact springs + the elements' stored energy [J] */
    double F[4];               /* forces on the platform points, dashpots included [N] */
    double P_dash, P_plat;     /* dashpot power, power of the platforms on the damper [W] */
} contact_out;

static const char *contacts_elastic(const upd_res *r, iwan_state *st, const double *q,
                                    const double P[2][2], int commit, contact_out *o)
{
    int i, k;
    memset(o->f_el, 0, sizeof o->f_el);
    o->E_el = 0.0;
    for (i = 0; i < r->nc; i++) {
        const upd_contact *c = &r->c[i];
        const double s = dot(c->Qs_d, q, 3) + dot(c->Qs_p, P[c->side], 2);
        const double p = dot(c->Qp_d, q, 3) + dot(c->Qp_p, P[c->side], 2);
        iwan_output out;
        iwan_status status = commit ? iwan_step(&c->law, &st[i], s - c->s0, c->kn * p, &out)
                                    : iwan_eval(&c->law, &st[i], s - c->s0, c->kn * p, NULL, &out);
        if (status != IWAN_OK) return iwan_status_text(status);
        o->N[i] = c->kn * fmax(p, 0.0);
        o->ft[i] = out.F;
        for (k = 0; k < 3; k++) o->f_el[k] += c->Qs_d[k] * o->ft[i] + c->Qp_d[k] * o->N[i];
        o->E_el += 0.5 * o->N[i] * fmax(p, 0.0) + out.E;
    }
    return NULL;
}

static void contacts_forces(const upd_res *r, const double *v, const double V[2][2],
                            contact_out *o)
{
    int i, k;
    memset(o->F, 0, sizeof o->F);
    o->P_dash = o->P_plat = 0.0;
    for (i = 0; i < r->nc; i++) {
        const upd_contact *c = &r->c[i];
        const double *Vc = V[c->side];
        const double sd = dot(c->Qs_d, v, 3) + dot(c->Qs_p, Vc, 2);
        const double pd = dot(c->Qp_d, v, 3) + dot(c->Qp_p, Vc, 2);
        const double ct = c->beta_c * c->kt, cn = c->beta_c * c->kn;
        const double ft = o->ft[i] + ct * sd, fn = o->N[i] + cn * pd;
        for (k = 0; k < 2; k++) o->F[2 * c->side + k] -= c->Qs_p[k] * ft + c->Qp_p[k] * fn;
        o->P_dash += ct * sd * sd + cn * pd * pd;
        o->P_plat += ft * dot(c->Qs_p, Vc, 2) + fn * dot(c->Qp_p, Vc, 2);
    }
}

/* Dashpot matrices: C_dd (3x3) on the damper's velocity and C_dp V (3) of the platforms. */
static void dashpots(const upd_res *r, const double V[2][2], double Cdd[9], double CdpV[3])
{
    int i, a, b;
    memset(Cdd, 0, 9 * sizeof(double));
    memset(CdpV, 0, 3 * sizeof(double));
    for (i = 0; i < r->nc; i++) {
        const upd_contact *c = &r->c[i];
        const double ct = c->beta_c * c->kt, cn = c->beta_c * c->kn;
        const double sp = dot(c->Qs_p, V[c->side], 2), pp = dot(c->Qp_p, V[c->side], 2);
        for (a = 0; a < 3; a++) {
            for (b = 0; b < 3; b++)
                Cdd[3 * a + b] += ct * c->Qs_d[a] * c->Qs_d[b] + cn * c->Qp_d[a] * c->Qp_d[b];
            CdpV[a] += ct * c->Qs_d[a] * sp + cn * c->Qp_d[a] * pp;
        }
    }
}

/* Solve the 3x3 system A x = b (Cramer: A is symmetric positive definite here). */
static void solve3(const double A[9], const double b[3], double x[3])
{
    const double c0 = A[4] * A[8] - A[5] * A[7], c1 = A[5] * A[6] - A[3] * A[8],
                 c2 = A[3] * A[7] - A[4] * A[6];
    const double det = A[0] * c0 + A[1] * c1 + A[2] * c2;
    x[0] = (b[0] * c0 + b[1] * (A[2] * A[7] - A[1] * A[8]) + b[2] * (A[1] * A[5] - A[2] * A[4])) / det;
    x[1] = (b[0] * c1 + b[1] * (A[0] * A[8] - A[2] * A[6]) + b[2] * (A[2] * A[3] - A[0] * A[5])) / det;
    x[2] = (b[0] * c2 + b[1] * (A[1] * A[6] - A[0] * A[7]) + b[2] * (A[0] * A[4] - A[1] * A[3])) / det;
}

static double energy(const upd_model *md, const upd_history *hs, double E_el)
{
    const double *M = md->r->M;
    return 0.5 * (M[0] * hs->v[0] * hs->v[0] + M[1] * hs->v[1] * hs->v[1]
                  + M[2] * hs->v[2] * hs->v[2]) + E_el - md->cf * (hs->q[1] - hs->y0);
}

static void store(const upd_model *md, const upd_history *hs, double E_el, double *out)
{
    int i;
    double W = 0.0;
    out[VR_F_LEFT_X] = hs->F[0]; out[VR_F_LEFT_Y] = hs->F[1];
    out[VR_F_RIGHT_X] = hs->F[2]; out[VR_F_RIGHT_Y] = hs->F[3];
    out[VR_F_LEFT_X_RATE] = hs->Fdot[0]; out[VR_F_LEFT_Y_RATE] = hs->Fdot[1];
    out[VR_F_RIGHT_X_RATE] = hs->Fdot[2]; out[VR_F_RIGHT_Y_RATE] = hs->Fdot[3];
    out[VR_X_D] = hs->q[0]; out[VR_Y_D] = hs->q[1]; out[VR_THETA_D] = hs->q[2];
    for (i = 0; i < md->r->nc; i++) {
        out[damper_outputs[OUT_N + i]] = hs->N[i];
        W += hs->s[i].w_diss;
    }
    out[VR_W_FRICTION] = W;
    out[VR_W_DASHPOTS] = hs->W_dash;
    out[VR_W_PLATFORMS] = hs->W_plat;
    out[VR_ENERGY] = energy(md, hs, E_el) - hs->E0;
}

const char *model_reset(const void *model, void *history, const double *value)
{
    const upd_model *md = (const upd_model *)model;
    const upd_res *r = md->r;
    upd_history *hs = (upd_history *)history;
    platforms pl;
    contact_out o;
    double rhs[3];
    const char *why;
    int i;
    memset(hs, 0, sizeof *hs);
    platforms_at(value, &pl);
    memcpy(hs->q, r->q0, sizeof hs->q);
    hs->y0 = r->q0[1];
    for (i = 0; i < r->nc; i++) {  /* virgin sliders (at s = s_0) under the start's load */
        const upd_contact *c = &r->c[i];
        const double p = dot(c->Qp_d, hs->q, 3) + dot(c->Qp_p, pl.P[c->side], 2);
        iwan_status st = iwan_state_init(&c->law, &hs->s[i], c->kn * p);
        if (st != IWAN_OK) return iwan_status_text(st);
    }
    why = contacts_elastic(r, hs->s, hs->q, pl.P, 0, &o);
    if (why) return why;
    contacts_forces(r, hs->v, pl.V, &o);
    rhs[0] = -o.f_el[0]; rhs[1] = md->cf - o.f_el[1]; rhs[2] = -o.f_el[2];
    for (i = 0; i < 3; i++) hs->a[i] = rhs[i] / r->M[i];
    memcpy(hs->F, o.F, sizeof hs->F);
    memcpy(hs->N, o.N, sizeof hs->N);
    hs->E0 = 0.0;
    hs->E0 = energy(md, hs, o.E_el);
    hs->P_dash = o.P_dash;
    hs->P_plat = o.P_plat;
    return NULL;
}

const char *model_eval(const void *model, const void *history, const double *value, double *out)
{
    const upd_model *md = (const upd_model *)model;
    const upd_history *hs = (const upd_history *)history;
    double E_el = 0.0;
    int i;
    (void)value;
    for (i = 0; i < md->r->nc; i++) {  /* the elastic energy of the committed point */
        const upd_contact *c = &md->r->c[i];
        iwan_output o;
        if (iwan_eval(&c->law, &hs->s[i], hs->s[i].u, hs->s[i].N, NULL, &o) != IWAN_OK)
            return "bad element history";
        E_el += 0.5 * hs->N[i] * hs->N[i] / c->kn + o.E;
    }
    store(md, hs, E_el, out);
    return NULL;
}

const char *model_step(const void *model, void *history, const double *start,
                       const double *end, double t, double h, double *out)
{
    const upd_model *md = (const upd_model *)model;
    const upd_res *r = md->r;
    upd_history *hs = (upd_history *)history;
    const double fext[3] = {0.0, md->cf, 0.0};
    double Cdd[9], CdpV[3], A[9], dt, steps_d;
    double F_start[4];
    platforms pl, at;
    contact_out o;
    long steps, k;
    int i, j;
    (void)end; (void)t;  /* inputs held with their velocity inputs */
    platforms_at(start, &pl);
    steps_d = ceil(h / r->dt_max);
    if (!(steps_d <= MAX_SUBSTEPS)) return "step too long for the damper's substeps";
    steps = (long)steps_d;
    dt = h / (double)steps;
    dashpots(r, pl.V, Cdd, CdpV);
    for (i = 0; i < 9; i++) A[i] = 0.5 * dt * Cdd[i];
    for (i = 0; i < 3; i++) A[4 * i] += r->M[i];
    memcpy(F_start, hs->F, sizeof F_start);
    at = pl;
    memset(&o, 0, sizeof o);
    for (k = 1; k <= steps; k++) {
        double vh[3], rhs[3];
        const char *why;
        const double tau = (double)k * dt;
        for (i = 0; i < 3; i++) {
            vh[i] = hs->v[i] + 0.5 * dt * hs->a[i];
            hs->q[i] += dt * vh[i];
        }
        for (j = 0; j < 2; j++)
            for (i = 0; i < 2; i++) at.P[j][i] = pl.P[j][i] + pl.V[j][i] * tau;
        why = contacts_elastic(r, hs->s, hs->q, at.P, 1, &o);
        if (why) return why;
        for (i = 0; i < 3; i++)
            rhs[i] = r->M[i] * vh[i] + 0.5 * dt * (fext[i] - o.f_el[i] - CdpV[i]);
        solve3(A, rhs, hs->v);
        for (i = 0; i < 3; i++) hs->a[i] = 2.0 * (hs->v[i] - vh[i]) / dt;
        contacts_forces(r, hs->v, at.V, &o);  /* dashpots at the end velocity */
        hs->W_dash += 0.5 * dt * (hs->P_dash + o.P_dash);
        hs->W_plat += 0.5 * dt * (hs->P_plat + o.P_plat);
        hs->P_dash = o.P_dash;
        hs->P_plat = o.P_plat;
    }
    memcpy(hs->F, o.F, sizeof hs->F);
    memcpy(hs->N, o.N, sizeof hs->N);
    for (i = 0; i < 4; i++) hs->Fdot[i] = (hs->F[i] - F_start[i]) / h;
    store(md, hs, o.E_el, out);
    return NULL;
}

const char *model_partial(const void *model, const void *history, const double *value,
                          unsigned int unknown, unsigned int known, double *d)
{
    (void)model; (void)history; (void)value; (void)unknown; (void)known; (void)d;
    return "not provided (the outputs are states: no direct feedthrough)";
}

const char *model_check_history(const void *model, const void *history)
{
    const upd_model *md = (const upd_model *)model;
    const upd_history *hs = (const upd_history *)history;
    const double *x = (const double *)hs;
    size_t k;
    int i;
    for (k = 0; k < offsetof(upd_history, s) / sizeof(double); k++)
        if (!isfinite(x[k])) return "damper state not finite";
    for (i = 0; i < md->r->nc; i++) {
        iwan_output o;
        if (iwan_eval(&md->r->c[i].law, &hs->s[i], hs->s[i].u, hs->s[i].N, NULL, &o) != IWAN_OK)
            return "bad element history";
    }
    return NULL;
}

double model_input_bound(const void *model, unsigned int vr)
{
    (void)model; (void)vr;
    return HUGE_VAL;
}
