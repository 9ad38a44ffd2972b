/*
 * fmu_instance.h -- the FMI-version-independent part of the friction-element FMU.
 *
 * Written once and shared by fmi2.c and fmi3.c (Reference-FMUs shape): the
 * instance, its mode (state machine), inputs/parameters stored by value reference,
 * the curve read from the resources, logging, doStep, FMU state and directional
 * derivatives. The physics is behind three small hooks (model.h), implemented by
 * model_iwan.c (the Masing/Iwan core) or model_passthrough.c (benchmark baseline).
 *
 * Co-simulation semantics (rate-independent element, see issue 5):
 * - the committed history changes only in doStep; getters evaluate a trial update
 *   from the committed state to the current inputs (direct feedthrough), so a master
 *   may set/get any number of times without corrupting the history;
 * - an input is a straight line in time, x(t) = x + dx (t - time): SetReal sets x,
 *   FMI 2 SetRealInputDerivatives sets dx for the next step (any order; dx is reset
 *   to 0 after each doStep). doStep(h) commits the path to the current inputs, then
 *   along the straight line to time + h, where the inputs then stand; the core
 *   advances every slider exactly along a straight (u, N) path, so no step-size
 *   dependence and no sub-stepping by the master are needed;
 * - everything a saved FMU state holds is the flat struct fmu_flat (no pointers).
 */
#ifndef FMU_INSTANCE_H
#define FMU_INSTANCE_H

#include <stddef.h>
#include <stdint.h>

#include "damper_vr.h"
#include "iwan.h"

#define FMU_STATE_MAGIC 0x46504d44   /* "DMPF": marks a serialized state of this FMU */
#define FMU_STATE_VERSION 1          /* bump when fmu_flat changes layout */
#define FMU_MAX_CURVE_POINTS 4096    /* largest curve table read from the resources */
#define FMU_CURVE_FILE "curve.txt"

typedef enum { FMU_OK = 0, FMU_WARNING = 1, FMU_ERROR = 2 } fmu_status;

/* Modes of the co-simulation state machine (bit flags, so a call lists where it is allowed). */
typedef enum {
    MODE_INSTANTIATED = 1,
    MODE_INIT = 2,
    MODE_STEP = 4,
    MODE_TERMINATED = 8
} fmu_mode;

/* Logger supplied by the FMI-specific wrapper: (context, status, category, message). */
typedef void (*fmu_logger)(void *ctx, fmu_status status, const char *category,
                           const char *message);

/* Everything an FMU state saves: flat, fixed size, no pointers, versioned. */
typedef struct {
    int32_t magic;                      /* FMU_STATE_MAGIC */
    int32_t version;                    /* FMU_STATE_VERSION */
    double time;                        /* current communication point [s] */
    double value[DAMPER_N_VARIABLES];   /* inputs and parameters, by value reference */
    double deriv[DAMPER_N_VARIABLES];   /* first time derivative of each input [unit/s] */
    iwan_state committed;               /* history committed by the last doStep */
} fmu_flat;

typedef struct {
    fmu_flat s;
    fmu_mode mode;
    iwan_model model;       /* built from the curve and the parameters */
    int model_ready;        /* model and committed state match the parameters */
    int out_valid;          /* `out` holds the outputs at the current inputs */
    iwan_output out;
    iwan_state backup;      /* committed state before the doStep in progress */
    /* virgin curve read from <resources>/curve.txt */
    size_t n_points;
    double *curve_u, *curve_T;
    double curve_n;
    int curve_fit;
    void **states;          /* FMU states this instance handed out (others are refused) */
    size_t n_states, cap_states;
    char name[128];
    fmu_logger log;
    void *log_ctx;
} fmu_instance;

/* Create an instance: check the token, read the curve from `resource_dir` (a native
 * directory path). Returns NULL (after logging why) on failure. */
fmu_instance *fmu_new(const char *name, const char *token, const char *resource_dir,
                      fmu_logger log, void *log_ctx);
void fmu_free(fmu_instance *inst);
void fmu_reset(fmu_instance *inst);            /* back to MODE_INSTANTIATED, start values */

/* printf-style log through the wrapper's callback; returns `status` for chaining. */
fmu_status fmu_log(const fmu_instance *inst, fmu_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Error (logged) unless the instance is in one of the `allowed` modes. */
fmu_status fmu_check_mode(fmu_instance *inst, int allowed, const char *function);

fmu_status fmu_enter_init(fmu_instance *inst, double start_time);
fmu_status fmu_exit_init(fmu_instance *inst);
fmu_status fmu_set(fmu_instance *inst, const unsigned int *vr, size_t n, const double *v);
fmu_status fmu_set_derivative(fmu_instance *inst, const unsigned int *vr, size_t n,
                              const int *order, const double *v);
fmu_status fmu_get(fmu_instance *inst, const unsigned int *vr, size_t n, double *v);
fmu_status fmu_do_step(fmu_instance *inst, double t, double h);
fmu_status fmu_directional_derivative(fmu_instance *inst, const unsigned int *unknowns,
                                      size_t n_unknowns, const unsigned int *knowns,
                                      size_t n_knowns, const double *seed, double *sensitivity);

/* FMU state: a heap copy of fmu_flat, serialized as its bytes. The instance keeps
 * a list of the states it handed out: a pointer not in it (an importer passing an
 * uninitialized FMUstate, a state of another instance, one already freed) is never
 * dereferenced or freed; GetFMUState then allocates a new state. */
fmu_status fmu_state_get(fmu_instance *inst, void **state);
fmu_status fmu_state_set(fmu_instance *inst, const void *state);
fmu_status fmu_state_free(fmu_instance *inst, void **state);
fmu_status fmu_state_size(fmu_instance *inst, const void *state, size_t *size);
fmu_status fmu_state_serialize(fmu_instance *inst, const void *state, void *bytes,
                               size_t size);
fmu_status fmu_state_from_bytes(fmu_instance *inst, const void *bytes, size_t size,
                                void **state);

#endif /* FMU_INSTANCE_H */
