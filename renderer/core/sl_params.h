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

#include <math.h> /* NAN, for SL_PARAM_AUTO */
#include <stdbool.h>

#include "sl_status.h"

#define SL_PARAMS_MAX 48
#define SL_PARAM_AUTO NAN /* sl_param_def.def[0] of a FLOAT whose default is "auto" */

typedef enum sl_param_type {
    SL_PARAM_FLOAT, /* one double in [min, max]; with def[0] = SL_PARAM_AUTO the
                       default is "auto": the technique picks the value per
                       dataset (sl_params_float gives NaN, sl_params_is_auto 1);
                       a number sets it, sl_params_set_auto sets auto again */
    SL_PARAM_INT,   /* one integer in [min, max] */
    SL_PARAM_BOOL,  /* 0 or 1 */
    SL_PARAM_ENUM,  /* index into choices (given and reported by name) */
    SL_PARAM_VEC3,  /* three doubles, each in [min, max] (directions, colours) */
    SL_PARAM_ATTRIBUTE, /* index of one of the dataset's per-vertex attributes, an
                           integer in [min, max]; min is -1 (then -1 = none) or 0.
                           The schema bounds every dataset; sl_params_check_attributes
                           narrows it to the dataset's count. Given as a number. */
    SL_PARAM_TRANSFER,  /* a transfer function (sl_transfer_function below); min/max
                           unused; default: def[0] = colormap index, opacity ramp
                           from def[1] at t = 0 to def[2] at t = 1 over the
                           dataset's value range, or, with def[1] =
                           SL_TF_AUTO_OPACITY, the dataset's automatic ramp
                           (auto_opacity). Set with sl_params_set_transfer. */
    SL_PARAM_VALUES,    /* a list of 0 .. SL_PARAM_VALUES_MAX doubles, each in
                           [min, max] (isovalues). The empty list means "auto":
                           the technique decides. The default is always the
                           empty list (def unused). Set with sl_params_set_numbers
                           (n = 0 .. 4), read with sl_params_values. */
    SL_PARAM_TRANSFER_2D, /* a 2D transfer function over the principal curvatures
                           (sl_transfer_function_2d below), at most one per
                           schema; min/max unused; default: the preset def[0]
                           of sl_transfer_function_2d_preset (0 =
                           SL_TF2D_PRESET_RIDGES_VALLEYS). Set with
                           sl_params_set_transfer_2d. */
} sl_param_type;

#define SL_PARAM_VALUES_MAX 4 /* numbers of a SL_PARAM_VALUES list */

/* A transfer function as given, in one of two forms (renderer/volume/
 * resolves either to control points for a dataset):
 *   points:   colormap < 0; point[k] = {value, r, g, b, a}, value in data
 *             units (non-decreasing), colour and opacity in [0, 1];
 *             piecewise linear, constant beyond the first and last point.
 *   colormap: colormap >= 0 (index into sl_colormap_names); point[k] =
 *             {t, alpha} (t in [0, 1], non-decreasing) an opacity ramp;
 *             t = 0 and 1 are range[0] and range[1] in data units when
 *             has_range, else the dataset's value range. With
 *             auto_opacity the ramp is not given (count 0): the volume
 *             techniques pick one per dataset from its histogram
 *             (sl_volume_tf_auto_opacity in renderer/volume/).
 * Unused entries are zero, so two equal functions compare equal bytewise. */
#define SL_TF_MAX_POINTS 64
#define SL_PARAMS_MAX_TF 2 /* transfer-function parameters per schema */
#define SL_TF_AUTO_OPACITY (-1.0) /* sl_param_def.def[1] of a default with auto_opacity */
typedef struct sl_transfer_function {
    int colormap;
    int auto_opacity;               /* colormap form only: the ramp comes from the data */
    int count;                      /* 1 .. SL_TF_MAX_POINTS; 0 with auto_opacity */
    int has_range;
    double range[2];                /* colormap form with has_range: range[0] < range[1] */
    double point[SL_TF_MAX_POINTS][5];
} sl_transfer_function;

/* A 2D transfer function over (k1, k2), the principal curvatures (van Pelt
 * et al. §4.2.5 after Kindlmann et al.): count circular widgets, each
 * widget[k] = {k1, k2, radius, r, g, b, a}, centre and radius in curvature
 * units; range (> 0) is the half width of the square [-range, range]^2 an
 * editor shows (a widget may lie outside it). Colours and alpha in [0, 1],
 * radius > 0, all finite (sl_transfer_function_2d_check). How widgets
 * combine is for the technique to say (in its README).
 * Unused widgets are zero, so equal functions compare equal field by field. */
#define SL_TF2D_MAX_WIDGETS 16
typedef struct sl_transfer_function_2d {
    int count;                                  /* 1 .. SL_TF2D_MAX_WIDGETS */
    double range;
    double widget[SL_TF2D_MAX_WIDGETS][7];
} sl_transfer_function_2d;

/* Presets of sl_transfer_function_2d_preset (sl_param_def.def[0] of a
 * SL_PARAM_TRANSFER_2D default). */
