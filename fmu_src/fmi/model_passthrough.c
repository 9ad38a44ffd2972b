/* model_passthrough.c -- a trivial model behind the same FMI layer: F = u (kt = 1, no
 * dissipation, no stored energy). Built exactly like the friction FMU, it measures
 * the cost of the FMI layer and the FMI calls alone (examples/bench_fmu.py). Its
 * history is the last committed input, nothing else. */
#include <math.h>
#include <string.h>

#include "fmu_vars.h"
#include "model.h"
#include "model_table.h"

typedef struct {
    double u;   /* last committed displacement [m] */
} passthrough_history;

/* The curve is read as by the element (the same start values), not used. */
const char *model_load(void **res, const char *dir, char *why, size_t why_size)
{
    return model_table_load((model_table **)res, dir, why, why_size);
}

void model_unload(void *res) { model_table_free((model_table *)res); }
size_t model_size(const void *res) { (void)res; return 1; }
size_t model_history_size(const void *res) { (void)res; return sizeof(passthrough_history); }
double model_start(const void *res, unsigned int vr)
{
    (void)vr;
    return ((const model_table *)res)->n_ref;
}

const char *model_check_parameter(const void *res, unsigned int vr, double v)
{
    (void)res; (void)vr; (void)v;
    return NULL;
}

void model_copy_history(const void *model, void *dst, const void *src)
{
    (void)model;
    memcpy(dst, src, sizeof(passthrough_history));
}

const char *model_build(void *model, const void *res, const double *value)
{
    (void)model; (void)res; (void)value;
    return NULL;
}

const char *model_reset(const void *model, void *history, const double *value)
{
    (void)model; (void)value;
    ((passthrough_history *)history)->u = 0.0;
    return NULL;
}

const char *model_eval(const void *model, const void *history, const double *value, double *out)
{
    (void)model; (void)history;
    out[VR_F] = value[VR_U];
    out[VR_KT] = 1.0;
    out[VR_W] = out[VR_SLIP] = out[VR_STORED_ENERGY] = 0.0;
    return NULL;
}

const char *model_step(const void *model, void *history, const double *start,
                       const double *end, double t, double h, double *out)
{
    (void)start; (void)t; (void)h;
    ((passthrough_history *)history)->u = end[VR_U];
    return model_eval(model, history, end, out);
}

const char *model_partial(const void *model, const void *history, const double *value,
                          unsigned int unknown, unsigned int known, double *d)
{
    (void)model; (void)history; (void)value;
    *d = (unknown == VR_F && known == VR_U) ? 1.0 : 0.0;
    return NULL;
}

const char *model_check_history(const void *model, const void *history)
{
    (void)model;
    return isfinite(((const passthrough_history *)history)->u) ? NULL : "u not finite";
}

double model_input_bound(const void *model, unsigned int vr)
{
    (void)model; (void)vr;
    return HUGE_VAL;
}
