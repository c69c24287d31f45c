/* sl_params.c — validation and access of technique parameters (see sl_params.h). */
#include "sl_params.h"

#include <assert.h>
#include <math.h>
#include <string.h>

#include "sl_colormap.h"

void sl_params_init(sl_params *p, const sl_param_def *schema, int count)
{
    assert(count >= 0 && count <= SL_PARAMS_MAX);
    memset(p, 0, sizeof *p);
    p->schema = schema;
    p->count = count;
    int slots = 0, tf2d_entries = 0;
    for (int i = 0; i < count; i++) {
        switch (schema[i].type) {
        case SL_PARAM_TRANSFER:
            assert(slots < SL_PARAMS_MAX_TF);
            if (slots >= SL_PARAMS_MAX_TF)
                continue;
            p->value[i][0] = slots;
            sl_transfer_function_default(&schema[i], &p->tf[slots++]);
            break;
        case SL_PARAM_TRANSFER_2D:
            assert(tf2d_entries == 0 && "one TRANSFER_2D entry per schema");
            if (tf2d_entries++ == 0)
                sl_transfer_function_2d_preset((int)schema[i].def[0], &p->tf2d);
            break;
        case SL_PARAM_VALUES: /* the empty list (auto) */
            break;
        case SL_PARAM_FLOAT:
        case SL_PARAM_INT:
        case SL_PARAM_BOOL:
        case SL_PARAM_ENUM:
        case SL_PARAM_VEC3:
        case SL_PARAM_ATTRIBUTE:
            memcpy(p->value[i], schema[i].def, sizeof schema[i].def);
            break;
        }
    }
}

void sl_transfer_function_default(const sl_param_def *d, sl_transfer_function *out)
{
    memset(out, 0, sizeof *out);
    out->colormap = (int)d->def[0];
    if (d->def[1] == SL_TF_AUTO_OPACITY) {
        out->auto_opacity = 1;
        return;
    }
    out->count = 2;
    out->point[0][0] = 0.0;
    out->point[0][1] = d->def[1];
    out->point[1][0] = 1.0;
    out->point[1][1] = d->def[2];
}

static int colormap_count(void)
{
    int n = 0;
    while (sl_colormap_names[n])
        n++;
    return n;
}

sl_status sl_transfer_function_check(const char *name, const sl_transfer_function *tf, sl_err *err)
{
    if (tf->colormap >= colormap_count())
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': no colormap %d (0 .. %d)", name, tf->colormap,
                          colormap_count() - 1);
    if (tf->auto_opacity) {
        if (tf->colormap < 0 || tf->count != 0)
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': an automatic opacity needs the colormap form "
                              "and no opacity points", name);
    } else if (tf->count < 1 || tf->count > SL_TF_MAX_POINTS)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes 1 to %d points, got %d", name,
                          SL_TF_MAX_POINTS, tf->count);
    int colormap_form = tf->colormap >= 0;
    if (colormap_form && tf->has_range &&
        !(isfinite(tf->range[0]) && isfinite(tf->range[1]) && tf->range[0] < tf->range[1]))
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': range [%g, %g] must be two finite values, low < high",
                          name, tf->range[0], tf->range[1]);
    static const char *const field[5] = {"value", "red", "green", "blue", "alpha"};
    static const char *const ramp_field[2] = {"t", "alpha"};
    int n = colormap_form ? 2 : 5;
    for (int k = 0; k < tf->count; k++) {
        const double *pt = tf->point[k];
        for (int c = 0; c < n; c++) {
            const char *what = colormap_form ? ramp_field[c] : field[c];
            int is_value = !colormap_form && c == 0;
            if (!isfinite(pt[c]))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': point %d: %s is %g, must be finite", name,
                                  k, what, pt[c]);
            if (!is_value && (pt[c] < 0.0 || pt[c] > 1.0))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': point %d: %s %g is outside [0, 1]", name, k,
                                  what, pt[c]);
        }
        if (k > 0 && pt[0] < tf->point[k - 1][0])
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': point %d: %s %g is below point %d's %g "
                              "(points are sorted by %s)", name, k, colormap_form ? "t" : "value", pt[0], k - 1,
                              tf->point[k - 1][0], colormap_form ? "t" : "value");
    }
    return SL_OK;
}

