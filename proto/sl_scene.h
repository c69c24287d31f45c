/* sl_scene.h — scene documents (proto/scene.md): what to render, parsed from JSON.
 *
 * A scene names a dataset (catalog name, file path or generator object), a
 * technique, its params, a camera (eye/target/up or orbit), image size and
 * background. Parsing checks every field and reports the first bad one by
 * its JSON path ("camera.orbit.distance ..."); unknown fields are errors.
 * Any thread; resolving the camera needs the dataset's bounds.
 */
#ifndef SL_SCENE_H
#define SL_SCENE_H

#include <cjson/cJSON.h>

#include "core/sl_camera.h"
#include "sl_scene_path.h"
#include "core/sl_params.h"
#include "core/sl_technique.h"
#include "data/sl_dataset.h"

#define SL_SCENE_MAX_SIZE 8192   /* largest width or height */

typedef struct sl_scene {
    cJSON *dataset;            /* owned copy: string (name or path) or generator object */
    char technique[64];
    cJSON *params;             /* owned copy of the params object (may be NULL) */
    sl_camera_spec camera;
    int width, height;
    float background[4];
    int orbit_frames;          /* 0: every frame uses the camera as given */
    sl_scene_path *path;       /* owned; NULL: no camera path (sl_scene_path.h) */
} sl_scene;

/* Parses a scene document. Defaults: technique "tubes_mesh", the camera
 * sl_camera_spec_default() (core/sl_camera.h), 256x256, background
 * [0.1,0.1,0.12,1]. On failure *scene is left deinitialized. */
sl_status sl_scene_parse(const char *json_text, sl_scene *scene, sl_err *err);
sl_status sl_scene_from_json(const cJSON *root, sl_scene *scene, sl_err *err);
void sl_scene_deinit(sl_scene *scene);

/* Applies "key.path=value" to a JSON document before parsing: the value is
 * parsed as JSON when it is valid JSON, else taken as a string; missing
 * intermediate objects are created. */
sl_status sl_scene_apply_override(cJSON *root, const char *assignment, sl_err *err);

/* Loads or generates the scene's dataset. data_dir (may be NULL) is where
 * relative file paths are looked up. */
sl_status sl_scene_open_dataset(const sl_scene *scene, const char *data_dir, sl_dataset **out, sl_err *err);

/* The view of frame `frame` (orbit_frames advance the azimuth by
 * 360/orbit_frames per frame; a path gives the camera at t = frame / fps)
 * for a dataset's bounds. */
sl_status sl_scene_view(const sl_scene *scene, const sl_dataset *ds, int frame, sl_view *view, sl_err *err);

#endif
