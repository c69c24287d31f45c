/* test_params.c — parameter schemas and their validation (core/sl_params.h, proto/sl_params_json.h).
 *
 * For every registered technique and every parameter: the schema is sane
 * (unique names, min <= max, a unit and a description), the default lies in
 * range and re-validates, a valid non-default value (given as JSON) is
 * applied and sl_params_compare reports exactly the declared invalidation
 * level, both ends of the range are accepted, values just outside, NaN and
 * +-Inf, wrong JSON types, non-integers and unknown names are rejected with
 * a message that names the parameter and the allowed range (or choices),
 * and a failed patch changes nothing. The schema JSON is checked field by
 * field against the C tables. A private schema covers every type and every
 * invalidation level, and the typed getters. Attribute indices: the schema
 * range ("none" = -1 only where min is -1), JSON numbers only, and the
 * dataset check (sl_params_check_attributes) word for word; every technique
 * declares `attribute` and `radius_attribute` with that type. Lists
 * (values): 0 to 4 numbers, the empty default, a 5th refused, each value's
 * range with its index named, JSON round trips, compare seeing the count and
 * each value. 2D transfer functions (transfer_2d): the preset default, JSON
 * both ways, each kind of bad widget refused naming the widget, equality.
 * The private schema holds one of each, so both are covered before any
 * technique declares them. No GL.
 */
#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/sl_colormap.h"
#include "core/sl_params.h"
#include "core/sl_technique.h"
#include "sl_params_json.h"
#include "sl_test.h"

static int choice_count(const sl_param_def *d)
{
    int n = 0;
    while (d->choices && d->choices[n])
        n++;
    return n;
}

static int is_numeric(const sl_param_def *d)
{
    return d->type == SL_PARAM_FLOAT || d->type == SL_PARAM_INT || d->type == SL_PARAM_VEC3 ||
           d->type == SL_PARAM_ATTRIBUTE;
}

static int same_values(const sl_params *a, const sl_params *b)
{
    /* compare also sees transfer functions (kept apart from value[]). */
    return a->count == b->count && memcmp(a->value, b->value, sizeof a->value) == 0 &&
           sl_params_compare(a, b) == SL_INVALIDATE_NONE;
}

/* Does the message name the parameter and its allowed range (or its choices)? */
static int names_range(const char *msg, const sl_param_def *d)
{
    char name[80];
    snprintf(name, sizeof name, "'%s'", d->name);
    if (!strstr(msg, name))
        return 0;
    char range[96];
    switch (d->type) {
    case SL_PARAM_FLOAT:
    case SL_PARAM_INT:
    case SL_PARAM_VEC3:
    case SL_PARAM_ATTRIBUTE:
        snprintf(range, sizeof range, "[%g, %g]", d->min, d->max);
        return strstr(msg, range) != NULL;
    case SL_PARAM_BOOL:
        return strstr(msg, "true") && strstr(msg, "false");
    case SL_PARAM_ENUM: {
        /* Either every choice by name or the index range. */
        int all = 1;
        for (int k = 0; d->choices[k]; k++)
            all &= strstr(msg, d->choices[k]) != NULL;
        snprintf(range, sizeof range, "[0, %d]", choice_count(d) - 1);
        return all || strstr(msg, range) != NULL;
    }
    case SL_PARAM_TRANSFER:
        return strstr(msg, "point") != NULL || strstr(msg, "[[value, r, g, b, a], ...]") != NULL;
    case SL_PARAM_VALUES:
        snprintf(range, sizeof range, "[%g, %g]", d->min, d->max);
        return strstr(msg, range) != NULL;
    case SL_PARAM_TRANSFER_2D:
        return strstr(msg, "widget") != NULL;
    }
    return 0;
}

/* Applies {name: item} (item is consumed); returns the status, err filled. */
static sl_status apply_one(sl_params *p, const char *name, cJSON *item, sl_err *err)
{
    cJSON *patch = cJSON_CreateObject();
    cJSON_AddItemToObject(patch, name, item);
    sl_status st = sl_params_apply_json(p, patch, err);
    cJSON_Delete(patch);
    return st;
}

/* Expects the patch to be refused with the parameter and range named, and nothing changed. */
static void expect_refused(const sl_params *base, const sl_param_def *d, cJSON *item, const char *what)
{
    sl_params p = *base;
    sl_err err = {0};
    char *text = cJSON_PrintUnformatted(item);
    sl_status st = apply_one(&p, d->name, item, &err);
    SL_CHECK_MSG(st == SL_ERR_INVALID, "%s = %s (%s) was accepted", d->name, text ? text : "?", what);
    SL_CHECK_MSG(names_range(err.message, d), "%s = %s (%s): message '%s' does not name the parameter and range",
                 d->name, text ? text : "?", what, err.message);
    SL_CHECK_MSG(same_values(&p, base), "%s = %s (%s): a refused patch changed values", d->name, text ? text : "?", what);
    cJSON_free(text);
}

static void expect_refused_numbers(const sl_params *base, const sl_param_def *d, double x, const char *what)
{
    sl_params p = *base;
    sl_err err = {0};
    double v[3] = {0, 0, 0};
    int idx = sl_params_find(base, d->name);
    int n = d->type == SL_PARAM_VEC3 ? 3 : 1;
    memcpy(v, base->value[idx], sizeof v);
    v[n - 1] = x;                               /* the last component is the bad one */
    sl_status st = sl_params_set_numbers(&p, d->name, v, n, &err);
    SL_CHECK_MSG(st == SL_ERR_INVALID, "%s = %g (%s) was accepted", d->name, x, what);
    SL_CHECK_MSG(names_range(err.message, d), "%s = %g (%s): message '%s' does not name the parameter and range",
                 d->name, x, what, err.message);
    SL_CHECK_MSG(same_values(&p, base), "%s = %g (%s): a refused set changed values", d->name, x, what);
    /* The same through JSON (cJSON holds NaN and Inf in memory even though JSON text cannot). */
    cJSON *item;
    if (d->type == SL_PARAM_VEC3)
        item = cJSON_CreateDoubleArray(v, 3);
    else
        item = cJSON_CreateNumber(x);
    if (d->type == SL_PARAM_BOOL) {
        cJSON_Delete(item);
        return;                                 /* bools take true/false in JSON, checked elsewhere */
    }
    expect_refused(base, d, item, what);
}

/* A valid value different from the default, as JSON; NULL when there is none. */
static cJSON *other_value(const sl_param_def *d, double out[3])
{
    memcpy(out, d->def, 3 * sizeof(double));
    switch (d->type) {
    case SL_PARAM_FLOAT:
    case SL_PARAM_VEC3:
        if (d->min == d->max)
            return NULL;
        if (isnan(d->def[0])) { /* auto: a number in the range is the other value */
            out[0] = 0.5 * d->min + 0.5 * d->max;
            return cJSON_CreateNumber(out[0]);
        }
        out[0] = d->def[0] < d->max ? d->def[0] + 0.5 * (d->max - d->def[0]) : 0.5 * (d->min + d->def[0]);
        return d->type == SL_PARAM_FLOAT ? cJSON_CreateNumber(out[0]) : cJSON_CreateDoubleArray(out, 3);
    case SL_PARAM_INT:
    case SL_PARAM_ATTRIBUTE:
        if (d->min == d->max)
            return NULL;
        out[0] = d->def[0] < d->max ? d->def[0] + 1 : d->def[0] - 1;
        return cJSON_CreateNumber(out[0]);
    case SL_PARAM_BOOL:
        out[0] = d->def[0] != 0.0 ? 0.0 : 1.0;
        return cJSON_CreateBool(out[0] != 0.0);
    case SL_PARAM_ENUM: {
        int n = choice_count(d);
        if (n < 2)
            return NULL;
        out[0] = ((int)d->def[0] + 1) % n;
        return cJSON_CreateString(d->choices[(int)out[0]]);
    }
    case SL_PARAM_TRANSFER: /* test_transfer_parameter */
    case SL_PARAM_VALUES: /* test_values_parameter */
    case SL_PARAM_TRANSFER_2D: /* test_transfer_2d_parameter */
        return NULL;
    }
    return NULL;
}

static const char *invalidation_name(sl_invalidation l)
{
    static const char *const names[] = {"none", "frame", "prepared", "dataset"};
    return l >= SL_INVALIDATE_NONE && l <= SL_INVALIDATE_DATASET ? names[l] : "?";
}

