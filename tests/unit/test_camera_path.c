/* test_camera_path.c — cameras between keyframes (renderer/core/sl_camera_path.h) and the `path` field of a
 * scene (proto/sl_scene_path.h).
 *
 * Against values computed by hand here: the Hermite / Catmull-Rom scalar on
 * uneven key times (and its C1 continuity at a key, the linear mode's
 * kinks), orbit azimuth the short way round (350 -> 10 passes 0, and -170 ->
 * 170 through 180), log distance (the midpoint of 1 and 4 is 2), the
 * elevation clamp of an overshooting curve, eye/target keys (the eye, the
 * slerped view direction, up orthogonal on 2000 samples of random keys),
 * opposite view directions, times outside the keys. Paths in scenes: frame
 * counts, keyframed params (linear numbers, rounded ints, stepping bools and
 * choices, vec3 by component, held before a parameter's first key; bit masks
 * of unit "sets" and value lists step), the
 * prepared-level list, and every malformed path refused with the field
 * named. No GL.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_camera_path.h"
#include "sl_scene.h"
#include "sl_test.h"

static sl_camera_key orbit_key(double t, double az, double el, double d, double fov)
{
    return (sl_camera_key){t, {.is_orbit = 1, .orbit = {az, el, d, fov}}};
}

static sl_camera_key look_key(double t, sl_vec3 eye, sl_vec3 target, sl_vec3 up)
{
    return (sl_camera_key){t, {.is_orbit = 0, .look_at = {eye, target, up, 45.0}}};
}

static sl_camera_spec at(const sl_camera_key *keys, int n, sl_path_interpolation mode, double t)
{
    sl_camera_spec out = {0};
    sl_err err = {0};
    sl_status st = sl_camera_path_at(keys, n, mode, t, sl_v3(-1, -1, -1), sl_v3(1, 1, 1), &out, &err);
    SL_CHECK_MSG(st == SL_OK, "path at %g: %s", t, err.message);
    return out;
}

static void test_scalar(void)
{
    const double t[3] = {0, 1, 3}, v[3] = {0, 1, 0};
    /* Segment 0, s = 0.5: m0 = 1 (one-sided), m1 = (0 - 0) / 3 = 0:
     * 0.5 * 0 + 0.125 * 1 * 1 + 0.5 * 1 - 0.125 * 1 * 0 = 0.625. */
    SL_CHECK_NEAR(sl_path_scalar_at(t, v, 3, SL_PATH_SMOOTH, 0.5), 0.625, 1e-15);
    SL_CHECK_NEAR(sl_path_scalar_at(t, v, 3, SL_PATH_LINEAR, 0.5), 0.5, 1e-15);
    /* Segment 1 (h = 2), s = 0.5: m1 = 0, m2 = -1/2: 0.5 * 1 + 0 + 0 - 0.125 * 2 * (-0.5) = 0.625. */
    SL_CHECK_NEAR(sl_path_scalar_at(t, v, 3, SL_PATH_SMOOTH, 2.0), 0.625, 1e-15);
    for (int k = 0; k < 3; k++) /* through every key, both modes */
        for (int m = 0; m < 2; m++)
            SL_CHECK_NEAR(sl_path_scalar_at(t, v, 3, (sl_path_interpolation)m, t[k]), v[k], 1e-15);
    SL_CHECK(sl_path_scalar_at(t, v, 3, SL_PATH_SMOOTH, -5) == 0 && sl_path_scalar_at(t, v, 3, SL_PATH_SMOOTH, 9) == 0);
    const double one = 7.0;
    SL_CHECK(sl_path_scalar_at(t, &one, 1, SL_PATH_SMOOTH, 2.0) == 7.0);
    /* C1 at the interior key t = 1 (smooth), a kink there (linear). */
    const double e = 1e-6;
    for (int m = 0; m < 2; m++) {
        double left = (sl_path_scalar_at(t, v, 3, (sl_path_interpolation)m, 1.0) -
                       sl_path_scalar_at(t, v, 3, (sl_path_interpolation)m, 1.0 - e)) / e;
        double right = (sl_path_scalar_at(t, v, 3, (sl_path_interpolation)m, 1.0 + e) -
                        sl_path_scalar_at(t, v, 3, (sl_path_interpolation)m, 1.0)) / e;
        if (m == SL_PATH_SMOOTH)
            SL_CHECK_MSG(fabs(left - right) < 1e-4, "smooth slope %g left, %g right of the key", left, right);
        else
            SL_CHECK_MSG(fabs(left - 1.0) < 1e-6 && fabs(right + 0.5) < 1e-6, "linear slopes %g, %g", left, right);
    }
}

