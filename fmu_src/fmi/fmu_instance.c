/* fmu_instance.c -- implementation of fmu_instance.h (see there for the semantics). */
#include "fmu_instance.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"

static void free_all_states(fmu_instance *inst);

/* A communication point may differ from the FMU's time by round-off of the master's
 * own t + h sums; more than this (relative to max(1, |t|)) is a master error. */
#define TIME_TOLERANCE 1e-9

fmu_status fmu_log(const fmu_instance *inst, fmu_status status, const char *fmt, ...)
{
    char message[512];
    va_list args;
    if (!inst || !inst->log) return status;
    va_start(args, fmt);
    vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    inst->log(inst->log_ctx, status,
              status == FMU_ERROR ? "logStatusError" : "logStatusWarning", message);
    return status;
}

static const char *mode_name(fmu_mode mode)
{
    switch (mode) {
    case MODE_INSTANTIATED: return "Instantiated";
    case MODE_INIT: return "InitializationMode";
    case MODE_STEP: return "StepMode";
    case MODE_TERMINATED: return "Terminated";
    }
    return "unknown";
}

fmu_status fmu_check_mode(fmu_instance *inst, int allowed, const char *function)
{
    if ((int)inst->mode & allowed) return FMU_OK;
    return fmu_log(inst, FMU_ERROR, "%s must not be called in %s", function,
                   mode_name(inst->mode));
}

/* Read the curve table written by fmu_src/fmu_build.py:
 *   damper-curve 1 / n_ref <N> / fit <0|1> / points <m> / m lines "u T". */
static int read_curve(fmu_instance *inst, const char *path)
{
    int version = 0, fit = 0;
    long m = 0, i;
    FILE *f = fopen(path, "r");
    if (!f) return fmu_log(inst, FMU_ERROR, "cannot open the curve file '%s'", path), 0;
    if (fscanf(f, " damper-curve %d n_ref %lf fit %d points %ld", &version, &inst->curve_n,
               &fit, &m) != 4 || version != 1 || m < 2 || m > FMU_MAX_CURVE_POINTS) {
        fclose(f);
        return fmu_log(inst, FMU_ERROR, "'%s' is not a damper-curve 1 file with 2..%d points",
                       path, FMU_MAX_CURVE_POINTS), 0;
    }
    inst->curve_u = (double *)malloc((size_t)m * sizeof(double));
    inst->curve_T = (double *)malloc((size_t)m * sizeof(double));
    if (!inst->curve_u || !inst->curve_T) {
        fclose(f);
        return fmu_log(inst, FMU_ERROR, "out of memory reading the curve"), 0;
    }
    for (i = 0; i < m; i++) {
        if (fscanf(f, "%lf %lf", &inst->curve_u[i], &inst->curve_T[i]) != 2) {
            fclose(f);
            return fmu_log(inst, FMU_ERROR, "'%s': point %ld of %ld unreadable", path, i, m), 0;
        }
    }
    fclose(f);
    inst->n_points = (size_t)m;
    inst->curve_fit = fit;
    return 1;
}

static int load_curve(fmu_instance *inst, const char *resource_dir)
{
    size_t len = strlen(resource_dir);
    char *path = (char *)malloc(len + sizeof(FMU_CURVE_FILE) + 2);
    int ok;
    if (!path) return 0;
    memcpy(path, resource_dir, len);
    if (len == 0 || path[len - 1] != '/') path[len++] = '/';
    memcpy(path + len, FMU_CURVE_FILE, sizeof(FMU_CURVE_FILE));
    ok = read_curve(inst, path);
    free(path);
    return ok;
}

fmu_instance *fmu_new(const char *name, const char *token, const char *resource_dir,
                      fmu_logger log, void *log_ctx)
{
    fmu_instance *inst = (fmu_instance *)calloc(1, sizeof(fmu_instance));
    if (!inst) return NULL;
    inst->log = log;
    inst->log_ctx = log_ctx;
    strncpy(inst->name, name ? name : "", sizeof inst->name - 1);
    if (!token || strcmp(token, DAMPER_TOKEN) != 0) {
        fmu_log(inst, FMU_ERROR, "instantiation token '%s' does not match this binary (%s)",
                token ? token : "(null)", DAMPER_TOKEN);
        fmu_free(inst);
        return NULL;
    }
    if (!resource_dir || !load_curve(inst, resource_dir)) {
        if (!resource_dir) fmu_log(inst, FMU_ERROR, "no resource location given");
        fmu_free(inst);
        return NULL;
    }
    fmu_reset(inst);
    return inst;
}