/* Checks one schema entry's JSON description against the C table. */
static void check_schema_json(const cJSON *o, const sl_param_def *d, const char *tech)
{
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(o, "name");
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(o, "type");
    const cJSON *def = cJSON_GetObjectItemCaseSensitive(o, "default");
    const cJSON *inv = cJSON_GetObjectItemCaseSensitive(o, "invalidates");
    const cJSON *unit = cJSON_GetObjectItemCaseSensitive(o, "unit");
    SL_CHECK_MSG(cJSON_IsString(name) && strcmp(name->valuestring, d->name) == 0, "%s: schema JSON name", tech);
    SL_CHECK_MSG(cJSON_IsString(type) && strcmp(type->valuestring, sl_param_type_name(d->type)) == 0,
                 "%s.%s: schema JSON type", tech, d->name);
    SL_CHECK_MSG(cJSON_IsString(inv) && strcmp(inv->valuestring, invalidation_name(d->invalidates)) == 0,
                 "%s.%s: schema JSON invalidates '%s', declared '%s'", tech, d->name,
                 cJSON_IsString(inv) ? inv->valuestring : "?", invalidation_name(d->invalidates));
    SL_CHECK_MSG(cJSON_IsString(unit) && strcmp(unit->valuestring, d->unit) == 0, "%s.%s: unit", tech, d->name);
    if (is_numeric(d) || d->type == SL_PARAM_VALUES) {
        const cJSON *mn = cJSON_GetObjectItemCaseSensitive(o, "min"), *mx = cJSON_GetObjectItemCaseSensitive(o, "max");
        SL_CHECK_MSG(cJSON_IsNumber(mn) && cJSON_IsNumber(mx) && mn->valuedouble == d->min && mx->valuedouble == d->max,
                     "%s.%s: schema JSON range", tech, d->name);
    }
    int def_ok = 0;
    switch (d->type) {
    case SL_PARAM_FLOAT:
        if (isnan(d->def[0])) { /* an "auto" default (SL_PARAM_AUTO) */
            def_ok = cJSON_IsString(def) && strcmp(def->valuestring, "auto") == 0;
            break;
        }
        /* fall through */
    case SL_PARAM_INT:
    case SL_PARAM_ATTRIBUTE: def_ok = cJSON_IsNumber(def) && def->valuedouble == d->def[0]; break;
    case SL_PARAM_BOOL: def_ok = cJSON_IsBool(def) && cJSON_IsTrue(def) == (d->def[0] != 0.0); break;
    case SL_PARAM_ENUM: {
        def_ok = cJSON_IsString(def) && strcmp(def->valuestring, d->choices[(int)d->def[0]]) == 0;
        const cJSON *ch = cJSON_GetObjectItemCaseSensitive(o, "choices");
        int n = choice_count(d), same = cJSON_IsArray(ch) && cJSON_GetArraySize(ch) == n;
        for (int k = 0; same && k < n; k++) {
            const cJSON *c = cJSON_GetArrayItem(ch, k);
            same = cJSON_IsString(c) && strcmp(c->valuestring, d->choices[k]) == 0;
        }
        SL_CHECK_MSG(same, "%s.%s: schema JSON choices", tech, d->name);
        break;
    }
    case SL_PARAM_VEC3:
        def_ok = cJSON_IsArray(def) && cJSON_GetArraySize(def) == 3;
        for (int k = 0; def_ok && k < 3; k++)
            def_ok = cJSON_GetArrayItem(def, k)->valuedouble == d->def[k];
        break;
    case SL_PARAM_TRANSFER: {
        /* {"colormap": choices[def[0]], "opacity": [[0, def[1]], [1, def[2]]] or "auto"} */
        const cJSON *cm = cJSON_GetObjectItemCaseSensitive(def, "colormap");
        const cJSON *op = cJSON_GetObjectItemCaseSensitive(def, "opacity");
        def_ok = cJSON_IsString(cm) && strcmp(cm->valuestring, sl_colormap_names[(int)d->def[0]]) == 0;
        if (d->def[1] == SL_TF_AUTO_OPACITY)
            def_ok = def_ok && cJSON_IsString(op) && strcmp(op->valuestring, "auto") == 0;
        else
            def_ok = def_ok && cJSON_GetArraySize(op) == 2 &&
                     cJSON_GetArrayItem(cJSON_GetArrayItem(op, 0), 1)->valuedouble == d->def[1] &&
                     cJSON_GetArrayItem(cJSON_GetArrayItem(op, 1), 1)->valuedouble == d->def[2];
        /* colormaps: every name a value may take, in order, each with 17 colours; the
         * middle one is sl_colormap_sample at t = 0.5 (to 1e-3). */
        const cJSON *maps = cJSON_GetObjectItemCaseSensitive(o, "colormaps");
        int k = 0, maps_ok = cJSON_IsArray(maps);
        const cJSON *m;
        cJSON_ArrayForEach(m, maps) {
            const cJSON *mn = cJSON_GetObjectItemCaseSensitive(m, "name");
            const cJSON *colors = cJSON_GetObjectItemCaseSensitive(m, "colors");
            float mid[3];
            maps_ok = maps_ok && sl_colormap_names[k] && cJSON_IsString(mn) &&
                      strcmp(mn->valuestring, sl_colormap_names[k]) == 0 && cJSON_GetArraySize(colors) == 17;
            if (!maps_ok)
                break;
            sl_colormap_sample(k, 0.5, mid);
            for (int c = 0; c < 3; c++)
                maps_ok = maps_ok && fabs(cJSON_GetArrayItem(cJSON_GetArrayItem(colors, 8), c)->valuedouble - mid[c]) <= 1e-3;
            k++;
        }
        SL_CHECK_MSG(maps_ok && !sl_colormap_names[k], "%s.%s: schema JSON colormaps (%d listed)", tech, d->name, k);
        break;
    }
    case SL_PARAM_VALUES: {
        /* The empty list, and how long a list may be. */
        const cJSON *mc = cJSON_GetObjectItemCaseSensitive(o, "max_count");
        def_ok = cJSON_IsArray(def) && cJSON_GetArraySize(def) == 0 && cJSON_IsNumber(mc) &&
                 mc->valuedouble == SL_PARAM_VALUES_MAX;
        break;
    }
    case SL_PARAM_TRANSFER_2D: {
        /* The preset def[0], widget by widget, and the widget limit. */
        sl_transfer_function_2d preset;
        sl_transfer_function_2d_preset((int)d->def[0], &preset);
        const cJSON *range = cJSON_GetObjectItemCaseSensitive(def, "range");
        const cJSON *widgets = cJSON_GetObjectItemCaseSensitive(def, "widgets");
        const cJSON *mw = cJSON_GetObjectItemCaseSensitive(o, "max_widgets");
        def_ok = cJSON_IsNumber(range) && range->valuedouble == preset.range && cJSON_IsArray(widgets) &&
                 cJSON_GetArraySize(widgets) == preset.count && cJSON_IsNumber(mw) &&
                 mw->valuedouble == SL_TF2D_MAX_WIDGETS;
        for (int k = 0; def_ok && k < preset.count; k++)
            for (int c = 0; def_ok && c < 7; c++) {
                const cJSON *e = cJSON_GetArrayItem(cJSON_GetArrayItem(widgets, k), c);
                def_ok = cJSON_IsNumber(e) && e->valuedouble == preset.widget[k][c];
            }
        break;
    }
    }
    SL_CHECK_MSG(def_ok, "%s.%s: schema JSON default", tech, d->name);
}

/* Applies the JSON text to a copy of base for a transfer-function parameter;
 * expects it refused with a message holding every `needles` (NULL-ended)
 * and nothing changed. */
static void expect_tf_refused(const sl_params *base, const sl_param_def *d, const char *json, const char *const *needles)
{
    sl_params p = *base;
    sl_err err = {0};
    cJSON *item = cJSON_Parse(json);
    SL_CHECK_MSG(item != NULL, "bad test JSON %s", json);
    sl_status st = apply_one(&p, d->name, item, &err);
    SL_CHECK_MSG(st == SL_ERR_INVALID, "%s = %s was accepted", d->name, json);
    char name[80];
    snprintf(name, sizeof name, "'%s'", d->name);
    SL_CHECK_MSG(strstr(err.message, name) != NULL, "%s = %s: message '%s' does not name it", d->name, json, err.message);
    for (int k = 0; needles[k]; k++)
        SL_CHECK_MSG(strstr(err.message, needles[k]) != NULL, "%s = %s: message '%s' lacks '%s'", d->name, json,
                     err.message, needles[k]);
    SL_CHECK_MSG(same_values(&p, base), "%s = %s: a refused patch changed values", d->name, json);
}

/* A SL_PARAM_TRANSFER parameter: both JSON forms apply, round-trip through
 * sl_params_to_json and report the declared level; each kind of bad point
 * is refused naming the point. */
