/* params_json.c — technique parameters to and from JSON (see sl_params_json.h). */
#include "sl_params_json.h"

#include "core/sl_colormap.h"
#include "data/sl_dataset.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* "a, b, c": the choices of an enum, for messages. */
static void choice_list(const sl_param_def *d, char *list, size_t size)
{
    list[0] = '\0';
    for (int k = 0; d->choices[k]; k++) {
        if (k)
            strncat(list, ", ", size - strlen(list) - 1);
        strncat(list, d->choices[k], size - strlen(list) - 1);
    }
}

/* A number given for an enum: the choice of that name when the choices are
 * numbers (quantization 4 means "4", not the fifth choice), else an index.
 * When some choice names are numbers and none matches, it is refused rather
 * than read as an index, which would silently mean another value. */
static sl_status apply_enum_number(sl_params *p, const sl_param_def *d, double v, sl_err *err)
{
    char text[32];
    snprintf(text, sizeof text, "%.17g", v);
    int numeric_names = 0;
    for (int k = 0; d->choices[k]; k++) {
        char *end = NULL;
        double c = strtod(d->choices[k], &end);
        if (end != d->choices[k] && *end == '\0') {
            numeric_names = 1;
            if (c == v)
                return sl_params_set_choice(p, d->name, d->choices[k], err);
        }
    }
    if (numeric_names) {
        char list[400];
        choice_list(d, list, sizeof list);
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' has no choice %s (choices: %s)", d->name, text, list);
    }
    return sl_params_set_numbers(p, d->name, &v, 1, err);
}

/* A transfer function from JSON: [[value, r, g, b, a], ...] (data units) or
 * {"colormap": name, "opacity": [[t, alpha], ...] | "auto", "range": [lo, hi]}
 * ("opacity" defaults to [[0, 0], [1, 1]], "range" to the dataset's value
 * range; "auto": the ramp the volume technique picks from the histogram). Shape errors name the point; value errors come from
 * sl_params_set_transfer. */
static sl_status apply_transfer(sl_params *p, const char *name, const cJSON *item, sl_err *err)
{
    static const char usage[] = "[[value, r, g, b, a], ...] or {\"colormap\": name, \"opacity\": [[t, alpha], ...] "
                                "or \"auto\", \"range\": [low, high]}";
    sl_transfer_function tf;
    memset(&tf, 0, sizeof tf);
    const cJSON *points = item;
    int width = 5;
    tf.colormap = -1;
    if (cJSON_IsObject(item)) {
        width = 2;
        for (const cJSON *k = item->child; k; k = k->next)
            if (strcmp(k->string, "colormap") != 0 && strcmp(k->string, "opacity") != 0 && strcmp(k->string, "range") != 0)
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': unknown key '%.40s' (takes %s)", name, k->string, usage);
        const cJSON *cm = cJSON_GetObjectItemCaseSensitive(item, "colormap");
        if (!cJSON_IsString(cm))
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': \"colormap\" must be a colormap name (takes %s)", name, usage);
        for (int k = 0; sl_colormap_names[k]; k++)
            if (strcmp(sl_colormap_names[k], cm->valuestring) == 0)
                tf.colormap = k;
        if (tf.colormap < 0) {
            char list[200] = "";
            for (int k = 0; sl_colormap_names[k]; k++)
                snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? ", " : "", sl_colormap_names[k]);
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': no colormap '%.60s' (colormaps: %s)", name,
                              cm->valuestring, list);
        }
        const cJSON *range = cJSON_GetObjectItemCaseSensitive(item, "range");
        if (range) {
            if (!cJSON_IsArray(range) || cJSON_GetArraySize(range) != 2 || !cJSON_IsNumber(cJSON_GetArrayItem(range, 0)) ||
                !cJSON_IsNumber(cJSON_GetArrayItem(range, 1)))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': \"range\" must be [low, high] in data units", name);
            tf.has_range = 1;
            tf.range[0] = cJSON_GetArrayItem(range, 0)->valuedouble;
            tf.range[1] = cJSON_GetArrayItem(range, 1)->valuedouble;
        }
        points = cJSON_GetObjectItemCaseSensitive(item, "opacity");
        if (cJSON_IsString(points)) {
            if (strcmp(points->valuestring, "auto") != 0)
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': \"opacity\" must be \"auto\" or "
                                  "[[t, alpha], ...] (got \"%.40s\")", name, points->valuestring);
            tf.auto_opacity = 1;
            return sl_params_set_transfer(p, name, &tf, err);
        }
        if (!points) {
            tf.count = 2;
            tf.point[1][0] = tf.point[1][1] = 1.0;
            return sl_params_set_transfer(p, name, &tf, err);
        }
    }
    if (!cJSON_IsArray(points))
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes %s", name, usage);
    int n = cJSON_GetArraySize(points);
    if (n < 1 || n > SL_TF_MAX_POINTS)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes 1 to %d points, got %d", name, SL_TF_MAX_POINTS, n);
    tf.count = n;
    int k = 0;
    for (const cJSON *pt = points->child; pt; pt = pt->next, k++) {
        if (!cJSON_IsArray(pt) || cJSON_GetArraySize(pt) != width)
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': point %d must be %s", name, k,
                              width == 5 ? "[value, r, g, b, a]" : "[t, alpha]");
        int c = 0;
        for (const cJSON *e = pt->child; e; e = e->next, c++) {
            if (!cJSON_IsNumber(e))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': point %d must be %s of numbers", name, k,
                                  width == 5 ? "[value, r, g, b, a]" : "[t, alpha]");
            tf.point[k][c] = e->valuedouble;
        }
    }
    return sl_params_set_transfer(p, name, &tf, err);
}