void fmu_free(fmu_instance *inst)
{
    if (!inst) return;
    free_all_states(inst);  /* states the importer did not free */
    free(inst->curve_u);
    free(inst->curve_T);
    free(inst);
}

void fmu_reset(fmu_instance *inst)
{
    int vr;
    memset(&inst->s, 0, sizeof inst->s);  /* also zeroes padding: states compare bytewise */
    inst->s.magic = FMU_STATE_MAGIC;
    inst->s.version = FMU_STATE_VERSION;
    for (vr = 0; vr < DAMPER_N_VARIABLES; vr++) {
        switch (damper_start_of[vr]) {
        case START_ONE: inst->s.value[vr] = 1.0; break;
        case START_CURVE_N: inst->s.value[vr] = inst->curve_n; break;
        default: inst->s.value[vr] = 0.0; break;
        }
    }
    inst->mode = MODE_INSTANTIATED;
    inst->model_ready = 0;
    inst->out_valid = 0;
}

/* Build the model when parameters changed; before stepping starts, also the virgin
 * state (in step mode a state restored with other parameters keeps its history). */
static fmu_status ensure_model(fmu_instance *inst)
{
    iwan_status st;
    if (inst->model_ready) return FMU_OK;
    st = model_build(inst);
    if (st == IWAN_OK && !(inst->mode & (MODE_STEP | MODE_TERMINATED)))
        st = model_reset_state(inst, inst->s.value[VR_N]);
    if (st != IWAN_OK)
        return fmu_log(inst, FMU_ERROR, "cannot build the friction element (scale = %g, "
                       "N_ref = %g N): %s", inst->s.value[VR_SCALE], inst->s.value[VR_N_REF],
                       iwan_status_text(st));
    inst->model_ready = 1;
    inst->out_valid = 0;
    return FMU_OK;
}

static int outputs_finite(const iwan_output *o)
{
    return isfinite(o->F) && isfinite(o->kt) && isfinite(o->dFdN) && isfinite(o->W)
           && isfinite(o->slip);
}

/* Outputs at the current inputs (trial from the committed state), cached. Finite
 * inputs so large that a force or energy overflows are refused, not passed on. */
static fmu_status ensure_outputs(fmu_instance *inst)
{
    iwan_status st;
    if (ensure_model(inst) != FMU_OK) return FMU_ERROR;
    if (inst->out_valid) return FMU_OK;
    st = model_eval(inst, inst->s.value[VR_U], inst->s.value[VR_N], &inst->out);
    if (st == IWAN_OK && !outputs_finite(&inst->out)) st = IWAN_ERR_NONFINITE;
    if (st != IWAN_OK)
        return fmu_log(inst, FMU_ERROR, "evaluating the element at u = %g m, N = %g N: %s",
                       inst->s.value[VR_U], inst->s.value[VR_N],
                       st == IWAN_ERR_NONFINITE ? "outputs overflow (inputs too large)"
                                                : iwan_status_text(st));
    inst->out_valid = 1;
    return FMU_OK;
}

/* Copy the part of a state an n-slider model uses: header, z[0..n-1], dir. */
static void copy_state(iwan_state *dst, const iwan_state *src, int32_t n)
{
    memcpy(dst, src, offsetof(iwan_state, z) + (size_t)n * sizeof(double));
    dst->dir = src->dir;
}

fmu_status fmu_enter_init(fmu_instance *inst, double start_time)
{
    if (fmu_check_mode(inst, MODE_INSTANTIATED, "EnterInitializationMode")) return FMU_ERROR;
    if (!isfinite(start_time))
        return fmu_log(inst, FMU_ERROR, "start time %g is not finite", start_time);
    inst->s.time = start_time;
    inst->mode = MODE_INIT;
    return FMU_OK;
}

fmu_status fmu_exit_init(fmu_instance *inst)
{
    if (fmu_check_mode(inst, MODE_INIT, "ExitInitializationMode")) return FMU_ERROR;
    inst->model_ready = 0;  /* virgin history at the inputs' normal load */
    if (ensure_outputs(inst) != FMU_OK) return FMU_ERROR;
    inst->mode = MODE_STEP;
    return FMU_OK;
}