static void test_transfer_parameter(const sl_technique *t, int i)
{
    const sl_param_def *d = &t->params[i];
    sl_params base;
    sl_params_init(&base, t->params, t->param_count);
    sl_err err = {0};
    const sl_transfer_function *def = sl_params_transfer(&base, d->name);
    if (d->def[1] == SL_TF_AUTO_OPACITY)
        SL_CHECK_MSG(def->colormap == (int)d->def[0] && def->auto_opacity && def->count == 0,
                     "%s.%s: automatic default", t->name, d->name);
    else
        SL_CHECK_MSG(def->colormap == (int)d->def[0] && !def->auto_opacity && def->count == 2 &&
                     def->point[1][1] == d->def[2], "%s.%s: default", t->name, d->name);
    SL_CHECK(sl_transfer_function_check(d->name, def, &err) == SL_OK);
    const char *good[] = {"[[0, 0, 0, 0, 0], [0.5, 1, 0.5, 0.25, 0.1], [2, 1, 1, 1, 1]]",
                          "{\"colormap\": \"magma\", \"opacity\": [[0, 0], [0.5, 0.2], [1, 1]], \"range\": [-1, 2]}",
                          "{\"colormap\": \"gray\"}", "[[3, 1, 0, 0, 0.5]]",
                          "{\"colormap\": \"magma\", \"opacity\": \"auto\", \"range\": [-1, 2]}"};
    for (int g = 0; g < 5; g++) {
        sl_params p = base;
        cJSON *item = cJSON_Parse(good[g]);
        sl_status st = apply_one(&p, d->name, item, &err);
        SL_CHECK_MSG(st == SL_OK, "%s.%s = %s: %s", t->name, d->name, good[g], err.message);
        SL_CHECK_MSG(sl_params_compare(&base, &p) == d->invalidates, "%s.%s = %s: compare", t->name, d->name, good[g]);
        cJSON *all = sl_params_to_json(&p);
        sl_params q = base;
        SL_CHECK_MSG(all && sl_params_apply_json(&q, all, &err) == SL_OK && same_values(&q, &p),
                     "%s.%s = %s: no round trip", t->name, d->name, good[g]);
        cJSON_Delete(all);
    }
    sl_params p = base;
    cJSON *item = cJSON_Parse(good[0]);
    SL_CHECK(apply_one(&p, d->name, item, &err) == SL_OK);
    const sl_transfer_function *tf = sl_params_transfer(&p, d->name);
    SL_CHECK(tf->colormap == -1 && tf->count == 3 && tf->point[1][0] == 0.5 && tf->point[1][3] == 0.25 &&
             tf->point[2][4] == 1.0);
    /* "auto" differs from an explicit ramp and from no ramp. */
    sl_params pa = base, pr = base;
    SL_CHECK(apply_one(&pa, d->name, cJSON_Parse("{\"colormap\": \"gray\", \"opacity\": \"auto\"}"), &err) == SL_OK);
    SL_CHECK(apply_one(&pr, d->name, cJSON_Parse("{\"colormap\": \"gray\"}"), &err) == SL_OK);
    SL_CHECK(sl_params_transfer(&pa, d->name)->auto_opacity && sl_params_transfer(&pa, d->name)->count == 0);
    SL_CHECK(sl_params_compare(&pa, &pr) == d->invalidates);
    /* An automatic ramp in the points form, or with points, is not a function. */
    sl_transfer_function bad = *sl_params_transfer(&pa, d->name);
    bad.colormap = -1;
    SL_CHECK(sl_transfer_function_check(d->name, &bad, &err) == SL_ERR_INVALID && strstr(err.message, "automatic"));
    bad = *sl_params_transfer(&pa, d->name);
    bad.count = 1;
    SL_CHECK(sl_transfer_function_check(d->name, &bad, &err) == SL_ERR_INVALID);

    expect_tf_refused(&base, d, "[[0, 0, 0, 0, 0], [1, 1, 1, 1, 1.5]]", (const char *[]){"point 1", "alpha", "[0, 1]", NULL});
    expect_tf_refused(&base, d, "[[0, 0, 0, 0, 0], [1, 1, 1, 1, 1], [0.5, 0, 0, 0, 0]]",
                      (const char *[]){"point 2", "below point 1", NULL});
    expect_tf_refused(&base, d, "[[0, -0.1, 0, 0, 0]]", (const char *[]){"point 0", "red", NULL});
    expect_tf_refused(&base, d, "[[0, 0, 0, 0]]", (const char *[]){"point 0", "[value, r, g, b, a]", NULL});
    expect_tf_refused(&base, d, "[[0, 0, 0, 0, 0], [1, 1, \"x\", 1, 1]]", (const char *[]){"point 1", NULL});
    expect_tf_refused(&base, d, "[]", (const char *[]){"1 to 64", NULL});
    expect_tf_refused(&base, d, "[[1e400, 0, 0, 0, 0]]", (const char *[]){"point 0", "finite", NULL});
    expect_tf_refused(&base, d, "\"viridis\"", (const char *[]){"[[value, r, g, b, a], ...]", NULL});
    expect_tf_refused(&base, d, "3", (const char *[]){"[[value, r, g, b, a], ...]", NULL});
    expect_tf_refused(&base, d, "{\"colormap\": \"nope\"}", (const char *[]){"nope", "viridis", NULL});
    expect_tf_refused(&base, d, "{\"colormap\": \"gray\", \"range\": [1, 1]}", (const char *[]){"range", NULL});
    expect_tf_refused(&base, d, "{\"colormap\": \"gray\", \"opacity\": [[0.5, 0], [0.2, 1]]}",
                      (const char *[]){"point 1", "t 0.2", NULL});
    expect_tf_refused(&base, d, "{\"colormap\": \"gray\", \"opacity\": [[0, 2]]}",
                      (const char *[]){"point 0", "alpha", NULL});
    expect_tf_refused(&base, d, "{\"colormap\": \"gray\", \"ramp\": []}", (const char *[]){"ramp", NULL});
    expect_tf_refused(&base, d, "{\"colormap\": \"gray\", \"opacity\": \"automatic\"}",
                      (const char *[]){"\"auto\"", "automatic", NULL});
    char many[4096] = "[";
    for (int k = 0; k < SL_TF_MAX_POINTS + 1; k++)
        snprintf(many + strlen(many), sizeof many - strlen(many), "%s[%d, 0, 0, 0, 0]", k ? "," : "", k);
    strcat(many, "]");
    expect_tf_refused(&base, d, many, (const char *[]){"1 to 64", "65", NULL});
    /* Numbers are refused by the number setter too. */
    sl_params q = base;
    SL_CHECK(sl_params_set_numbers(&q, d->name, d->def, 1, &err) == SL_ERR_INVALID && strstr(err.message, d->name));
}

/* Applies the JSON text (for tests) to p; returns the status, err filled. */
static sl_status apply_text(sl_params *p, const char *name, const char *json, sl_err *err)
{
    cJSON *item = cJSON_Parse(json);
    SL_CHECK_MSG(item != NULL, "bad test JSON %s", json);
    return item ? apply_one(p, name, item, err) : SL_ERR_INVALID;
}

/* Expects the JSON text refused for d with a message naming d (quoted) and
 * holding every `needles` (NULL-ended), and nothing changed. */
static void expect_text_refused(const sl_params *base, const sl_param_def *d, const char *json,
                                const char *const *needles)
{
    sl_params p = *base;
    sl_err err = {0};
    SL_CHECK_MSG(apply_text(&p, d->name, json, &err) == SL_ERR_INVALID, "%s = %s was accepted", d->name, json);
    char name[80];
    snprintf(name, sizeof name, "'%s'", d->name);
    SL_CHECK_MSG(strstr(err.message, name) != NULL, "%s = %s: message '%s' does not name it", d->name, json, err.message);
    for (int k = 0; needles[k]; k++)
        SL_CHECK_MSG(strstr(err.message, needles[k]) != NULL, "%s = %s: message '%s' lacks '%s'", d->name, json,
                     err.message, needles[k]);
    SL_CHECK_MSG(same_values(&p, base), "%s = %s: a refused patch changed values", d->name, json);
}

/* Expects sl_params_set_numbers(v, n) refused for d, its message holding every needle, nothing changed. */
static void expect_values_refused(const sl_params *base, const sl_param_def *d, const double *v, int n,
                                  const char *const *needles)
{
    sl_params p = *base;
    sl_err err = {0};
    SL_CHECK_MSG(sl_params_set_numbers(&p, d->name, v, n, &err) == SL_ERR_INVALID, "%s: %d numbers accepted", d->name, n);
    SL_CHECK_MSG(names_range(err.message, d), "%s: message '%s' does not name it and its range", d->name, err.message);
    for (int k = 0; needles[k]; k++)
        SL_CHECK_MSG(strstr(err.message, needles[k]) != NULL, "%s: message '%s' lacks '%s'", d->name, err.message,
                     needles[k]);
    SL_CHECK_MSG(same_values(&p, base), "%s: a refused list changed values", d->name);
}

/* A SL_PARAM_VALUES parameter: the empty default, 0 .. 4 values set,
 * read back, compared and round-tripped through JSON; a 5th value, a value
 * out of range (its index named), NaN and non-numbers refused. */
static void test_values_parameter(const sl_technique *t, int i)
{
    const sl_param_def *d = &t->params[i];
    sl_params base;
    sl_params_init(&base, t->params, t->param_count);
    sl_err err = {0};
    SL_CHECK_MSG(d->unit && d->description && d->description[0], "%s[%d]: unit and description", t->name, i);
    SL_CHECK_MSG(isfinite(d->min) && isfinite(d->max) && d->min < d->max, "%s.%s: range [%g, %g]", t->name, d->name,
                 d->min, d->max);
    double got[SL_PARAM_VALUES_MAX] = {9, 9, 9, 9};
    SL_CHECK_MSG(sl_params_values(&base, d->name, got) == 0 && got[0] == 0.0 && got[3] == 0.0,
                 "%s.%s: the default is the empty list", t->name, d->name);

    /* 0 .. 4 values inside the range: stored, read back, reported at the declared level, round-tripped. */
    double v[SL_PARAM_VALUES_MAX + 1];
    for (int k = 0; k <= SL_PARAM_VALUES_MAX; k++)
        v[k] = d->min + (d->max - d->min) * (k + 1) / (SL_PARAM_VALUES_MAX + 2);
    sl_params prev = base;
    for (int n = 0; n <= SL_PARAM_VALUES_MAX; n++) {
        sl_params p = base;
        SL_CHECK_MSG(sl_params_set_numbers(&p, d->name, n ? v : NULL, n, &err) == SL_OK, "%s.%s: %d values: %s",
                     t->name, d->name, n, err.message);
        int count = sl_params_values(&p, d->name, got);
        SL_CHECK_MSG(count == n, "%s.%s: %d values read back as %d", t->name, d->name, n, count);
        for (int k = 0; k < SL_PARAM_VALUES_MAX; k++)
            SL_CHECK(got[k] == (k < n ? v[k] : 0.0));
        SL_CHECK(sl_params_compare(&base, &p) == (n ? d->invalidates : SL_INVALIDATE_NONE));
        /* One more value (same first ones) is a change: compare sees the count. */
        if (n > 0)
            SL_CHECK_MSG(sl_params_compare(&prev, &p) == d->invalidates, "%s.%s: %d -> %d values not seen", t->name,
                         d->name, n - 1, n);
        cJSON *all = sl_params_to_json(&p);
        const cJSON *mine = cJSON_GetObjectItemCaseSensitive(all, d->name);
        SL_CHECK(cJSON_IsArray(mine) && cJSON_GetArraySize(mine) == n);
        for (int k = 0; k < n && cJSON_IsArray(mine); k++)
            SL_CHECK(cJSON_GetArrayItem(mine, k)->valuedouble == v[k]);
        sl_params q = base;
        SL_CHECK_MSG(all && sl_params_apply_json(&q, all, &err) == SL_OK && same_values(&q, &p),
                     "%s.%s: %d values: no round trip (%s)", t->name, d->name, n, err.message);
        cJSON_Delete(all);
        prev = p;
    }
    /* A changed value, same count. */
    sl_params a = base, b = base;
    SL_CHECK(sl_params_set_numbers(&a, d->name, v, 2, &err) == SL_OK);
    SL_CHECK(sl_params_set_numbers(&b, d->name, (double[]){v[0], v[2]}, 2, &err) == SL_OK);
    SL_CHECK(sl_params_compare(&a, &b) == d->invalidates);
    /* A count alone: [v0] and [v0, 0] hold the same numbers in value[] (unused entries are 0). */
    if (d->min <= 0.0 && d->max >= 0.0) {
        SL_CHECK(sl_params_set_numbers(&a, d->name, v, 1, &err) == SL_OK);
        SL_CHECK(sl_params_set_numbers(&b, d->name, (double[]){v[0], 0.0}, 2, &err) == SL_OK);
        SL_CHECK_MSG(sl_params_compare(&a, &b) == d->invalidates, "%s.%s: a count change alone not seen", t->name,
                     d->name);
    }
    /* Both ends are valid. */
    SL_CHECK(sl_params_set_numbers(&a, d->name, (double[]){d->min, d->max}, 2, &err) == SL_OK);
    /* JSON: [] = auto, a list, and a patch that empties a list again. */
    sl_params p = base;
    char text[256];
    snprintf(text, sizeof text, "[%.17g, %.17g, %.17g]", v[0], v[1], v[2]);
    SL_CHECK_MSG(apply_text(&p, d->name, text, &err) == SL_OK && sl_params_values(&p, d->name, got) == 3 &&
                 got[2] == v[2], "%s.%s = %s: %s", t->name, d->name, text, err.message);
    SL_CHECK(apply_text(&p, d->name, "[]", &err) == SL_OK && sl_params_values(&p, d->name, got) == 0);
    SL_CHECK(sl_params_compare(&base, &p) == SL_INVALIDATE_NONE);

    /* A 5th value, by setter and by JSON: the limit named. */
    expect_values_refused(&base, d, v, SL_PARAM_VALUES_MAX + 1, (const char *[]){"0 to 4", "got 5", NULL});
    snprintf(text, sizeof text, "[%.17g, %.17g, %.17g, %.17g, %.17g]", v[0], v[1], v[2], v[3], v[4]);
    expect_text_refused(&base, d, text, (const char *[]){"at most 4 values", "got 5", NULL});
    /* Each value's range, the bad one named by its index. */
    double bad[3] = {v[0], v[1], nextafter(d->max, INFINITY)};
    expect_values_refused(&base, d, bad, 3, (const char *[]){"value 2", "out of range", NULL});
    bad[2] = v[2];
    bad[0] = nextafter(d->min, -INFINITY);
    expect_values_refused(&base, d, bad, 3, (const char *[]){"value 0", NULL});
    bad[0] = v[0];
    bad[1] = NAN;
    expect_values_refused(&base, d, bad, 2, (const char *[]){"value 1", "finite", NULL});
    bad[1] = INFINITY;
    expect_values_refused(&base, d, bad, 2, (const char *[]){"value 1", "finite", NULL});
    expect_values_refused(&base, d, v, -1, (const char *[]){"got -1", NULL});
    snprintf(text, sizeof text, "[%.17g, %.17g]", v[0], d->max * 2 + 1);
    expect_text_refused(&base, d, text, (const char *[]){"value 1", NULL});
    /* Wrong JSON types: a bare number, a string, a non-number element, null. */
    snprintf(text, sizeof text, "%.17g", v[0]);
    expect_text_refused(&base, d, text, (const char *[]){"array", "[] = auto", NULL});
    expect_text_refused(&base, d, "\"1, 2\"", (const char *[]){"array", NULL});
    expect_text_refused(&base, d, "null", (const char *[]){"array", NULL});
    expect_text_refused(&base, d, "{}", (const char *[]){"array", NULL});
    snprintf(text, sizeof text, "[%.17g, \"x\"]", v[0]);
    expect_text_refused(&base, d, text, (const char *[]){"value 1", "must be a number", NULL});
    expect_text_refused(&base, d, "[[0.5]]", (const char *[]){"value 0", NULL});
    expect_text_refused(&base, d, "[true]", (const char *[]){"value 0", NULL});
}

