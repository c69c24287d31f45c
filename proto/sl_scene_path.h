/* sl_scene_path.h — the `path` field of a scene (proto/scene.md "Paths"): camera and parameter keyframes.
 *
 * {"fps": F, "interpolation": "linear" | "smooth", "keyframes": [{"t": seconds, "camera": {...},
 * "params": {...}}, ...]}: at least one key, t finite, >= 0 and strictly
 * ascending, every key with a camera (either form; core/sl_camera_path.h
 * says how cameras between keys are made), params optional and partial.
 * Frame k of the path is at t = k / fps, k = 0 .. floor(t_last fps); at
 * most SL_PATH_MAX_FRAMES frames and SL_PATH_MAX_KEYS keys.
 * A parameter named in some keys follows those keys only: numbers (and
 * arrays of numbers, component by component) by the path's interpolation,
 * rounded for an int parameter and clamped to its schema range; any other
 * value (a bool, a choice, a transfer function) steps, holding the value of
 * the last key at or before t. Before its first key and after its last the
 * parameter holds that key's value. Any thread.
 */
#ifndef SL_SCENE_PATH_H
#define SL_SCENE_PATH_H

#include <cjson/cJSON.h>

#include "core/sl_camera_path.h"
#include "core/sl_technique.h"

#define SL_PATH_MAX_KEYS 1000
#define SL_PATH_MAX_FRAMES 100000
#define SL_PATH_MAX_FPS 240.0

typedef struct sl_scene_path {
    double fps;                        /* (0, SL_PATH_MAX_FPS] */
    sl_path_interpolation interpolation;
    int key_count;
    sl_camera_key *keys;               /* owned */
    cJSON **key_params;                /* owned, per key: a params object or NULL */
} sl_scene_path;

/* Parses and checks a path object against the technique's schema (every
 * keyed parameter must be valid for it). On failure (SL_ERR_INVALID naming
 * the field as "path.keyframes[2].t ...") *out is NULL. */
sl_status sl_scene_path_parse(const cJSON *obj, const sl_technique *technique, sl_scene_path **out, sl_err *err);
void sl_scene_path_destroy(sl_scene_path *path); /* NULL is fine */

/* Frames of the path: floor(t_last fps + 1e-9) + 1. */
int sl_scene_path_frames(const sl_scene_path *path);

/* A new params object: a copy of base (NULL: empty) with every keyframed
 * parameter set to its value at time t. NULL when out of memory. */
cJSON *sl_scene_path_params(const sl_scene_path *path, double t, const cJSON *base, const sl_technique *technique);

/* The keyframed parameters whose change re-prepares the technique (its
 * schema says SL_INVALIDATE_PREPARED), comma-separated into names (empty
 * when none); returns how many. */
int sl_scene_path_prepared_params(const sl_scene_path *path, const sl_technique *technique, char *names, size_t size);

#endif
