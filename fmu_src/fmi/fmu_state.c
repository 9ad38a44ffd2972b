/* fmu_state.c -- FMU states of the FMI layer (fmu_instance.h): one flat block,
 * fmu_header + the model's history, checksummed; validated before a deserialized
 * state is accepted. */
#include "fmu_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t fmu_state_bytes(const fmu_instance *inst)
{
    return sizeof(fmu_header) + inst->history_size;
}

/* 64-bit FNV-1a of every byte after the checksum field: a flipped or changed byte
 * anywhere in the header or the history changes it. */
static uint64_t state_checksum(const unsigned char *state, size_t size)
{
    const size_t start = offsetof(fmu_header, checksum) + sizeof(uint64_t);
    uint64_t hash = 0xcbf29ce484222325u;
    size_t i;
    for (i = start; i < size; i++) {
        hash ^= state[i];
        hash *= 0x100000001b3u;
    }
    return hash;
}

static size_t find_state(const fmu_instance *inst, const void *state)
{
    size_t i;
    for (i = 0; i < inst->n_states; i++)
        if (state && inst->states[i] == state) return i;
    return (size_t)-1;
}

/* The state at *state if this instance handed it out, else a new registered one. */
static unsigned char *own_state(fmu_instance *inst, void **state)
{
    unsigned char *s;
    if (find_state(inst, *state) != (size_t)-1) return (unsigned char *)*state;
    if (inst->n_states == inst->cap_states) {
        size_t cap = inst->cap_states ? 2 * inst->cap_states : 8;
        void **grown = (void **)realloc(inst->states, cap * sizeof(void *));
        if (!grown) return NULL;
        inst->states = grown;
        inst->cap_states = cap;
    }
    s = (unsigned char *)malloc(fmu_state_bytes(inst));
    if (s) inst->states[inst->n_states++] = s;
    return s;
}

fmu_status fmu_state_get(fmu_instance *inst, void **state)
{
    unsigned char *s;
    fmu_header h;
    if (!state) return fmu_log(inst, FMU_ERROR, "GetFMUState: null pointer");
    s = own_state(inst, state);
    if (!s) return fmu_log(inst, FMU_ERROR, "GetFMUState: out of memory");
    h = inst->h;
    h.size = fmu_state_bytes(inst);
    memcpy(s, &h, sizeof h);
    memcpy(s + sizeof h, inst->history, inst->history_size);
    h.checksum = state_checksum(s, h.size);
    memcpy(s, &h, sizeof h);
    *state = s;
    return FMU_OK;
}

/* Restore: values, time, history and the saved mode, except that an instance in
 * Initialization Mode stays there (Exit Initialization Mode then keeps the history). */
fmu_status fmu_state_set(fmu_instance *inst, const void *state)
{
    fmu_header h;
    int mode = inst->h.mode;
    if (find_state(inst, state) == (size_t)-1)
        return fmu_log(inst, FMU_ERROR, "SetFMUState: not a state of this instance");
    memcpy(&h, state, sizeof h);
    inst->h = h;
    if (mode == MODE_INIT) inst->h.mode = MODE_INIT;
    memcpy(inst->history, (const unsigned char *)state + sizeof h, inst->history_size);
    inst->model_ready = 0;  /* the state's parameters; a history is kept (has_history) */
    inst->out_valid = 0;
    if (fmu_ensure_model(inst) != FMU_OK)
        return fmu_log(inst, FMU_ERROR, "SetFMUState: cannot rebuild the model for the "
                       "state's parameters");
    return FMU_OK;
}

fmu_status fmu_state_free(fmu_instance *inst, void **state)
{
    size_t i;
    if (!state || !*state) return FMU_OK;  /* freeing NULL is a no-op */
    i = find_state(inst, *state);
    if (i == (size_t)-1)
        return fmu_log(inst, FMU_ERROR, "FreeFMUState: not a state of this instance");
    free(*state);
    inst->states[i] = inst->states[--inst->n_states];
    *state = NULL;
    return FMU_OK;
}

void fmu_free_states(fmu_instance *inst)
{
    size_t i;
    for (i = 0; i < inst->n_states; i++) free(inst->states[i]);
    free(inst->states);
    inst->states = NULL;
    inst->n_states = inst->cap_states = 0;
}

