/* model_blade.c -- the model hooks (model.h) of a linear reduced blade integrated exactly.
 *
 * The blade M q'' + C q' + K q = f(t) (n DOFs) in first-order form z = [q, q'],
 * A z' = B z + [f, 0], A = [[C, M], [M, 0]], B = [[-K, 0], [0, M]], is diagonalised at
 * build time (fmu_src/blade_fmu.py): A^-1 B = V diag(lambda) V^-1, modal coordinates
 * eta = V^-1 z (m = 2n, complex), eta' = lambda eta + G f. Over a communication step
 * [t, t + h] the inputs x (forces at the interface DOFs and the neighbours' coupling
 * DOFs, each with its rate) give a force that is a straight line in tau = s - t,
 * G f = a + b tau (a = value_map x, b = rate_map x: a first-order hold), and the
 * engine-order excitation F0 cos(Omega s + psi_j) on the forced DOF adds
 * g (F0 / 2) (e^(i psi) e^(i Omega tau) + c.c.), psi = Omega t + j phi. Per mode
 * (lambda, tau-integrals in divided differences of exp, exp[x_0, ..., x_k]):
 *
 *   eta(h) = e^(lambda h) eta0 + h exp[0, L] a + h^2 exp[0, 0, L] b
 *            + h exp[L, iO] g+ + h exp[L, -iO] g-                      L = lambda h,
 *                                                                       iO = i Omega h,
 * the exact solution for any h (no step limit of its own). The energies are exact too:
 * the work of an input force f0 + f1 tau on the DOFs D is f0 . dq_D + f1 . (h q_D(h) -
 * int q_D) with int eta = h exp[0, L] eta0 + h^2 exp[0, 0, L] a + h^3 exp[0, 0, 0, L] b
 * + h^2 exp[0, L, +-iO] g+-; the excitation's work is [F q_f] - int F' q_f with
 * int e^(i Omega tau) eta in the same closed form; the mechanical energy E =
 * (q'^T M q' + q^T K q) / 2 = Re(eta^H S eta) / 2; the structural dissipation is the
 * balance W_excitation + W_interface + W_neighbours (stiffness and damping parts) -
 * (E - E(0)). The inputs' works are kept in three groups (interface forces, the
 * neighbours' K_next and C_next forces), each with a value and a rate map.
 * Divided differences are evaluated without cancellation: a Taylor series about the
 * points' mean when they lie within DD_SERIES_SPREAD of each other, else the
 * recursion on the two farthest points.
 */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_vars.h"
#include "model.h"
#include "model_table.h"

#define BLADE_FILE "blade.txt"
#define DD_SERIES_SPREAD 1.0  /* largest |x_i - x_j| summed by the series */
#define DD_SERIES_TERMS 30    /* terms: spread^k / k! < 1e-32 at k = 30 */
#define N_ENERGY_OUTPUTS 6    /* the last outputs: W_excitation .. energy */
#define N_GROUPS 3            /* work groups: interface, neighbours K_next, C_next */
#define MAX_MODES 4096
#define TWO_PI 6.283185307179586476925286766559

typedef double complex cplx;

/* Resources (blade.txt): everything the step needs, computed at build time. */
typedef struct {
    int m, n_in, n_out;       /* modes (2 n), inputs, kinematic outputs */
    cplx *lambda, *eta0;      /* (m) eigenvalues [1/s], initial modal state */
    cplx *value_map;          /* (m, n_in): G f at the step start per input */
    cplx *rate_map;           /* (m, n_in): G f' per input */
    cplx *exc;                /* (m): G column of the forced DOF [modal / N] */
    cplx *out_rows;           /* (n_out, m): rows of V of the outputs (q or q') */
    cplx *forced_row;         /* (m): row of V of the forced DOF's q */
    cplx *work[2 * N_GROUPS]; /* (n_in, m): value and rate map of each work group */
    cplx *energy;             /* (m, m): S = V^H blkdiag(K, M) V */
    double *buf;
} blade_res;

/* Step coefficients of one step size (cached in the model: derived, never saved). */
enum { C_E, C_P1, C_P2, C_P3, C_XP, C_XM, C_IXP, C_IXM, C_J0, C_J1, C_J2, C_JP, C_JM, C_N };

