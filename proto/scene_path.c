/* scene_path.c — the `path` field of a scene: parse, frame count, parameters at a time (see sl_scene_path.h).
 * Any thread. Errors name the JSON path of the field ("path.keyframes[2].t"). */
#include "sl_scene_path.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sl_camera_json.h"
#include "sl_params_json.h"

void sl_scene_path_destroy(sl_scene_path *p)
{
    if (!p)
        return;
    for (int k = 0; p->key_params && k < p->key_count; k++)
        cJSON_Delete(p->key_params[k]);
    free(p->key_params);
    free(p->keys);
    free(p);
}

int sl_scene_path_frames(const sl_scene_path *p)
{
    double last = p->keys[p->key_count - 1].t;
    return (int)floor(last * p->fps + 1e-9) + 1;
}

static sl_status only_keys(const cJSON *obj, const char *where, const char *const *allowed, sl_err *err)
{
    for (const cJSON *c = obj->child; c; c = c->next) {
        int ok = 0;
        for (int i = 0; allowed[i] && !ok; i++)
            ok = c->string && strcmp(c->string, allowed[i]) == 0;
        if (!ok)
            return sl_err_set(err, SL_ERR_INVALID, "%s.%.64s: unknown field", where, c->string ? c->string : "?");
    }
    return SL_OK;
}

/* One keyframe: t after the previous key's (prev_t < 0: the first), a camera, optional params. */
static sl_status parse_key(const cJSON *item, int k, double prev_t, const sl_technique *tech, sl_camera_key *key,
                           cJSON **params, sl_err *err)
{
    static const char *const key_fields[] = {"t", "camera", "params", NULL};
    char where[64];
    snprintf(where, sizeof where, "path.keyframes[%d]", k);
    if (!cJSON_IsObject(item))
        return sl_err_set(err, SL_ERR_INVALID, "%s must be an object {\"t\", \"camera\", \"params\"}", where);
    sl_status st = only_keys(item, where, key_fields, err);
    if (st != SL_OK)
        return st;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(item, "t");
    if (!cJSON_IsNumber(t) || !isfinite(t->valuedouble) || t->valuedouble < 0.0)
        return sl_err_set(err, SL_ERR_INVALID, "%s.t must be a finite number of seconds >= 0", where);
    if (prev_t >= 0.0 && !(t->valuedouble > prev_t))
        return sl_err_set(err, SL_ERR_INVALID, "%s.t = %g must be after the previous key's %g", where,
                          t->valuedouble, prev_t);
    key->t = t->valuedouble;
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(item, "camera");
    if (!cam)
        return sl_err_set(err, SL_ERR_INVALID, "%s.camera is required", where);
    if ((st = sl_camera_json_parse(cam, &key->camera, err)) != SL_OK) {
        sl_err_prefix(err, "%s", where);
        return st;
    }
    const cJSON *par = cJSON_GetObjectItemCaseSensitive(item, "params");
    if (!par)
        return SL_OK;
    if (!cJSON_IsObject(par))
        return sl_err_set(err, SL_ERR_INVALID, "%s.params must be an object", where);
    sl_params check;
    sl_params_init(&check, tech->params, tech->param_count);
    if ((st = sl_params_apply_json(&check, par, err)) != SL_OK) {
        sl_err_prefix(err, "%s.params", where);
        return st;
    }
    *params = cJSON_Duplicate(par, 1);
    return *params ? SL_OK : sl_err_set(err, SL_ERR_NOMEM, "out of memory");
}

sl_status sl_scene_path_parse(const cJSON *obj, const sl_technique *tech, sl_scene_path **out, sl_err *err)
{
    static const char *const path_fields[] = {"fps", "interpolation", "keyframes", NULL};
    *out = NULL;
    if (!cJSON_IsObject(obj))
        return sl_err_set(err, SL_ERR_INVALID, "path must be an object {\"fps\", \"interpolation\", \"keyframes\"}");
    sl_status st = only_keys(obj, "path", path_fields, err);
    if (st != SL_OK)
        return st;
    const cJSON *fps = cJSON_GetObjectItemCaseSensitive(obj, "fps");
    if (!cJSON_IsNumber(fps) || !(fps->valuedouble > 0.0 && fps->valuedouble <= SL_PATH_MAX_FPS))
        return sl_err_set(err, SL_ERR_INVALID, "path.fps must be a number in (0, %g]", SL_PATH_MAX_FPS);
    sl_path_interpolation mode = SL_PATH_SMOOTH;
    const cJSON *interp = cJSON_GetObjectItemCaseSensitive(obj, "interpolation");
    if (interp) {
        if (cJSON_IsString(interp) && strcmp(interp->valuestring, "linear") == 0)
            mode = SL_PATH_LINEAR;
        else if (!(cJSON_IsString(interp) && strcmp(interp->valuestring, "smooth") == 0))
            return sl_err_set(err, SL_ERR_INVALID, "path.interpolation must be \"linear\" or \"smooth\"");
    }
    const cJSON *keys = cJSON_GetObjectItemCaseSensitive(obj, "keyframes");
    int n = cJSON_IsArray(keys) ? cJSON_GetArraySize(keys) : -1;
    if (n < 1 || n > SL_PATH_MAX_KEYS)
        return sl_err_set(err, SL_ERR_INVALID, "path.keyframes must be an array of 1 to %d keys", SL_PATH_MAX_KEYS);
    sl_scene_path *p = calloc(1, sizeof *p);
    if (p) {
        p->keys = calloc((size_t)n, sizeof *p->keys);
        p->key_params = calloc((size_t)n, sizeof *p->key_params);
    }
    if (!p || !p->keys || !p->key_params) {
        sl_scene_path_destroy(p);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    }
    p->fps = fps->valuedouble;
    p->interpolation = mode;
    p->key_count = n;
    int k = 0;
    for (const cJSON *item = keys->child; item; item = item->next, k++) {
        st = parse_key(item, k, k ? p->keys[k - 1].t : -1.0, tech, &p->keys[k], &p->key_params[k], err);
        if (st != SL_OK) {
            sl_scene_path_destroy(p);
            return st;
        }
    }
    double frames = floor(p->keys[n - 1].t * p->fps + 1e-9) + 1.0;
    if (frames > SL_PATH_MAX_FRAMES) {
        sl_scene_path_destroy(p);
        return sl_err_set(err, SL_ERR_INVALID, "path: %.0f frames (last key's t x fps + 1), more than %d", frames,
                          SL_PATH_MAX_FRAMES);
    }
    *out = p;
    return SL_OK;
}

