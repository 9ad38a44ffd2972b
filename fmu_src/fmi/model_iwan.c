/* model_iwan.c -- the model hooks (model.h) on the Masing/Iwan core (fmu_src/core/iwan.h).
 * The FMU adds no physics of its own: the same core is reached from Python through
 * fmu_src.element, so both give the same numbers for the same history. */
#include "model.h"

iwan_status model_build(fmu_instance *inst)
{
    iwan_status st = iwan_model_init(&inst->model, inst->curve_u, inst->curve_T,
                                     inst->n_points, inst->s.value[VR_N_REF],
                                     inst->curve_fit ? IWAN_FIT_CONCAVE : IWAN_FIT_REJECT);
    if (st != IWAN_OK) return st;
    if (!(inst->s.value[VR_SCALE] >= 0.0)) return IWAN_ERR_BAD_PARAM;
    inst->model.scale = inst->s.value[VR_SCALE];
    return IWAN_OK;
}

iwan_status model_reset_state(fmu_instance *inst, double N)
{
    return iwan_state_init(&inst->model, &inst->s.committed, N);
}

iwan_status model_eval(const fmu_instance *inst, double u, double N, iwan_output *out)
{
    return iwan_eval(&inst->model, &inst->s.committed, u, N, NULL, out);
}

iwan_status model_commit(fmu_instance *inst, double u, double N, iwan_output *out)
{
    return iwan_step(&inst->model, &inst->s.committed, u, N, out);
}