/* A widget list of n widgets (JSON) with widget `bad` replaced by bad_widget (when >= 0). */
static void tf2d_text(char *out, size_t size, int n, int bad, const char *bad_widget, const char *range)
{
    snprintf(out, size, "{\"range\": %s, \"widgets\": [", range);
    for (int k = 0; k < n; k++)
        snprintf(out + strlen(out), size - strlen(out), "%s%s", k ? ", " : "",
                 k == bad ? bad_widget : "[0.1, -0.05, 0.2, 0.5, 0.25, 1, 0.75]");
    snprintf(out + strlen(out), size - strlen(out), "]}");
}

/* A SL_PARAM_TRANSFER_2D parameter: the preset default; JSON forms apply,
 * round-trip and report the declared level; each bad widget or shape is
 * refused naming the widget; equality looks at used widgets only. */
static void test_transfer_2d_parameter(const sl_technique *t, int i)
{
    const sl_param_def *d = &t->params[i];
    sl_params base;
    sl_params_init(&base, t->params, t->param_count);
    sl_err err = {0};
    SL_CHECK_MSG(d->unit && d->description && d->description[0], "%s[%d]: unit and description", t->name, i);
    SL_CHECK_MSG(d->def[0] >= 0 && d->def[0] < SL_TF2D_PRESET_COUNT && d->def[0] == floor(d->def[0]),
                 "%s.%s: def[0] %g is no preset", t->name, d->name, d->def[0]);
    for (int j = 0; j < t->param_count; j++)
        SL_CHECK_MSG(j == i || t->params[j].type != SL_PARAM_TRANSFER_2D, "%s: a second transfer_2d entry '%s'",
                     t->name, t->params[j].name);
    const sl_transfer_function_2d *def = sl_params_transfer_2d(&base, d->name);
    sl_transfer_function_2d preset;
    sl_transfer_function_2d_preset((int)d->def[0], &preset);
    SL_CHECK_MSG(sl_transfer_function_2d_equal(def, &preset), "%s.%s: default is not the preset", t->name, d->name);
    SL_CHECK_MSG(sl_transfer_function_2d_check(d->name, def, &err) == SL_OK, "%s.%s: default: %s", t->name, d->name,
                 err.message);

    char text[4096];
    const int counts[3] = {1, 5, SL_TF2D_MAX_WIDGETS};
    for (int g = 0; g < 3; g++) {
        tf2d_text(text, sizeof text, counts[g], g, "[-0.4, 0.3, 0.01, 0, 0, 0, 0]", g == 2 ? "2.5" : "0.5");
        sl_params p = base;
        SL_CHECK_MSG(apply_text(&p, d->name, text, &err) == SL_OK, "%s.%s = %s: %s", t->name, d->name, text,
                     err.message);
        const sl_transfer_function_2d *tf = sl_params_transfer_2d(&p, d->name);
        SL_CHECK(tf->count == counts[g] && tf->range == (g == 2 ? 2.5 : 0.5) && tf->widget[g][0] == -0.4 &&
                 tf->widget[g][2] == 0.01 && tf->widget[counts[g] - 1][6] == (g == counts[g] - 1 ? 0.0 : 0.75));
        SL_CHECK_MSG(sl_params_compare(&base, &p) == d->invalidates, "%s.%s = %s: compare", t->name, d->name, text);
        cJSON *all = sl_params_to_json(&p);
        sl_params q = base;
        SL_CHECK_MSG(all && sl_params_apply_json(&q, all, &err) == SL_OK && same_values(&q, &p) &&
                     sl_transfer_function_2d_equal(sl_params_transfer_2d(&q, d->name), tf),
                     "%s.%s: %d widgets: no round trip (%s)", t->name, d->name, counts[g], err.message);
        cJSON_Delete(all);
    }
    /* The last widget's alpha alone is a change; so is the range alone. */
    sl_params a = base, b = base;
    sl_transfer_function_2d tf = preset;
    tf.widget[tf.count - 1][6] = 0.25;
    SL_CHECK(sl_params_set_transfer_2d(&b, d->name, &tf, &err) == SL_OK);
    SL_CHECK(sl_params_compare(&a, &b) == d->invalidates && !sl_transfer_function_2d_equal(&preset, &tf));
    tf = preset;
    tf.range = 0.75;
    SL_CHECK(sl_params_set_transfer_2d(&b, d->name, &tf, &err) == SL_OK && sl_params_compare(&a, &b) == d->invalidates);
    /* Widgets past count do not count; -0 is stored as 0. */
    tf = preset;
    tf.widget[tf.count][4] = 0.5;
    SL_CHECK(sl_transfer_function_2d_equal(&preset, &tf));
    tf.widget[0][1] = -0.0;
    b = base;
    SL_CHECK(sl_params_set_transfer_2d(&b, d->name, &tf, &err) == SL_OK);
    SL_CHECK(sl_params_transfer_2d(&b, d->name)->widget[tf.count][4] == 0.0 &&
             !signbit(sl_params_transfer_2d(&b, d->name)->widget[0][1]));

    /* Bad widgets, by JSON, each named. */
    tf2d_text(text, sizeof text, 4, 3, "[0, 0, 0, 1, 1, 1, 1]", "0.5");
    expect_text_refused(&base, d, text, (const char *[]){"widget 3: radius 0 must be > 0", NULL});
    tf2d_text(text, sizeof text, 2, 1, "[0, 0, -0.2, 1, 1, 1, 1]", "0.5");
    expect_text_refused(&base, d, text, (const char *[]){"widget 1: radius -0.2", NULL});
    tf2d_text(text, sizeof text, 2, 0, "[0, 0, 0.2, 1, 1, 1, 1.5]", "0.5");
    expect_text_refused(&base, d, text, (const char *[]){"widget 0", "alpha 1.5", "[0, 1]", NULL});
    tf2d_text(text, sizeof text, 3, 2, "[0, 0, 0.2, -0.1, 1, 1, 1]", "0.5");
    expect_text_refused(&base, d, text, (const char *[]){"widget 2", "red", NULL});
    tf2d_text(text, sizeof text, 2, 1, "[1e400, 0, 0.2, 1, 1, 1, 1]", "0.5");
    expect_text_refused(&base, d, text, (const char *[]){"widget 1", "k1", "finite", NULL});
    tf2d_text(text, sizeof text, 2, 1, "[0, 0, 0.2, 1, 1, 1]", "0.5");
    expect_text_refused(&base, d, text, (const char *[]){"widget 1", "[k1, k2, radius, r, g, b, a]", NULL});
    tf2d_text(text, sizeof text, 2, 0, "[0, 0, 0.2, 1, \"x\", 1, 1]", "0.5");
    expect_text_refused(&base, d, text, (const char *[]){"widget 0", "numbers", NULL});
    tf2d_text(text, sizeof text, 2, -1, "", "0");
    expect_text_refused(&base, d, text, (const char *[]){"range 0", "> 0", NULL});
    tf2d_text(text, sizeof text, 2, -1, "", "-1");
    expect_text_refused(&base, d, text, (const char *[]){"range -1", NULL});
    tf2d_text(text, sizeof text, 2, -1, "", "\"wide\"");
    expect_text_refused(&base, d, text, (const char *[]){"\"range\"", NULL});
    tf2d_text(text, sizeof text, SL_TF2D_MAX_WIDGETS + 1, -1, "", "0.5");
    expect_text_refused(&base, d, text, (const char *[]){"1 to 16 widgets", "got 17", NULL});
    expect_text_refused(&base, d, "{\"range\": 0.5, \"widgets\": []}", (const char *[]){"1 to 16", "got 0", NULL});
    expect_text_refused(&base, d, "{\"widgets\": [[0, 0, 0.2, 1, 1, 1, 1]]}", (const char *[]){"\"range\"", NULL});
    expect_text_refused(&base, d, "{\"range\": 0.5}", (const char *[]){"\"widgets\"", NULL});
    expect_text_refused(&base, d, "{\"range\": 0.5, \"widgets\": [[0, 0, 0.2, 1, 1, 1, 1]], \"ramp\": 1}",
                        (const char *[]){"unknown key 'ramp'", NULL});
    expect_text_refused(&base, d, "[[0, 0, 0.2, 1, 1, 1, 1]]", (const char *[]){"widgets", NULL});
    expect_text_refused(&base, d, "0.5", (const char *[]){"widgets", NULL});
    /* The checker alone: count and range. */
    tf = preset;
    tf.count = 0;
    SL_CHECK(sl_transfer_function_2d_check(d->name, &tf, &err) == SL_ERR_INVALID && strstr(err.message, "got 0"));
    tf = preset;
    tf.range = NAN;
    SL_CHECK(sl_transfer_function_2d_check(d->name, &tf, &err) == SL_ERR_INVALID && strstr(err.message, "range"));
    /* Numbers are refused by the number setter, naming the JSON form. */
    sl_params q = base;
    SL_CHECK(sl_params_set_numbers(&q, d->name, d->def, 1, &err) == SL_ERR_INVALID && strstr(err.message, d->name) &&
             strstr(err.message, "widgets"));
    SL_CHECK(same_values(&q, &base));
}