static double wrapped(double deg)
{
    double w = fmod(deg, 360.0);
    return w < 0 ? w + 360.0 : w;
}

static void test_orbit(void)
{
    sl_camera_key k[2] = {orbit_key(0, 350, 10, 1, 40), orbit_key(1, 10, 30, 4, 60)};
    for (int m = 0; m < 2; m++) {
        sl_camera_spec c = at(k, 2, (sl_path_interpolation)m, 0.5);
        SL_CHECK(c.is_orbit);
        SL_CHECK_MSG(fabs(wrapped(c.orbit.azimuth_deg + 1e-9) - 0.0) < 1e-6 || fabs(wrapped(c.orbit.azimuth_deg) - 360.0) < 1e-6,
                     "350 -> 10 halfway is 0, got %g", c.orbit.azimuth_deg);
        SL_CHECK_NEAR(c.orbit.elevation_deg, 20.0, 1e-12);
        SL_CHECK_NEAR(c.orbit.distance, 2.0, 1e-12);  /* log distance: the geometric mean of 1 and 4 */
        SL_CHECK_NEAR(c.orbit.fov_y_deg, 50.0, 1e-12);
        c = at(k, 2, (sl_path_interpolation)m, 0.25);
        SL_CHECK_NEAR(wrapped(c.orbit.azimuth_deg), 355.0, 1e-9);
    }
    /* -170 -> 170 goes through 180, not through 0. */
    sl_camera_key w[2] = {orbit_key(0, -170, 0, 2, 45), orbit_key(2, 170, 0, 2, 45)};
    SL_CHECK_NEAR(wrapped(at(w, 2, SL_PATH_LINEAR, 1.0).orbit.azimuth_deg), 180.0, 1e-9);
    /* Ends: before the first and after the last key, their cameras. */
    SL_CHECK_NEAR(at(k, 2, SL_PATH_SMOOTH, -3).orbit.distance, 1.0, 1e-12);
    SL_CHECK_NEAR(at(k, 2, SL_PATH_SMOOTH, 3).orbit.elevation_deg, 30.0, 1e-12);
    /* An overshooting curve is clamped to the elevation limit: 0, 89, 89.9 at 0, 1, 1.1
     * would reach 90.36 at t = 1.05 (hand value of the Hermite). */
    sl_camera_key o[3] = {orbit_key(0, 0, 0, 2, 45), orbit_key(1, 0, 89, 2, 45), orbit_key(1.1, 0, 89.9, 2, 45)};
    SL_CHECK_NEAR(at(o, 3, SL_PATH_SMOOTH, 1.05).orbit.elevation_deg, SL_ORBIT_MAX_ELEVATION, 0.0);
    SL_CHECK_NEAR(at(o, 3, SL_PATH_LINEAR, 1.05).orbit.elevation_deg, 89.45, 1e-9);
}