/* Whether some key's params name the parameter. */
static int keyed(const sl_scene_path *p, const char *name)
{
    for (int k = 0; k < p->key_count; k++)
        if (p->key_params[k] && cJSON_GetObjectItemCaseSensitive(p->key_params[k], name))
            return 1;
    return 0;
}

/* Whether values of this schema type are interpolated (else they step): an
 * int with unit "sets" is a bit mask, whose in-between values mean nothing. */
static int interpolated(const sl_param_def *d)
{
    return d->type == SL_PARAM_FLOAT || d->type == SL_PARAM_VEC3 ||
           (d->type == SL_PARAM_INT && strcmp(d->unit, "sets") != 0);
}

/* The number of components of a number (1) or an array of numbers (its size <= 3), else 0. */
static int components(const cJSON *v)
{
    if (cJSON_IsNumber(v))
        return 1;
    int n = cJSON_IsArray(v) ? cJSON_GetArraySize(v) : 0;
    if (n < 1 || n > 3)
        return 0;
    for (const cJSON *e = v->child; e; e = e->next)
        if (!cJSON_IsNumber(e))
            return 0;
    return n;
}

static double component(const cJSON *v, int c)
{
    return cJSON_IsNumber(v) ? v->valuedouble : cJSON_GetArrayItem(v, c)->valuedouble;
}

/* The value of parameter d at t over the keys that name it (times/values scratch of key_count). */
static cJSON *param_at(const sl_scene_path *p, const sl_param_def *d, double t, double *times, double *values,
                       const cJSON **items)
{
    int m = 0;
    for (int k = 0; k < p->key_count; k++) {
        const cJSON *v = p->key_params[k] ? cJSON_GetObjectItemCaseSensitive(p->key_params[k], d->name) : NULL;
        if (v) {
            times[m] = p->keys[k].t;
            items[m++] = v;
        }
    }
    if (m == 0)
        return NULL;
    int nc = components(items[0]);
    for (int k = 1; k < m && nc; k++)
        if (components(items[k]) != nc)
            nc = 0;
    if (!interpolated(d) || nc == 0) { /* steps: the last key at or before t, else the first */
        int at = 0;
        while (at + 1 < m && times[at + 1] <= t)
            at++;
        return cJSON_Duplicate(items[at], 1);
    }
    double out[3];
    for (int c = 0; c < nc; c++) {
        for (int k = 0; k < m; k++)
            values[k] = component(items[k], c);
        double v = sl_path_scalar_at(times, values, m, p->interpolation, t);
        if (d->type == SL_PARAM_INT)
            v = floor(v + 0.5);
        out[c] = v < d->min ? d->min : v > d->max ? d->max : v;
    }
    return cJSON_IsNumber(items[0]) ? cJSON_CreateNumber(out[0]) : cJSON_CreateDoubleArray(out, nc);
}

cJSON *sl_scene_path_params(const sl_scene_path *p, double t, const cJSON *base, const sl_technique *tech)
{
    cJSON *out = base ? cJSON_Duplicate(base, 1) : cJSON_CreateObject();
    double *times = malloc((size_t)p->key_count * sizeof *times);
    double *values = malloc((size_t)p->key_count * sizeof *values);
    const cJSON **items = malloc((size_t)p->key_count * sizeof *items);
    int ok = out && times && values && items;
    for (int i = 0; ok && i < tech->param_count; i++) {
        const sl_param_def *d = &tech->params[i];
        if (!keyed(p, d->name))
            continue;
        cJSON *v = param_at(p, d, t, times, values, items);
        if (!v) {
            ok = 0;
            break;
        }
        cJSON_DeleteItemFromObjectCaseSensitive(out, d->name);
        cJSON_AddItemToObject(out, d->name, v);
    }
    free(times);
    free(values);
    free(items);
    if (!ok) {
        cJSON_Delete(out);
        return NULL;
    }
    return out;
}

int sl_scene_path_prepared_params(const sl_scene_path *p, const sl_technique *tech, char *names, size_t size)
{
    int count = 0;
    if (size)
        names[0] = '\0';
    for (int i = 0; i < tech->param_count; i++) {
        const sl_param_def *d = &tech->params[i];
        if (d->invalidates < SL_INVALIDATE_PREPARED || !keyed(p, d->name))
            continue;
        size_t len = strlen(names);
        if (size > len)
            snprintf(names + len, size - len, "%s%s", count ? ", " : "", d->name);
        count++;
    }
    return count;
}