static void test_parameter(const sl_technique *t, int i)
{
    const sl_param_def *d = &t->params[i];
    if (d->type == SL_PARAM_TRANSFER) {
        test_transfer_parameter(t, i);
        return;
    }
    if (d->type == SL_PARAM_VALUES) {
        test_values_parameter(t, i);
        return;
    }
    if (d->type == SL_PARAM_TRANSFER_2D) {
        test_transfer_2d_parameter(t, i);
        return;
    }
    sl_params base;
    sl_params_init(&base, t->params, t->param_count);
    sl_err err = {0};

    /* Schema sanity and the default in range. */
    SL_CHECK_MSG(d->name && d->name[0] && d->unit && d->description && d->description[0],
                 "%s[%d]: name, unit and description are required", t->name, i);
    SL_CHECK_MSG(d->invalidates >= SL_INVALIDATE_NONE && d->invalidates <= SL_INVALIDATE_DATASET, "%s.%s", t->name, d->name);
    SL_CHECK(memcmp(base.value[i], d->def, sizeof d->def) == 0 && base.value[i][3] == 0.0 && base.value_count[i] == 0);
    int in_range = 1;
    switch (d->type) {
    case SL_PARAM_VEC3:
        for (int k = 0; k < 3; k++)
            in_range &= d->def[k] >= d->min && d->def[k] <= d->max;
        in_range &= isfinite(d->min) && isfinite(d->max) && d->min <= d->max;
        break;
    case SL_PARAM_ATTRIBUTE:
        /* min -1 (-1 = none) or 0; an index, so max is a small integer. */
        in_range &= (d->min == -1.0 || d->min == 0.0) && d->max == floor(d->max) && d->max >= 0 && d->max < 1024;
        /* fall through */
    case SL_PARAM_INT:
        in_range &= d->def[0] == floor(d->def[0]);
        /* fall through */
    case SL_PARAM_FLOAT:
        in_range &= isfinite(d->min) && isfinite(d->max) && d->min <= d->max;
        in_range &= (d->type == SL_PARAM_FLOAT && sl_param_def_has_auto(d)) ||
                    (d->def[0] >= d->min && d->def[0] <= d->max);
        break;
    case SL_PARAM_BOOL:
        in_range &= d->def[0] == 0.0 || d->def[0] == 1.0;
        break;
    case SL_PARAM_ENUM:
        in_range &= choice_count(d) >= 1 && d->def[0] == floor(d->def[0]) && d->def[0] >= 0 &&
                    d->def[0] < choice_count(d);
        break;
    case SL_PARAM_TRANSFER: /* test_transfer_parameter */
    case SL_PARAM_VALUES: /* test_values_parameter */
    case SL_PARAM_TRANSFER_2D: /* test_transfer_2d_parameter */
        break;
    }
    SL_CHECK_MSG(in_range, "%s.%s: default out of its own range", t->name, d->name);
    sl_params p = base;
    if (sl_param_def_has_auto(d)) /* auto is set by name, never as a number (NaN is refused) */
        SL_CHECK_MSG(sl_params_set_auto(&p, d->name, &err) == SL_OK && sl_params_is_auto(&p, d->name),
                     "%s.%s: the auto default does not validate: %s", t->name, d->name, err.message);
    else
        SL_CHECK_MSG(sl_params_set_numbers(&p, d->name, d->def, d->type == SL_PARAM_VEC3 ? 3 : 1, &err) == SL_OK,
                     "%s.%s: the default does not validate: %s", t->name, d->name, err.message);

    /* A valid other value: applied, reported at the declared level. */
    double want[3];
    cJSON *item = other_value(d, want);
    if (item) {
        p = base;
        char *text = cJSON_PrintUnformatted(item);
        sl_status st = apply_one(&p, d->name, item, &err);
        SL_CHECK_MSG(st == SL_OK, "%s.%s = %s: %s", t->name, d->name, text ? text : "?", err.message);
        SL_CHECK_MSG(memcmp(p.value[i], want, sizeof want) == 0, "%s.%s = %s not stored", t->name, d->name, text ? text : "?");
        cJSON_free(text);
        for (int k = 0; k < base.count; k++)
            if (k != i)
                SL_CHECK_MSG(memcmp(p.value[k], base.value[k], sizeof p.value[k]) == 0, "%s: setting %s changed %s",
                             t->name, d->name, base.schema[k].name);
        SL_CHECK_MSG(sl_params_compare(&base, &p) == d->invalidates, "%s.%s: compare gives %d, declared %d", t->name,
                     d->name, (int)sl_params_compare(&base, &p), (int)d->invalidates);
        SL_CHECK(sl_params_compare(&p, &base) == d->invalidates);
        /* sl_params_to_json reports the new value, and re-applying it is a no-op. */
        cJSON *all = sl_params_to_json(&p);
        sl_params q = base;
        SL_CHECK(all && sl_params_apply_json(&q, all, &err) == SL_OK && same_values(&q, &p));
        cJSON_Delete(all);
    }

    /* Both ends of the range are valid; just outside is not. */
    if (is_numeric(d)) {
        const double ends[2] = {d->min, d->max};
        for (int e = 0; e < 2; e++) {
            p = base;
            double v[3] = {ends[e], ends[e], ends[e]};
            SL_CHECK_MSG(sl_params_set_numbers(&p, d->name, v, d->type == SL_PARAM_VEC3 ? 3 : 1, &err) == SL_OK,
                         "%s.%s = %g (an end of its range): %s", t->name, d->name, ends[e], err.message);
        }
        double step = d->type == SL_PARAM_INT || d->type == SL_PARAM_ATTRIBUTE ? 1.0 : 0.0;
        double below = step ? d->min - 1 : nextafter(d->min, -INFINITY);
        double above = step ? d->max + 1 : nextafter(d->max, INFINITY);
        expect_refused_numbers(&base, d, below, "below min");
        expect_refused_numbers(&base, d, above, "above max");
        expect_refused_numbers(&base, d, d->min - 1e6 * (1 + fabs(d->min)), "far below min");
    }
    if ((d->type == SL_PARAM_INT || d->type == SL_PARAM_ATTRIBUTE) && d->min < d->max)
        expect_refused_numbers(&base, d, d->min + 0.5, "not an integer");
    if (d->type == SL_PARAM_ENUM) {
        /* Past the last index, and no choice's name (numeric names are
         * read as names, see test_numeric_enum). */
        int past = choice_count(d);
        for (int k = 0; d->choices[k]; k++) {
            char text[32];
            snprintf(text, sizeof text, "%d", past);
            if (strcmp(d->choices[k], text) == 0) {
                past++;
                k = -1;
            }
        }
        expect_refused_numbers(&base, d, (double)past, "index past the choices");
        expect_refused_numbers(&base, d, -1.0, "negative index");
        expect_refused_numbers(&base, d, 0.5, "fractional index");
    }
    if (d->type == SL_PARAM_BOOL) {
        expect_refused_numbers(&base, d, 0.5, "bool 0.5");
        expect_refused_numbers(&base, d, 2.0, "bool 2");
    }

    /* NaN and infinities, for every type. */
    expect_refused_numbers(&base, d, NAN, "NaN");
    expect_refused_numbers(&base, d, INFINITY, "+Inf");
    expect_refused_numbers(&base, d, -INFINITY, "-Inf");

    /* Wrong JSON types. */
    expect_refused(&base, d, cJSON_CreateNull(), "null");
    expect_refused(&base, d, cJSON_CreateObject(), "an object");
    switch (d->type) {
    case SL_PARAM_FLOAT:
    case SL_PARAM_INT:
    case SL_PARAM_ATTRIBUTE:
        expect_refused(&base, d, cJSON_CreateString("1"), "a string");
        expect_refused(&base, d, cJSON_CreateTrue(), "a bool");
        expect_refused(&base, d, cJSON_CreateDoubleArray(d->def, 1), "an array");
        break;
    case SL_PARAM_BOOL:
        expect_refused(&base, d, cJSON_CreateNumber(1), "a number");
        expect_refused(&base, d, cJSON_CreateString("true"), "a string");
        break;
    case SL_PARAM_ENUM:
        expect_refused(&base, d, cJSON_CreateString("no_such_choice"), "an unknown choice");
        expect_refused(&base, d, cJSON_CreateString(""), "an empty choice");
        expect_refused(&base, d, cJSON_CreateTrue(), "a bool");
        expect_refused(&base, d, cJSON_CreateStringArray(d->choices, 1), "an array");
        break;
    case SL_PARAM_VEC3: {
        expect_refused(&base, d, cJSON_CreateNumber(d->def[0]), "a number");
        expect_refused(&base, d, cJSON_CreateDoubleArray(d->def, 2), "two numbers");
        double four[4] = {d->def[0], d->def[1], d->def[2], d->def[0]};
        expect_refused(&base, d, cJSON_CreateDoubleArray(four, 4), "four numbers");
        cJSON *mixed = cJSON_CreateDoubleArray(d->def, 2);
        cJSON_AddItemToArray(mixed, cJSON_CreateString("0"));
        expect_refused(&base, d, mixed, "a string component");
        break;
    }
    case SL_PARAM_TRANSFER: /* test_transfer_parameter */
    case SL_PARAM_VALUES:
    case SL_PARAM_TRANSFER_2D:
        break;
    }

    /* All-or-nothing: a valid change followed by a bad one changes nothing. */
    item = other_value(d, want);
    if (item) {
        p = base;
        cJSON *patch = cJSON_CreateObject();
        cJSON_AddItemToObject(patch, d->name, item);
        cJSON_AddNumberToObject(patch, "no_such_parameter", 1);
        SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_ERR_INVALID);
        SL_CHECK_MSG(same_values(&p, &base), "%s.%s: a failed patch applied its valid part", t->name, d->name);
        cJSON_Delete(patch);
    }
}

