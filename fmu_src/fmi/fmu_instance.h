/*
 * fmu_instance.h -- the FMI-version-independent, model-independent part of the FMUs.
 *
 * Written once and shared by fmi2.c and fmi3.c (Reference-FMUs shape): the
 * instance, its mode (state machine), variable values by value reference
 * (fmu_vars.h), the model's resources, logging, doStep, FMU states and directional
 * derivatives. It knows nothing of the physics: that is behind the hooks of
 * model.h (model_iwan.c: the Masing/Iwan element; model_point.c: the 3D contact
 * point; model_passthrough.c: F = u; model_blade.c: a linear blade; model_upd.c: an
 * underplatform damper), and nothing of the variables but what the model's generated
 * table (fmu_vars.h) lists.
 *
 * Co-simulation semantics:
 * - the committed history changes only in doStep; getters evaluate the outputs from
 *   the committed history (a direct-feedthrough model: a trial update to the current
 *   inputs), so a master may set/get any number of times without corrupting the history;
 * - an input is a straight line in time, x(t) = x + dx (t - time): SetReal sets x,
 *   FMI 2 SetRealInputDerivatives sets dx for the next step (dx is reset to 0 after
 *   each doStep; models that do not interpolate inputs refuse it). doStep(h), h > 0,
 *   hands the model the inputs at time and at time + h (model_step);
 * - inputs beyond the model's bound (model_input_bound; stated in the FMU's
 *   documentation) are refused with a logged message.
 *
 * FMU state: one flat block, fmu_header followed by the model's history
 * (model_history_size() bytes), no pointers; the serialized state is these bytes.
 * It carries the mode, time, values, input derivatives, whether a history has been
 * committed (after Exit Initialization Mode), and a 64-bit FNV-1a checksum of
 * everything after the checksum field. Get/Set/Serialize/Deserialize are allowed
 * in every mode. SetFMUState restores the saved mode (as Reference-FMUs do), so a
 * state restored into a fresh instance straight after instantiation continues
 * stepping; an instance in Initialization Mode stays there, and Exit
 * Initialization Mode keeps a restored history instead of starting a virgin one.
 * A deserialized state is accepted only if its size, magic, version, checksum,
 * header (mode, finite values, parameter ranges) and the model's physical
 * invariants (model_check_history, with the model rebuilt for the state's
 * parameters) all hold.
 * Numbers read from the resources or written to logs do not depend on the
 * process locale (a C locale object is used around every scanf/printf).
 */
#ifndef FMU_INSTANCE_H
#define FMU_INSTANCE_H

#include <stddef.h>
#include <stdint.h>

#include "fmu_vars.h"
#include "model.h"

#define FMU_STATE_MAGIC 0x46504d44u  /* "DMPF": marks a state of this FMU */
#define FMU_STATE_VERSION 3          /* bump when fmu_header or a history changes layout */

typedef enum { FMU_OK = 0, FMU_WARNING = 1, FMU_ERROR = 2 } fmu_status;

/* Modes of the co-simulation state machine (bit flags, so a call lists where it is allowed). */
typedef enum {
    MODE_INSTANTIATED = 1,
    MODE_INIT = 2,
    MODE_STEP = 4,
    MODE_TERMINATED = 8
} fmu_mode;
#define MODE_ANY (MODE_INSTANTIATED | MODE_INIT | MODE_STEP | MODE_TERMINATED)

/* Logger supplied by the FMI-specific wrapper: (context, status, category, message). */
typedef void (*fmu_logger)(void *ctx, fmu_status status, const char *category,
                           const char *message);

/* The saved part of an instance, followed in a state by the model's history. */
typedef struct {
    uint32_t magic;                     /* FMU_STATE_MAGIC */
    uint32_t version;                   /* FMU_STATE_VERSION */
    uint64_t checksum;                  /* FNV-1a 64 of the bytes after this field */
    uint64_t size;                      /* bytes of the whole state */
    int32_t mode;                       /* fmu_mode when saved */
    int32_t has_history;                /* 1 once Exit Initialization Mode committed one */
    double time;                        /* current communication point [s] */
    double value[DAMPER_N_VARIABLES];   /* inputs and parameters, by value reference */
    double deriv[DAMPER_N_VARIABLES];   /* first time derivative of each input [unit/s] */
} fmu_header;

typedef struct fmu_instance fmu_instance;

/* Create an instance: check the token, read the model's resources from `resource_dir`
 * (a native directory path). Returns NULL (after logging why) on failure. */
fmu_instance *fmu_new(const char *name, const char *token, const char *resource_dir,
                      fmu_logger log, void *log_ctx);
void fmu_free(fmu_instance *inst);
void fmu_reset(fmu_instance *inst);            /* back to MODE_INSTANTIATED, start values */

/* printf-style log through the wrapper's callback (C locale); returns `status`. */
fmu_status fmu_log(const fmu_instance *inst, fmu_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Error (logged) unless the instance is in one of the `allowed` modes. */
fmu_status fmu_check_mode(fmu_instance *inst, int allowed, const char *function);

fmu_status fmu_enter_init(fmu_instance *inst, double start_time);
fmu_status fmu_exit_init(fmu_instance *inst);
fmu_status fmu_terminate(fmu_instance *inst);
double fmu_time(const fmu_instance *inst);   /* current communication point [s] */
fmu_status fmu_set(fmu_instance *inst, const unsigned int *vr, size_t n, const double *v);
fmu_status fmu_set_derivative(fmu_instance *inst, const unsigned int *vr, size_t n,
                              const int *order, const double *v);
/* Values in any mode: in Instantiated (and after Reset) the start values, and the
 * outputs of the virgin history at the start inputs. */
fmu_status fmu_get(fmu_instance *inst, const unsigned int *vr, size_t n, double *v);
fmu_status fmu_do_step(fmu_instance *inst, double t, double h);
fmu_status fmu_directional_derivative(fmu_instance *inst, const unsigned int *unknowns,
                                      size_t n_unknowns, const unsigned int *knowns,
                                      size_t n_knowns, const double *seed, double *sensitivity);

/* FMU states. The instance keeps a list of the states it handed out: a pointer not
 * in it (an importer passing an uninitialized FMUstate, a state of another instance,
 * one already freed) is never dereferenced or freed; GetFMUState then allocates. */
fmu_status fmu_state_get(fmu_instance *inst, void **state);
fmu_status fmu_state_set(fmu_instance *inst, const void *state);
fmu_status fmu_state_free(fmu_instance *inst, void **state);
fmu_status fmu_state_size(fmu_instance *inst, const void *state, size_t *size);
fmu_status fmu_state_serialize(fmu_instance *inst, const void *state, void *bytes,
                               size_t size);
fmu_status fmu_state_from_bytes(fmu_instance *inst, const void *bytes, size_t size,
                                void **state);

#endif /* FMU_INSTANCE_H */
