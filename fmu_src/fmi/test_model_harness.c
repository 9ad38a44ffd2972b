/*
 * test_model_harness.c -- our own importer test of the FMUs the Python side builds (the
 * linear blade, fmu_src/blade_fmu.py; the underplatform damper, fmu_src/upd_fmu.py).
 *
 * Their variable tables are generated per FMU (from the blade's DOFs, the damper's
 * contacts), so this harness is compiled against the table the FMU carries (its
 * sources/fmu_vars.h; a table of fmu_xml.VALUE_START_RULES) and knows nothing of the
 * model: one harness for every such FMU. tests/system/test_fmu_harness.py builds the
 * FMUs, compiles this file with -Werror and runs it, also under valgrind.
 *
 * Usage: fmu_model_harness <FMI 2 FMU dir> <FMI 3 FMU dir> <drive.txt> <scratch dir>
 *
 * The FMU dirs are unzipped FMUs; drive.txt (written by the test) gives the step size,
 * parameter values and every input at every step:
 *     damper-drive 1
 *     h <step size [s]>
 *     parameters <k>             then k pairs: <name> <value>
 *     inputs <m> <name> ...      every input of the table, once each
 *     steps <n>                  then n rows of m values
 * Checks (FMI 2 and FMI 3 binaries loaded side by side with dlopen): start values as
 * the table says; the two versions give the same bits; after refused calls (an output,
 * the time, an unknown reference or a fixed parameter set; NaN or infinite inputs,
 * alone or in a vector; bad doStep sizes and times) the serialized FMU state is
 * byte-identical and the run continues bit-identically; rollback by get/set FMU
 * state and by serialized bytes into a fresh instance continue bit-identically; a
 * corrupted or resized state is refused; Reset runs the history again bit-identically;
 * wrong token, missing, truncated or non-finite resources refused at instantiation.
 * An FMU state left unfreed is freed by FreeInstance (valgrind's leak check sees it).
 * Exit status 0 when all pass.
 */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "harness_api.h"

#define N_IN DAMPER_N_INPUTS
#define N_OUT DAMPER_N_OUTPUTS
#define MAX_STEPS 100000
#define N_CUTS 40          /* truncation points per resource file */
#define N_FLIPS 61         /* corrupted bytes per serialized state */

typedef struct {
    double h;                                /* step size [s] */
    int n_par, n_steps;
    unsigned int par_vr[DAMPER_N_VARIABLES];
    double par_value[DAMPER_N_VARIABLES];
    unsigned int in_vr[N_IN];
    double *u;                               /* (n_steps, N_IN) inputs per step */
} drive;

static void expect_error(inst *x, int status, const char *what)
{
    CHECK(status == 3, "FMI %d: %s returned %d, expected an error", x->a->v, what, status);
}

/* ------------------------------------------------------------------ drive file */
static int vr_of(const char *name, damper_causality causality)
{
    int vr;
    for (vr = 0; vr < DAMPER_N_VARIABLES; vr++)
        if (strcmp(damper_name_of[vr], name) == 0)
            return damper_causality_of[vr] == causality ? vr : -1;
    return -1;
}