typedef enum sl_tf2d_preset {
    SL_TF2D_PRESET_RIDGES_VALLEYS = 0, /* range 0.5; ridge {0.25, 0, 0.3} light (0.95, 0.95, 0.9),
                                          valley {0, -0.25, 0.3} dark (0.1, 0.1, 0.1), both alpha 1 */
    SL_TF2D_PRESET_COUNT
} sl_tf2d_preset;

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
    double min, max;             /* FLOAT, INT, VEC3 (per component), VALUES (per value) */
    double def[3];               /* default; ENUM: index into choices; BOOL: 0/1; VALUES: unused
                                    (the empty list); TRANSFER_2D: def[0] = sl_tf2d_preset */
    const char *const *choices;  /* ENUM: NULL-terminated list of names */
    const char *unit;            /* "world", "deg", "" ... (never NULL in a schema) */
    const char *description;     /* one line, shown as a tooltip */
    sl_invalidation invalidates;
} sl_param_def;

typedef struct sl_params {
    const sl_param_def *schema; /* borrowed, static */
    int count;
    /* One row per entry: scalars in [0], VEC3 in [0..2], VALUES in
     * [0 .. value_count - 1] (the rest zero), TRANSFER: [0] = its slot in
     * tf; TRANSFER_2D: zero (the function is tf2d). */
    double value[SL_PARAMS_MAX][SL_PARAM_VALUES_MAX];
    int value_count[SL_PARAMS_MAX];   /* VALUES: the list's length (0 = auto); other types 0 */
    sl_transfer_function tf[SL_PARAMS_MAX_TF];
    sl_transfer_function_2d tf2d;     /* the schema's one TRANSFER_2D entry, if any */
} sl_params;

/* Sets every value to its schema default. count must be <= SL_PARAMS_MAX,
 * with at most SL_PARAMS_MAX_TF transfer-function entries and one
 * TRANSFER_2D entry. */
void sl_params_init(sl_params *p, const sl_param_def *schema, int count);

/* Index of the named parameter, or -1. */
int sl_params_find(const sl_params *p, const char *name);

/* Checked setters; on failure the value is unchanged and err names the
 * parameter, the value and the allowed range. `n` is the count of numbers
 * given (1 for scalars and enum indices, 3 for VEC3, 0 .. 4 for VALUES,
 * where v may be NULL when n is 0; a bad value of a list is named by its
 * index: "parameter 'isovalues': value 2 = 7 is out of range [0, 1] data"). */
sl_status sl_params_set_numbers(sl_params *p, const char *name, const double *v, int n, sl_err *err);
sl_status sl_params_set_choice(sl_params *p, const char *name, const char *choice, sl_err *err);
/* Back to "auto": only a FLOAT whose schema default is SL_PARAM_AUTO takes it. */
sl_status sl_params_set_auto(sl_params *p, const char *name, sl_err *err);
/* 1 when d is a FLOAT whose default is auto (def[0] is SL_PARAM_AUTO). */
int sl_param_def_has_auto(const sl_param_def *d);
/* 1 when the FLOAT `name` is auto (then sl_params_float is NaN). */
int sl_params_is_auto(const sl_params *p, const char *name);

/* Checked setter of a SL_PARAM_TRANSFER parameter: on failure nothing
 * changes and err names the parameter and the bad point ("point 3 ...")
 * with what is wrong and the allowed range. */
sl_status sl_params_set_transfer(sl_params *p, const char *name, const sl_transfer_function *tf, sl_err *err);
/* The schema default of a SL_PARAM_TRANSFER entry (see sl_param_type). */
void sl_transfer_function_default(const sl_param_def *d, sl_transfer_function *out);
/* Validates tf alone; err names `name` and the bad point. */
sl_status sl_transfer_function_check(const char *name, const sl_transfer_function *tf, sl_err *err);
/* 1 when a and b are the same function as given (field by field). */
int sl_transfer_function_equal(const sl_transfer_function *a, const sl_transfer_function *b);

/* Checked setter of the SL_PARAM_TRANSFER_2D parameter: on failure nothing
 * changes and err names the parameter and the bad widget. */
sl_status sl_params_set_transfer_2d(sl_params *p, const char *name, const sl_transfer_function_2d *tf, sl_err *err);
/* Preset `preset` (sl_tf2d_preset; an unknown index gives preset 0) into out (transfer_2d.c). */
void sl_transfer_function_2d_preset(int preset, sl_transfer_function_2d *out);
/* Validates tf alone; err names `name` and the bad widget
 * ("parameter 'curvature_tf': widget 3: radius 0 must be > 0"). */
sl_status sl_transfer_function_2d_check(const char *name, const sl_transfer_function_2d *tf, sl_err *err);
/* 1 when a and b are the same function (count, range and the used widgets). */
int sl_transfer_function_2d_equal(const sl_transfer_function_2d *a, const sl_transfer_function_2d *b);

/* Getters for techniques; the name must exist in the schema with that type
 * (a programmer error otherwise: asserts, then returns 0). */
double sl_params_float(const sl_params *p, const char *name);
int sl_params_int(const sl_params *p, const char *name);
bool sl_params_bool(const sl_params *p, const char *name);
int sl_params_attribute(const sl_params *p, const char *name);    /* attribute index, -1 = none */
int sl_params_choice(const sl_params *p, const char *name);       /* enum index */
const char *sl_params_choice_name(const sl_params *p, const char *name);
void sl_params_vec3(const sl_params *p, const char *name, float out[3]);
const sl_transfer_function *sl_params_transfer(const sl_params *p, const char *name); /* borrowed from p */
/* The list's numbers into out (zero past the count); returns the count, 0 = auto. */
int sl_params_values(const sl_params *p, const char *name, double out[SL_PARAM_VALUES_MAX]);
const sl_transfer_function_2d *sl_params_transfer_2d(const sl_params *p, const char *name); /* borrowed from p */

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