static void test_look_at(void)
{
    sl_camera_key k[2] = {look_key(0, sl_v3(0, 0, 5), sl_v3(0, 0, 0), sl_v3(0, 1, 0)),
                          look_key(1, sl_v3(5, 0, 0), sl_v3(0, 0, 0), sl_v3(0, 1, 0))};
    sl_camera_spec c = at(k, 2, SL_PATH_LINEAR, 0.5);
    SL_CHECK(!c.is_orbit);
    SL_CHECK_NEAR(c.look_at.eye.x, 2.5, 1e-12);
    SL_CHECK_NEAR(c.look_at.eye.z, 2.5, 1e-12);
    /* view direction: slerp of -z and -x halfway = -(1, 0, 1)/sqrt 2; distance 5 */
    double h = 5.0 / sqrt(2.0);
    SL_CHECK_NEAR(c.look_at.target.x, 2.5 - h, 1e-12);
    SL_CHECK_NEAR(c.look_at.target.z, 2.5 - h, 1e-12);
    SL_CHECK_NEAR(c.look_at.up.y, 1.0, 1e-12);
    /* Opposite view directions turn about a perpendicular: unit, finite, orthogonal up. */
    sl_camera_key opp[2] = {look_key(0, sl_v3(0, 0, 5), sl_v3(0, 0, 0), sl_v3(0, 1, 0)),
                            look_key(1, sl_v3(0, 0, 5), sl_v3(0, 0, 10), sl_v3(0, 1, 0))};
    c = at(opp, 2, SL_PATH_SMOOTH, 0.5);
    sl_vec3 f = sl_v3_normalize(sl_v3_sub(c.look_at.target, c.look_at.eye));
    SL_CHECK_MSG(fabs(f.z) < 1e-9 && sl_v3_is_finite(c.look_at.up), "halfway between -z and +z: (%g, %g, %g)", f.x,
                 f.y, f.z);
    SL_CHECK_NEAR(sl_v3_dot(f, c.look_at.up), 0.0, 1e-12);
    /* A mixed path (an orbit beside a look-at key) is eye/target/up throughout; at t = 0 it
     * is the orbit resolved for the bounds. */
    sl_camera_key mixed[2] = {orbit_key(0, 0, 0, 2, 45), k[1]};
    c = at(mixed, 2, SL_PATH_SMOOTH, 0.0);
    SL_CHECK(!c.is_orbit);
    SL_CHECK_NEAR(c.look_at.eye.z, 2.0 * sqrt(3.0), 1e-9); /* on +z at 2 bounding-sphere radii */
    /* Random look-at keys: up stays unit and orthogonal, everything finite. */
    srand(7);
    sl_camera_key r[6];
    for (int i = 0; i < 6; i++) {
        sl_vec3 e = sl_v3(rand() / (double)RAND_MAX * 8 - 4, rand() / (double)RAND_MAX * 8 - 4, 3 + i);
        sl_vec3 u = sl_v3_normalize(sl_v3(rand() / (double)RAND_MAX - 0.5, 1, rand() / (double)RAND_MAX - 0.5));
        r[i] = look_key(i * 0.7 + (i % 2) * 0.3, e, sl_v3(0, 0, 0), u);
    }
    double worst = 0.0;
    for (int s = 0; s < 2000; s++) {
        double t = s * 4.0 / 1999.0 - 0.2;
        c = at(r, 6, SL_PATH_SMOOTH, t);
        f = sl_v3_normalize(sl_v3_sub(c.look_at.target, c.look_at.eye));
        worst = fmax(worst, fabs(sl_v3_dot(f, c.look_at.up)) + fabs(sl_v3_length(c.look_at.up) - 1.0));
        SL_CHECK(sl_v3_is_finite(c.look_at.eye) && sl_v3_is_finite(c.look_at.target));
    }
    SL_CHECK_MSG(worst < 1e-12, "up: worst |up.f| + ||up| - 1| = %g", worst);
}

