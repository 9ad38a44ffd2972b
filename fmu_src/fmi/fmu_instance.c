/* fmu_instance.c -- instance, modes, values and doStep of the FMI layer (fmu_instance.h).
 * The FMU states are in fmu_state.c; the physics behind the hooks of model.h. */
#include "fmu_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A communication point may differ from the FMU's time by round-off of the master's
 * own t + h sums; more than this (relative to max(1, |t|)) is a master error. */
#define TIME_TOLERANCE 1e-9

fmu_status fmu_log(const fmu_instance *inst, fmu_status status, const char *fmt, ...)
{
    char message[512];
    va_list args;
    locale_t old = (locale_t)0;
    if (!inst || !inst->log) return status;
    if (inst->c_locale) old = uselocale(inst->c_locale);  /* "1.5", never "1,5" */
    va_start(args, fmt);
    vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    if (inst->c_locale) uselocale(old);
    inst->log(inst->log_ctx, status,
              status == FMU_ERROR ? "logStatusError" : "logStatusWarning", message);
    return status;
}

static const char *mode_name(int mode)
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
    if (inst->h.mode & allowed) return FMU_OK;
    return fmu_log(inst, FMU_ERROR, "%s must not be called in %s", function,
                   mode_name(inst->h.mode));
}

/* The model's resources, read in the C locale whatever setlocale the importer did. */
static int load_resources(fmu_instance *inst, const char *resource_dir)
{
    char why[512];
    const char *err;
    locale_t old = uselocale(inst->c_locale);
    err = model_load(&inst->res, resource_dir, why, sizeof why);
    uselocale(old);
    if (err) fmu_log(inst, FMU_ERROR, "cannot read the resources in '%s': %s", resource_dir, err);
    return err == NULL;
}

fmu_instance *fmu_new(const char *name, const char *token, const char *resource_dir,
                      fmu_logger log, void *log_ctx)
{
    fmu_instance *inst = (fmu_instance *)calloc(1, sizeof(fmu_instance));
    if (!inst) return NULL;
    inst->log = log;
    inst->log_ctx = log_ctx;
    inst->c_locale = newlocale(LC_ALL_MASK, "C", (locale_t)0);
    strncpy(inst->name, name ? name : "", sizeof inst->name - 1);
    if (!inst->c_locale) {
        fmu_log(inst, FMU_ERROR, "out of memory creating the instance");
        fmu_free(inst);
        return NULL;
    }
    if (!token || strcmp(token, DAMPER_TOKEN) != 0) {
        fmu_log(inst, FMU_ERROR, "instantiation token '%s' does not match this binary (%s)",
                token ? token : "(null)", DAMPER_TOKEN);
        fmu_free(inst);
        return NULL;
    }
    if (!resource_dir || !load_resources(inst, resource_dir)) {
        if (!resource_dir) fmu_log(inst, FMU_ERROR, "no resource location given");
        fmu_free(inst);
        return NULL;
    }
    inst->history_size = model_history_size(inst->res);
    inst->history = (unsigned char *)calloc(1, inst->history_size);
    inst->trial = (unsigned char *)calloc(1, inst->history_size);
    inst->model = calloc(1, model_size(inst->res));
    if (!inst->history || !inst->trial || !inst->model) {
        fmu_log(inst, FMU_ERROR, "out of memory creating the instance");
        fmu_free(inst);
        return NULL;
    }
    fmu_reset(inst);
    return inst;
}

void fmu_free(fmu_instance *inst)
{
    if (!inst) return;
    fmu_free_states(inst);  /* states the importer did not free */
    model_unload(inst->res);
    free(inst->history);
    free(inst->trial);
    free(inst->model);
    if (inst->c_locale) freelocale(inst->c_locale);
    free(inst);
}

void fmu_reset(fmu_instance *inst)
{
    int vr;
    memset(&inst->h, 0, sizeof inst->h);  /* also zeroes padding: states compare bytewise */
    memset(inst->history, 0, inst->history_size);
    inst->h.magic = FMU_STATE_MAGIC;
    inst->h.version = FMU_STATE_VERSION;
    inst->h.size = fmu_state_bytes(inst);
    for (vr = 0; vr < DAMPER_N_VARIABLES; vr++) {
        switch (damper_start_of[vr]) {
        case START_ONE: inst->h.value[vr] = 1.0; break;
        case START_NONE: case START_ZERO: inst->h.value[vr] = 0.0; break;
        default: inst->h.value[vr] = model_start(inst->res, (unsigned int)vr); break;
        }
    }
    inst->h.mode = MODE_INSTANTIATED;
    inst->model_ready = 0;
    inst->out_valid = 0;
}