static const char *read_drive(FILE *f, drive *d)
{
    char name[128];
    int i, j, m, vr;
    size_t k, n;
    if (fscanf(f, " damper-drive 1 h %lf parameters %d", &d->h, &d->n_par) != 2
        || !(d->h > 0.0) || d->n_par < 0 || d->n_par > DAMPER_N_VARIABLES)
        return "not a damper-drive 1 file (h > 0, parameters)";
    for (i = 0; i < d->n_par; i++) {
        if (fscanf(f, " %127s %lf", name, &d->par_value[i]) != 2
            || (vr = vr_of(name, CAUS_PARAMETER)) < 0)
            return "a parameter line names no parameter of this FMU";
        d->par_vr[i] = (unsigned int)vr;
    }
    if (fscanf(f, " inputs %d", &m) != 1 || m != N_IN) return "the drive must give every input";
    for (i = 0; i < N_IN; i++) {
        if (fscanf(f, " %127s", name) != 1 || (vr = vr_of(name, CAUS_INPUT)) < 0)
            return "an input name is not an input of this FMU";
        d->in_vr[i] = (unsigned int)vr;
        for (j = 0; j < i; j++)
            if (d->in_vr[j] == d->in_vr[i]) return "an input is named twice";
    }
    if (fscanf(f, " steps %d", &d->n_steps) != 1 || d->n_steps < 4 || d->n_steps > MAX_STEPS)
        return "steps must be 4 .. 100000";
    n = (size_t)d->n_steps * N_IN;
    d->u = (double *)malloc(n * sizeof(double));
    if (!d->u) return "out of memory";
    for (k = 0; k < n; k++)
        if (fscanf(f, "%lf", &d->u[k]) != 1 || !isfinite(d->u[k]))
            return "input rows truncated or not finite";
    return NULL;
}

/* ------------------------------------------------------------------ driving */
static int set_many(inst *x, const unsigned int *vr, size_t n, const double *v)
{
    return x->a->v == 2 ? (int)x->a->set2(x->c, vr, n, v) : (int)x->a->set3(x->c, vr, n, v, n);
}

static int terminate(inst *x)
{
    return x->a->v == 2 ? (int)x->a->term2(x->c) : (int)x->a->term3(x->c);
}

/* Inputs and parameters at their start values (rules zero, one, value). */
static void check_start_values(inst *x)
{
    int vr;
    for (vr = 0; vr < DAMPER_N_VARIABLES; vr++) {
        const damper_start_rule rule = damper_start_of[vr];
        const double want = rule == START_ZERO ? 0.0 : rule == START_ONE ? 1.0
                                                                       : damper_start_value[vr];
        double v = NAN;
        if ((damper_causality_of[vr] != CAUS_INPUT && damper_causality_of[vr] != CAUS_PARAMETER)
            || (rule != START_ZERO && rule != START_ONE && rule != START_VALUE))
            continue;
        CHECK(get(x, (unsigned int)vr, &v) == 0 && v == want, "FMI %d: start of %s = %.17g, "
              "the table says %.17g", x->a->v, damper_name_of[vr], v, want);
    }
}

/* Enter Initialization Mode, set the drive's parameters, leave it (t = 0). */
static int initialize(inst *x, const drive *d)
{
    int i, ok;
    x->t = 0.0;
    ok = enter_init(x) == 0;
    for (i = 0; ok && i < d->n_par; i++) ok = set(x, d->par_vr[i], d->par_value[i]) == 0;
    ok = ok && exit_init(x) == 0;
    CHECK(ok, "FMI %d: initialization failed: %s", x->a->v, g_last_log);
    return ok;
}

/* A fresh instance with its start values checked, in step mode at t = 0 (or c == NULL). */
static inst begin(const api *a, const drive *d, const char *name)
{
    inst x = {a, NULL, 0.0};
    x.c = instantiate(a, name, DAMPER_TOKEN, a->resources);
    CHECK(x.c != NULL, "FMI %d: instantiate failed: %s", a->v, g_last_log);
    if (!x.c) return x;
    check_start_values(&x);
    if (!initialize(&x, d)) release(&x);
    return x;
}

/* Steps k0 .. k0+n-1 of the drive: every input (one vector call), doStep, every output
 * into out[(k - k0) N_OUT + j]. Returns 0 at the first failure (reported). */
static int run(inst *x, const drive *d, int k0, int n, double *out)
{
    int k, j, ok = 1;
    for (k = k0; ok && k < k0 + n; k++) {
        ok = set_many(x, d->in_vr, N_IN, d->u + (size_t)k * N_IN) == 0 && do_step(x, d->h) == 0;
        for (j = 0; ok && j < N_OUT; j++)
            ok = get(x, damper_outputs[j], &out[(size_t)(k - k0) * N_OUT + (size_t)j]) == 0;
        CHECK(ok, "FMI %d: step %d failed: %s", x->a->v, k, g_last_log);
    }
    return ok;
}

