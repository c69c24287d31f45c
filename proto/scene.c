/* scene.c — scene documents: parse, override, resolve dataset and view (see sl_scene.h, scene.md).
 * Any thread. Every error names the JSON path of the offending field. */
#include "sl_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "data/sl_dataset_open.h"
#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "sl_camera_json.h"
#include "sl_json_keys.h"
#include "sl_params_json.h"

void sl_scene_deinit(sl_scene *s)
{
    cJSON_Delete(s->dataset);
    cJSON_Delete(s->params);
    sl_scene_path_destroy(s->path);
    memset(s, 0, sizeof *s);
}

sl_status sl_scene_from_json(const cJSON *root, sl_scene *s, sl_err *err)
{
    static const char *const scene_keys[] = {"dataset", "technique", "params", "camera", "width", "height",
                                             "background", "orbit_frames", "path", "description", NULL};
    memset(s, 0, sizeof *s);
    snprintf(s->technique, sizeof s->technique, "tubes_mesh");
    s->camera = sl_camera_spec_default();
    s->width = s->height = 256;
    const float bg[4] = {0.1f, 0.1f, 0.12f, 1.0f};
    memcpy(s->background, bg, sizeof bg);
    if (!cJSON_IsObject(root))
        return sl_err_set(err, SL_ERR_INVALID, "a scene must be a JSON object");
    sl_status st = sl_json_check_keys(root, "", scene_keys, err);
    if (st != SL_OK)
        return st;
    const cJSON *ds = cJSON_GetObjectItemCaseSensitive(root, "dataset");
    if (!ds)
        return sl_err_set(err, SL_ERR_INVALID, "dataset is required (a catalog name, a file path or {\"generator\": ...})");
    if (!(cJSON_IsString(ds) && ds->valuestring[0]) && !cJSON_IsObject(ds))
        return sl_err_set(err, SL_ERR_INVALID, "dataset must be a name, a path, a generator object or inline Hermite data {\"nodes\": ..., \"segments\": ...}");
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(root, "technique");
    if (t) {
        if (!cJSON_IsString(t) || strlen(t->valuestring) >= sizeof s->technique)
            return sl_err_set(err, SL_ERR_INVALID, "technique must be a technique name");
        if (!sl_technique_find(t->valuestring)) {
            int n;
            const sl_technique *const *list = sl_technique_list(&n);
            char names[256] = "";
            for (int i = 0; i < n; i++) {
                strncat(names, list[i]->name, sizeof names - strlen(names) - 1);
                if (i + 1 < n)
                    strncat(names, ", ", sizeof names - strlen(names) - 1);
            }
            return sl_err_set(err, SL_ERR_INVALID, "technique '%.64s' is unknown (known: %s)", t->valuestring, names);
        }
        snprintf(s->technique, sizeof s->technique, "%s", t->valuestring);
    }
    const cJSON *params = cJSON_GetObjectItemCaseSensitive(root, "params");
    if (params && !cJSON_IsObject(params))
        return sl_err_set(err, SL_ERR_INVALID, "params must be an object");
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    if (cam && (st = sl_camera_json_parse(cam, &s->camera, err)) != SL_OK)
        return st;
    const char *size_keys[2] = {"width", "height"};
    int *size_out[2] = {&s->width, &s->height};
    for (int k = 0; k < 2; k++) {
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, size_keys[k]);
        if (!v)
            continue;
        if (!cJSON_IsNumber(v) || v->valuedouble != floor(v->valuedouble) || v->valuedouble < 1 || v->valuedouble > SL_SCENE_MAX_SIZE)
            return sl_err_set(err, SL_ERR_INVALID, "%s must be an integer in [1, %d]", size_keys[k], SL_SCENE_MAX_SIZE);
        *size_out[k] = (int)v->valuedouble;
    }
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(root, "background");
    if (b) {
        int n = cJSON_IsArray(b) ? cJSON_GetArraySize(b) : 0;
        if (n != 3 && n != 4)
            return sl_err_set(err, SL_ERR_INVALID, "background must be [r, g, b] or [r, g, b, a] in 0..1");
        for (int k = 0; k < n; k++) {
            const cJSON *e = cJSON_GetArrayItem(b, k);
            if (!cJSON_IsNumber(e) || !(e->valuedouble >= 0.0 && e->valuedouble <= 1.0))
                return sl_err_set(err, SL_ERR_INVALID, "background must be [r, g, b] or [r, g, b, a] in 0..1");
            s->background[k] = (float)e->valuedouble;
        }
    }
    const cJSON *of = cJSON_GetObjectItemCaseSensitive(root, "orbit_frames");
    if (of) {
        if (!cJSON_IsNumber(of) || of->valuedouble != floor(of->valuedouble) || of->valuedouble < 0 || of->valuedouble > 1e6)
            return sl_err_set(err, SL_ERR_INVALID, "orbit_frames must be an integer in [0, 1000000]");
        s->orbit_frames = (int)of->valuedouble;
        if (s->orbit_frames > 0 && !s->camera.is_orbit)
            return sl_err_set(err, SL_ERR_INVALID, "orbit_frames turns an orbit camera, but this camera is "
                                                   "eye/target/up (use camera.orbit, or remove orbit_frames)");
    }
    s->dataset = cJSON_Duplicate(ds, 1);
    s->params = params ? cJSON_Duplicate(params, 1) : NULL;
    if (!s->dataset || (params && !s->params)) {
        sl_scene_deinit(s);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    }
    /* Validate params against the schema now, so errors surface at parse time. */
    const sl_technique *tech = sl_technique_find(s->technique);
    sl_params check;
    sl_params_init(&check, tech->params, tech->param_count);
    if ((st = sl_params_apply_json(&check, s->params, err)) != SL_OK) {
        sl_err_prefix(err, "params");
        sl_scene_deinit(s);
        return st;
    }
    const cJSON *path = cJSON_GetObjectItemCaseSensitive(root, "path");
    if (path) {
        if (cam || s->orbit_frames > 0) {
            sl_scene_deinit(s);
            return sl_err_set(err, SL_ERR_INVALID, "path: its keyframes give every frame's camera, so the scene "
                                                   "must not have %s too", cam ? "a camera" : "orbit_frames");
        }
        if ((st = sl_scene_path_parse(path, tech, &s->path, err)) != SL_OK) {
            sl_scene_deinit(s);
            return st;
        }
    }
    return SL_OK;
}