fmu_status fmu_state_size(fmu_instance *inst, const void *state, size_t *size)
{
    if (find_state(inst, state) == (size_t)-1 || !size)
        return fmu_log(inst, FMU_ERROR, "SerializedFMUStateSize: not a state of this instance");
    *size = fmu_state_bytes(inst);
    return FMU_OK;
}

fmu_status fmu_state_serialize(fmu_instance *inst, const void *state, void *bytes,
                               size_t size)
{
    if (find_state(inst, state) == (size_t)-1 || !bytes || size != fmu_state_bytes(inst))
        return fmu_log(inst, FMU_ERROR, "SerializeFMUState: not a state of this instance, "
                       "or %lu bytes instead of %lu", (unsigned long)size,
                       (unsigned long)fmu_state_bytes(inst));
    memcpy(bytes, state, size);
    return FMU_OK;
}

/* Reason a header cannot be a state of this FMU, or NULL. */
static const char *header_refusal(const fmu_instance *inst, const fmu_header *h,
                                  const unsigned char *bytes, size_t size)
{
    int vr;
    if (h->magic != FMU_STATE_MAGIC) return "not a state of this FMU (magic)";
    if (h->version != FMU_STATE_VERSION) return "state of another version of this FMU";
    if (h->size != size) return "size field does not match";
    if (h->checksum != state_checksum(bytes, size)) return "checksum mismatch (corrupted)";
    if (h->mode != MODE_INSTANTIATED && h->mode != MODE_INIT && h->mode != MODE_STEP
        && h->mode != MODE_TERMINATED)
        return "unknown mode";
    if (h->has_history != 0 && h->has_history != 1) return "bad history flag";
    if ((h->mode & (MODE_STEP | MODE_TERMINATED)) && !h->has_history)
        return "no history in a stepping mode";
    if (!isfinite(h->time)) return "time is not finite";
    for (vr = 0; vr < DAMPER_N_VARIABLES; vr++) {
        if (!isfinite(h->value[vr]) || !isfinite(h->deriv[vr])) return "a value is not finite";
        if (damper_causality_of[vr] != CAUS_INPUT && h->deriv[vr] != 0.0)
            return "derivative of a non-input";
        if (damper_causality_of[vr] == CAUS_PARAMETER
            && model_check_parameter(inst->res, (unsigned int)vr, h->value[vr]))
            return "parameter out of range";
    }
    return NULL;
}

/* Reason the model refuses the state (built for the state's parameters), or NULL. */
static const char *model_refusal(fmu_instance *inst, const fmu_header *h,
                                 const unsigned char *history)
{
    const char *why;
    int vr;
    void *model = calloc(1, model_size(inst->res));
    if (!model) return "out of memory";
    why = model_build(model, inst->res, h->value);
    for (vr = 0; !why && vr < DAMPER_N_VARIABLES; vr++)
        if (damper_causality_of[vr] == CAUS_INPUT
            && fabs(h->value[vr]) > model_input_bound(model, (unsigned int)vr))
            why = "an input lies beyond the FMU's bound";
    if (!why && h->has_history) why = model_check_history(model, history);
    free(model);
    return why;
}

fmu_status fmu_state_from_bytes(fmu_instance *inst, const void *bytes, size_t size,
                                void **state)
{
    fmu_header h;
    const char *why;
    unsigned char *s;
    if (!bytes || !state || size != fmu_state_bytes(inst))
        return fmu_log(inst, FMU_ERROR, "DeSerializeFMUState: expected %lu bytes, got %lu",
                       (unsigned long)fmu_state_bytes(inst), (unsigned long)size);
    memcpy(&h, bytes, sizeof h);
    why = header_refusal(inst, &h, (const unsigned char *)bytes, size);
    if (!why) why = model_refusal(inst, &h, (const unsigned char *)bytes + sizeof h);
    if (why) return fmu_log(inst, FMU_ERROR, "DeSerializeFMUState: state refused: %s", why);
    s = own_state(inst, state);
    if (!s) return fmu_log(inst, FMU_ERROR, "DeSerializeFMUState: out of memory");
    memcpy(s, bytes, size);
    *state = s;
    return FMU_OK;
}