/* A VALUES list from JSON: an array of 0 .. SL_PARAM_VALUES_MAX numbers ([] = auto);
 * range errors come from sl_params_set_numbers, naming the index. */
static sl_status apply_values(sl_params *p, const sl_param_def *d, const cJSON *item, sl_err *err)
{
    const char *space = d->unit[0] ? " " : "";
    if (!cJSON_IsArray(item))
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be an array of 0 to %d numbers in [%g, %g]%s%s "
                          "([] = auto)", d->name, SL_PARAM_VALUES_MAX, d->min, d->max, space, d->unit);
    int n = cJSON_GetArraySize(item);
    if (n > SL_PARAM_VALUES_MAX)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes at most %d values in [%g, %g]%s%s, got %d",
                          d->name, SL_PARAM_VALUES_MAX, d->min, d->max, space, d->unit, n);
    double v[SL_PARAM_VALUES_MAX];
    int k = 0;
    for (const cJSON *e = item->child; e; e = e->next, k++) {
        if (!cJSON_IsNumber(e))
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': value %d must be a number in [%g, %g]%s%s", d->name,
                              k, d->min, d->max, space, d->unit);
        v[k] = e->valuedouble;
    }
    return sl_params_set_numbers(p, d->name, v, n, err);
}

/* A 2D transfer function from JSON: {"range": r, "widgets": [[k1, k2, radius,
 * r, g, b, a], ...]}, both keys required. Shape errors name the widget;
 * value errors come from sl_params_set_transfer_2d. */
