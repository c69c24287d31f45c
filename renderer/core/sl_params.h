/* sl_params.h — technique parameter schemas, values and validation.
 *
 * A technique declares a static array of sl_param_def; a sl_params holds one
 * value per schema entry (always valid: defaults first, then only checked
 * sets). Every error names the parameter and the allowed range. Each
 * definition says what a change invalidates, so callers re-render, re-prepare
 * or reload only as much as needed (sl_params_compare). Any thread; no GL.
 * JSON binding lives in proto/sl_params_json.h, not here.
 */
#ifndef SL_PARAMS_H
#define SL_PARAMS_H

#include <stdbool.h>

#include "sl_status.h"

#define SL_PARAMS_MAX 48

typedef enum sl_param_type {
    SL_PARAM_FLOAT, /* one double in [min, max] */
    SL_PARAM_INT,   /* one integer in [min, max] */
    SL_PARAM_BOOL,  /* 0 or 1 */
    SL_PARAM_ENUM,  /* index into choices (given and reported by name) */
    SL_PARAM_VEC3,  /* three doubles, each in [min, max] (directions, colours) */
    SL_PARAM_ATTRIBUTE, /* index of one of the dataset's per-vertex attributes, an
                           integer in [min, max]; min is -1 (then -1 = none) or 0.
                           The schema bounds every dataset; sl_params_check_attributes
                           narrows it to the dataset's count. Given as a number. */
} sl_param_type;

/* Ordered: a larger level implies every smaller one. */
typedef enum sl_invalidation {
    SL_INVALIDATE_NONE = 0,
    SL_INVALIDATE_FRAME,    /* re-render only */
    SL_INVALIDATE_PREPARED, /* re-run the technique's prepare (re-upload, re-voxelize) */
    SL_INVALIDATE_DATASET,  /* reload the dataset */
} sl_invalidation;

typedef struct sl_param_def {
    const char *name;
    sl_param_type type;
    double min, max;             /* FLOAT, INT, VEC3 (per component) */
    double def[3];               /* default; ENUM: index into choices; BOOL: 0/1 */
    const char *const *choices;  /* ENUM: NULL-terminated list of names */
    const char *unit;            /* "world", "deg", "" ... (never NULL in a schema) */
    const char *description;     /* one line, shown as a tooltip */
    sl_invalidation invalidates;
} sl_param_def;

typedef struct sl_params {
    const sl_param_def *schema; /* borrowed, static */
    int count;
    double value[SL_PARAMS_MAX][3];
} sl_params;

/* Sets every value to its schema default. count must be <= SL_PARAMS_MAX. */
void sl_params_init(sl_params *p, const sl_param_def *schema, int count);

/* Index of the named parameter, or -1. */
int sl_params_find(const sl_params *p, const char *name);

/* Checked setters; on failure the value is unchanged and err names the
 * parameter, the value and the allowed range. `n` is the count of numbers
 * given (1 for scalars and enum indices, 3 for VEC3). */
sl_status sl_params_set_numbers(sl_params *p, const char *name, const double *v, int n, sl_err *err);
sl_status sl_params_set_choice(sl_params *p, const char *name, const char *choice, sl_err *err);

/* Getters for techniques; the name must exist in the schema with that type
 * (a programmer error otherwise: asserts, then returns 0). */
double sl_params_float(const sl_params *p, const char *name);
int sl_params_int(const sl_params *p, const char *name);
bool sl_params_bool(const sl_params *p, const char *name);
int sl_params_attribute(const sl_params *p, const char *name);    /* attribute index, -1 = none */
int sl_params_choice(const sl_params *p, const char *name);       /* enum index */
const char *sl_params_choice_name(const sl_params *p, const char *name);
void sl_params_vec3(const sl_params *p, const char *name, float out[3]);

/* Checks every SL_PARAM_ATTRIBUTE value against a dataset with `count`
 * per-vertex attributes: SL_OK when each is -1, below count, or its schema
 * default (a default of 0 means "the first attribute, if any" and reads as
 * none on a dataset without attributes); else SL_ERR_INVALID naming the
 * first offender: "params.NAME = V: the dataset has N per-vertex attributes
 * (valid: -1 .. N-1)". */
sl_status sl_params_check_attributes(const sl_params *p, int count, sl_err *err);

/* The largest invalidation level among parameters whose values differ.
 * Both must share one schema; a schema change counts as PREPARED. */
sl_invalidation sl_params_compare(const sl_params *a, const sl_params *b);

const char *sl_param_type_name(sl_param_type t);

#endif