/* Whether run from step k0 reproduces the reference's steps k0 .. end to the bit. */
static int continues_as(inst *x, const drive *d, int k0, const double *ref, double *out)
{
    const size_t n = (size_t)(d->n_steps - k0) * N_OUT;
    return run(x, d, k0, d->n_steps - k0, out)
           && memcmp(out, ref + (size_t)k0 * N_OUT, n * sizeof(double)) == 0;
}

/* The instance's current FMU state as serialized bytes (malloc'd), or NULL. */
static unsigned char *snapshot(inst *x, size_t *size)
{
    void *s = NULL;
    unsigned char *bytes = NULL;
    const int ok = get_state(x, &s) == 0 && serialize(x, s, &bytes, size) == 0;
    CHECK(ok, "FMI %d: get and serialize the FMU state: %s", x->a->v, g_last_log);
    free_state(x, &s);
    if (!ok) free(bytes);
    return ok ? bytes : NULL;
}

/* ------------------------------------------------------------------ tests */
/* FMI 2 and FMI 3 give the same bits; all outputs finite, most of them moving. */
static void test_versions_agree(const api *a2, const api *a3, const drive *d, double *ref)
{
    const size_t n = (size_t)d->n_steps * N_OUT;
    double *other = (double *)malloc(n * sizeof(double));
    inst x = begin(a2, d, "ref2"), y = begin(a3, d, "ref3");
    size_t k;
    int j, moving = 0, finite = 1;
    if (other && x.c && y.c && run(&x, d, 0, d->n_steps, ref) && run(&y, d, 0, d->n_steps, other)) {
        CHECK(memcmp(ref, other, n * sizeof(double)) == 0, "FMI 2 and FMI 3 binaries differ");
        for (k = 0; k < n; k++) finite = finite && isfinite(ref[k]);
        for (j = 0; j < N_OUT; j++)
            for (k = 1; k < (size_t)d->n_steps; k++)
                if (ref[k * N_OUT + (size_t)j] != ref[(size_t)j]) {
                    moving++;
                    break;
                }
        CHECK(finite, "an output is not finite");
        CHECK(2 * moving >= N_OUT, "only %d of %d outputs move under the drive", moving, N_OUT);
        CHECK(terminate(&x) == 0 && terminate(&y) == 0, "Terminate: %s", g_last_log);
    }
    if (x.c) release(&x);
    if (y.c) release(&y);
    free(other);
}

/* Calls the FMU refuses in step mode: each an error, the serialized state unchanged
 * by all of them, and the run continuing bit-identically. */
static void refused_calls(inst *x, const drive *d)
{
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    const double t = x->t;
    unsigned int two[2];
    double mixed[2] = {0.0, NAN};
    int i, j, logs;
    expect_error(x, set(x, damper_outputs[0], 1.0), "setting an output");
    expect_error(x, set(x, VR_TIME, 1.0), "setting the independent variable");
    expect_error(x, set(x, DAMPER_N_VARIABLES, 1.0), "an unknown value reference");
    if (d->n_par > 0)
        expect_error(x, set(x, d->par_vr[0], d->par_value[0]), "a fixed parameter in step mode");
    for (i = 0; i < N_IN; i++)
        for (j = 0; j < 3; j++) {
            logs = g_log_count;
            expect_error(x, set(x, d->in_vr[i], bad[j]), "a non-finite input");
            CHECK(g_log_count > logs && strstr(g_last_log, "NaN or infinite"),
                  "FMI %d: non-finite %s not logged clearly: '%s'", x->a->v,
                  damper_name_of[d->in_vr[i]], g_last_log);
        }
    two[0] = d->in_vr[0];
    two[1] = d->in_vr[N_IN - 1];
    mixed[0] = d->u[0] + 1.0;  /* a good value, not the current one: must not be stored */
    expect_error(x, set_many(x, two, 2, mixed), "a vector with one NaN");
    expect_error(x, do_step(x, 0.0), "DoStep with h = 0");
    expect_error(x, do_step(x, -d->h), "DoStep with h < 0");
    expect_error(x, do_step(x, NAN), "DoStep with h = NaN");
    x->t = t + 1.0;
    expect_error(x, do_step(x, d->h), "DoStep at a wrong communication point");
    x->t = t;
    if (x->a->v == 2 && !DAMPER_INTERPOLATES) {
        const int order = 1;
        const double rate = 1.0;
        expect_error(x, (int)x->a->sid2(x->c, &two[0], 1, &order, &rate), "input derivatives");
    }
    if (!DAMPER_DIRECTIONAL) {
        double dv;
        expect_error(x, dir_deriv(x, damper_outputs[0], d->in_vr[0], 1.0, &dv),
                     "a directional derivative");
    }
}

