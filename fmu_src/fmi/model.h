/*
 * model.h -- the four hooks a model provides to the shared FMU wrapper
 * (fmu_instance.c). model_iwan.c implements them with the Masing/Iwan core;
 * model_passthrough.c with F = u (a baseline that shows the wrapper's own cost).
 * All return an iwan_status; on failure the committed state is unchanged.
 */
#ifndef MODEL_H
#define MODEL_H

#include "fmu_instance.h"

/* Build inst->model from the curve and the parameters scale, N_ref. */
iwan_status model_build(fmu_instance *inst);

/* Virgin committed state at u = 0 with normal load N. */
iwan_status model_reset_state(fmu_instance *inst, double N);

/* Outputs at (u, N): trial update from the committed state (not modified). */
iwan_status model_eval(const fmu_instance *inst, double u, double N, iwan_output *out);

/* Commit the straight path from the committed state to (u, N); outputs there. */
iwan_status model_commit(fmu_instance *inst, double u, double N, iwan_output *out);

#endif /* MODEL_H */