sl_status sl_params_set_transfer(sl_params *p, const char *name, const sl_transfer_function *tf, sl_err *err)
{
    int i = sl_params_find(p, name);
    if (i < 0)
        return sl_err_set(err, SL_ERR_INVALID, "unknown parameter '%s'", name);
    if (p->schema[i].type != SL_PARAM_TRANSFER)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' (%s) takes no transfer function", name,
                          sl_param_type_name(p->schema[i].type));
    sl_status st = sl_transfer_function_check(name, tf, err);
    if (st != SL_OK)
        return st;
    /* Stored with unused entries zeroed, so equal functions compare equal. */
    sl_transfer_function clean;
    memset(&clean, 0, sizeof clean);
    clean.colormap = tf->colormap < 0 ? -1 : tf->colormap;
    clean.auto_opacity = tf->auto_opacity != 0;
    clean.count = tf->count;
    clean.has_range = clean.colormap >= 0 && tf->has_range;
    if (clean.has_range)
        memcpy(clean.range, tf->range, sizeof clean.range);
    int n = clean.colormap >= 0 ? 2 : 5;
    for (int k = 0; k < tf->count; k++)
        for (int c = 0; c < n; c++)
            clean.point[k][c] = tf->point[k][c] == 0.0 ? 0.0 : tf->point[k][c]; /* -0 -> 0 */
    p->tf[(int)p->value[i][0]] = clean;
    return SL_OK;
}

sl_status sl_params_set_transfer_2d(sl_params *p, const char *name, const sl_transfer_function_2d *tf, sl_err *err)
{
    int i = sl_params_find(p, name);
    if (i < 0)
        return sl_err_set(err, SL_ERR_INVALID, "unknown parameter '%s'", name);
    if (p->schema[i].type != SL_PARAM_TRANSFER_2D)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' (%s) takes no 2D transfer function", name,
                          sl_param_type_name(p->schema[i].type));
    sl_status st = sl_transfer_function_2d_check(name, tf, err);
    if (st != SL_OK)
        return st;
    /* Stored with unused widgets zeroed, so equal functions compare equal. */
    sl_transfer_function_2d clean;
    memset(&clean, 0, sizeof clean);
    clean.count = tf->count;
    clean.range = tf->range;
    for (int k = 0; k < tf->count; k++)
        for (int c = 0; c < 7; c++)
            clean.widget[k][c] = tf->widget[k][c] == 0.0 ? 0.0 : tf->widget[k][c]; /* -0 -> 0 */
    p->tf2d = clean;
    return SL_OK;
}

int sl_params_find(const sl_params *p, const char *name)
{
    for (int i = 0; i < p->count; i++)
        if (strcmp(p->schema[i].name, name) == 0)
            return i;
    return -1;
}

static int choice_count(const sl_param_def *d)
{
    int n = 0;
    while (d->choices && d->choices[n])
        n++;
    return n;
}

static sl_status unknown_parameter(const sl_params *p, const char *name, sl_err *err)
{
    char known[600] = "";
    size_t used = 0;
    for (int i = 0; i < p->count && used + 40 < sizeof known; i++) {
        size_t len = strlen(p->schema[i].name);
        if (used + len + 3 >= sizeof known)
            break;
        if (i) { memcpy(known + used, ", ", 2); used += 2; }
        memcpy(known + used, p->schema[i].name, len);
        used += len;
        known[used] = '\0';
    }
    return sl_err_set(err, SL_ERR_INVALID, "unknown parameter '%s' (known: %s)", name, known);
}

/* A VALUES list: 0 .. SL_PARAM_VALUES_MAX finite numbers, each in [min, max]; errors name the index. */
static sl_status set_values(sl_params *p, int i, const double *v, int n, sl_err *err)
{
    const sl_param_def *d = &p->schema[i];
    const char *space = d->unit[0] ? " " : "";
    if (n < 0 || n > SL_PARAM_VALUES_MAX)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' (values) takes 0 to %d numbers in [%g, %g]%s%s, got %d",
                          d->name, SL_PARAM_VALUES_MAX, d->min, d->max, space, d->unit, n);
    for (int k = 0; k < n; k++) {
        if (!isfinite(v[k]))
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': value %d must be a finite number in [%g, %g]%s%s, "
                              "got %g", d->name, k, d->min, d->max, space, d->unit, v[k]);
        if (v[k] < d->min || v[k] > d->max)
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': value %d = %g is out of range [%g, %g]%s%s", d->name,
                              k, v[k], d->min, d->max, space, d->unit);
    }
    /* Unused entries zero, so equal lists compare equal bytewise. */
    for (int k = 0; k < SL_PARAM_VALUES_MAX; k++)
        p->value[i][k] = k < n ? v[k] : 0.0;
    p->value_count[i] = n;
    return SL_OK;
}