static sl_status apply_transfer_2d(sl_params *p, const char *name, const cJSON *item, sl_err *err)
{
    static const char usage[] = "{\"range\": r, \"widgets\": [[k1, k2, radius, r, g, b, a], ...]}";
    if (!cJSON_IsObject(item))
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes %s", name, usage);
    for (const cJSON *k = item->child; k; k = k->next)
        if (strcmp(k->string, "range") != 0 && strcmp(k->string, "widgets") != 0)
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': unknown key '%.40s' (takes %s)", name, k->string,
                              usage);
    const cJSON *range = cJSON_GetObjectItemCaseSensitive(item, "range");
    const cJSON *widgets = cJSON_GetObjectItemCaseSensitive(item, "widgets");
    if (!cJSON_IsNumber(range))
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': \"range\" must be a number > 0 (takes %s)", name, usage);
    if (!cJSON_IsArray(widgets))
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': \"widgets\" must be an array (takes %s)", name, usage);
    int n = cJSON_GetArraySize(widgets);
    if (n < 1 || n > SL_TF2D_MAX_WIDGETS)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes 1 to %d widgets, got %d", name,
                          SL_TF2D_MAX_WIDGETS, n);
    sl_transfer_function_2d tf;
    memset(&tf, 0, sizeof tf);
    tf.count = n;
    tf.range = range->valuedouble;
    int k = 0;
    for (const cJSON *w = widgets->child; w; w = w->next, k++) {
        if (!cJSON_IsArray(w) || cJSON_GetArraySize(w) != 7)
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': widget %d must be [k1, k2, radius, r, g, b, a]",
                              name, k);
        int c = 0;
        for (const cJSON *e = w->child; e; e = e->next, c++) {
            if (!cJSON_IsNumber(e))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': widget %d must be [k1, k2, radius, r, g, b, a] "
                                  "of numbers", name, k);
            tf.widget[k][c] = e->valuedouble;
        }
    }
    return sl_params_set_transfer_2d(p, name, &tf, err);
}

static sl_status apply_one(sl_params *p, const cJSON *item, sl_err *err)
{
    const char *name = item->string;
    int i = sl_params_find(p, name);
    if (i < 0) {
        double dummy = 0.0;
        return sl_params_set_numbers(p, name, &dummy, 1, err); /* reports the unknown name with the known list */
    }
    const sl_param_def *d = &p->schema[i];
    switch (d->type) {
    case SL_PARAM_BOOL:
        if (!cJSON_IsBool(item))
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be true or false", name);
        return sl_params_set_numbers(p, name, &(double){cJSON_IsTrue(item) ? 1.0 : 0.0}, 1, err);
    case SL_PARAM_ENUM: {
        if (cJSON_IsString(item))
            return sl_params_set_choice(p, name, item->valuestring, err);
        if (cJSON_IsNumber(item))
            return apply_enum_number(p, d, item->valuedouble, err);
        char list[400];
        choice_list(d, list, sizeof list);
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be a choice name (choices: %s)", name, list);
    }
    case SL_PARAM_VEC3: {
        double v[3];
        if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3)
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be an array of 3 numbers in [%g, %g]", name, d->min, d->max);
        for (int k = 0; k < 3; k++) {
            const cJSON *e = cJSON_GetArrayItem(item, k);
            if (!cJSON_IsNumber(e))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be an array of 3 numbers in [%g, %g]", name, d->min, d->max);
            v[k] = e->valuedouble;
        }
        return sl_params_set_numbers(p, name, v, 3, err);
    }
    case SL_PARAM_ATTRIBUTE:
        if (!cJSON_IsNumber(item))
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be an attribute index in [%g, %g]%s", name,
                              d->min, d->max, d->min < 0 ? " (-1 = none)" : "");
        return sl_params_set_numbers(p, name, &item->valuedouble, 1, err);
    case SL_PARAM_TRANSFER:
        return apply_transfer(p, name, item, err);
    case SL_PARAM_VALUES:
        return apply_values(p, d, item, err);
    case SL_PARAM_TRANSFER_2D:
        return apply_transfer_2d(p, name, item, err);
    case SL_PARAM_FLOAT:
    case SL_PARAM_INT:
        if (sl_param_def_has_auto(d) && cJSON_IsString(item) && strcmp(item->valuestring, "auto") == 0)
            return sl_params_set_auto(p, name, err);
        if (!cJSON_IsNumber(item))
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be a number in [%g, %g]%s", name, d->min,
                              d->max, sl_param_def_has_auto(d) ? " or \"auto\"" : "");
        return sl_params_set_numbers(p, name, &item->valuedouble, 1, err);
    }
    return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' has an unknown type", name);
}

