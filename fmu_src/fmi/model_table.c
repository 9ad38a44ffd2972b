/* model_table.c -- the friction models' resource files (model_table.h). */
#include "model_table.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* "<dir>/<name>" (malloc'ed) or NULL. */
static char *join(const char *dir, const char *name)
{
    size_t len = strlen(dir), nlen = strlen(name);
    char *path = (char *)malloc(len + nlen + 2);
    if (!path) return NULL;
    memcpy(path, dir, len);
    if (len == 0 || path[len - 1] != '/') path[len++] = '/';
    memcpy(path + len, name, nlen + 1);
    return path;
}

/* m pairs of numbers into freshly allocated *a, *b. */
static const char *scan_pairs(FILE *f, const char *path, long m, double **a, double **b,
                              char *why, size_t nw)
{
    long i;
    *a = (double *)malloc((size_t)m * sizeof(double));
    *b = (double *)malloc((size_t)m * sizeof(double));
    if (!*a || !*b) return "out of memory reading a table";
    for (i = 0; i < m; i++)
        if (fscanf(f, "%lf %lf", &(*a)[i], &(*b)[i]) != 2) {
            snprintf(why, nw, "'%s': point %ld of %ld unreadable", path, i, m);
            return why;
        }
    return NULL;
}

static const char *scan_curve(model_table *t, FILE *f, const char *path, char *why, size_t nw)
{
    int version = 0, fit = 0;
    long m = 0;
    const char *err;
    if (fscanf(f, " damper-curve %d n_ref %lf fit %d points %ld", &version, &t->n_ref, &fit,
               &m) != 4 || version != 1 || m < 2 || m > MODEL_MAX_TABLE_POINTS) {
        snprintf(why, nw, "'%s' is not a damper-curve 1 file with 2..%d points", path,
                 MODEL_MAX_TABLE_POINTS);
        return why;
    }
    if ((err = scan_pairs(f, path, m, &t->u, &t->T, why, nw)) != NULL) return err;
    t->n = (size_t)m;
    t->fit = fit;
    return NULL;
}

static const char *scan_normal(model_table *t, FILE *f, const char *path, char *why, size_t nw)
{
    int version = 0;
    long m = 0;
    const char *err;
    if (fscanf(f, " damper-normal %d p_start %lf points %ld", &version, &t->p_start, &m) != 3
        || version != 1 || m < 2 || m > MODEL_MAX_TABLE_POINTS) {
        snprintf(why, nw, "'%s' is not a damper-normal 1 file with 2..%d points", path,
                 MODEL_MAX_TABLE_POINTS);
        return why;
    }
    if ((err = scan_pairs(f, path, m, &t->p, &t->N, why, nw)) != NULL) return err;
    t->n_normal = (size_t)m;
    return NULL;
}

/* Read <dir>/<name> with `scan`; a missing optional file is no error. */
static const char *read_file(model_table *t, const char *dir, const char *name, int optional,
                             const char *(*scan)(model_table *, FILE *, const char *, char *, size_t),
                             char *why, size_t nw)
{
    char *path = join(dir, name);
    const char *err = NULL;
    FILE *f;
    if (!path) return "out of memory";
    f = fopen(path, "r");
    if (!f) {
        if (!optional) {
            snprintf(why, nw, "cannot open the resource file '%s'", path);
            err = why;
        }
    } else {
        err = scan(t, f, path, why, nw);
        fclose(f);
    }
    free(path);
    return err;
}

FILE *model_open_resource(const char *dir, const char *name, const char *what, char *why,
                          size_t why_size)
{
    char *path = join(dir, name);
    FILE *f;
    if (!path) {
        snprintf(why, why_size, "out of memory reading the %s", what);
        return NULL;
    }
    f = fopen(path, "r");
    if (!f) snprintf(why, why_size, "cannot open the %s file '%s'", what, path);
    free(path);
    return f;
}

void model_table_free(model_table *t)
{
    if (!t) return;
    free(t->u);
    free(t->T);
    free(t->p);
    free(t->N);
    free(t);
}

const char *model_table_load(model_table **out, const char *dir, char *why, size_t why_size)
{
    model_table *t = (model_table *)calloc(1, sizeof(model_table));
    const char *err;
    *out = NULL;
    if (!t) return "out of memory reading the curve";
    err = read_file(t, dir, "curve.txt", 0, scan_curve, why, why_size);
    if (!err) err = read_file(t, dir, "normal.txt", 1, scan_normal, why, why_size);
    if (err) {
        model_table_free(t);
        return err;
    }
    *out = t;
    return NULL;
}