/* "name = value unit, ..." of the variables of one causality (C locale), for messages. */
static const char *describe(const fmu_instance *inst, int causality, const double *value,
                            char *buf, size_t size)
{
    size_t used = 0;
    int vr;
    locale_t old = inst->c_locale ? uselocale(inst->c_locale) : (locale_t)0;
    buf[0] = '\0';
    for (vr = 0; vr < DAMPER_N_VARIABLES && used < size; vr++) {
        int k;
        if ((int)damper_causality_of[vr] != causality) continue;
        k = snprintf(buf + used, size - used, "%s%s = %g %s", used ? ", " : "",
                     damper_name_of[vr], value[vr], damper_unit_of[vr]);
        if (k < 0) break;
        used += (size_t)k;
    }
    if (inst->c_locale) uselocale(old);
    return buf;
}

fmu_status fmu_ensure_model(fmu_instance *inst)
{
    const char *why;
    int i;
    if (inst->model_ready) return FMU_OK;
    memset(inst->model, 0, model_size(inst->res));
    why = model_build(inst->model, inst->res, inst->h.value);
    if (!why && !inst->h.has_history) why = model_reset(inst->model, inst->history, inst->h.value);
    if (why) {
        char params[256];
        return fmu_log(inst, FMU_ERROR, "cannot build the model (%s): %s",
                       describe(inst, CAUS_PARAMETER, inst->h.value, params, sizeof params), why);
    }
    for (i = 0; i < DAMPER_N_INPUTS; i++)
        inst->bound[damper_inputs[i]] = model_input_bound(inst->model, damper_inputs[i]);
    inst->model_ready = 1;
    inst->out_valid = 0;
    return FMU_OK;
}

/* Error (logged) if an input of `value` lies beyond the model's bound. */
static fmu_status check_bounds(fmu_instance *inst, const double *value, const char *what)
{
    int i;
    for (i = 0; i < DAMPER_N_INPUTS; i++) {
        const unsigned int vr = damper_inputs[i];
        if (fabs(value[vr]) > inst->bound[vr])
            return fmu_log(inst, FMU_ERROR, "%s: input %s = %g is beyond the bound |%s| <= %.17g "
                           "of this FMU (see its documentation)", what,
                           damper_name_of[vr], value[vr], damper_name_of[vr], inst->bound[vr]);
    }
    return FMU_OK;
}

static int outputs_finite(const double *out)
{
    int i;
    for (i = 0; i < DAMPER_N_OUTPUTS; i++)
        if (!isfinite(out[damper_outputs[i]])) return 0;
    return 1;
}

/* Outputs at the current inputs (trial from the committed history), cached. */
static fmu_status ensure_outputs(fmu_instance *inst)
{
    const char *why;
    if (inst->out_valid) return FMU_OK;  /* implies model_ready */
    if (fmu_ensure_model(inst) != FMU_OK) return FMU_ERROR;
    if (check_bounds(inst, inst->h.value, "evaluating the outputs") != FMU_OK) return FMU_ERROR;
    why = model_eval(inst->model, inst->history, inst->h.value, inst->out);
    if (!why && !outputs_finite(inst->out)) why = "outputs overflow (inputs too large)";
    if (why) {
        char in[256];
        return fmu_log(inst, FMU_ERROR, "evaluating the model at %s: %s",
                       describe(inst, CAUS_INPUT, inst->h.value, in, sizeof in), why);
    }
    inst->out_valid = 1;
    return FMU_OK;
}

fmu_status fmu_enter_init(fmu_instance *inst, double start_time)
{
    if (fmu_check_mode(inst, MODE_INSTANTIATED, "EnterInitializationMode")) return FMU_ERROR;
    if (!isfinite(start_time))
        return fmu_log(inst, FMU_ERROR, "start time %g is not finite", start_time);
    inst->h.time = start_time;
    inst->h.mode = MODE_INIT;
    return FMU_OK;
}

/* A history restored by SetFMUState is kept; otherwise a virgin one at the inputs. */
fmu_status fmu_exit_init(fmu_instance *inst)
{
    if (fmu_check_mode(inst, MODE_INIT, "ExitInitializationMode")) return FMU_ERROR;
    if (!inst->h.has_history) inst->model_ready = 0;
    if (ensure_outputs(inst) != FMU_OK) return FMU_ERROR;
    inst->h.has_history = 1;
    inst->h.mode = MODE_STEP;
    return FMU_OK;
}