sl_status sl_params_apply_json(sl_params *params, const cJSON *patch, sl_err *err)
{
    if (!patch || cJSON_IsNull(patch))
        return SL_OK;
    if (!cJSON_IsObject(patch))
        return sl_err_set(err, SL_ERR_INVALID, "params must be an object of name: value");
    sl_params next = *params;
    for (const cJSON *item = patch->child; item; item = item->next) {
        sl_status st = apply_one(&next, item, err);
        if (st != SL_OK)
            return st;
    }
    *params = next;
    return SL_OK;
}

static cJSON *transfer_json(const sl_transfer_function *tf)
{
    if (tf->colormap < 0) {
        cJSON *a = cJSON_CreateArray();
        for (int k = 0; a && k < tf->count; k++)
            cJSON_AddItemToArray(a, cJSON_CreateDoubleArray(tf->point[k], 5));
        return a;
    }
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "colormap", sl_colormap_names[tf->colormap]);
    if (tf->auto_opacity) {
        cJSON_AddStringToObject(o, "opacity", "auto");
    } else {
        cJSON *a = cJSON_AddArrayToObject(o, "opacity");
        for (int k = 0; a && k < tf->count; k++)
            cJSON_AddItemToArray(a, cJSON_CreateDoubleArray(tf->point[k], 2));
    }
    if (tf->has_range)
        cJSON_AddItemToObject(o, "range", cJSON_CreateDoubleArray(tf->range, 2));
    return o;
}

static cJSON *transfer_2d_json(const sl_transfer_function_2d *tf)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "range", tf->range);
    cJSON *a = cJSON_AddArrayToObject(o, "widgets");
    for (int k = 0; a && k < tf->count; k++)
        cJSON_AddItemToArray(a, cJSON_CreateDoubleArray(tf->widget[k], 7));
    return o;
}

/* [v0, ...] of a VALUES list ([] when empty). */
static cJSON *values_json(const double *v, int count)
{
    cJSON *a = cJSON_CreateArray();
    for (int k = 0; a && k < count; k++)
        cJSON_AddItemToArray(a, cJSON_CreateNumber(v[k]));
    return a;
}

/* The value of entry d, of which v holds the numbers (a schema default: d->def). */
static cJSON *value_json(const sl_param_def *d, const double *v)
{
    switch (d->type) {
    case SL_PARAM_TRANSFER: {
        sl_transfer_function tf;
        sl_transfer_function_default(d, &tf);
        return transfer_json(&tf);
    }
    case SL_PARAM_TRANSFER_2D: {
        sl_transfer_function_2d tf;
        sl_transfer_function_2d_preset((int)d->def[0], &tf);
        return transfer_2d_json(&tf);
    }
    case SL_PARAM_VALUES: return values_json(v, 0); /* the default: the empty list */
    case SL_PARAM_BOOL: return cJSON_CreateBool(v[0] != 0.0);
    case SL_PARAM_ENUM: return cJSON_CreateString(d->choices[(int)v[0]]);
    case SL_PARAM_VEC3: return cJSON_CreateDoubleArray(v, 3);
    case SL_PARAM_FLOAT:
        if (isnan(v[0])) /* auto (sl_param_def_has_auto); no other float holds NaN */
            return cJSON_CreateString("auto");
        return cJSON_CreateNumber(v[0]);
    case SL_PARAM_INT:
    case SL_PARAM_ATTRIBUTE: return cJSON_CreateNumber(v[0]);
    }
    return cJSON_CreateNull();
}

cJSON *sl_params_to_json(const sl_params *p)
{
    cJSON *o = cJSON_CreateObject();
    for (int i = 0; o && i < p->count; i++) {
        const sl_param_def *d = &p->schema[i];
        cJSON *v = d->type == SL_PARAM_TRANSFER      ? transfer_json(&p->tf[(int)p->value[i][0]])
                   : d->type == SL_PARAM_TRANSFER_2D ? transfer_2d_json(&p->tf2d)
                   : d->type == SL_PARAM_VALUES      ? values_json(p->value[i], p->value_count[i])
                                                     : value_json(d, p->value[i]);
        cJSON_AddItemToObject(o, d->name, v);
    }
    return o;
}

