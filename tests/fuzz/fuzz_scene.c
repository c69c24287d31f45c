/* fuzz_scene.c — scene documents and --set overrides (proto/sl_scene.h) on
 * arbitrary bytes; opens no file.
 *
 * The whole input is a scene document for sl_scene_parse. When its first
 * line holds '=', that line is also a --set assignment
 * (sl_scene_apply_override) applied to the rest of the input parsed as JSON
 * (or to {"dataset": "tornado"} when the rest is not JSON), and the result
 * goes through sl_scene_from_json. A parsed scene must hold what the parser
 * promises: a dataset (non-empty string or object), a known technique whose
 * schema takes its params, sizes in [1, SL_SCENE_MAX_SIZE], a background in
 * 0..1, a valid camera or orbit, orbit_frames only on an orbit; its view of
 * a stand-in dataset (bounds only, never loaded: sl_scene_open_dataset reads
 * files and is not driven here) is either SL_OK with finite matrices or an
 * error with a message. A path has 1 .. SL_PATH_MAX_FRAMES frames, strictly
 * ascending key times, and its parameters at the first, a middle and the
 * last frame are valid for the technique's schema (interpolated values stay
 * in range). A failure leaves the scene owning nothing and says why.
 * Violations abort(). Seed corpus: tests/fuzz/corpus/scene/. Single-threaded.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sl_params_json.h"
#include "sl_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Deinitialized: owns no JSON (sl_scene_deinit on it would free nothing). */
static int owns_nothing(const sl_scene *s)
{
    return s->dataset == NULL && s->params == NULL && s->path == NULL;
}

static void check_scene(sl_status st, sl_scene *s, const sl_err *err)
{
    if (st != SL_OK) {
        if ((st != SL_ERR_INVALID && st != SL_ERR_NOMEM) || !err->message[0] || !owns_nothing(s))
            abort();
        return;
    }
    if (!s->dataset || !((cJSON_IsString(s->dataset) && s->dataset->valuestring[0]) || cJSON_IsObject(s->dataset)))
        abort();
    if (strnlen(s->technique, sizeof s->technique) == sizeof s->technique)
        abort();
    const sl_technique *tech = sl_technique_find(s->technique);
    if (!tech)
        abort();
    sl_params p;
    sl_params_init(&p, tech->params, tech->param_count);
    sl_err perr = {0};
    if ((s->params && !cJSON_IsObject(s->params)) || sl_params_apply_json(&p, s->params, &perr) != SL_OK)
        abort();
    if (s->width < 1 || s->width > SL_SCENE_MAX_SIZE || s->height < 1 || s->height > SL_SCENE_MAX_SIZE)
        abort();
    for (int k = 0; k < 4; k++)
        if (!(s->background[k] >= 0.0f && s->background[k] <= 1.0f))
            abort();
    if (s->orbit_frames < 0 || s->orbit_frames > 1000000 || (s->orbit_frames > 0 && !s->camera.is_orbit))
        abort();
    sl_err cerr = {0};
    const sl_orbit *orbit = &s->camera.orbit;
    if (s->camera.is_orbit) {
        if (!(orbit->distance > 0.0) || !isfinite(orbit->distance) || !isfinite(orbit->azimuth_deg) ||
            !(fabs(orbit->elevation_deg) <= SL_ORBIT_MAX_ELEVATION) ||
            !(orbit->fov_y_deg > 0.0 && orbit->fov_y_deg < 180.0))
            abort();
    } else if (sl_camera_validate(&s->camera.look_at, &cerr) != SL_OK) {
        abort();
    }

    int frames = 2;
    if (s->path) {
        frames = sl_scene_path_frames(s->path);
        if (frames < 1 || frames > SL_PATH_MAX_FRAMES || s->path->key_count < 1)
            abort();
        for (int k = 1; k < s->path->key_count; k++)
            if (!(s->path->keys[k].t > s->path->keys[k - 1].t))
                abort();
        const int probe[3] = {0, frames / 2, frames - 1};
        for (int i = 0; i < 3; i++) {
            cJSON *at = sl_scene_path_params(s->path, probe[i] / s->path->fps, s->params, tech);
            sl_params q;
            sl_params_init(&q, tech->params, tech->param_count);
            sl_err qerr = {0};
            if (at && sl_params_apply_json(&q, at, &qerr) != SL_OK)
                abort();
            cJSON_Delete(at);
        }
    }

    /* The view of a stand-in dataset: bounds only (no lines are read). */
    sl_dataset ds;
    memset(&ds, 0, sizeof ds);
    ds.kind = SL_DATASET_LINES;
    ds.origin = sl_v3(0.5, -2.0, 3.0);
    ds.bounds_min = sl_v3(-0.5, -3.0, 2.0);
    ds.bounds_max = sl_v3(1.5, -1.0, 4.5);
    for (int f = 0; f < 3; f++) {
        int frame = f == 2 ? frames - 1 : f;
        sl_view view;
        sl_err verr = {0};
        sl_status vs = sl_scene_view(s, &ds, frame, &view, &verr);
        if (vs != SL_OK) {
            if (!verr.message[0])
                abort();
            continue;
        }
        if (view.width != s->width || view.height != s->height)
            abort();
        for (int i = 0; i < 16; i++)
            if (!isfinite(view.view_projection.m[i]))
                abort();
    }
    sl_scene_deinit(s);
    if (!owns_nothing(s))
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';

    sl_scene scene;
    sl_err err = {0};
    check_scene(sl_scene_parse(text, &scene, &err), &scene, &err);

    char *nl = strchr(text, '\n');
    if (nl && memchr(text, '=', (size_t)(nl - text))) {
        *nl = '\0';
        cJSON *root = cJSON_ParseWithOpts(nl + 1, NULL, 1);
        if (!root)
            root = cJSON_Parse("{\"dataset\": \"tornado\"}");
        if (root && cJSON_IsObject(root)) {
            sl_err oerr = {0};
            sl_status st = sl_scene_apply_override(root, text, &oerr);
            if (st != SL_OK && (st != SL_ERR_INVALID || !oerr.message[0]))
                abort();
            if (st == SL_OK) {
                sl_err serr = {0};
                check_scene(sl_scene_from_json(root, &scene, &serr), &scene, &serr);
            }
        }
        cJSON_Delete(root);
    }
    free(text);
    return 0;
}