sl_status sl_scene_parse(const char *json_text, sl_scene *scene, sl_err *err)
{
    memset(scene, 0, sizeof *scene);
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithOpts(json_text, &end, 1);
    if (!root) {
        long at = end ? (long)(end - json_text) : 0;
        return sl_err_set(err, SL_ERR_INVALID, "scene is not valid JSON (near byte %ld)", at);
    }
    sl_status st = sl_scene_from_json(root, scene, err);
    cJSON_Delete(root);
    return st;
}

static void drop_eye_target_up(cJSON *camera)
{
    cJSON_DeleteItemFromObjectCaseSensitive(camera, "eye");
    cJSON_DeleteItemFromObjectCaseSensitive(camera, "target");
    cJSON_DeleteItemFromObjectCaseSensitive(camera, "up");
}

sl_status sl_scene_apply_override(cJSON *root, const char *assignment, sl_err *err)
{
    const char *eq = strchr(assignment, '=');
    if (!eq || eq == assignment)
        return sl_err_set(err, SL_ERR_INVALID, "--set expects key.path=value, got '%.100s'", assignment);
    size_t key_len = (size_t)(eq - assignment);
    char key[256];
    if (key_len >= sizeof key)
        return sl_err_set(err, SL_ERR_INVALID, "--set key is too long");
    memcpy(key, assignment, key_len);
    key[key_len] = '\0';
    /* JSON only when the whole value is JSON ("2024_run.vtk" stays a string). */
    cJSON *value = cJSON_ParseWithOpts(eq + 1, NULL, 1);
    if (!value)
        value = cJSON_CreateString(eq + 1);
    if (!value)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    cJSON *node = root;
    char *save = NULL;
    char *part = strtok_r(key, ".", &save);
    while (part) {
        char *next = strtok_r(NULL, ".", &save);
        if (!next) {
            if (cJSON_GetObjectItemCaseSensitive(node, part))
                cJSON_ReplaceItemInObjectCaseSensitive(node, part, value);
            else
                cJSON_AddItemToObject(node, part, value);
            /* Orbit and eye/target/up are alternatives: setting one drops the
             * other (up belongs to eye/target; an orbit's up is always +y). */
            if (node != root && cJSON_GetObjectItemCaseSensitive(root, "camera") == node) {
                if (strcmp(part, "orbit") == 0) {
                    drop_eye_target_up(node);
                } else if (strcmp(part, "eye") == 0 || strcmp(part, "target") == 0) {
                    cJSON_DeleteItemFromObjectCaseSensitive(node, "orbit");
                }
            }
            return SL_OK;
        }
        cJSON *child = cJSON_GetObjectItemCaseSensitive(node, part);
        if (!child) {
            child = cJSON_AddObjectToObject(node, part);
        } else if (!cJSON_IsObject(child)) {
            cJSON_Delete(value);
            return sl_err_set(err, SL_ERR_INVALID, "--set %s: '%s' is not an object", key, part);
        }
        if (node == cJSON_GetObjectItemCaseSensitive(root, "camera") && strcmp(part, "orbit") == 0)
            drop_eye_target_up(node);
        node = child;
        part = next;
    }
    cJSON_Delete(value);
    return sl_err_set(err, SL_ERR_INVALID, "--set expects key.path=value");
}

sl_status sl_scene_open_dataset(const sl_scene *s, const char *data_dir, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *dirs[1] = {data_dir};
    sl_dataset_dirs where = {.dirs = dirs, .count = data_dir && data_dir[0] ? 1 : 0, .confine = 0};
    if (cJSON_IsObject(s->dataset)) {
        char *text = cJSON_PrintUnformatted(s->dataset);
        if (!text)
            return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
        sl_status st = sl_dataset_open(text, &where, out, err);
        free(text);
        return st;
    }
    return sl_dataset_open(s->dataset->valuestring, &where, out, err);
}

sl_status sl_scene_view(const sl_scene *s, const sl_dataset *ds, int frame, sl_view *view, sl_err *err)
{
    memset(view, 0, sizeof *view);
    view->width = s->width;
    view->height = s->height;
    memcpy(view->background, s->background, sizeof view->background);
    view->origin = ds->origin;
    view->quality = SL_QUALITY_STILL;
    sl_camera_spec cam = s->camera;
    if (cam.is_orbit && s->orbit_frames > 0)
        cam.orbit.azimuth_deg += 360.0 * (double)frame / (double)s->orbit_frames;
    sl_status st = SL_OK;
    if (s->path)
        st = sl_camera_path_at(s->path->keys, s->path->key_count, s->path->interpolation, frame / s->path->fps,
                               ds->bounds_min, ds->bounds_max, &cam, err);
    if (st != SL_OK)
        return st;
    st = sl_camera_spec_resolve(&cam, ds->bounds_min, ds->bounds_max, &view->camera, err);
    if (st != SL_OK)
        return st;
    return sl_view_init(view, sl_dataset_radius(ds), err);
}
