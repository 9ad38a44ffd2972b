/* model_passthrough.c -- a trivial model behind the same FMI layer: F = u (kt = 1, no
 * dissipation, no stored energy). Built exactly like the friction FMU, it measures
 * the cost of the FMI layer and the FMI calls alone (examples/bench_fmu.py). Its
 * history is the last committed input, nothing else. */
#include <math.h>
#include <string.h>

#include "fmu_vars.h"
#include "model.h"

typedef struct {
    double u;   /* last committed displacement [m] */
} passthrough_history;

size_t model_size(void) { return 1; }
size_t model_history_size(void) { return sizeof(passthrough_history); }

void model_copy_history(const void *model, void *dst, const void *src)
{
    (void)model;
    memcpy(dst, src, sizeof(passthrough_history));
}

const char *model_build(void *model, const model_table *table, const double *value)
{
    (void)model; (void)table; (void)value;
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

const char *model_commit(const void *model, void *history, const double *value, double *out)
{
    ((passthrough_history *)history)->u = value[VR_U];
    return model_eval(model, history, value, out);
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

const char *model_check_parameter(unsigned int vr, double v)
{
    (void)vr; (void)v;
    return NULL;
}

double model_start_value(const model_table *table, unsigned int vr)
{
    (void)table; (void)vr;
    return 0.0;
}
