/* sl_camera_json.h — camera objects in JSON, shared by scene documents, camera paths and the
 * wire protocol (proto/scene.md "camera").
 *
 * Either {"eye", "target", "up", "fov_y"} or {"orbit": {"azimuth", "elevation", "distance"},
 * "fov_y"}; finite numbers, distance > 0, |elevation| <= SL_ORBIT_MAX_ELEVATION, a valid
 * look-at (core/sl_camera.h). Any thread.
 */
#ifndef SL_CAMERA_JSON_H
#define SL_CAMERA_JSON_H

#include <cjson/cJSON.h>

#include "core/sl_camera.h"
#include "core/sl_status.h"

/* Parses a camera object (either form) — shared with the wire protocol.
 * Keys it leaves out take sl_orbit_default's values (up: +y). On failure
 * (SL_ERR_INVALID naming the field) *out is unchanged. */
sl_status sl_camera_json_parse(const cJSON *obj, sl_camera_spec *out, sl_err *err);
/* The complete camera object of spec (every key, defaults written out),
 * which sl_camera_json_parse reads back to the same numbers to within
 * cJSON's printing (15 digits when that is within DBL_EPSILON); NULL when
 * out of memory. Free with cJSON_Delete. */
cJSON *sl_camera_to_json(const sl_camera_spec *spec);

#endif