static void test_techniques(void)
{
    int n = 0;
    const sl_technique *const *list = sl_technique_list(&n);
    SL_CHECK(list != NULL && n >= 1);
    for (int ti = 0; ti < n; ti++) {
        const sl_technique *t = list[ti];
        SL_CHECK_MSG(t && t->name && t->name[0] && t->description && t->description[0], "technique %d", ti);
        SL_CHECK(sl_technique_find(t->name) == t);
        SL_CHECK_MSG(t->param_count >= 0 && t->param_count <= SL_PARAMS_MAX, "%s: %d params", t->name, t->param_count);
        SL_CHECK(t->prepare && t->render && t->release);
        for (int tj = 0; tj < ti; tj++)
            SL_CHECK_MSG(strcmp(list[tj]->name, t->name) != 0, "technique name '%s' is registered twice", t->name);
        for (int i = 0; i < t->param_count; i++)
            for (int j = 0; j < i; j++)
                SL_CHECK_MSG(strcmp(t->params[i].name, t->params[j].name) != 0, "%s: parameter '%s' twice", t->name,
                             t->params[i].name);

        for (int i = 0; i < t->param_count; i++)
            test_parameter(t, i);

        /* Defaults as JSON re-apply as a no-op. */
        sl_params base, p;
        sl_params_init(&base, t->params, t->param_count);
        p = base;
        sl_err err = {0};
        cJSON *defaults = sl_params_to_json(&base);
        SL_CHECK(cJSON_GetArraySize(defaults) == t->param_count);
        SL_CHECK(sl_params_apply_json(&p, defaults, &err) == SL_OK && same_values(&p, &base));
        SL_CHECK(sl_params_compare(&p, &base) == SL_INVALIDATE_NONE);
        cJSON_Delete(defaults);
        /* NULL, JSON null and {} are empty patches; a non-object is an error. */
        SL_CHECK(sl_params_apply_json(&p, NULL, &err) == SL_OK);
        cJSON *x = cJSON_CreateNull();
        SL_CHECK(sl_params_apply_json(&p, x, &err) == SL_OK);
        cJSON_Delete(x);
        x = cJSON_CreateArray();
        SL_CHECK(sl_params_apply_json(&p, x, &err) == SL_ERR_INVALID);
        SL_CHECK(strstr(err.message, "object") != NULL);
        cJSON_Delete(x);
        SL_CHECK(same_values(&p, &base));

        /* Unknown names: the name is quoted and every known name listed. */
        x = cJSON_CreateObject();
        cJSON_AddNumberToObject(x, "no_such_parameter", 1);
        SL_CHECK(sl_params_apply_json(&p, x, &err) == SL_ERR_INVALID);
        cJSON_Delete(x);
        SL_CHECK_MSG(strstr(err.message, "'no_such_parameter'") != NULL, "%s", err.message);
        for (int i = 0; i < t->param_count; i++)
            SL_CHECK_MSG(strstr(err.message, t->params[i].name) != NULL, "%s: unknown-name message lacks '%s': %s",
                         t->name, t->params[i].name, err.message);
        SL_CHECK(sl_params_set_numbers(&p, "Radius", (double[]){1}, 1, &err) == SL_ERR_INVALID); /* case matters */
        SL_CHECK(sl_params_set_choice(&p, "no_such_parameter", "x", &err) == SL_ERR_INVALID);
        SL_CHECK(strstr(err.message, "'no_such_parameter'") != NULL);
        SL_CHECK(sl_params_find(&p, "no_such_parameter") == -1);
        SL_CHECK(same_values(&p, &base));

        /* The schema as JSON. */
        cJSON *tj = sl_technique_json(t);
        const cJSON *params = cJSON_GetObjectItemCaseSensitive(tj, "params");
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(tj, "name");
        const cJSON *kinds = cJSON_GetObjectItemCaseSensitive(tj, "dataset_kinds");
        SL_CHECK(cJSON_IsString(name) && strcmp(name->valuestring, t->name) == 0);
        SL_CHECK(cJSON_IsArray(kinds) && cJSON_GetArraySize(kinds) >= 1);
        SL_CHECK_MSG(cJSON_IsArray(params) && cJSON_GetArraySize(params) == t->param_count, "%s: schema JSON size", t->name);
        for (int i = 0; i < t->param_count && i < cJSON_GetArraySize(params); i++)
            check_schema_json(cJSON_GetArrayItem(params, i), &t->params[i], t->name);
        cJSON_Delete(tj);
    }
    SL_CHECK(sl_technique_find("no_such_technique") == NULL);
    SL_CHECK(sl_technique_find("") == NULL);
}

/* A private schema: every type and every invalidation level. */
static const char *const fruit[] = {"apple", "banana", "cherry", NULL};
static const sl_param_def test_schema[] = {
    {"f", SL_PARAM_FLOAT, -2.5, 10.0, {1.5}, NULL, "world", "a float", SL_INVALIDATE_NONE},
    {"i", SL_PARAM_INT, -3, 7, {2}, NULL, "", "an int", SL_INVALIDATE_FRAME},
    {"b", SL_PARAM_BOOL, 0, 1, {1}, NULL, "", "a bool", SL_INVALIDATE_PREPARED},
    {"e", SL_PARAM_ENUM, 0, 0, {1}, fruit, "", "an enum", SL_INVALIDATE_DATASET},
    {"v", SL_PARAM_VEC3, -1, 1, {0.1, 0.2, 0.3}, NULL, "rgb", "a vec3", SL_INVALIDATE_FRAME},
    {"a", SL_PARAM_ATTRIBUTE, -1, 3, {0}, NULL, "", "an attribute, -1 = none", SL_INVALIDATE_FRAME},
    {"ra", SL_PARAM_ATTRIBUTE, 0, 3, {1}, NULL, "", "an attribute without none", SL_INVALIDATE_PREPARED},
    {"iso", SL_PARAM_VALUES, -1, 2, {0}, NULL, "data", "a list of up to 4 values, [] = auto", SL_INVALIDATE_PREPARED},
    {"ctf", SL_PARAM_TRANSFER_2D, 0, 0, {SL_TF2D_PRESET_RIDGES_VALLEYS}, NULL, "1/voxel", "a 2D transfer function",
     SL_INVALIDATE_FRAME},
};
enum { TEST_COUNT = (int)(sizeof test_schema / sizeof test_schema[0]) };
static const sl_technique test_tech = {.name = "private", .description = "a private schema", .dataset_kinds = 1,
                                        .params = test_schema, .param_count = TEST_COUNT};