typedef struct {
    const blade_res *r;
    double omega;             /* excitation [rad/s] */
    double psi0;              /* blade_index * interblade_phase [rad] */
    double F0;                /* [N] */
    double h;                 /* step size of the cached coefficients (0: none) */
    cplx *coef;               /* (C_N, m) */
    cplx *scratch;            /* (4, m): a step's work arrays (no allocation per step) */
} blade_model;

typedef struct {
    double W_exc;             /* cumulative work of the excitation [J] */
    double W[N_GROUPS];       /* cumulative works of the input groups [J] */
    double E0;                /* energy at the start [J] */
    double eta[];             /* (m) complex as (re, im) pairs */
} blade_history;

/* ------------------------------------------------------------ divided differences */
static cplx dd_exp(const cplx *x, int k);

/* exp[x_0..x_k] by the series e^c sum_j h_j(x - c) / (j + k)!, h_j the complete
 * homogeneous symmetric polynomials (recurrence over the points). */
static cplx dd_series(const cplx *x, int k)
{
    cplx c = 0.0, y[4], hh[DD_SERIES_TERMS + 1], sum = 0.0;
    double fact = 1.0;
    int i, j;
    for (i = 0; i <= k; i++) c += x[i];
    c /= (double)(k + 1);
    for (i = 0; i <= k; i++) y[i] = x[i] - c;
    hh[0] = 1.0;
    for (j = 1; j <= DD_SERIES_TERMS; j++) hh[j] = 0.0;
    for (i = 0; i <= k; i++)
        for (j = 1; j <= DD_SERIES_TERMS; j++) hh[j] += y[i] * hh[j - 1];
    for (j = 2; j <= k; j++) fact *= (double)j;  /* k! */
    for (j = 0; j <= DD_SERIES_TERMS; j++) {
        sum += hh[j] / fact;
        fact *= (double)(j + k + 1);
    }
    return cexp(c) * sum;
}

static cplx dd_exp(const cplx *x, int k)
{
    cplx a[4], b[4];
    double best = -1.0;
    int i, j, bi = 0, bj = 0, na = 0, nb = 0;
    if (k == 0) return cexp(x[0]);
    for (i = 0; i <= k; i++)
        for (j = i + 1; j <= k; j++)
            if (cabs(x[i] - x[j]) > best) {
                best = cabs(x[i] - x[j]);
                bi = i;
                bj = j;
            }
    if (best <= DD_SERIES_SPREAD) return dd_series(x, k);
    for (i = 0; i <= k; i++) {
        if (i != bj) a[na++] = x[i];
        if (i != bi) b[nb++] = x[i];
    }
    return (dd_exp(a, k - 1) - dd_exp(b, k - 1)) / (x[bi] - x[bj]);
}

static cplx dd2(cplx a, cplx b) { cplx x[2]; x[0] = a; x[1] = b; return dd_exp(x, 1); }
static cplx dd3(cplx a, cplx b, cplx c) { cplx x[3]; x[0] = a; x[1] = b; x[2] = c; return dd_exp(x, 2); }
static cplx dd4(cplx a, cplx b, cplx c, cplx d)
{
    cplx x[4];
    x[0] = a; x[1] = b; x[2] = c; x[3] = d;
    return dd_exp(x, 3);
}

/* ------------------------------------------------------------ resources */
static int read_cplx(FILE *f, cplx *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        double re, im;
        if (fscanf(f, "%lf %lf", &re, &im) != 2 || !isfinite(re) || !isfinite(im)) return 0;
        v[i] = re + I * im;
    }
    return 1;
}

/* Each block: its keyword, then its numbers. */
static int read_block(FILE *f, const char *key, cplx *v, size_t n)
{
    char word[32];
    return fscanf(f, " %31s", word) == 1 && strcmp(word, key) == 0 && read_cplx(f, v, n);
}

void model_unload(void *res)
{
    blade_res *r = (blade_res *)res;
    if (!r) return;
    free(r->buf);
    free(r);
}

