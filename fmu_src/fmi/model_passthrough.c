/* model_passthrough.c -- a trivial model for the same wrapper: F = u (kt = 1, no
 * dissipation). Built exactly like the friction FMU, it measures the cost of the
 * wrapper and the FMI calls alone (examples/bench_fmu.py). */
#include <string.h>

#include "model.h"

iwan_status model_build(fmu_instance *inst)
{
    (void)inst;
    return IWAN_OK;
}

iwan_status model_reset_state(fmu_instance *inst, double N)
{
    memset(&inst->s.committed, 0, sizeof inst->s.committed);
    inst->s.committed.version = IWAN_STATE_VERSION;
    inst->s.committed.N = N;
    return IWAN_OK;
}

iwan_status model_eval(const fmu_instance *inst, double u, double N, iwan_output *out)
{
    (void)inst;
    (void)N;
    memset(out, 0, sizeof *out);
    out->F = u;
    out->kt = 1.0;
    return IWAN_OK;
}

iwan_status model_commit(fmu_instance *inst, double u, double N, iwan_output *out)
{
    inst->s.committed.u = u;
    inst->s.committed.N = N;
    return model_eval(inst, u, N, out);
}