sl_status sl_params_set_numbers(sl_params *p, const char *name, const double *v, int n, sl_err *err)
{
    int i = sl_params_find(p, name);
    if (i < 0)
        return unknown_parameter(p, name, err);
    const sl_param_def *d = &p->schema[i];
    if (d->type == SL_PARAM_TRANSFER)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' (transfer_function) takes control points "
                          "[[value, r, g, b, a], ...] or {\"colormap\": name, \"opacity\": [[t, a], ...]}, not numbers", name);
    if (d->type == SL_PARAM_TRANSFER_2D)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' (transfer_2d) takes {\"range\": r, \"widgets\": "
                          "[[k1, k2, radius, r, g, b, a], ...]}, not numbers", name);
    if (d->type == SL_PARAM_VALUES)
        return set_values(p, i, v, n, err);
    int want = d->type == SL_PARAM_VEC3 ? 3 : 1;
    if (n != want)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' (%s) takes %d number%s, got %d",
                          name, sl_param_type_name(d->type), want, want == 1 ? "" : "s", n);
    for (int k = 0; k < n; k++) {
        /* Non-finite bools and enum indices fail their own checks below, which name their range. */
        if (!isfinite(v[k]) && d->type != SL_PARAM_BOOL && d->type != SL_PARAM_ENUM)
            return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be a finite number in [%g, %g]%s%s, got %g",
                              name, d->min, d->max, d->unit[0] ? " " : "", d->unit, v[k]);
        switch (d->type) {
        case SL_PARAM_BOOL:
            if (v[k] != 0.0 && v[k] != 1.0)
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' is a bool: true or false", name);
            break;
        case SL_PARAM_ENUM: {
            int nc = choice_count(d);
            if (v[k] != floor(v[k]) || v[k] < 0 || v[k] >= nc)
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes a choice index in [0, %d]", name, nc - 1);
            break;
        }
        case SL_PARAM_ATTRIBUTE:
            if (v[k] != floor(v[k]) || v[k] < d->min || v[k] > d->max)
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes an attribute index in [%g, %g]%s, got %g",
                                  name, d->min, d->max, d->min < 0 ? " (-1 = none)" : "", v[k]);
            break;
        case SL_PARAM_INT:
            if (v[k] != floor(v[k]))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' must be an integer in [%g, %g], got %g",
                                  name, d->min, d->max, v[k]);
            /* fall through */
        case SL_PARAM_TRANSFER: /* refused or handled above */
        case SL_PARAM_TRANSFER_2D:
        case SL_PARAM_VALUES:
        case SL_PARAM_FLOAT:
        case SL_PARAM_VEC3:
            if (v[k] < d->min || v[k] > d->max)
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' = %g is out of range [%g, %g]%s%s",
                                  name, v[k], d->min, d->max, d->unit[0] ? " " : "", d->unit);
            break;
        }
    }
    for (int k = 0; k < n; k++)
        p->value[i][k] = v[k];
    return SL_OK;
}

sl_status sl_params_set_choice(sl_params *p, const char *name, const char *choice, sl_err *err)
{
    int i = sl_params_find(p, name);
    if (i < 0)
        return unknown_parameter(p, name, err);
    const sl_param_def *d = &p->schema[i];
    if (d->type != SL_PARAM_ENUM)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' (%s) takes no choice name", name, sl_param_type_name(d->type));
    char list[400] = "";
    size_t used = 0;
    for (int k = 0; d->choices[k]; k++) {
        if (strcmp(d->choices[k], choice) == 0) {
            p->value[i][0] = k;
            return SL_OK;
        }
        size_t len = strlen(d->choices[k]);
        if (used + len + 3 < sizeof list) {
            if (k) { memcpy(list + used, ", ", 2); used += 2; }
            memcpy(list + used, d->choices[k], len);
            used += len;
            list[used] = '\0';
        }
    }
    return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' has no choice '%.100s' (choices: %s)", name, choice, list);
}

static int checked_index(const sl_params *p, const char *name, sl_param_type type)
{
    int i = sl_params_find(p, name);
    assert(i >= 0 && "parameter not in schema");
    assert(i < 0 || p->schema[i].type == type);
    (void)type;
    return i;
}

int sl_param_def_has_auto(const sl_param_def *d)
{
    return d->type == SL_PARAM_FLOAT && isnan(d->def[0]);
}

sl_status sl_params_set_auto(sl_params *p, const char *name, sl_err *err)
{
    int i = sl_params_find(p, name);
    if (i < 0)
        return unknown_parameter(p, name, err);
    if (!sl_param_def_has_auto(&p->schema[i]))
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' has no \"auto\" value: give a number in [%g, %g]%s%s",
                          name, p->schema[i].min, p->schema[i].max, p->schema[i].unit[0] ? " " : "", p->schema[i].unit);
    memcpy(p->value[i], p->schema[i].def, sizeof p->schema[i].def);
    return SL_OK;
}

int sl_params_is_auto(const sl_params *p, const char *name)
{
    int i = checked_index(p, name, SL_PARAM_FLOAT);
    return i >= 0 && isnan(p->value[i][0]);
}

double sl_params_float(const sl_params *p, const char *name)
{
    int i = checked_index(p, name, SL_PARAM_FLOAT);
    return i < 0 ? 0.0 : p->value[i][0];
}

