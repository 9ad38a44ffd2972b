/*
 * model_table.h -- the curve and normal-law resource files of the friction models
 * (model_iwan.c, model_point.c, model_passthrough.c), read by their model_load, and the
 * opener of the blade's and the damper's resource files:
 *   resources/curve.txt   damper-curve 1 / n_ref <N> / fit <0|1> / points <m> / m lines "u T"
 *                         (written by fmu_src/fmu_build.py),
 *   resources/normal.txt  damper-normal 1 / p_start <p> / points <m> / m lines "p N"
 *                         (optional; written by fmu_src/fmu_point.py).
 * The caller has set the C numeric locale (the FMI layer does around model_load).
 */
#ifndef MODEL_TABLE_H
#define MODEL_TABLE_H

#include <stddef.h>
#include <stdio.h>

#define MODEL_MAX_TABLE_POINTS 4096   /* largest table read (fmu_build.check_curve says so too) */

typedef struct {
    size_t n;          /* number of points */
    double *u, *T;     /* the virgin curve [m], [N] */
    double n_ref;      /* normal load it was computed at [N] */
    int fit;           /* 0: refuse a non-concave table, 1: use its concave majorant */
    size_t n_normal;   /* points of the normal law (0: none) */
    double *p, *N;     /* the normal law N(p) [m], [N] */
    double p_start;    /* start value of the penetration [m] */
} model_table;

/* Read curve.txt (required) and normal.txt (optional) from the directory `dir` into a
 * new table *out. On failure returns the reason (in `why` when it names a file) and
 * *out is NULL. */
const char *model_table_load(model_table **out, const char *dir, char *why, size_t why_size);
void model_table_free(model_table *t);

/* fopen("<dir>/<name>", "r") for the models with their own resource file (model_blade.c,
 * model_upd.c); NULL with the reason in `why` ("cannot open the <what> file '<path>'",
 * or out of memory). */
FILE *model_open_resource(const char *dir, const char *name, const char *what, char *why,
                          size_t why_size);

#endif /* MODEL_TABLE_H */