static void test_errors(void)
{
    sl_camera_key k[2] = {orbit_key(1, 0, 0, 2, 45), orbit_key(1, 10, 0, 2, 45)};
    sl_camera_spec out;
    sl_err err = {0};
    SL_CHECK(sl_camera_path_at(k, 2, SL_PATH_SMOOTH, 0.5, sl_v3(0, 0, 0), sl_v3(1, 1, 1), &out, &err) == SL_ERR_INVALID);
    SL_CHECK(strstr(err.message, "ascending") != NULL);
    SL_CHECK(sl_camera_path_at(k, 0, SL_PATH_SMOOTH, 0.5, sl_v3(0, 0, 0), sl_v3(1, 1, 1), &out, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_camera_path_at(k, 1, SL_PATH_SMOOTH, NAN, sl_v3(0, 0, 0), sl_v3(1, 1, 1), &out, &err) == SL_ERR_INVALID);
}

/* ---- paths in scenes ------------------------------------------------------- */

static const char *path_scene =
    "{\"dataset\": \"tornado\", \"technique\": \"tubes_mesh\", \"params\": {\"radius\": 0.01},"
    " \"path\": {\"fps\": 4, \"interpolation\": \"linear\", \"keyframes\": ["
    "  {\"t\": 0, \"camera\": {\"orbit\": {\"azimuth\": 0}}, \"params\": {\"sides\": 8, \"color\": [0, 0, 0]}},"
    "  {\"t\": 1, \"camera\": {\"orbit\": {\"azimuth\": 90}}, \"params\": {\"radius\": 0.02, \"colormap\": \"magma\"}},"
    "  {\"t\": 2.1, \"camera\": {\"orbit\": {\"azimuth\": 180}}, \"params\": {\"sides\": 16, \"color\": [1, 0.5, 0.25],"
    "   \"radius\": 0.04}}]}}";

static double number_of(const cJSON *o, const char *name)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, name);
    return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

static const sl_param_def masks_params[] = {
    {"sides", SL_PARAM_INT, 0, 31, {1}, NULL, "sets", "a bit mask", SL_INVALIDATE_FRAME},
    {"color", SL_PARAM_VALUES, 0, 1, {0}, NULL, "", "a list", SL_INVALIDATE_FRAME},
};
static const sl_technique masks_technique = {.name = "masks", .description = "test-only", .params = masks_params,
                                             .param_count = 2};

static void test_scene_paths(void)
{
    sl_scene s;
    sl_err err = {0};
    SL_CHECK_MSG(sl_scene_parse(path_scene, &s, &err) == SL_OK, "%s", err.message);
    if (!s.path)
        return;
    const sl_technique *tech = sl_technique_find("tubes_mesh");
    SL_CHECK(sl_scene_path_frames(s.path) == 9); /* floor(2.1 * 4) + 1 */
    cJSON *p = sl_scene_path_params(s.path, 0.5, s.params, tech);
    SL_CHECK(p != NULL);
    /* radius: keyed at 1 and 2.1 only: held at 0.02 before t = 1 (the scene's 0.01 is overridden) */
    SL_CHECK_NEAR(number_of(p, "radius"), 0.02, 1e-15);
    SL_CHECK_NEAR(number_of(p, "sides"), 10.0, 0.0); /* an int: 8 + (16 - 8) 0.5 / 2.1 = 9.9, rounded */
    cJSON_Delete(p);
    p = sl_scene_path_params(s.path, 1.6, s.params, tech);
    SL_CHECK_NEAR(number_of(p, "radius"), 0.02 + 0.02 * 0.6 / 1.1, 1e-15);
    const cJSON *color = cJSON_GetObjectItemCaseSensitive(p, "color");
    SL_CHECK(cJSON_GetArraySize(color) == 3);
    SL_CHECK_NEAR(cJSON_GetArrayItem(color, 1)->valuedouble, 0.5 * 1.6 / 2.1, 1e-15);
    const cJSON *cm = cJSON_GetObjectItemCaseSensitive(p, "colormap");
    SL_CHECK(cJSON_IsString(cm) && strcmp(cm->valuestring, "magma") == 0); /* a choice steps: held after t = 1 */
    cJSON_Delete(p);
    char names[128];
    SL_CHECK(sl_scene_path_prepared_params(s.path, tech, names, sizeof names) == 1 && strcmp(names, "sides") == 0);
    /* The same keys read by a schema where "sides" is a bit mask (unit
     * "sets") and "color" a value list: both step, never blend. */
    p = sl_scene_path_params(s.path, 0.5, s.params, &masks_technique);
    SL_CHECK_NEAR(number_of(p, "sides"), 8.0, 0.0);
    cJSON_Delete(p);
    p = sl_scene_path_params(s.path, 1.6, s.params, &masks_technique);
    SL_CHECK_NEAR(number_of(p, "sides"), 8.0, 0.0);
    color = cJSON_GetObjectItemCaseSensitive(p, "color");
    SL_CHECK(cJSON_GetArraySize(color) == 3 && cJSON_GetArrayItem(color, 1)->valuedouble == 0.0);
    cJSON_Delete(p);
    p = sl_scene_path_params(s.path, 2.1, s.params, &masks_technique);
    SL_CHECK_NEAR(number_of(p, "sides"), 16.0, 0.0);
    cJSON_Delete(p);
    sl_scene_deinit(&s);
}