/* Reason a value cannot be set now, or NULL. */
static const char *set_refusal(const fmu_instance *inst, unsigned int vr, double v)
{
    if (vr >= DAMPER_N_VARIABLES) return "unknown value reference";
    if (!isfinite(v)) return "value is NaN or infinite";
    switch (damper_causality_of[vr]) {
    case CAUS_INPUT:
        return (inst->mode & (MODE_INSTANTIATED | MODE_INIT | MODE_STEP)) ? NULL
               : "inputs cannot be set after Terminate";
    case CAUS_PARAMETER:
        if (!(inst->mode & (MODE_INSTANTIATED | MODE_INIT)))
            return "fixed parameters can only be set before initialization ends";
        if (vr == VR_SCALE && v < 0.0) return "scale must be >= 0";
        if (vr == VR_N_REF && v <= 0.0) return "N_ref must be > 0";
        return NULL;
    default:
        return "only inputs and parameters can be set";
    }
}

fmu_status fmu_set(fmu_instance *inst, const unsigned int *vr, size_t n, const double *v)
{
    size_t i;
    const char *why;
    if (n > 0 && (!vr || !v)) return fmu_log(inst, FMU_ERROR, "SetReal: null array");
    for (i = 0; i < n; i++) {  /* all or nothing: check every value first */
        why = set_refusal(inst, vr[i], v[i]);
        if (why)
            return fmu_log(inst, FMU_ERROR, "cannot set value reference %u (%s) to %g: %s",
                           vr[i], vr[i] < DAMPER_N_VARIABLES ? damper_name_of[vr[i]] : "?",
                           v[i], why);
    }
    for (i = 0; i < n; i++) {
        inst->s.value[vr[i]] = v[i];
        if (damper_causality_of[vr[i]] == CAUS_PARAMETER) inst->model_ready = 0;
    }
    inst->out_valid = 0;
    return FMU_OK;
}

fmu_status fmu_set_derivative(fmu_instance *inst, const unsigned int *vr, size_t n,
                              const int *order, const double *v)
{
    size_t i;
    if (fmu_check_mode(inst, MODE_INIT | MODE_STEP, "SetRealInputDerivatives")) return FMU_ERROR;
    if (n > 0 && (!vr || !v || !order)) return fmu_log(inst, FMU_ERROR, "null array");
    for (i = 0; i < n; i++) {
        if (vr[i] >= DAMPER_N_VARIABLES || damper_causality_of[vr[i]] != CAUS_INPUT)
            return fmu_log(inst, FMU_ERROR, "value reference %u is not an input", vr[i]);
        if (order[i] != 1)
            return fmu_log(inst, FMU_ERROR, "input derivative order %d not supported "
                           "(inputs are interpolated linearly: order 1 only)", order[i]);
        if (!isfinite(v[i]))
            return fmu_log(inst, FMU_ERROR, "derivative of %s is NaN or infinite",
                           damper_name_of[vr[i]]);
    }
    for (i = 0; i < n; i++) inst->s.deriv[vr[i]] = v[i];
    return FMU_OK;
}

fmu_status fmu_get(fmu_instance *inst, const unsigned int *vr, size_t n, double *v)
{
    size_t i;
    if (fmu_check_mode(inst, MODE_INIT | MODE_STEP | MODE_TERMINATED, "GetReal"))
        return FMU_ERROR;
    if (n > 0 && (!vr || !v)) return fmu_log(inst, FMU_ERROR, "GetReal: null array");
    for (i = 0; i < n; i++) {
        if (vr[i] >= DAMPER_N_VARIABLES)
            return fmu_log(inst, FMU_ERROR, "unknown value reference %u", vr[i]);
        if (damper_causality_of[vr[i]] == CAUS_OUTPUT && ensure_outputs(inst) != FMU_OK)
            return FMU_ERROR;
        switch (vr[i]) {
        case VR_TIME: v[i] = inst->s.time; break;
        case VR_F: v[i] = inst->out.F; break;
        case VR_KT: v[i] = inst->out.kt; break;
        case VR_W: v[i] = inst->out.W; break;
        case VR_SLIP: v[i] = inst->out.slip; break;
        default: v[i] = inst->s.value[vr[i]]; break;
        }
    }
    return FMU_OK;
}

/* Commit the history to the current inputs, then along their straight lines to
 * time + h (FMI 2 input derivatives, then reset: a master that sets none holds
 * its inputs); the core's straight-path update is exact.
 * All or nothing: a failed or overflowing update leaves the history as it was. */