static const char *read_blade(blade_res *r, FILE *f, char *why, size_t nw)
{
    int version = 0;
    size_t m, ni, no, total, off = 0;
    cplx *p;
    int k;
    if (fscanf(f, " damper-blade %d modes %d inputs %d outputs %d", &version, &r->m, &r->n_in,
               &r->n_out) != 4 || version != 1 || r->m < 2 || r->m > MAX_MODES || r->m % 2
        || r->n_in != DAMPER_N_INPUTS || r->n_out + N_ENERGY_OUTPUTS != DAMPER_N_OUTPUTS) {
        snprintf(why, nw, "not a damper-blade 1 file for this interface (%d inputs, %d outputs)",
                 DAMPER_N_INPUTS, DAMPER_N_OUTPUTS);
        return why;
    }
    m = (size_t)r->m; ni = (size_t)r->n_in; no = (size_t)r->n_out;
    total = 2 * m + 2 * m * ni + m + no * m + m + 2 * N_GROUPS * ni * m + m * m;
    r->buf = (double *)malloc(total * sizeof(cplx));
    if (!r->buf) return "out of memory reading the blade";
    p = (cplx *)r->buf;
#define TAKE(n) (off += (n), p + off - (n))
    r->lambda = TAKE(m); r->eta0 = TAKE(m);
    r->value_map = TAKE(m * ni); r->rate_map = TAKE(m * ni);
    r->exc = TAKE(m); r->out_rows = TAKE(no * m); r->forced_row = TAKE(m);
    for (k = 0; k < 2 * N_GROUPS; k++) r->work[k] = TAKE(ni * m);
    r->energy = TAKE(m * m);
#undef TAKE
    if (!read_block(f, "lambda", r->lambda, m) || !read_block(f, "eta0", r->eta0, m)
        || !read_block(f, "value_map", r->value_map, m * ni)
        || !read_block(f, "rate_map", r->rate_map, m * ni)
        || !read_block(f, "excitation", r->exc, m)
        || !read_block(f, "outputs", r->out_rows, no * m)
        || !read_block(f, "forced", r->forced_row, m)
        || !read_block(f, "work_interface_value", r->work[0], ni * m)
        || !read_block(f, "work_interface_rate", r->work[1], ni * m)
        || !read_block(f, "work_stiffness_value", r->work[2], ni * m)
        || !read_block(f, "work_stiffness_rate", r->work[3], ni * m)
        || !read_block(f, "work_damping_value", r->work[4], ni * m)
        || !read_block(f, "work_damping_rate", r->work[5], ni * m)
        || !read_block(f, "energy", r->energy, m * m))
        return "blade file truncated or holding a non-finite number";
    return NULL;
}

const char *model_load(void **res, const char *dir, char *why, size_t why_size)
{
    blade_res *r = (blade_res *)calloc(1, sizeof(blade_res));
    const char *err;
    FILE *f;
    *res = NULL;
    if (!r) return "out of memory reading the blade";
    f = model_open_resource(dir, BLADE_FILE, "blade", why, why_size);
    err = f ? read_blade(r, f, why, why_size) : why;
    if (f) fclose(f);
    if (err) {
        model_unload(r);
        return err;
    }
    *res = r;
    return NULL;
}

size_t model_size(const void *res)
{
    return sizeof(blade_model) + (size_t)(C_N + 4) * (size_t)((const blade_res *)res)->m * sizeof(cplx);
}

size_t model_history_size(const void *res)
{
    return sizeof(blade_history) + 2 * (size_t)((const blade_res *)res)->m * sizeof(double);
}

double model_start(const void *res, unsigned int vr)
{
    (void)res;
    return damper_start_value[vr];  /* rule "value": the variable table's number */
}

const char *model_check_parameter(const void *res, unsigned int vr, double v)
{
    (void)res;
    if (vr == VR_FREQUENCY && !(v >= 0.0)) return "frequency must be >= 0";
    return isfinite(v) ? NULL : "parameter not finite";
}

void model_copy_history(const void *model, void *dst, const void *src)
{
    memcpy(dst, src, model_history_size(((const blade_model *)model)->r));
}

const char *model_build(void *model, const void *res, const double *value)
{
    blade_model *b = (blade_model *)model;
    b->r = (const blade_res *)res;
    b->omega = TWO_PI * value[VR_FREQUENCY];
    b->psi0 = value[VR_BLADE_INDEX] * value[VR_INTERBLADE_PHASE];
    b->F0 = value[VR_F0];
    b->coef = (cplx *)((unsigned char *)model + sizeof(blade_model));
    b->scratch = b->coef + (size_t)C_N * (size_t)b->r->m;
    b->h = 0.0;
    return NULL;
}