static void test_refusals(const api *a, const drive *d, const double *ref)
{
    const int half = d->n_steps / 2;
    double *out = (double *)malloc((size_t)d->n_steps * N_OUT * sizeof(double));
    inst x = begin(a, d, "refuse");
    unsigned char *before = NULL, *after = NULL;
    size_t n0 = 0, n1 = 0;
    if (out && x.c && run(&x, d, 0, half, out)) {
        before = snapshot(&x, &n0);
        refused_calls(&x, d);
        after = snapshot(&x, &n1);
        CHECK(before && after && n0 == n1 && memcmp(before, after, n0) == 0,
              "FMI %d: refused calls changed the FMU state", a->v);
        CHECK(continues_as(&x, d, half, ref, out),
              "FMI %d: the run after refused calls differs from the reference", a->v);
    }
    if (x.c) release(&x);
    free(before);
    free(after);
    free(out);
}

/* Bytes changed one at a time, or a size off by one: every one refused. */
static void corrupted_states_refused(inst *z, unsigned char *bytes, size_t size)
{
    size_t pos, tried = 0, refused = 0;
    void *s = NULL;
    for (pos = 0; pos < size; pos += size / N_FLIPS + 1) {
        bytes[pos] ^= 0x5a;
        tried++;
        refused += deserialize(z, bytes, size, &s) == 3;
        if (s) free_state(z, &s);  /* accepted (reported below) */
        bytes[pos] ^= 0x5a;
    }
    CHECK(refused == tried, "FMI %d: %lu of %lu corrupted states accepted", z->a->v,
          (unsigned long)(tried - refused), (unsigned long)tried);
    expect_error(z, deserialize(z, bytes, size - 1, &s), "a state one byte short");
    CHECK(s == NULL, "FMI %d: a refused state was handed out", z->a->v);
    if (s) free_state(z, &s);
}

/* Save at half way, continue, restore, continue: the reference's bits; the serialized
 * bytes restored into a fresh instance (straight after instantiation) the same. */
static void test_rollback(const api *a, const drive *d, const double *ref)
{
    const int half = d->n_steps / 2;
    double *out = (double *)malloc((size_t)d->n_steps * N_OUT * sizeof(double));
    inst x = begin(a, d, "roll"), z = {a, NULL, 0.0};
    void *s = NULL, *s2 = NULL, *kept = NULL;
    unsigned char *bytes = NULL;
    size_t size = 0;
    double t_half;
    if (out && x.c && run(&x, d, 0, half, out)) {
        t_half = x.t;
        CHECK(get_state(&x, &s) == 0 && get_state(&x, &s) == 0  /* the same state, updated */
              && serialize(&x, s, &bytes, &size) == 0, "FMI %d: get/serialize: %s", a->v,
              g_last_log);
        CHECK(continues_as(&x, d, half, ref, out), "FMI %d: run before rollback", a->v);
        CHECK(set_state(&x, s) == 0, "FMI %d: SetFMUState: %s", a->v, g_last_log);
        x.t = t_half;
        CHECK(continues_as(&x, d, half, ref, out), "FMI %d: rollback not bit-identical", a->v);
        z.c = instantiate(a, "restored", DAMPER_TOKEN, a->resources);
        CHECK(z.c && bytes && deserialize(&z, bytes, size, &s2) == 0 && set_state(&z, s2) == 0,
              "FMI %d: deserialize into a fresh instance: %s", a->v, g_last_log);
        z.t = t_half;
        CHECK(z.c && continues_as(&z, d, half, ref, out),
              "FMI %d: deserialized continuation not bit-identical", a->v);
        if (z.c) {
            expect_error(&z, set_state(&z, s), "SetFMUState with another instance's state");
            if (bytes) corrupted_states_refused(&z, bytes, size);
            /* left to FreeInstance, which frees the states the importer did not */
            CHECK(get_state(&z, &kept) == 0, "FMI %d: GetFMUState", a->v);
        }
    }
    if (s) free_state(&x, &s);
    if (s2) free_state(&z, &s2);
    if (x.c) release(&x);
    if (z.c) release(&z);
    free(bytes);
    free(out);
}