int sl_params_int(const sl_params *p, const char *name)
{
    int i = checked_index(p, name, SL_PARAM_INT);
    return i < 0 ? 0 : (int)p->value[i][0];
}

bool sl_params_bool(const sl_params *p, const char *name)
{
    int i = checked_index(p, name, SL_PARAM_BOOL);
    return i < 0 ? false : p->value[i][0] != 0.0;
}

int sl_params_attribute(const sl_params *p, const char *name)
{
    int i = checked_index(p, name, SL_PARAM_ATTRIBUTE);
    return i < 0 ? -1 : (int)p->value[i][0];
}

sl_status sl_params_check_attributes(const sl_params *p, int count, sl_err *err)
{
    for (int i = 0; i < p->count; i++) {
        const sl_param_def *d = &p->schema[i];
        if (d->type != SL_PARAM_ATTRIBUTE)
            continue;
        int v = (int)p->value[i][0]; /* an integer in the schema's small range */
        if (v < count || p->value[i][0] == d->def[0])
            continue;
        return sl_err_set(err, SL_ERR_INVALID, "params.%s = %d: the dataset has %d per-vertex attribute%s "
                          "(valid: %d .. %d)", d->name, v, count, count == 1 ? "" : "s", (int)d->min, count - 1);
    }
    return SL_OK;
}

int sl_params_choice(const sl_params *p, const char *name)
{
    int i = checked_index(p, name, SL_PARAM_ENUM);
    return i < 0 ? 0 : (int)p->value[i][0];
}

const char *sl_params_choice_name(const sl_params *p, const char *name)
{
    int i = checked_index(p, name, SL_PARAM_ENUM);
    return i < 0 ? "" : p->schema[i].choices[(int)p->value[i][0]];
}

void sl_params_vec3(const sl_params *p, const char *name, float out[3])
{
    int i = checked_index(p, name, SL_PARAM_VEC3);
    for (int k = 0; k < 3; k++)
        out[k] = i < 0 ? 0.0f : (float)p->value[i][k];
}

const sl_transfer_function *sl_params_transfer(const sl_params *p, const char *name)
{
    int i = checked_index(p, name, SL_PARAM_TRANSFER);
    return i < 0 ? &p->tf[0] : &p->tf[(int)p->value[i][0]];
}

int sl_params_values(const sl_params *p, const char *name, double out[SL_PARAM_VALUES_MAX])
{
    int i = checked_index(p, name, SL_PARAM_VALUES);
    int n = i < 0 ? 0 : p->value_count[i];
    for (int k = 0; k < SL_PARAM_VALUES_MAX; k++)
        out[k] = k < n ? p->value[i][k] : 0.0;
    return n;
}

const sl_transfer_function_2d *sl_params_transfer_2d(const sl_params *p, const char *name)
{
    (void)checked_index(p, name, SL_PARAM_TRANSFER_2D);
    return &p->tf2d;
}

/* Field by field (no padding compared). */
int sl_transfer_function_equal(const sl_transfer_function *a, const sl_transfer_function *b)
{
    return a->colormap == b->colormap && a->auto_opacity == b->auto_opacity && a->count == b->count &&
           a->has_range == b->has_range &&
           memcmp(a->range, b->range, sizeof a->range) == 0 && memcmp(a->point, b->point, sizeof a->point) == 0;
}

sl_invalidation sl_params_compare(const sl_params *a, const sl_params *b)
{
    if (a->schema != b->schema || a->count != b->count)
        return SL_INVALIDATE_PREPARED;
    sl_invalidation level = SL_INVALIDATE_NONE;
    for (int i = 0; i < a->count; i++) {
        int differs = memcmp(a->value[i], b->value[i], sizeof a->value[i]) != 0 ||
                      a->value_count[i] != b->value_count[i];
        if (!differs && a->schema[i].type == SL_PARAM_TRANSFER)
            differs = !sl_transfer_function_equal(&a->tf[(int)a->value[i][0]], &b->tf[(int)b->value[i][0]]);
        if (!differs && a->schema[i].type == SL_PARAM_TRANSFER_2D)
            differs = !sl_transfer_function_2d_equal(&a->tf2d, &b->tf2d);
        if (differs && a->schema[i].invalidates > level)
            level = a->schema[i].invalidates;
    }
    return level;
}

const char *sl_param_type_name(sl_param_type t)
{
    switch (t) {
    case SL_PARAM_FLOAT: return "float";
    case SL_PARAM_INT: return "int";
    case SL_PARAM_BOOL: return "bool";
    case SL_PARAM_ENUM: return "enum";
    case SL_PARAM_VEC3: return "vec3";
    case SL_PARAM_ATTRIBUTE: return "attribute";
    case SL_PARAM_TRANSFER: return "transfer_function";
    case SL_PARAM_VALUES: return "values";
    case SL_PARAM_TRANSFER_2D: return "transfer_2d";
    }
    return "unknown";
}