fmu_status fmu_terminate(fmu_instance *inst)
{
    if (fmu_check_mode(inst, MODE_INIT | MODE_STEP, "Terminate")) return FMU_ERROR;
    inst->h.mode = MODE_TERMINATED;
    return FMU_OK;
}

double fmu_time(const fmu_instance *inst)
{
    return inst->h.time;
}

/* Reason a value cannot be set now, or NULL. */
static const char *set_refusal(const fmu_instance *inst, unsigned int vr, double v)
{
    if (vr >= DAMPER_N_VARIABLES) return "unknown value reference";
    if (!isfinite(v)) return "value is NaN or infinite";
    switch (damper_causality_of[vr]) {
    case CAUS_INPUT:
        return (inst->h.mode & MODE_TERMINATED) ? "inputs cannot be set after Terminate" : NULL;
    case CAUS_PARAMETER:
        if (!(inst->h.mode & (MODE_INSTANTIATED | MODE_INIT)))
            return "fixed parameters can only be set before initialization ends";
        return model_check_parameter(inst->res, vr, v);
    default:
        return "only inputs and parameters can be set";
    }
}

fmu_status fmu_set(fmu_instance *inst, const unsigned int *vr, size_t n, const double *v)
{
    size_t i;
    const char *why;
    if (n > 0 && (!vr || !v)) return fmu_log(inst, FMU_ERROR, "SetReal: null array");
    for (i = 0; i < n && !inst->model_ready; i++)  /* the input bounds need the model */
        if (vr[i] < DAMPER_N_VARIABLES && damper_causality_of[vr[i]] == CAUS_INPUT) {
            fmu_ensure_model(inst);
            break;
        }
    for (i = 0; i < n; i++) {  /* all or nothing: check every value first */
        why = set_refusal(inst, vr[i], v[i]);
        if (why)
            return fmu_log(inst, FMU_ERROR, "cannot set value reference %u (%s) to %g: %s",
                           vr[i], vr[i] < DAMPER_N_VARIABLES ? damper_name_of[vr[i]] : "?",
                           v[i], why);
        if (damper_causality_of[vr[i]] == CAUS_INPUT && inst->model_ready) {
            double bound = inst->bound[vr[i]];
            if (fabs(v[i]) > bound)
                return fmu_log(inst, FMU_ERROR, "cannot set %s to %g: beyond the bound |%s| <= "
                               "%.17g of this FMU (stated in its documentation)",
                               damper_name_of[vr[i]], v[i], damper_name_of[vr[i]], bound);
        }
    }
    for (i = 0; i < n; i++) {
        inst->h.value[vr[i]] = v[i];
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
    if (n > 0 && !DAMPER_INTERPOLATES)
        return fmu_log(inst, FMU_ERROR, "this FMU does not interpolate inputs "
                       "(canInterpolateInputs = false)");
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
    for (i = 0; i < n; i++) inst->h.deriv[vr[i]] = v[i];
    return FMU_OK;
}

fmu_status fmu_get(fmu_instance *inst, const unsigned int *vr, size_t n, double *v)
{
    size_t i;
    if (n > 0 && (!vr || !v)) return fmu_log(inst, FMU_ERROR, "GetReal: null array");
    for (i = 0; i < n; i++) {
        if (vr[i] >= DAMPER_N_VARIABLES)
            return fmu_log(inst, FMU_ERROR, "unknown value reference %u", vr[i]);
        if (damper_causality_of[vr[i]] == CAUS_OUTPUT) {
            if (ensure_outputs(inst) != FMU_OK) return FMU_ERROR;
            v[i] = inst->out[vr[i]];
        } else if (damper_causality_of[vr[i]] == CAUS_INDEPENDENT) {
            v[i] = inst->h.time;
        } else {
            v[i] = inst->h.value[vr[i]];
        }
    }
    return FMU_OK;
}

/* Hand the model the inputs at time and at time + h (FMI 2 input derivatives, then
 * reset: a master that sets none holds its inputs). All or nothing: the update runs on
 * a copy that replaces the history only when it succeeded. */
fmu_status fmu_do_step(fmu_instance *inst, double t, double h)
{
    double end[DAMPER_N_VARIABLES];
    const char *why = NULL;
    unsigned char *swap;
    int i, moves = 0;
    if (fmu_check_mode(inst, MODE_STEP, "DoStep")) return FMU_ERROR;
    if (!isfinite(t) || !isfinite(h) || !(h > 0.0))
        return fmu_log(inst, FMU_ERROR, "DoStep: bad step t = %g, h = %g (the step size must "
                       "be finite and > 0)", t, h);
    if (!isfinite(t + h))  /* the time after the step must be a number too */
        return fmu_log(inst, FMU_ERROR, "DoStep: t + h = %g + %g overflows (the end of the step "
                       "must be finite)", t, h);
    if (fabs(t - inst->h.time) > TIME_TOLERANCE * fmax(1.0, fabs(inst->h.time)))
        return fmu_log(inst, FMU_ERROR, "DoStep at t = %.17g, but the FMU is at t = %.17g",
                       t, inst->h.time);
    if (fmu_ensure_model(inst) != FMU_OK) return FMU_ERROR;
    memcpy(end, inst->h.value, sizeof end);
    for (i = 0; i < DAMPER_N_INPUTS; i++) moves |= inst->h.deriv[damper_inputs[i]] != 0.0;
    if (moves) {  /* FMI 2 input derivatives: the inputs' values at t + h */
        for (i = 0; i < DAMPER_N_INPUTS; i++) {
            const unsigned int vr = damper_inputs[i];
            end[vr] += inst->h.deriv[vr] * h;
            if (!isfinite(end[vr]))
                return fmu_log(inst, FMU_ERROR, "DoStep: extrapolated input %s overflows",
                               damper_name_of[vr]);
        }
    }
    if (check_bounds(inst, inst->h.value, "DoStep") != FMU_OK
        || (moves && check_bounds(inst, end, "DoStep (extrapolated input)") != FMU_OK))
        return FMU_ERROR;
    model_copy_history(inst->model, inst->trial, inst->history);
    why = model_step(inst->model, inst->trial, inst->h.value, end, t, h, inst->out);
    if (!why && !outputs_finite(inst->out)) why = "outputs overflow (inputs too large)";
    if (why) {
        char in[256];
        inst->out_valid = 0;
        return fmu_log(inst, FMU_ERROR, "DoStep from t = %g over h = %g with %s refused: %s",
                       t, h, describe(inst, CAUS_INPUT, end, in, sizeof in), why);
    }
    swap = inst->history;
    inst->history = inst->trial;
    inst->trial = swap;
    if (moves) {
        memcpy(inst->h.value, end, sizeof end);
        memset(inst->h.deriv, 0, sizeof inst->h.deriv);  /* valid for one step only */
    }
    inst->out_valid = 1;
    inst->h.time = t + h;
    return FMU_OK;
}

/* Tangent for continued motion from the model's partial derivatives. */
fmu_status fmu_directional_derivative(fmu_instance *inst, const unsigned int *unknowns,
                                      size_t n_unknowns, const unsigned int *knowns,
                                      size_t n_knowns, const double *seed, double *sensitivity)
{
    size_t i, k;
    if (fmu_check_mode(inst, MODE_INIT | MODE_STEP, "GetDirectionalDerivative")) return FMU_ERROR;
    if (!DAMPER_DIRECTIONAL)
        return fmu_log(inst, FMU_ERROR, "this FMU provides no directional derivatives");
    if ((n_unknowns && (!unknowns || !sensitivity)) || (n_knowns && (!knowns || !seed)))
        return fmu_log(inst, FMU_ERROR, "GetDirectionalDerivative: null array");
    for (k = 0; k < n_knowns; k++) {
        if (knowns[k] >= DAMPER_N_VARIABLES || damper_causality_of[knowns[k]] != CAUS_INPUT)
            return fmu_log(inst, FMU_ERROR, "known %u is not an input", knowns[k]);
        if (!isfinite(seed[k])) return fmu_log(inst, FMU_ERROR, "seed is NaN or infinite");
    }
    if (ensure_outputs(inst) != FMU_OK) return FMU_ERROR;
    for (i = 0; i < n_unknowns; i++) {
        double sum = 0.0, d;
        for (k = 0; k < n_knowns; k++) {
            const char *why = unknowns[i] < DAMPER_N_VARIABLES
                ? model_partial(inst->model, inst->history, inst->h.value, unknowns[i],
                                knowns[k], &d)
                : "unknown value reference";
            if (why)
                return fmu_log(inst, FMU_ERROR, "no directional derivative of value reference "
                               "%u: %s", unknowns[i], why);
            sum += d * seed[k];
        }
        sensitivity[i] = sum;
    }
    return FMU_OK;
}