/* Run, Terminate, Reset: start values back, the same history gives the same bits. */
static void test_reset(const api *a, const drive *d, const double *ref)
{
    double *out = (double *)malloc((size_t)d->n_steps * N_OUT * sizeof(double));
    inst x = begin(a, d, "reset");
    if (out && x.c && run(&x, d, 0, d->n_steps, out)) {
        CHECK(terminate(&x) == 0, "FMI %d: Terminate", a->v);
        expect_error(&x, do_step(&x, d->h), "DoStep after Terminate");
        CHECK((a->v == 2 ? (int)a->reset2(x.c) : (int)a->reset3(x.c)) == 0, "FMI %d: Reset",
              a->v);
        check_start_values(&x);
        CHECK(initialize(&x, d) && continues_as(&x, d, 0, ref, out),
              "FMI %d: the run after Reset differs from the first", a->v);
    }
    if (x.c) release(&x);
    free(out);
}

/* ------------------------------------------------------------------ resources */
static int write_file(const char *dir, const char *name, const char *text, size_t len)
{
    char path[1200];
    FILE *f;
    size_t written;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "wb");
    if (!f) return 0;
    written = fwrite(text, 1, len, f);
    return (fclose(f) == 0) & (written == len);
}

static char *read_file(const char *dir, const char *name, size_t *len)
{
    char path[1200];
    FILE *f;
    char *text = NULL;
    long size;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "rb");
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (size = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0
        && (text = (char *)malloc((size_t)size + 1)) != NULL) {
        *len = fread(text, 1, (size_t)size, f);
        text[*len] = '\0';
    }
    fclose(f);
    return text;
}

/* Instantiate with the resources in `dir` (a native path); NULL if refused. */
static void *instantiate_from(const api *a, const char *dir)
{
    char location[1200];
    snprintf(location, sizeof location, a->v == 2 ? "file://%s" : "%s/", dir);
    return instantiate(a, "broken", DAMPER_TOKEN, location);
}

/* One resource file `name` cut short at N_CUTS places, and its last line made NaN: every
 * cut before the last line and the NaN refused, any instance that loads freed. */
static void broken_file_refused(const api *a, const char *scratch, const char *name,
                                const char *text, size_t len)
{
    char *copy = (char *)malloc(len + 32);
    size_t last = len > 1 ? len - 1 : 0, cut;
    int c, refused = 0, must = 0;
    inst x = {a, NULL, 0.0};
    if (!copy) return;
    while (last > 0 && text[last - 1] != '\n') last--;  /* start of the last line */
    for (c = 0; c < N_CUTS; c++) {
        cut = len * (size_t)c / N_CUTS;
        CHECK(write_file(scratch, name, text, cut), "cannot write %s/%s", scratch, name);
        x.c = instantiate_from(a, scratch);
        must += cut < last;
        refused += cut < last && x.c == NULL;
        if (x.c) release(&x);
    }
    CHECK(refused == must, "FMI %d: %s cut short accepted %d times", a->v, name, must - refused);
    memcpy(copy, text, last);
    memcpy(copy + last, "nan nan nan\n", 12);
    CHECK(write_file(scratch, name, copy, last + 12), "cannot write %s/%s", scratch, name);
    x.c = instantiate_from(a, scratch);
    CHECK(x.c == NULL, "FMI %d: a NaN in %s accepted", a->v, name);
    if (x.c) release(&x);
    CHECK(write_file(scratch, name, text, len), "cannot write %s/%s", scratch, name);
    free(copy);
}