static cplx *eta_of(void *history) { return (cplx *)((blade_history *)history)->eta; }
static const cplx *ceta_of(const void *history)
{
    return (const cplx *)((const blade_history *)history)->eta;
}

/* E = Re(eta^H S eta) / 2 [J]. */
static double energy(const blade_res *r, const cplx *eta)
{
    cplx sum = 0.0;
    int i, j;
    for (i = 0; i < r->m; i++) {
        cplx row = 0.0;
        for (j = 0; j < r->m; j++) row += r->energy[(size_t)i * (size_t)r->m + (size_t)j] * eta[j];
        sum += conj(eta[i]) * row;
    }
    return 0.5 * creal(sum);
}

const char *model_reset(const void *model, void *history, const double *value)
{
    const blade_model *b = (const blade_model *)model;
    blade_history *hs = (blade_history *)history;
    (void)value;
    memcpy(eta_of(history), b->r->eta0, (size_t)b->r->m * sizeof(cplx));
    hs->W_exc = hs->W[0] = hs->W[1] = hs->W[2] = 0.0;
    hs->E0 = energy(b->r, b->r->eta0);
    return NULL;
}

static double dot_re(const cplx *row, const cplx *eta, int m)
{
    cplx s = 0.0;
    int k;
    for (k = 0; k < m; k++) s += row[k] * eta[k];
    return creal(s);
}

const char *model_eval(const void *model, const void *history, const double *value, double *out)
{
    const blade_model *b = (const blade_model *)model;
    const blade_res *r = b->r;
    const blade_history *hs = (const blade_history *)history;
    const cplx *eta = ceta_of(history);
    double E = energy(r, eta);
    int i;
    (void)value;
    for (i = 0; i < r->n_out; i++)
        out[damper_outputs[i]] = dot_re(r->out_rows + (size_t)i * (size_t)r->m, eta, r->m);
    out[VR_W_EXCITATION] = hs->W_exc;
    out[VR_W_INTERFACE] = hs->W[0];
    out[VR_W_NEIGHBOURS_STIFFNESS] = hs->W[1];
    out[VR_W_NEIGHBOURS_DAMPING] = hs->W[2];
    out[VR_ENERGY] = E;
    out[VR_W_DAMPING] = hs->W_exc + hs->W[0] + hs->W[1] + hs->W[2] - (E - hs->E0);
    return NULL;
}

/* Coefficients of step size h per mode (module docstring). */
static void coefficients(blade_model *b, double h)
{
    const int m = b->r->m;
    const cplx iO = I * b->omega * h;
    int k;
    for (k = 0; k < m; k++) {
        const cplx L = b->r->lambda[k] * h, B = L + iO;
        cplx *c = b->coef;
        c[C_E * m + k] = cexp(L);
        c[C_P1 * m + k] = h * dd2(0.0, L);
        c[C_P2 * m + k] = h * h * dd3(0.0, 0.0, L);
        c[C_P3 * m + k] = h * h * h * dd4(0.0, 0.0, 0.0, L);
        c[C_XP * m + k] = h * dd2(L, iO);
        c[C_XM * m + k] = h * dd2(L, -iO);
        c[C_IXP * m + k] = h * h * dd3(0.0, L, iO);
        c[C_IXM * m + k] = h * h * dd3(0.0, L, -iO);
        c[C_J0 * m + k] = h * dd2(0.0, B);
        c[C_J1 * m + k] = h * h * dd3(0.0, iO, B);
        c[C_J2 * m + k] = h * h * h * dd4(0.0, iO, iO, B);
        c[C_JP * m + k] = h * h * dd3(0.0, 2.0 * iO, B);
        c[C_JM * m + k] = h * h * dd3(0.0, 0.0, B);
    }
    b->h = h;
}

/* x^T W (n_in, m) times v (m): Re. */
static double work_term(const blade_res *r, const cplx *W, const double *x, const cplx *v)
{
    cplx s = 0.0;
    int i, k;
    for (i = 0; i < r->n_in; i++) {
        cplx row = 0.0;
        const double xi = x[damper_inputs[i]];
        if (xi == 0.0) continue;
        for (k = 0; k < r->m; k++) row += W[(size_t)i * (size_t)r->m + (size_t)k] * v[k];
        s += xi * row;
    }
    return creal(s);
}