fmu_status fmu_do_step(fmu_instance *inst, double t, double h)
{
    double u = inst->s.value[VR_U], N = inst->s.value[VR_N];
    double du = inst->s.deriv[VR_U] * h, dN = inst->s.deriv[VR_N] * h;
    iwan_status st;
    if (fmu_check_mode(inst, MODE_STEP, "DoStep")) return FMU_ERROR;
    if (!isfinite(t) || !isfinite(h) || h < 0.0)
        return fmu_log(inst, FMU_ERROR, "DoStep: bad step t = %g, h = %g", t, h);
    if (fabs(t - inst->s.time) > TIME_TOLERANCE * fmax(1.0, fabs(inst->s.time)))
        return fmu_log(inst, FMU_ERROR, "DoStep at t = %.17g, but the FMU is at t = %.17g",
                       t, inst->s.time);
    if (!isfinite(u + du) || !isfinite(N + dN))
        return fmu_log(inst, FMU_ERROR, "DoStep: extrapolated inputs overflow");
    if (ensure_model(inst) != FMU_OK) return FMU_ERROR;
    copy_state(&inst->backup, &inst->s.committed, inst->model.n);
    st = model_commit(inst, u, N, &inst->out);
    if (st == IWAN_OK && (du != 0.0 || dN != 0.0))
        st = model_commit(inst, u + du, N + dN, &inst->out);
    if (st == IWAN_OK && !outputs_finite(&inst->out)) st = IWAN_ERR_NONFINITE;
    if (st != IWAN_OK) {
        copy_state(&inst->s.committed, &inst->backup, inst->model.n);
        inst->out_valid = 0;
        return fmu_log(inst, FMU_ERROR, "DoStep to u = %g m, N = %g N refused: %s", u + du,
                       N + dN, st == IWAN_ERR_NONFINITE ? "outputs overflow (inputs too large)"
                                                        : iwan_status_text(st));
    }
    inst->s.value[VR_U] = u + du;
    inst->s.value[VR_N] = N + dN;
    inst->s.deriv[VR_U] = inst->s.deriv[VR_N] = 0.0;  /* valid for one step only */
    inst->out_valid = 1;
    inst->s.time = t + h;
    return FMU_OK;
}

/* Tangent for continued motion: dF = kt du + dF/dN dN; kt and slip are piecewise
 * constant in (u, N) (zero derivative). dW is not linear in the direction of motion
 * (it depends on its sign), so it is refused rather than approximated. */
fmu_status fmu_directional_derivative(fmu_instance *inst, const unsigned int *unknowns,
                                      size_t n_unknowns, const unsigned int *knowns,
                                      size_t n_knowns, const double *seed, double *sensitivity)
{
    double du = 0.0, dN = 0.0;
    size_t i;
    if (fmu_check_mode(inst, MODE_INIT | MODE_STEP, "GetDirectionalDerivative")) return FMU_ERROR;
    if ((n_unknowns && (!unknowns || !sensitivity)) || (n_knowns && (!knowns || !seed)))
        return fmu_log(inst, FMU_ERROR, "GetDirectionalDerivative: null array");
    for (i = 0; i < n_knowns; i++) {
        if (knowns[i] == VR_U) du += seed[i];
        else if (knowns[i] == VR_N) dN += seed[i];
        else return fmu_log(inst, FMU_ERROR, "known %u is not an input (u or N)", knowns[i]);
        if (!isfinite(seed[i])) return fmu_log(inst, FMU_ERROR, "seed is NaN or infinite");
    }
    if (ensure_outputs(inst) != FMU_OK) return FMU_ERROR;
    for (i = 0; i < n_unknowns; i++) {
        switch (unknowns[i]) {
        case VR_F: sensitivity[i] = inst->out.kt * du + inst->out.dFdN * dN; break;
        case VR_KT: case VR_SLIP: sensitivity[i] = 0.0; break;
        default:
            return fmu_log(inst, FMU_ERROR, "no directional derivative of value reference %u "
                           "(provided: F, kt, slip)", unknowns[i]);
        }
    }
    return FMU_OK;
}

static size_t find_state(const fmu_instance *inst, const void *state)
{
    size_t i;
    for (i = 0; i < inst->n_states; i++)
        if (state && inst->states[i] == state) return i;
    return (size_t)-1;
}

/* The state at *state if this instance handed it out, else a new registered one. */
static fmu_flat *own_state(fmu_instance *inst, void **state)
{
    fmu_flat *s;
    if (find_state(inst, *state) != (size_t)-1) return (fmu_flat *)*state;
    if (inst->n_states == inst->cap_states) {
        size_t cap = inst->cap_states ? 2 * inst->cap_states : 8;
        void **grown = (void **)realloc(inst->states, cap * sizeof(void *));
        if (!grown) return NULL;
        inst->states = grown;
        inst->cap_states = cap;
    }
    s = (fmu_flat *)malloc(sizeof(fmu_flat));
    if (s) inst->states[inst->n_states++] = s;
    return s;
}