/* Every resource file of `res` copied into `scratch`, then broken one at a time. */
static void test_broken_resources(const api *a, const char *res, const char *scratch)
{
    DIR *dir = opendir(res);
    struct dirent *e;
    int files = 0, pass;
    CHECK(dir != NULL, "cannot list %s", res);
    for (pass = 0; dir && pass < 2; pass++) {
        rewinddir(dir);
        while ((e = readdir(dir)) != NULL) {
            size_t len = 0;
            char *text = e->d_name[0] == '.' ? NULL : read_file(res, e->d_name, &len);
            if (!text) continue;
            if (pass == 0)
                CHECK(write_file(scratch, e->d_name, text, len), "cannot copy %s", e->d_name);
            else
                broken_file_refused(a, scratch, e->d_name, text, len);
            files += pass;
            free(text);
        }
    }
    if (dir) closedir(dir);
    CHECK(files > 0, "no resource file in %s", res);
}

/* The shared instantiation checks, with a missing folder below the scratch folder. */
static void test_instantiation_errors(const api *a, const char *scratch)
{
    char missing[1200];
    snprintf(missing, sizeof missing, a->v == 2 ? "file://%s/missing" : "%s/missing/", scratch);
    check_instantiation_errors(a, DAMPER_TOKEN, missing);
}

/* ------------------------------------------------------------------ main */
static int load_fmu(api *a, int v, const char *fmu_dir)
{
    char bin[1200], res[1200];
    snprintf(bin, sizeof bin, "%s/binaries/%s/%s.so", fmu_dir, v == 2 ? "linux64" : "x86_64-linux",
             DAMPER_MODEL_IDENTIFIER);
    snprintf(res, sizeof res, "%s/resources", fmu_dir);
    return load(a, v, bin, res);
}

int main(int argc, char **argv)
{
    static api a2, a3;
    drive d;
    const char *why = "cannot open it";
    double *ref = NULL;
    char res[1200];
    FILE *f;
    int i;
    memset(&d, 0, sizeof d);
    if (argc != 5) {
        fprintf(stderr, "usage: %s <FMI 2 FMU dir> <FMI 3 FMU dir> <drive.txt> <scratch dir>\n",
                argv[0]);
        return 2;
    }
    f = fopen(argv[3], "r");
    if (f) {
        why = read_drive(f, &d);
        fclose(f);
    }
    mkdir(argv[4], 0755);
    if (!why) ref = (double *)calloc((size_t)d.n_steps * N_OUT, sizeof(double));
    if (why || !ref) {
        fprintf(stderr, "drive file %s: %s\n", argv[3], why ? why : "out of memory");
        free(d.u);
        return 2;
    }
    if (load_fmu(&a2, 2, argv[1]) && load_fmu(&a3, 3, argv[2])) {
        test_versions_agree(&a2, &a3, &d, ref);
        for (i = 0; i < 2; i++) {
            const api *a = i == 0 ? &a2 : &a3;
            test_refusals(a, &d, ref);
            test_rollback(a, &d, ref);
            test_reset(a, &d, ref);
            test_instantiation_errors(a, argv[4]);
            snprintf(res, sizeof res, "%s/resources", argv[i + 1]);
            test_broken_resources(a, res, argv[4]);
        }
    }
    if (a2.lib) dlclose(a2.lib);
    if (a3.lib) dlclose(a3.lib);
    free(ref);
    free(d.u);
    printf("fmu_model_harness (%s): %d checks, %d failures\n", DAMPER_MODEL_IDENTIFIER, g_checks,
           g_failures);
    return g_failures ? 1 : 0;
}
