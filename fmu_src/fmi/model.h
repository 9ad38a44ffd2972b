/*
 * model.h -- the hooks a model provides to the FMI layer (fmu_instance.c), in the
 * shape of Reference-FMUs' model.h: the FMI layer owns the instance, its mode, the
 * variable values by value reference, logging, FMU states; the model owns the
 * physics, its resource files and three opaque blocks of memory it sizes itself:
 *   - its resources (read once per instance from the FMU's resources folder),
 *   - the built model (from the resources and the parameters; rebuilt, never saved),
 *   - its committed history: flat, fixed size per resource set, no pointers, so an
 *     FMU state saves it by copying its bytes.
 * The variable table (value references, causalities, start rules) is damper_vr.h,
 * generated per model by fmu_src/fmu_xml.py. Implemented by model_iwan.c (the
 * Masing/Iwan core), model_passthrough.c (F = u, the benchmark's baseline),
 * model_blade.c (a linear reduced blade integrated exactly) and model_upd.c (an
 * underplatform damper between two platforms). Every hook returns NULL on success
 * or a static text saying what is wrong; on failure the history is unchanged.
 * `value` is the instance's array of variable values by value reference
 * (damper_vr.h): inputs and parameters are read from it; `out` receives outputs
 * at their value references (other entries untouched).
 */
#ifndef MODEL_H
#define MODEL_H

#include <stddef.h>

/* Read the model's resource files from the directory `dir` (a native path ending in
 * '/' or not; the caller has set the C numeric locale). On failure returns `why`
 * holding the reason (at most `why_size` bytes) and *res is NULL. */
const char *model_load(void **res, const char *dir, char *why, size_t why_size);
void model_unload(void *res);

size_t model_size(const void *res);          /* bytes of a built model */
size_t model_history_size(const void *res);  /* bytes of a committed history */

/* Start value of a variable whose start rule is START_MODEL (from the resources). */
double model_start(const void *res, unsigned int vr);

/* Reason a parameter value is refused, or NULL. */
const char *model_check_parameter(const void *res, unsigned int vr, double v);

/* Copy history `src` to `dst` (only what the model uses: doStep copies the history
 * once per step to stay all-or-nothing, so this is on the hot path). */
void model_copy_history(const void *model, void *dst, const void *src);

/* Build `model` (model_size bytes, zeroed) from the resources and the parameters. */
const char *model_build(void *model, const void *res, const double *value);

/* Initial history at the inputs in `value`. */
const char *model_reset(const void *model, void *history, const double *value);

/* Outputs at the inputs in `value` without changing `history`: a direct-feedthrough
 * model evaluates a trial update to the inputs, a model without feedthrough returns
 * the outputs of its history. */
const char *model_eval(const void *model, const void *history, const double *value,
                       double *out);

/* Advance the history over the communication step [t, t + h]: the inputs stand at
 * `start` at t and at `end` at t + h (equal unless the importer set FMI 2 input
 * derivatives; in between they are straight lines). Outputs at t + h. */
const char *model_step(const void *model, void *history, const double *start,
                       const double *end, double t, double h, double *out);

/* Partial derivative d(output `unknown`)/d(input `known`) at the inputs in `value` for
 * continued motion, or a reason why it is not provided. */
const char *model_partial(const void *model, const void *history, const double *value,
                          unsigned int unknown, unsigned int known, double *d);

/* Physical invariants of a history (a deserialized state is checked with them). */
const char *model_check_history(const void *model, const void *history);

/* Largest |value| accepted for input `vr` (HUGE_VAL: any finite value). */
double model_input_bound(const void *model, unsigned int vr);

#endif /* MODEL_H */
