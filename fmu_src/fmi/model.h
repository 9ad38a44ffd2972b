/*
 * model.h -- the hooks a model provides to the FMI layer (fmu_instance.c), in the
 * shape of Reference-FMUs' model.h: the FMI layer owns the instance, its mode, the
 * variable values by value reference, logging, FMU states and the resources; the
 * model owns the physics and two opaque blocks of memory it sizes itself:
 *   - the built model (from the resource table and the parameters; rebuilt, never saved),
 *   - its committed history: flat, fixed size, no pointers, so an FMU state saves it
 *     by copying its bytes.
 * Implemented by model_iwan.c (the Masing/Iwan core), model_point.c (the 3D contact
 * point, contact_point.h) and model_passthrough.c (F = u, the benchmark's baseline).
 * Each model has its own variable table (fmu_vars.h includes it: damper_vr.h or
 * point_vr.h, generated from fmu_src/fmu_xml.py). Every hook returns NULL on success or a static text
 * saying what is wrong; on failure the history is unchanged.
 * `value` is the instance's array of variable values by value reference
 * (damper_vr.h): inputs and parameters are read from it; `out` receives outputs
 * at their value references (other entries untouched).
 */
#ifndef MODEL_H
#define MODEL_H

#include <stddef.h>

/* The resource tables as read by the FMI layer: resources/curve.txt (required) and
 * resources/normal.txt (optional: n_normal = 0 without it). */
typedef struct {
    size_t n;          /* number of points */
    double *u, *T;     /* the table [m], [N] */
    double n_ref;      /* normal load it was computed at [N] */
    int fit;           /* 0: refuse a non-concave table, 1: use its concave majorant */
    size_t n_normal;   /* points of the normal law (0: none) */
    double *p, *N;     /* the normal law N(p) [m], [N] */
    double p_start;    /* start value of the penetration [m] */
} model_table;

size_t model_size(void);          /* bytes of a built model */
size_t model_history_size(void);  /* bytes of a committed history */

/* Copy history `src` to `dst` (only what the model uses: doStep copies the history
 * once per step to stay all-or-nothing, so this is on the hot path). */
void model_copy_history(const void *model, void *dst, const void *src);

/* Build `model` from the table and the parameters in `value`. */
const char *model_build(void *model, const model_table *table, const double *value);

/* Virgin history at the inputs in `value`. */
const char *model_reset(const void *model, void *history, const double *value);

/* Outputs at the inputs in `value`: trial update from `history` (not modified). */
const char *model_eval(const void *model, const void *history, const double *value,
                       double *out);

/* Commit the path from `history` to the inputs in `value`; outputs there. */
const char *model_commit(const void *model, void *history, const double *value, double *out);

/* Partial derivative d(output `unknown`)/d(input `known`) at the inputs in `value` for
 * continued motion, or a reason why it is not provided. */
const char *model_partial(const void *model, const void *history, const double *value,
                          unsigned int unknown, unsigned int known, double *d);

/* Physical invariants of a history (a deserialized state is checked with them). */
const char *model_check_history(const void *model, const void *history);

/* Largest |value| accepted for input `vr` (HUGE_VAL: any finite value). */
double model_input_bound(const void *model, unsigned int vr);

/* Why parameter `vr` cannot take the value v, or NULL. */
const char *model_check_parameter(unsigned int vr, double v);

/* Start value of variable `vr` whose start rule is the model's own (not none, zero,
 * one or curve_n: e.g. the start penetration of the normal law). */
double model_start_value(const model_table *table, unsigned int vr);

#endif /* MODEL_H */