static void test_private_schema(void)
{
    for (int i = 0; i < TEST_COUNT; i++)
        test_parameter(&test_tech, i);

    sl_params p, base;
    sl_params_init(&p, test_schema, TEST_COUNT);
    base = p;
    SL_CHECK(p.count == TEST_COUNT && p.schema == test_schema);
    SL_CHECK(sl_params_float(&p, "f") == 1.5);
    SL_CHECK(sl_params_int(&p, "i") == 2);
    SL_CHECK(sl_params_bool(&p, "b") == true);
    SL_CHECK(sl_params_choice(&p, "e") == 1);
    SL_CHECK(strcmp(sl_params_choice_name(&p, "e"), "banana") == 0);
    float v[3];
    sl_params_vec3(&p, "v", v);
    SL_CHECK(v[0] == 0.1f && v[1] == 0.2f && v[2] == 0.3f);

    sl_err err = {0};
    cJSON *patch = cJSON_Parse("{\"f\": -2.5, \"i\": 7, \"b\": false, \"e\": \"cherry\", \"v\": [-1, 0, 1]}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_OK);
    cJSON_Delete(patch);
    SL_CHECK(sl_params_float(&p, "f") == -2.5);
    SL_CHECK(sl_params_int(&p, "i") == 7);
    SL_CHECK(sl_params_bool(&p, "b") == false);
    SL_CHECK(sl_params_choice(&p, "e") == 2 && strcmp(sl_params_choice_name(&p, "e"), "cherry") == 0);
    sl_params_vec3(&p, "v", v);
    SL_CHECK(v[0] == -1.0f && v[1] == 0.0f && v[2] == 1.0f);
    /* Everything changed: the largest level wins. */
    SL_CHECK(sl_params_compare(&base, &p) == SL_INVALIDATE_DATASET);
    /* An enum by index too. */
    patch = cJSON_Parse("{\"e\": 0}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_OK && sl_params_choice(&p, "e") == 0);
    cJSON_Delete(patch);
    /* set_choice on a non-enum names the parameter. */
    SL_CHECK(sl_params_set_choice(&p, "f", "apple", &err) == SL_ERR_INVALID && strstr(err.message, "'f'"));
    /* A wrong count of numbers. */
    SL_CHECK(sl_params_set_numbers(&p, "v", (double[]){0.5}, 1, &err) == SL_ERR_INVALID && strstr(err.message, "'v'"));
    SL_CHECK(sl_params_set_numbers(&p, "f", (double[]){1, 2, 3}, 3, &err) == SL_ERR_INVALID && strstr(err.message, "'f'"));

    /* Levels combine by maximum; only differing values count. */
    sl_params a = base, b = base;
    SL_CHECK(sl_params_compare(&a, &b) == SL_INVALIDATE_NONE);
    SL_CHECK(sl_params_set_numbers(&b, "f", (double[]){3}, 1, &err) == SL_OK);
    SL_CHECK(sl_params_compare(&a, &b) == SL_INVALIDATE_NONE);   /* f is declared NONE */
    SL_CHECK(sl_params_set_numbers(&b, "v", (double[]){0.1, 0.2, 0.35}, 3, &err) == SL_OK);
    SL_CHECK(sl_params_compare(&a, &b) == SL_INVALIDATE_FRAME);
    SL_CHECK(sl_params_set_numbers(&b, "b", (double[]){0}, 1, &err) == SL_OK);
    SL_CHECK(sl_params_compare(&a, &b) == SL_INVALIDATE_PREPARED);
    SL_CHECK(sl_params_set_choice(&b, "e", "apple", &err) == SL_OK);
    SL_CHECK(sl_params_compare(&a, &b) == SL_INVALIDATE_DATASET);
    SL_CHECK(sl_params_set_choice(&b, "e", "banana", &err) == SL_OK);  /* back to the default */
    SL_CHECK(sl_params_compare(&a, &b) == SL_INVALIDATE_PREPARED);

    /* A different schema counts as PREPARED. */
    int n = 0;
    const sl_technique *const *list = sl_technique_list(&n);
    sl_params other;
    sl_params_init(&other, list[0]->params, list[0]->param_count);
    SL_CHECK(sl_params_compare(&a, &other) == SL_INVALIDATE_PREPARED);
    sl_params shorter;
    sl_params_init(&shorter, test_schema, TEST_COUNT - 1);
    SL_CHECK(sl_params_compare(&a, &shorter) == SL_INVALIDATE_PREPARED);

    /* Type names. */
    SL_CHECK(strcmp(sl_param_type_name(SL_PARAM_FLOAT), "float") == 0);
    SL_CHECK(strcmp(sl_param_type_name(SL_PARAM_INT), "int") == 0);
    SL_CHECK(strcmp(sl_param_type_name(SL_PARAM_BOOL), "bool") == 0);
    SL_CHECK(strcmp(sl_param_type_name(SL_PARAM_ENUM), "enum") == 0);
    SL_CHECK(strcmp(sl_param_type_name(SL_PARAM_VEC3), "vec3") == 0);
    SL_CHECK(strcmp(sl_param_type_name(SL_PARAM_ATTRIBUTE), "attribute") == 0);
    SL_CHECK(strcmp(sl_param_type_name(SL_PARAM_VALUES), "values") == 0);
    SL_CHECK(strcmp(sl_param_type_name(SL_PARAM_TRANSFER_2D), "transfer_2d") == 0);

    /* The list and the 2D function next to the other types: defaults, a
     * patch of both, and the preset word for word (the particles default). */
    sl_params_init(&p, test_schema, TEST_COUNT);
    double numbers[SL_PARAM_VALUES_MAX];
    SL_CHECK(sl_params_values(&p, "iso", numbers) == 0);
    const sl_transfer_function_2d *ctf = sl_params_transfer_2d(&p, "ctf");
    SL_CHECK(ctf->count == 2 && ctf->range == 0.5);
    SL_CHECK(ctf->widget[0][0] == 0.25 && ctf->widget[0][1] == 0.0 && ctf->widget[0][2] == 0.3 &&
             ctf->widget[0][3] == 0.95 && ctf->widget[0][5] == 0.9 && ctf->widget[0][6] == 1.0);
    SL_CHECK(ctf->widget[1][0] == 0.0 && ctf->widget[1][1] == -0.25 && ctf->widget[1][3] == 0.1 &&
             ctf->widget[1][6] == 1.0 && ctf->widget[2][6] == 0.0);
    base = p;
    patch = cJSON_Parse("{\"iso\": [0.5, -1], \"ctf\": {\"range\": 1, \"widgets\": [[0.5, 0.5, 0.1, 1, 0, 0, 1]]},"
                        " \"f\": 2}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_OK);
    cJSON_Delete(patch);
    SL_CHECK(sl_params_values(&p, "iso", numbers) == 2 && numbers[0] == 0.5 && numbers[1] == -1.0 && numbers[2] == 0.0);
    SL_CHECK(sl_params_transfer_2d(&p, "ctf")->count == 1 && sl_params_transfer_2d(&p, "ctf")->widget[0][3] == 1.0);
    SL_CHECK(sl_params_compare(&base, &p) == SL_INVALIDATE_PREPARED); /* iso */
    /* A bad numbers in a patch with a good 2D function: nothing applies. */
    sl_params before = p;
    patch = cJSON_Parse("{\"ctf\": {\"range\": 2, \"widgets\": [[0, 0, 0.1, 1, 1, 1, 1]]}, \"iso\": [0, 1, 2, 3]}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_ERR_INVALID && strstr(err.message, "'iso'") &&
             strstr(err.message, "value 3 = 3") && strstr(err.message, "[-1, 2] data"));
    cJSON_Delete(patch);
    SL_CHECK(same_values(&p, &before) && sl_params_transfer_2d(&p, "ctf")->range == 1.0);
    /* set_transfer_2d on another type, and an unknown name. */
    SL_CHECK(sl_params_set_transfer_2d(&p, "f", ctf, &err) == SL_ERR_INVALID && strstr(err.message, "'f'"));
    SL_CHECK(sl_params_set_transfer_2d(&p, "nope", ctf, &err) == SL_ERR_INVALID && strstr(err.message, "'nope'"));

    /* A concrete message, word for word where it matters. */
    sl_params_init(&p, test_schema, TEST_COUNT);
    SL_CHECK(sl_params_set_numbers(&p, "f", (double[]){11}, 1, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "'f'") && strstr(err.message, "11") && strstr(err.message, "[-2.5, 10]") &&
                 strstr(err.message, "world"), "%s", err.message);
    SL_CHECK(err.status == SL_ERR_INVALID);
}

/* Attribute indices: the schema range, then the dataset's count
 * (sl_params_check_attributes), with "none" only where min is -1. */
static void test_attributes(void)
{
    sl_params p;
    sl_params_init(&p, test_schema, TEST_COUNT);
    sl_err err = {0};
    SL_CHECK(sl_params_attribute(&p, "a") == 0 && sl_params_attribute(&p, "ra") == 1);
    /* Schema range: -1 is "none" for a, out of range for ra; fractions and past max are refused. */
    SL_CHECK(sl_params_set_numbers(&p, "a", (double[]){-1}, 1, &err) == SL_OK && sl_params_attribute(&p, "a") == -1);
    SL_CHECK(sl_params_set_numbers(&p, "a", (double[]){-2}, 1, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "'a'") && strstr(err.message, "[-1, 3]") && strstr(err.message, "-1 = none") &&
                 strstr(err.message, "-2"), "%s", err.message);
    SL_CHECK(sl_params_set_numbers(&p, "ra", (double[]){-1}, 1, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "'ra'") && strstr(err.message, "[0, 3]") && !strstr(err.message, "none"), "%s",
                 err.message);
    SL_CHECK(sl_params_set_numbers(&p, "a", (double[]){1.5}, 1, &err) == SL_ERR_INVALID && strstr(err.message, "'a'"));
    SL_CHECK(sl_params_set_numbers(&p, "a", (double[]){4}, 1, &err) == SL_ERR_INVALID && strstr(err.message, "'a'"));
    SL_CHECK(sl_params_attribute(&p, "a") == -1 && sl_params_attribute(&p, "ra") == 1);
    /* JSON takes an index, not a name, nor a bool or null. */
    const char *bad[] = {"{\"a\": \"speed\"}", "{\"a\": true}", "{\"a\": null}", "{\"a\": [1]}", "{\"a\": 0.5}"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        cJSON *patch = cJSON_Parse(bad[k]);
        SL_CHECK_MSG(sl_params_apply_json(&p, patch, &err) == SL_ERR_INVALID && strstr(err.message, "'a'"), "%s: %s",
                     bad[k], err.message);
        cJSON_Delete(patch);
    }
    SL_CHECK(sl_params_attribute(&p, "a") == -1);
    cJSON *patch = cJSON_Parse("{\"a\": 2, \"ra\": 0}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_OK && sl_params_attribute(&p, "a") == 2 &&
             sl_params_attribute(&p, "ra") == 0);
    cJSON_Delete(patch);
    cJSON *json = sl_params_to_json(&p);
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(json, "a");
    SL_CHECK(cJSON_IsNumber(a) && a->valuedouble == 2);
    cJSON_Delete(json);
    cJSON *schema = sl_params_schema_json(test_schema, TEST_COUNT);
    const cJSON *def = cJSON_GetArrayItem(schema, 5);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(def, "type");
    const cJSON *mn = cJSON_GetObjectItemCaseSensitive(def, "min");
    SL_CHECK(cJSON_IsString(type) && strcmp(type->valuestring, "attribute") == 0 && cJSON_IsNumber(mn) &&
             mn->valuedouble == -1 && !cJSON_GetObjectItemCaseSensitive(def, "choices"));
    cJSON_Delete(schema);

    /* Against a dataset with 3 attributes: a = 2, ra = 0 exist. */
    SL_CHECK_MSG(sl_params_check_attributes(&p, 3, &err) == SL_OK, "%s", err.message);
    /* With 2, a = 2 does not: the message names it, its value and the valid range. */
    SL_CHECK(sl_params_check_attributes(&p, 2, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strcmp(err.message, "params.a = 2: the dataset has 2 per-vertex attributes (valid: -1 .. 1)") == 0,
                 "%s", err.message);
    /* -1 (none) fits every dataset, even one without attributes. */
    SL_CHECK(sl_params_set_numbers(&p, "a", (double[]){-1}, 1, &err) == SL_OK);
    SL_CHECK(sl_params_check_attributes(&p, 2, &err) == SL_OK);
    SL_CHECK(sl_params_check_attributes(&p, 1, &err) == SL_OK); /* ra = 0 */
    SL_CHECK(sl_params_check_attributes(&p, 0, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strcmp(err.message, "params.ra = 0: the dataset has 0 per-vertex attributes (valid: 0 .. -1)") == 0,
                 "%s", err.message);
    /* A default is accepted on any dataset ("the first, if any"): a = 0 and ra = 1 with no attributes. */
    sl_params_init(&p, test_schema, TEST_COUNT);
    SL_CHECK_MSG(sl_params_check_attributes(&p, 0, &err) == SL_OK, "%s", err.message);
    SL_CHECK(sl_params_set_numbers(&p, "a", (double[]){1}, 1, &err) == SL_OK);
    SL_CHECK(sl_params_check_attributes(&p, 1, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strcmp(err.message, "params.a = 1: the dataset has 1 per-vertex attribute (valid: -1 .. 0)") == 0,
                 "%s", err.message);
    SL_CHECK(sl_params_check_attributes(&p, 2, &err) == SL_OK);
    /* Other parameters' values are never read as indices (a float at -1e30 is no int). */
    const sl_technique *t = sl_technique_find("tubes_mesh");
    SL_CHECK(t != NULL);
    if (t) {
        sl_params_init(&p, t->params, t->param_count);
        SL_CHECK(sl_params_set_numbers(&p, "scalar_min", (double[]){-1e30}, 1, &err) == SL_OK);
        SL_CHECK_MSG(sl_params_check_attributes(&p, 1, &err) == SL_OK, "%s", err.message);
    }
}

/* The technique schemas' shared names: a few declared facts the rest of the code relies on. */
static void test_known_parameters(void)
{
    /* Every line technique's attribute indices are typed as such, so the page
     * builds their selects from the schema alone. */
    int n = 0, attribute_params = 0;
    const sl_technique *const *list = sl_technique_list(&n);
    for (int ti = 0; ti < n; ti++)
        for (int i = 0; i < list[ti]->param_count; i++) {
            const sl_param_def *d = &list[ti]->params[i];
            if (strcmp(d->name, "attribute") == 0 || strcmp(d->name, "radius_attribute") == 0) {
                SL_CHECK_MSG(d->type == SL_PARAM_ATTRIBUTE && d->min == -1, "%s.%s is a %s", list[ti]->name, d->name,
                             sl_param_type_name(d->type));
                attribute_params++;
            }
        }
    SL_CHECK_MSG(attribute_params >= 4, "%d attribute parameters in the registry", attribute_params);
    const sl_technique *t = sl_technique_find("tubes_mesh");
    SL_CHECK(t != NULL);
    if (!t)
        return;
    sl_params p;
    sl_params_init(&p, t->params, t->param_count);
    int r = sl_params_find(&p, "radius"), s = sl_params_find(&p, "sides"), c = sl_params_find(&p, "colormap");
    SL_CHECK(r >= 0 && s >= 0 && c >= 0);
    if (r < 0 || s < 0 || c < 0)
        return;
    SL_CHECK(t->params[r].type == SL_PARAM_FLOAT && t->params[r].invalidates == SL_INVALIDATE_FRAME);
    SL_CHECK(t->params[s].type == SL_PARAM_INT && t->params[s].invalidates == SL_INVALIDATE_PREPARED);
    sl_err err = {0};
    cJSON *patch = cJSON_Parse("{\"radius\": 0.5, \"colormap\": \"magma\", \"sides\": 7}");
    sl_params q = p;
    SL_CHECK_MSG(sl_params_apply_json(&q, patch, &err) == SL_OK, "%s", err.message);
    cJSON_Delete(patch);
    SL_CHECK(sl_params_float(&q, "radius") == 0.5);
    SL_CHECK(strcmp(sl_params_choice_name(&q, "colormap"), "magma") == 0);
    SL_CHECK(sl_params_int(&q, "sides") == 7);
    SL_CHECK(sl_params_compare(&p, &q) == SL_INVALIDATE_PREPARED);
    patch = cJSON_Parse("{\"radius\": -0.5}");
    SL_CHECK(sl_params_apply_json(&q, patch, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "'radius'") && strstr(err.message, "-0.5") && strstr(err.message, "[0, 1e+09]"),
                 "%s", err.message);
    cJSON_Delete(patch);
    SL_CHECK(sl_params_float(&q, "radius") == 0.5);
}

/* An enum whose choices are numbers takes a JSON number as that choice's
 * name, never as an index; a number that names no choice is refused. */
static const char *const bins_choices[] = {"2", "4", "8", NULL};
static const sl_param_def bins_schema[] = {
    {.name = "bins", .type = SL_PARAM_ENUM, .def = {0}, .choices = bins_choices, .unit = "",
     .description = "numeric choices", .invalidates = SL_INVALIDATE_FRAME},
};

static void test_numeric_enum(void)
{
    sl_params p;
    sl_params_init(&p, bins_schema, 1);
    sl_err err = {0};
    cJSON *patch = cJSON_Parse("{\"bins\": 4}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_OK && strcmp(sl_params_choice_name(&p, "bins"), "4") == 0);
    cJSON_Delete(patch);
    patch = cJSON_Parse("{\"bins\": 1}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_ERR_INVALID && strstr(err.message, "'bins'"));
    SL_CHECK(strcmp(sl_params_choice_name(&p, "bins"), "4") == 0);
    cJSON_Delete(patch);
    patch = cJSON_Parse("{\"bins\": \"8\"}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_OK && sl_params_choice(&p, "bins") == 2);
    cJSON_Delete(patch);
}

/* A FLOAT whose default is "auto" (SL_PARAM_AUTO): NaN inside, "auto" in
 * JSON both ways; a number sets it, "auto" sets it back, NaN as a number and
 * "auto" on a float without an auto default are refused; equal autos
 * compare equal (bytewise), a number against auto differs. */
static void test_auto_float(void)
{
    static const sl_param_def schema[] = {
        {"level", SL_PARAM_FLOAT, -10.0, 10.0, {SL_PARAM_AUTO}, NULL, "data", "a level", SL_INVALIDATE_FRAME},
        {"plain", SL_PARAM_FLOAT, 0.0, 1.0, {0.5}, NULL, "", "a plain float", SL_INVALIDATE_FRAME},
    };
    sl_params p, base;
    sl_params_init(&p, schema, 2);
    base = p;
    sl_err err = {0};
    SL_CHECK(sl_param_def_has_auto(&schema[0]) && !sl_param_def_has_auto(&schema[1]));
    SL_CHECK(sl_params_is_auto(&p, "level") && isnan(sl_params_float(&p, "level")) && !sl_params_is_auto(&p, "plain"));
    SL_CHECK(sl_params_compare(&base, &p) == SL_INVALIDATE_NONE);
    cJSON *all = sl_params_to_json(&p);
    const cJSON *lv = cJSON_GetObjectItemCaseSensitive(all, "level");
    SL_CHECK_MSG(cJSON_IsString(lv) && strcmp(lv->valuestring, "auto") == 0, "auto is reported as \"auto\"");
    cJSON_Delete(all);
    cJSON *patch = cJSON_Parse("{\"level\": 2.5}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_OK && sl_params_float(&p, "level") == 2.5 &&
             !sl_params_is_auto(&p, "level"));
    cJSON_Delete(patch);
    SL_CHECK(sl_params_compare(&base, &p) == SL_INVALIDATE_FRAME);
    patch = cJSON_Parse("{\"level\": \"auto\"}");
    SL_CHECK(sl_params_apply_json(&p, patch, &err) == SL_OK && sl_params_is_auto(&p, "level"));
    cJSON_Delete(patch);
    SL_CHECK(sl_params_compare(&base, &p) == SL_INVALIDATE_NONE);
    double nan = NAN;
    sl_params q = p;
    SL_CHECK(sl_params_set_numbers(&q, "level", &nan, 1, &err) == SL_ERR_INVALID && strstr(err.message, "finite"));
    patch = cJSON_Parse("{\"plain\": \"auto\"}");
    SL_CHECK(sl_params_apply_json(&q, patch, &err) == SL_ERR_INVALID && strstr(err.message, "plain"));
    cJSON_Delete(patch);
    SL_CHECK(sl_params_set_auto(&q, "plain", &err) == SL_ERR_INVALID && strstr(err.message, "no \"auto\""));
    patch = cJSON_Parse("{\"level\": \"automatic\"}");
    SL_CHECK(sl_params_apply_json(&q, patch, &err) == SL_ERR_INVALID && strstr(err.message, "or \"auto\""));
    cJSON_Delete(patch);
    SL_CHECK(memcmp(&q, &p, sizeof q) == 0);
}

int main(void)
{
    test_auto_float();
    test_techniques();
    test_private_schema();
    test_numeric_enum();
    test_attributes();
    test_known_parameters();
    SL_TEST_END();
}