fmu_status fmu_state_get(fmu_instance *inst, void **state)
{
    fmu_flat *s;
    if (fmu_check_mode(inst, MODE_INIT | MODE_STEP | MODE_TERMINATED, "GetFMUState"))
        return FMU_ERROR;
    if (!state) return fmu_log(inst, FMU_ERROR, "GetFMUState: null pointer");
    s = own_state(inst, state);
    if (!s) return fmu_log(inst, FMU_ERROR, "GetFMUState: out of memory");
    memcpy(s, &inst->s, sizeof(fmu_flat));
    *state = s;
    return FMU_OK;
}

static int state_valid(const fmu_flat *s)
{
    return s->magic == FMU_STATE_MAGIC && s->version == FMU_STATE_VERSION
           && s->committed.version == IWAN_STATE_VERSION;
}

fmu_status fmu_state_set(fmu_instance *inst, const void *state)
{
    fmu_flat tmp;
    if (fmu_check_mode(inst, MODE_INIT | MODE_STEP | MODE_TERMINATED, "SetFMUState"))
        return FMU_ERROR;
    if (find_state(inst, state) == (size_t)-1)
        return fmu_log(inst, FMU_ERROR, "SetFMUState: not a state of this instance");
    memcpy(&tmp, state, sizeof tmp);
    inst->out_valid = 0;
    if (inst->model_ready && tmp.value[VR_SCALE] == inst->s.value[VR_SCALE]
        && tmp.value[VR_N_REF] == inst->s.value[VR_N_REF]) {
        inst->s = tmp;
        return FMU_OK;
    }
    inst->s = tmp;  /* parameters of the saved state: rebuild the model, keep the history */
    inst->model_ready = model_build(inst) == IWAN_OK;
    if (!inst->model_ready)
        return fmu_log(inst, FMU_ERROR, "SetFMUState: cannot rebuild the element for the "
                       "state's parameters");
    return FMU_OK;
}

fmu_status fmu_state_free(fmu_instance *inst, void **state)
{
    size_t i;
    if (!state || !*state) return FMU_OK;  /* freeing NULL is a no-op */
    i = find_state(inst, *state);
    if (i == (size_t)-1)
        return fmu_log(inst, FMU_ERROR, "FreeFMUState: not a state of this instance");
    free(*state);
    inst->states[i] = inst->states[--inst->n_states];
    *state = NULL;
    return FMU_OK;
}

static void free_all_states(fmu_instance *inst)
{
    size_t i;
    for (i = 0; i < inst->n_states; i++) free(inst->states[i]);
    free(inst->states);
    inst->states = NULL;
    inst->n_states = inst->cap_states = 0;
}

fmu_status fmu_state_size(fmu_instance *inst, const void *state, size_t *size)
{
    if (find_state(inst, state) == (size_t)-1 || !size)
        return fmu_log(inst, FMU_ERROR, "SerializedFMUStateSize: not a state of this instance");
    *size = sizeof(fmu_flat);
    return FMU_OK;
}

fmu_status fmu_state_serialize(fmu_instance *inst, const void *state, void *bytes,
                               size_t size)
{
    if (find_state(inst, state) == (size_t)-1 || !bytes || size != sizeof(fmu_flat))
        return fmu_log(inst, FMU_ERROR, "SerializeFMUState: not a state of this instance, "
                       "or %lu bytes instead of %lu", (unsigned long)size,
                       (unsigned long)sizeof(fmu_flat));
    memcpy(bytes, state, size);
    return FMU_OK;
}

fmu_status fmu_state_from_bytes(fmu_instance *inst, const void *bytes, size_t size,
                                void **state)
{
    fmu_flat tmp, *s;
    if (!bytes || !state || size != sizeof(fmu_flat))
        return fmu_log(inst, FMU_ERROR, "DeSerializeFMUState: expected %lu bytes, got %lu",
                       (unsigned long)sizeof(fmu_flat), (unsigned long)size);
    memcpy(&tmp, bytes, sizeof tmp);
    if (!state_valid(&tmp))
        return fmu_log(inst, FMU_ERROR, "DeSerializeFMUState: not a state of this FMU");
    s = own_state(inst, state);
    if (!s) return fmu_log(inst, FMU_ERROR, "DeSerializeFMUState: out of memory");
    memcpy(s, &tmp, sizeof tmp);
    *state = s;
    return FMU_OK;
}
