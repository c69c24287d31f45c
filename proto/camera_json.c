/* camera_json.c — sl_camera_json.h: camera objects (eye/target/up or orbit) to and from JSON.
 * Any thread. Every error names the JSON path of the offending field. */
#include "sl_camera_json.h"

#include <math.h>

#include "sl_json_keys.h"

static sl_status get_number(const cJSON *obj, const char *key, const char *path, double *out, int required, sl_err *err)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        if (required)
            return sl_err_set(err, SL_ERR_INVALID, "%s.%s is required", path, key);
        return SL_OK;
    }
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble))
        return sl_err_set(err, SL_ERR_INVALID, "%s.%s must be a finite number", path, key);
    *out = item->valuedouble;
    return SL_OK;
}

static sl_status get_vec3(const cJSON *obj, const char *key, const char *path, sl_vec3 *out, int required, sl_err *err)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        if (required)
            return sl_err_set(err, SL_ERR_INVALID, "%s.%s is required", path, key);
        return SL_OK;
    }
    double v[3];
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3)
        return sl_err_set(err, SL_ERR_INVALID, "%s.%s must be an array of 3 finite numbers", path, key);
    for (int k = 0; k < 3; k++) {
        const cJSON *e = cJSON_GetArrayItem(item, k);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
            return sl_err_set(err, SL_ERR_INVALID, "%s.%s must be an array of 3 finite numbers", path, key);
        v[k] = e->valuedouble;
    }
    *out = sl_v3(v[0], v[1], v[2]);
    return SL_OK;
}

sl_status sl_camera_json_parse(const cJSON *obj, sl_camera_spec *out, sl_err *err)
{
    static const char *const camera_keys[] = {"eye", "target", "up", "fov_y", "orbit", NULL};
    static const char *const orbit_keys[] = {"azimuth", "elevation", "distance", NULL};
    if (!cJSON_IsObject(obj))
        return sl_err_set(err, SL_ERR_INVALID, "camera must be an object");
    sl_status st = sl_json_check_keys(obj, "camera", camera_keys, err);
    if (st != SL_OK)
        return st;
    double fov = sl_orbit_default.fov_y_deg;
    if ((st = get_number(obj, "fov_y", "camera", &fov, 0, err)) != SL_OK)
        return st;
    if (!(fov > 0.0 && fov < 180.0))
        return sl_err_set(err, SL_ERR_INVALID, "camera.fov_y must be in (0, 180) degrees, got %g", fov);
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(obj, "orbit");
    if (o) {
        /* The two forms first: an orbit beside eye/target is a mix of two
         * cameras, whatever else is wrong with either. */
        int has_eye = cJSON_GetObjectItemCaseSensitive(obj, "eye") != NULL;
        int has_target = cJSON_GetObjectItemCaseSensitive(obj, "target") != NULL;
        if (has_eye || has_target)
            return sl_err_set(err, SL_ERR_INVALID,
                              "camera: give either orbit or eye/target/up, not both (this camera has orbit and %s)",
                              has_eye && has_target ? "eye, target" : has_eye ? "eye" : "target");
        if (cJSON_GetObjectItemCaseSensitive(obj, "up"))
            return sl_err_set(err, SL_ERR_INVALID, "camera.up: an orbit camera's up is always +y (use eye/target/up for another)");
        if (!cJSON_IsObject(o))
            return sl_err_set(err, SL_ERR_INVALID, "camera.orbit must be an object");
        if ((st = sl_json_check_keys(o, "camera.orbit", orbit_keys, err)) != SL_OK)
            return st;
        sl_orbit r = sl_orbit_default;
        r.fov_y_deg = fov;
        if ((st = get_number(o, "azimuth", "camera.orbit", &r.azimuth_deg, 0, err)) != SL_OK ||
            (st = get_number(o, "elevation", "camera.orbit", &r.elevation_deg, 0, err)) != SL_OK ||
            (st = get_number(o, "distance", "camera.orbit", &r.distance, 0, err)) != SL_OK)
            return st;
        if (!(r.distance > 0.0))
            return sl_err_set(err, SL_ERR_INVALID, "camera.orbit.distance must be > 0, got %g", r.distance);
        if (fabs(r.elevation_deg) > SL_ORBIT_MAX_ELEVATION)
            return sl_err_set(err, SL_ERR_INVALID, "camera.orbit.elevation must be in [%g, %g] degrees, got %g",
                              -SL_ORBIT_MAX_ELEVATION, SL_ORBIT_MAX_ELEVATION, r.elevation_deg);
        *out = (sl_camera_spec){.is_orbit = 1, .orbit = r};
        return SL_OK;
    }
    sl_camera c = {.up = sl_v3(0, 1, 0), .fov_y_deg = fov};
    if ((st = get_vec3(obj, "eye", "camera", &c.eye, 1, err)) != SL_OK ||
        (st = get_vec3(obj, "target", "camera", &c.target, 1, err)) != SL_OK ||
        (st = get_vec3(obj, "up", "camera", &c.up, 0, err)) != SL_OK)
        return st;
    if ((st = sl_camera_validate(&c, err)) != SL_OK)
        return st;
    *out = (sl_camera_spec){.is_orbit = 0, .look_at = c};
    return SL_OK;
}

static cJSON *vec3_json(sl_vec3 v)
{
    const double a[3] = {v.x, v.y, v.z};
    return cJSON_CreateDoubleArray(a, 3);
}

cJSON *sl_camera_to_json(const sl_camera_spec *spec)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    double fov;
    if (spec->is_orbit) {
        cJSON *orbit = cJSON_AddObjectToObject(o, "orbit");
        cJSON_AddNumberToObject(orbit, "azimuth", spec->orbit.azimuth_deg);
        cJSON_AddNumberToObject(orbit, "elevation", spec->orbit.elevation_deg);
        cJSON_AddNumberToObject(orbit, "distance", spec->orbit.distance);
        fov = spec->orbit.fov_y_deg;
    } else {
        cJSON_AddItemToObject(o, "eye", vec3_json(spec->look_at.eye));
        cJSON_AddItemToObject(o, "target", vec3_json(spec->look_at.target));
        cJSON_AddItemToObject(o, "up", vec3_json(spec->look_at.up));
        fov = spec->look_at.fov_y_deg;
    }
    if (!cJSON_AddNumberToObject(o, "fov_y", fov)) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}
