/*
 * fmu_internal.h -- the instance struct shared by the two halves of the FMI layer:
 * fmu_instance.c (instance, modes, values, doStep) and fmu_state.c (FMU states).
 * Not part of the wrappers' API (fmu_instance.h).
 */
#ifndef FMU_INTERNAL_H
#define FMU_INTERNAL_H

#define _POSIX_C_SOURCE 200809L  /* newlocale / uselocale: locale-independent numbers */
#include <locale.h>

#include "fmu_instance.h"

struct fmu_instance {
    fmu_header h;               /* saved part: mode, time, values, input derivatives */
    unsigned char *history;     /* committed history (history_size bytes, saved) */
    unsigned char *trial;       /* scratch history of the doStep in progress */
    void *model;                /* built model (model_size(res) bytes) */
    void *res;                  /* the model's resources (model_load) */
    size_t history_size;        /* model_history_size(res) */
    int model_ready;            /* model (and, before a history exists, the virgin
                                   history) match the parameters */
    int out_valid;              /* `out` holds the outputs at the current inputs */
    double out[DAMPER_N_VARIABLES];
    double bound[DAMPER_N_VARIABLES];  /* model_input_bound of each input (model_ready) */
    void **states;              /* FMU states this instance handed out */
    size_t n_states, cap_states;
    char name[128];
    fmu_logger log;
    void *log_ctx;
    locale_t c_locale;          /* "C" numeric locale for every scanf/printf */
};

/* Bytes of a whole state: header + history. */
size_t fmu_state_bytes(const fmu_instance *inst);

/* Build the model for the current parameters if needed (and the virgin history
 * while none has been committed). */
fmu_status fmu_ensure_model(fmu_instance *inst);

/* Free every state the instance handed out (at fmu_free). */
void fmu_free_states(fmu_instance *inst);

#endif /* FMU_INTERNAL_H */