static void path_bad(const char *path_json, const char *word)
{
    char text[2048];
    snprintf(text, sizeof text, "{\"dataset\": \"tornado\", \"technique\": \"tubes_mesh\", \"path\": %s}", path_json);
    sl_scene s;
    sl_err err = {0};
    sl_status st = sl_scene_parse(text, &s, &err);
    SL_CHECK_MSG(st == SL_ERR_INVALID, "%s was accepted", path_json);
    SL_CHECK_MSG(strstr(err.message, word) != NULL, "%s: message '%s' lacks '%s'", path_json, err.message, word);
    if (st == SL_OK)
        sl_scene_deinit(&s);
}

static void test_bad_paths(void)
{
    const char *cam = "\"camera\": {\"orbit\": {}}";
    char k[512];
    path_bad("[]", "path must be an object");
    path_bad("{\"keyframes\": [{\"t\": 0, \"camera\": {}}]}", "path.fps");
    path_bad("{\"fps\": 0, \"keyframes\": []}", "path.fps");
    path_bad("{\"fps\": 300, \"keyframes\": []}", "path.fps");
    path_bad("{\"fps\": 24, \"keyframes\": []}", "path.keyframes");
    path_bad("{\"fps\": 24, \"speed\": 2, \"keyframes\": []}", "path.speed: unknown field");
    snprintf(k, sizeof k, "{\"fps\": 24, \"interpolation\": \"cubic\", \"keyframes\": [{\"t\": 0, %s}]}", cam);
    path_bad(k, "path.interpolation");
    snprintf(k, sizeof k, "{\"fps\": 24, \"keyframes\": [{\"t\": 1, %s}, {\"t\": 1, %s}]}", cam, cam);
    path_bad(k, "path.keyframes[1].t = 1 must be after");
    snprintf(k, sizeof k, "{\"fps\": 24, \"keyframes\": [{\"t\": -1, %s}]}", cam);
    path_bad(k, "path.keyframes[0].t");
    path_bad("{\"fps\": 24, \"keyframes\": [{\"t\": 0}]}", "path.keyframes[0].camera is required");
    snprintf(k, sizeof k, "{\"fps\": 24, \"keyframes\": [{\"t\": 0, %s, \"zoom\": 1}]}", cam);
    path_bad(k, "path.keyframes[0].zoom: unknown field");
    path_bad("{\"fps\": 24, \"keyframes\": [{\"t\": 0, \"camera\": {\"orbit\": {\"distance\": -1}}}]}",
             "path.keyframes[0]: camera.orbit.distance");
    snprintf(k, sizeof k, "{\"fps\": 24, \"keyframes\": [{\"t\": 0, %s, \"params\": {\"radius\": -1}}]}", cam);
    path_bad(k, "path.keyframes[0].params");
    snprintf(k, sizeof k, "{\"fps\": 240, \"keyframes\": [{\"t\": 0, %s}, {\"t\": 1000, %s}]}", cam, cam);
    path_bad(k, "more than 100000");
    /* The path gives every frame's camera: a scene camera or orbit_frames beside it is refused. */
    sl_scene s;
    sl_err err = {0};
    snprintf(k, sizeof k, "{\"dataset\": \"tornado\", \"camera\": {\"orbit\": {}}, \"path\": {\"fps\": 24,"
             " \"keyframes\": [{\"t\": 0, %s}]}}", cam);
    SL_CHECK(sl_scene_parse(k, &s, &err) == SL_ERR_INVALID && strstr(err.message, "must not have a camera"));
}

int main(void)
{
    test_scalar();
    test_orbit();
    test_look_at();
    test_errors();
    test_scene_paths();
    test_bad_paths();
    SL_TEST_END();
}