const char *model_step(const void *model, void *history, const double *start,
                       const double *end, double t, double h, double *out)
{
    blade_model *b = (blade_model *)model;  /* the coefficient cache and scratch only */
    const blade_res *r = b->r;
    const int m = r->m;
    blade_history *hs = (blade_history *)history;
    cplx *eta = eta_of(history), *e1, *ie, *dq, *hq;
    const cplx psi = I * (b->omega * t + b->psi0);
    const cplx gp_f = 0.5 * b->F0 * cexp(psi), gm_f = 0.5 * b->F0 * cexp(-psi);
    double Fs, Fe;
    cplx jf = 0.0;
    int i, k;
    (void)end;  /* inputs are held with their rate inputs (no FMI input derivatives) */
    if (b->h != h) coefficients(b, h);
    e1 = b->scratch;
    ie = e1 + m; dq = ie + m; hq = dq + m;
    for (k = 0; k < m; k++) {
        const cplx *c = b->coef;
        cplx a = 0.0, be = 0.0, gp = r->exc[k] * gp_f, gm = r->exc[k] * gm_f;
        for (i = 0; i < r->n_in; i++) {
            const double x = start[damper_inputs[i]];
            a += r->value_map[(size_t)k * (size_t)r->n_in + (size_t)i] * x;
            be += r->rate_map[(size_t)k * (size_t)r->n_in + (size_t)i] * x;
        }
        e1[k] = c[C_E * m + k] * eta[k] + c[C_P1 * m + k] * a + c[C_P2 * m + k] * be
                + c[C_XP * m + k] * gp + c[C_XM * m + k] * gm;
        ie[k] = c[C_P1 * m + k] * eta[k] + c[C_P2 * m + k] * a + c[C_P3 * m + k] * be
                + c[C_IXP * m + k] * gp + c[C_IXM * m + k] * gm;
        jf += r->forced_row[k] * (c[C_J0 * m + k] * eta[k] + c[C_J1 * m + k] * a
                                  + c[C_J2 * m + k] * be + c[C_JP * m + k] * gp
                                  + c[C_JM * m + k] * gm);
        dq[k] = e1[k] - eta[k];
        hq[k] = h * e1[k] - ie[k];
    }
    /* works of the inputs (value part on dq, rate part on h q(h) - int q) */
    for (i = 0; i < N_GROUPS; i++)
        hs->W[i] += work_term(r, r->work[2 * i], start, dq)
                    + work_term(r, r->work[2 * i + 1], start, hq);
    /* excitation: F q_f at the ends minus int F' q_f, F' = Re(i Omega F0 e^(i psi) e^(i Omega tau)) */
    Fs = b->F0 * cos(b->omega * t + b->psi0);
    Fe = b->F0 * cos(b->omega * (t + h) + b->psi0);
    hs->W_exc += Fe * dot_re(r->forced_row, e1, m) - Fs * dot_re(r->forced_row, eta, m)
                 - creal(I * b->omega * b->F0 * cexp(psi) * jf);
    memcpy(eta, e1, (size_t)m * sizeof(cplx));
    return model_eval(model, history, start, out);
}

const char *model_partial(const void *model, const void *history, const double *value,
                          unsigned int unknown, unsigned int known, double *d)
{
    (void)model; (void)history; (void)value; (void)unknown; (void)known; (void)d;
    return "not provided (the outputs are states: no direct feedthrough)";
}

const char *model_check_history(const void *model, const void *history)
{
    const blade_model *b = (const blade_model *)model;
    const blade_history *hs = (const blade_history *)history;
    int k;
    for (k = 0; k < 2 * b->r->m; k++)
        if (!isfinite(hs->eta[k])) return "modal state not finite";
    if (!isfinite(hs->W_exc) || !isfinite(hs->W[0]) || !isfinite(hs->W[1])
        || !isfinite(hs->W[2]) || !isfinite(hs->E0))
        return "energy not finite";
    return NULL;
}

double model_input_bound(const void *model, unsigned int vr)
{
    (void)model; (void)vr;
    return HUGE_VAL;
}