static const char *invalidation_name(sl_invalidation level)
{
    switch (level) {
    case SL_INVALIDATE_NONE: return "none";
    case SL_INVALIDATE_FRAME: return "frame";
    case SL_INVALIDATE_PREPARED: return "prepared";
    case SL_INVALIDATE_DATASET: return "dataset";
    }
    return "frame";
}

cJSON *sl_params_schema_json(const sl_param_def *schema, int count)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < count; i++) {
        const sl_param_def *d = &schema[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", d->name);
        cJSON_AddStringToObject(o, "type", sl_param_type_name(d->type));
        if (d->type == SL_PARAM_FLOAT || d->type == SL_PARAM_INT || d->type == SL_PARAM_VEC3 ||
            d->type == SL_PARAM_ATTRIBUTE || d->type == SL_PARAM_VALUES) {
            cJSON_AddNumberToObject(o, "min", d->min);
            cJSON_AddNumberToObject(o, "max", d->max);
        }
        if (d->type == SL_PARAM_VALUES)
            cJSON_AddNumberToObject(o, "max_count", SL_PARAM_VALUES_MAX);
        if (d->type == SL_PARAM_TRANSFER_2D)
            cJSON_AddNumberToObject(o, "max_widgets", SL_TF2D_MAX_WIDGETS);
        cJSON_AddItemToObject(o, "default", value_json(d, d->def));
        if (d->type == SL_PARAM_ENUM) {
            cJSON *c = cJSON_AddArrayToObject(o, "choices");
            for (int k = 0; d->choices[k]; k++)
                cJSON_AddItemToArray(c, cJSON_CreateString(d->choices[k]));
        }
        if (d->type == SL_PARAM_TRANSFER) {
            /* The colormaps a value may name, each sampled at t = k / 16, so a
             * client can draw and edit the colormap form without tables of its own. */
            cJSON *maps = cJSON_AddArrayToObject(o, "colormaps");
            for (int k = 0; sl_colormap_names[k]; k++) {
                cJSON *m = cJSON_CreateObject();
                cJSON_AddStringToObject(m, "name", sl_colormap_names[k]);
                cJSON *colors = cJSON_AddArrayToObject(m, "colors");
                for (int j = 0; j <= 16; j++) {
                    float rgb[3];
                    sl_colormap_sample(k, j / 16.0, rgb);
                    double c[3];
                    for (int i2 = 0; i2 < 3; i2++)
                        c[i2] = round(rgb[i2] * 1000.0) / 1000.0;
                    cJSON_AddItemToArray(colors, cJSON_CreateDoubleArray(c, 3));
                }
                cJSON_AddItemToArray(maps, m);
            }
        }
        cJSON_AddStringToObject(o, "unit", d->unit ? d->unit : "");
        cJSON_AddStringToObject(o, "description", d->description ? d->description : "");
        cJSON_AddStringToObject(o, "invalidates", invalidation_name(d->invalidates));
        cJSON_AddItemToArray(a, o);
    }
    return a;
}

cJSON *sl_technique_json(const sl_technique *t)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "name", t->name);
    cJSON_AddStringToObject(o, "description", t->description);
    cJSON *kinds = cJSON_AddArrayToObject(o, "dataset_kinds");
    for (int i = 0; i < SL_DATASET_KIND_COUNT; i++)
        if (t->dataset_kinds & (unsigned)sl_dataset_kinds[i])
            cJSON_AddItemToArray(kinds, cJSON_CreateString(sl_dataset_kind_name(sl_dataset_kinds[i])));
    cJSON_AddItemToObject(o, "params", sl_params_schema_json(t->params, t->param_count));
    return o;
}
