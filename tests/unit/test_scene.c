/* test_scene.c — scene documents (proto/sl_scene.h, proto/scene.md).
 *
 * Parses valid scenes (dataset as catalog name, path, generator object and
 * inline Hermite data; camera as eye/target/up and as orbit; defaults and
 * the size limits) and checks every field; malformed JSON, unknown keys,
 * wrong types, non-finite numbers (1e400 in the text, NaN through --set and
 * in cJSON trees built in memory), zero and huge sizes are SL_ERR_INVALID
 * with a message naming the field, and leave the scene deinitialized.
 * --set overrides (sl_scene_apply_override) are checked one by one,
 * including the orbit/eye exclusivity and bad key paths. Datasets are
 * opened for a built-in name, a generator, inline Hermite data and a file
 * under a data dir (temporary, mkdtemp under /tmp); a missing file fails
 * with SL_ERR_IO naming it. sl_scene_view turns an orbit into the view of
 * a frame. No GL.
 */
#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_dataset.h"
#include "sl_camera_json.h"
#include "sl_params_json.h"
#include "sl_scene.h"
#include "sl_test.h"

static char tmpdir[64];

static const char *hermite_json =
    "{\"nodes\":[{\"p\":[0,0,0],\"t\":[1,0,0],\"r\":0.1},{\"p\":[1,0,0],\"t\":[1,0,0],\"r\":0.1}],"
    "\"segments\":[[0,1]]}";

/* Parses text that must be valid; returns 1 on success (scene filled). */
static int parse_ok(const char *text, sl_scene *s)
{
    sl_err err = {0};
    sl_status st = sl_scene_parse(text, s, &err);
    SL_CHECK_MSG(st == SL_OK, "'%s' -> %s", text, err.message);
    return st == SL_OK;
}

/* Text that must be refused with SL_ERR_INVALID and a message holding every
 * one of the (up to three) words; the scene must be left deinitialized. */
static void parse_bad(const char *text, const char *w1, const char *w2, const char *w3)
{
    sl_scene s;
    memset(&s, 0x5a, sizeof s);
    sl_err err = {0};
    sl_status st = sl_scene_parse(text, &s, &err);
    SL_CHECK_MSG(st == SL_ERR_INVALID, "'%s' was accepted (status %d)", text, (int)st);
    const char *words[3] = {w1, w2, w3};
    for (int k = 0; k < 3; k++)
        if (words[k])
            SL_CHECK_MSG(strstr(err.message, words[k]) != NULL, "'%s': message '%s' lacks '%s'", text, err.message, words[k]);
    SL_CHECK_MSG(s.dataset == NULL && s.params == NULL, "'%s': a failed parse left owned JSON behind", text);
    if (st == SL_OK)
        sl_scene_deinit(&s);
}

/* Applies the overrides to the base document, then parses it. */
static sl_status parse_with(const char *base, const char *const *sets, int n, sl_scene *s, sl_err *err)
{
    memset(s, 0, sizeof *s);
    cJSON *root = cJSON_Parse(base);
    if (!root)
        return sl_err_set(err, SL_ERR_INVALID, "test: base is not JSON");
    sl_status st = SL_OK;
    for (int k = 0; k < n && st == SL_OK; k++)
        st = sl_scene_apply_override(root, sets[k], err);
    if (st == SL_OK)
        st = sl_scene_from_json(root, s, err);
    cJSON_Delete(root);
    return st;
}

static int float_eq(float a, float b) { return a == b; }

/* ---- valid scenes --------------------------------------------------------- */

static void test_defaults(void)
{
    sl_scene s;
    if (!parse_ok("{\"dataset\": \"tornado\"}", &s))
        return;
    SL_CHECK(cJSON_IsString(s.dataset) && strcmp(s.dataset->valuestring, "tornado") == 0);
    SL_CHECK(strcmp(s.technique, "tubes_mesh") == 0);
    SL_CHECK(s.params == NULL);
    SL_CHECK(s.camera.is_orbit == 1);
    SL_CHECK(s.camera.orbit.azimuth_deg == 30.0 && s.camera.orbit.elevation_deg == 20.0 && s.camera.orbit.distance == 2.5);
    SL_CHECK(s.camera.orbit.fov_y_deg == 45.0);
    SL_CHECK(s.width == 256 && s.height == 256);
    SL_CHECK(float_eq(s.background[0], 0.1f) && float_eq(s.background[1], 0.1f) && float_eq(s.background[2], 0.12f) &&
             float_eq(s.background[3], 1.0f));
    SL_CHECK(s.orbit_frames == 0);
    sl_scene_deinit(&s);
    SL_CHECK(s.dataset == NULL && s.params == NULL);
}

static void test_valid(void)
{
    sl_scene s;
    /* The example of scene.md, verbatim. */
    if (parse_ok("{\"description\": \"The built-in tornado streamlines as tessellated tubes, coloured by speed.\","
                 " \"dataset\": \"tornado\", \"technique\": \"tubes_mesh\","
                 " \"params\": {\"colormap\": \"viridis\", \"radius\": 0.01},"
                 " \"camera\": {\"orbit\": {\"azimuth\": 30, \"elevation\": 20, \"distance\": 2.2}, \"fov_y\": 45},"
                 " \"width\": 640, \"height\": 480, \"background\": [0.1, 0.1, 0.12, 1]}", &s)) {
        SL_CHECK(s.width == 640 && s.height == 480);
        SL_CHECK(s.camera.is_orbit && s.camera.orbit.distance == 2.2 && s.camera.orbit.fov_y_deg == 45.0);
        const cJSON *r = cJSON_GetObjectItemCaseSensitive(s.params, "radius");
        SL_CHECK(cJSON_IsNumber(r) && r->valuedouble == 0.01);
        sl_scene_deinit(&s);
    }

    /* Dataset forms. */
    if (parse_ok("{\"dataset\": \"lines/fibres.trk\"}", &s)) {
        SL_CHECK(cJSON_IsString(s.dataset) && strcmp(s.dataset->valuestring, "lines/fibres.trk") == 0);
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": {\"generator\": \"tornado\", \"lines\": 5, \"points\": 10, \"seed\": 2}}", &s)) {
        const cJSON *g = cJSON_GetObjectItemCaseSensitive(s.dataset, "generator");
        const cJSON *l = cJSON_GetObjectItemCaseSensitive(s.dataset, "lines");
        SL_CHECK(cJSON_IsString(g) && strcmp(g->valuestring, "tornado") == 0 && cJSON_IsNumber(l) && l->valuedouble == 5);
        sl_scene_deinit(&s);
    }
    char text[1024];
    snprintf(text, sizeof text, "{\"dataset\": %s, \"technique\": \"tubes\"}", hermite_json);
    if (parse_ok(text, &s)) {
        SL_CHECK(cJSON_IsObject(s.dataset) && cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(s.dataset, "nodes")) == 2);
        SL_CHECK(strcmp(s.technique, "tubes") == 0);
        sl_scene_deinit(&s);
    }

    /* Camera, explicit, with and without up. */
    if (parse_ok("{\"dataset\": \"x.vtk\", \"camera\": {\"eye\": [1, 2, 3], \"target\": [0, -1, 0.5],"
                 " \"up\": [0, 0, 1], \"fov_y\": 30}}", &s)) {
        SL_CHECK(!s.camera.is_orbit);
        SL_CHECK(s.camera.look_at.eye.x == 1 && s.camera.look_at.eye.y == 2 && s.camera.look_at.eye.z == 3);
        SL_CHECK(s.camera.look_at.target.x == 0 && s.camera.look_at.target.y == -1 && s.camera.look_at.target.z == 0.5);
        SL_CHECK(s.camera.look_at.up.x == 0 && s.camera.look_at.up.y == 0 && s.camera.look_at.up.z == 1);
        SL_CHECK(s.camera.look_at.fov_y_deg == 30.0);
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": \"x.vtk\", \"camera\": {\"eye\": [0, 0, 5], \"target\": [0, 0, 0]}}", &s)) {
        SL_CHECK(!s.camera.is_orbit && s.camera.look_at.up.x == 0 && s.camera.look_at.up.y == 1 && s.camera.look_at.up.z == 0);
        SL_CHECK(s.camera.look_at.fov_y_deg == 45.0);
        sl_scene_deinit(&s);
    }
    /* Orbit: missing fields take the defaults; fov_y sits beside orbit. */
    if (parse_ok("{\"dataset\": \"x.vtk\", \"camera\": {\"orbit\": {\"azimuth\": -75.5}, \"fov_y\": 60}}", &s)) {
        SL_CHECK(s.camera.is_orbit && s.camera.orbit.azimuth_deg == -75.5 && s.camera.orbit.elevation_deg == 20.0 &&
                 s.camera.orbit.distance == 2.5 && s.camera.orbit.fov_y_deg == 60.0);
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": \"x.vtk\", \"camera\": {\"orbit\": {}}}", &s)) {
        SL_CHECK(s.camera.is_orbit && s.camera.orbit.azimuth_deg == 30.0 && s.camera.orbit.fov_y_deg == 45.0);
        sl_scene_deinit(&s);
    }

    /* Sizes at the limits, background with 3 and 4 components, orbit_frames. */
    if (parse_ok("{\"dataset\": \"x.vtk\", \"width\": 1, \"height\": 8192, \"background\": [1, 0, 0.5],"
                 " \"orbit_frames\": 1000000}", &s)) {
        SL_CHECK(s.width == 1 && s.height == SL_SCENE_MAX_SIZE);
        SL_CHECK(s.background[0] == 1.0f && s.background[1] == 0.0f && s.background[2] == 0.5f && s.background[3] == 1.0f);
        SL_CHECK(s.orbit_frames == 1000000);
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": \"x.vtk\", \"width\": 8192, \"height\": 1, \"background\": [0, 0, 0, 0]}", &s)) {
        SL_CHECK(s.width == 8192 && s.height == 1 && s.background[3] == 0.0f);
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": \"x.vtk\", \"width\": 3.0e2}", &s)) {   /* an integer written as a float */
        SL_CHECK(s.width == 300 && s.height == 256);
        sl_scene_deinit(&s);
    }

    /* Every registered technique is accepted, with valid params of its own:
     * every parameter at its default, as sl_params_to_json writes it (a
     * volume technique has no `radius`). */
    int n = 0;
    const sl_technique *const *list = sl_technique_list(&n);
    for (int k = 0; k < n; k++) {
        sl_params defaults;
        sl_params_init(&defaults, list[k]->params, list[k]->param_count);
        cJSON *pj = sl_params_to_json(&defaults);
        char *ptext = pj ? cJSON_PrintUnformatted(pj) : NULL;
        cJSON_Delete(pj);
        char big[8192];
        snprintf(big, sizeof big, "{\"dataset\": \"x.vtk\", \"technique\": \"%s\", \"params\": %s}", list[k]->name,
                 ptext ? ptext : "{}");
        cJSON_free(ptext);
        if (parse_ok(big, &s)) {
            SL_CHECK(strcmp(s.technique, list[k]->name) == 0);
            sl_scene_deinit(&s);
        }
    }
}

/* ---- invalid scenes ------------------------------------------------------- */

static void test_invalid(void)
{
    /* Malformed JSON and non-objects. */
    parse_bad("", "JSON", NULL, NULL);
    parse_bad("{", "JSON", NULL, NULL);
    parse_bad("{\"dataset\": \"x.vtk\",}", "JSON", NULL, NULL);
    parse_bad("{\"dataset\": \"x.vtk\"} trailing", "JSON", NULL, NULL);
    parse_bad("{\"dataset\": 'x.vtk'}", "JSON", NULL, NULL);
    parse_bad("[1, 2]", "object", NULL, NULL);
    parse_bad("\"tornado\"", "object", NULL, NULL);
    parse_bad("null", "object", NULL, NULL);

    /* Dataset. */
    parse_bad("{}", "dataset", "required", NULL);
    parse_bad("{\"dataset\": \"\"}", "dataset", NULL, NULL);
    parse_bad("{\"dataset\": 5}", "dataset", NULL, NULL);
    parse_bad("{\"dataset\": [\"tornado\"]}", "dataset", NULL, NULL);
    parse_bad("{\"dataset\": null}", "dataset", NULL, NULL);

    /* Unknown keys, at every level, named by path. */
    parse_bad("{\"dataset\": \"x.vtk\", \"widht\": 5}", "widht", "unknown", NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"camera\": {\"zoom\": 2}}", "camera.zoom", "unknown", NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"camera\": {\"orbit\": {\"radius\": 2}}}", "camera.orbit.radius", "unknown", NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"Width\": 5}", "Width", NULL, NULL);   /* keys are case-sensitive */

    /* Technique and params. */
    parse_bad("{\"dataset\": \"x.vtk\", \"technique\": \"raytrace\"}", "raytrace", "tubes_mesh", "voxel_lines");
    parse_bad("{\"dataset\": \"x.vtk\", \"technique\": 3}", "technique", NULL, NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"technique\": \"\"}", "technique", NULL, NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"params\": [1]}", "params", NULL, NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"params\": {\"radius\": -1}}", "params", "radius", "[0, 1e+09]");
    parse_bad("{\"dataset\": \"x.vtk\", \"params\": {\"no_such\": 1}}", "params", "no_such", NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"params\": {\"radius\": \"big\"}}", "params", "radius", NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"params\": {\"radius\": 1e400}}", "params", "radius", NULL);
    /* Params are checked against the scene's technique: sides is 6..30 for tubes_mesh, 3..30 for lines_oit. */
    parse_bad("{\"dataset\": \"x.vtk\", \"params\": {\"sides\": 4}}", "sides", "[6, 30]", NULL);
    sl_scene s;
    if (parse_ok("{\"dataset\": \"x.vtk\", \"technique\": \"lines_oit\", \"params\": {\"sides\": 4}}", &s))
        sl_scene_deinit(&s);

    /* Sizes. */
    const char *sizes[] = {"0", "-1", "8193", "1e9", "1e400", "-1e400", "1.5", "\"256\"", "true", "null", "[256]"};
    char text[512];
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        snprintf(text, sizeof text, "{\"dataset\": \"x.vtk\", \"width\": %s}", sizes[k]);
        parse_bad(text, "width", "8192", NULL);
        snprintf(text, sizeof text, "{\"dataset\": \"x.vtk\", \"height\": %s}", sizes[k]);
        parse_bad(text, "height", "8192", NULL);
    }

    /* Background. */
    const char *bgs[] = {"[1, 1]", "[0, 0, 0, 0, 0]", "[0, 0, 2]", "[0, 0, -0.1]", "[0, \"0\", 0]", "\"red\"",
                         "[0, 0, 1e400]", "[]", "0.5"};
    for (size_t k = 0; k < sizeof bgs / sizeof bgs[0]; k++) {
        snprintf(text, sizeof text, "{\"dataset\": \"x.vtk\", \"background\": %s}", bgs[k]);
        parse_bad(text, "background", NULL, NULL);
    }

    /* orbit_frames. */
    parse_bad("{\"dataset\": \"x.vtk\", \"orbit_frames\": -1}", "orbit_frames", NULL, NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"orbit_frames\": 2.5}", "orbit_frames", NULL, NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"orbit_frames\": 1000001}", "orbit_frames", NULL, NULL);
    parse_bad("{\"dataset\": \"x.vtk\", \"orbit_frames\": \"4\"}", "orbit_frames", NULL, NULL);
    /* orbit_frames turns an orbit: with eye/target/up it would be ignored, so it is an error. */
    parse_bad("{\"dataset\": \"x.vtk\", \"orbit_frames\": 4, \"camera\": {\"eye\": [0, 0, 5], \"target\": [0, 0, 0]}}",
              "orbit_frames", "orbit camera", "eye/target/up");
    sl_scene ok;
    if (parse_ok("{\"dataset\": \"x.vtk\", \"orbit_frames\": 0, \"camera\": {\"eye\": [0, 0, 5], \"target\": [0, 0, 0]}}",
                 &ok)) {
        SL_CHECK(!ok.camera.is_orbit && ok.orbit_frames == 0);
        sl_scene_deinit(&ok);
    }
    if (parse_ok("{\"dataset\": \"x.vtk\", \"orbit_frames\": 8}", &ok)) {   /* the default camera is an orbit */
        SL_CHECK(ok.camera.is_orbit && ok.orbit_frames == 8);
        sl_scene_deinit(&ok);
    }
    /* Elevation at its limits is accepted as given (no clamp). */
    if (parse_ok("{\"dataset\": \"x.vtk\", \"camera\": {\"orbit\": {\"elevation\": -89.9}}}", &ok)) {
        SL_CHECK(ok.camera.orbit.elevation_deg == -89.9);
        sl_scene_deinit(&ok);
    }

    /* Cameras. */
    const struct { const char *cam, *w1, *w2; } cams[] = {
        {"5", "camera", NULL},
        {"[]", "camera", NULL},
        {"{}", "camera.eye", "required"},
        {"{\"eye\": [0, 0, 5]}", "camera.target", "required"},
        {"{\"target\": [0, 0, 5]}", "camera.eye", "required"},
        {"{\"eye\": [0, 0], \"target\": [0, 0, 0]}", "camera.eye", NULL},
        {"{\"eye\": [0, 0, 5, 1], \"target\": [0, 0, 0]}", "camera.eye", NULL},
        {"{\"eye\": \"0 0 5\", \"target\": [0, 0, 0]}", "camera.eye", NULL},
        {"{\"eye\": [0, 0, 5], \"target\": [0, null, 0]}", "camera.target", NULL},
        {"{\"eye\": [0, 0, 1e400], \"target\": [0, 0, 0]}", "camera.eye", "finite"},
        {"{\"eye\": [0, 0, 5], \"target\": [-1e400, 0, 0]}", "camera.target", "finite"},
        {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1e400, 0]}", "camera.up", "finite"},
        {"{\"eye\": [1, 2, 3], \"target\": [1, 2, 3]}", "differ", NULL},
        {"{\"eye\": [0, 5, 0], \"target\": [0, 0, 0]}", "camera.up", "parallel"},   /* default up = +y */
        {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 0, 0]}", "camera.up", NULL},
        {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"fov_y\": 0}", "camera.fov_y", "(0, 180)"},
        {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"fov_y\": 180}", "camera.fov_y", NULL},
        {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"fov_y\": -30}", "camera.fov_y", NULL},
        {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"fov_y\": \"45\"}", "camera.fov_y", NULL},
        {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"fov_y\": 1e400}", "camera.fov_y", NULL},
        {"{\"orbit\": {\"distance\": 2}, \"fov_y\": 200}", "camera.fov_y", NULL},
        {"{\"orbit\": {\"azimuth\": 10}, \"eye\": [0, 0, 5]}", "orbit", "eye"},
        {"{\"orbit\": {\"azimuth\": 10}, \"target\": [0, 0, 0]}", "orbit", "target"},
        {"{\"orbit\": 5}", "camera.orbit", NULL},
        {"{\"orbit\": [30, 20, 2]}", "camera.orbit", NULL},
        {"{\"orbit\": {\"distance\": 0}}", "camera.orbit.distance", NULL},
        {"{\"orbit\": {\"distance\": -2}}", "camera.orbit.distance", NULL},
        {"{\"orbit\": {\"distance\": \"far\"}}", "camera.orbit.distance", NULL},
        {"{\"orbit\": {\"distance\": 1e400}}", "camera.orbit.distance", "finite"},
        {"{\"orbit\": {\"azimuth\": 1e400}}", "camera.orbit.azimuth", "finite"},
        {"{\"orbit\": {\"elevation\": -1e400}}", "camera.orbit.elevation", "finite"},
        {"{\"orbit\": {\"azimuth\": true}}", "camera.orbit.azimuth", NULL},
        {"{\"orbit\": {\"elevation\": null}}", "camera.orbit.elevation", NULL},
        {"{\"orbit\": {\"elevation\": 100}}", "camera.orbit.elevation", "[-89.9, 89.9]"},
        {"{\"orbit\": {\"elevation\": -90}}", "camera.orbit.elevation", "got -90"},
        {"{\"orbit\": {\"elevation\": 89.90001}}", "camera.orbit.elevation", "[-89.9, 89.9]"},
        /* Both forms: the conflict is named first, with the fields found, even with up present. */
        {"{\"orbit\": {\"distance\": 2}, \"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0]}",
         "not both", "orbit and eye, target"},
        {"{\"orbit\": {\"distance\": 2}, \"up\": [0, 1, 0]}", "camera.up", "always +y"},
    };
    for (size_t k = 0; k < sizeof cams / sizeof cams[0]; k++) {
        snprintf(text, sizeof text, "{\"dataset\": \"x.vtk\", \"camera\": %s}", cams[k].cam);
        parse_bad(text, cams[k].w1, cams[k].w2, NULL);
    }
}

/* NaN cannot be written in JSON, but cJSON trees built in memory (the server's
 * messages, --set values) can hold it: sl_scene_from_json must refuse it. */
static void test_nan_in_memory(void)
{
    const char *paths[][3] = {
        {"camera", "orbit", "azimuth"}, {"camera", "orbit", "elevation"}, {"camera", "orbit", "distance"},
        {"camera", "fov_y", NULL}, {"width", NULL, NULL}, {"height", NULL, NULL}, {"orbit_frames", NULL, NULL},
    };
    const double bad[] = {NAN, INFINITY, -INFINITY};
    for (size_t k = 0; k < sizeof paths / sizeof paths[0]; k++)
        for (int b = 0; b < 3; b++) {
            cJSON *root = cJSON_Parse("{\"dataset\": \"x.vtk\", \"camera\": {\"orbit\": {}}}");
            cJSON *node = root;
            int depth = 0;
            while (depth < 2 && paths[k][depth + 1]) {
                node = cJSON_GetObjectItemCaseSensitive(node, paths[k][depth]);
                depth++;
            }
            cJSON_AddItemToObject(node, paths[k][depth], cJSON_CreateNumber(bad[b]));
            sl_scene s;
            sl_err err = {0};
            sl_status st = sl_scene_from_json(root, &s, &err);
            SL_CHECK_MSG(st == SL_ERR_INVALID, "%s.%s = %g accepted", paths[k][0], paths[k][depth], bad[b]);
            SL_CHECK_MSG(strstr(err.message, paths[k][depth]) != NULL, "%s = %g: '%s'", paths[k][depth], bad[b], err.message);
            if (st == SL_OK)
                sl_scene_deinit(&s);
            cJSON_Delete(root);
        }
    /* Explicit eye/target/up with NaN components. */
    const char *vecs[] = {"eye", "target", "up"};
    for (int v = 0; v < 3; v++)
        for (int c = 0; c < 3; c++) {
            cJSON *root = cJSON_Parse("{\"dataset\": \"x.vtk\", \"camera\": {\"eye\": [0, 0, 5], \"target\": [0, 0, 0],"
                                      " \"up\": [0, 1, 0]}}");
            cJSON *arr = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "camera"), vecs[v]);
            cJSON_ReplaceItemInArray(arr, c, cJSON_CreateNumber(NAN));
            sl_scene s;
            sl_err err = {0};
            sl_status st = sl_scene_from_json(root, &s, &err);
            SL_CHECK_MSG(st == SL_ERR_INVALID && strstr(err.message, vecs[v]), "%s[%d] = NaN: %s", vecs[v], c, err.message);
            if (st == SL_OK)
                sl_scene_deinit(&s);
            cJSON_Delete(root);
        }
    /* The camera parser shared with the protocol, directly. */
    cJSON *cam = cJSON_CreateObject();
    cJSON *orbit = cJSON_AddObjectToObject(cam, "orbit");
    cJSON_AddNumberToObject(orbit, "distance", NAN);
    sl_camera_spec spec = {.is_orbit = -1};
    sl_err err = {0};
    SL_CHECK(sl_camera_json_parse(cam, &spec, &err) == SL_ERR_INVALID);
    SL_CHECK(spec.is_orbit == -1 && spec.orbit.distance == 0.0);   /* output untouched on failure */
    cJSON_Delete(cam);
}

/* n doubles at a and b agree to within cJSON's printing, which writes 15
 * digits when they read back within DBL_EPSILON (relative) of the value. */
static int same_printed(const void *a, const void *b, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        double x, y;
        memcpy(&x, (const double *)a + i, sizeof x);
        memcpy(&y, (const double *)b + i, sizeof y);
        if (!(fabs(x - y) <= 2.0 * DBL_EPSILON * fmax(fabs(x), fabs(y))))
            return 0;
    }
    return 1;
}

/* sl_camera_to_json writes every key (defaults included) and reads back to
 * the same numbers (to cJSON's printing precision) in both forms. */
static void test_camera_json(void)
{
    const char *cases[] = {
        "{}",   /* no camera key: the scene's default */
        "{\"camera\": {\"orbit\": {\"azimuth\": 75}}}",
        "{\"camera\": {\"orbit\": {\"azimuth\": 0.1, \"elevation\": -89.9, \"distance\": 1e-3}, \"fov_y\": 179.5}}",
        "{\"camera\": {\"eye\": [1, 2, 3], \"target\": [0.30000000000000004, -1, 1e30]}}",
        "{\"camera\": {\"eye\": [0, 0, -5], \"target\": [0, 0, 0], \"up\": [1, 0, 0], \"fov_y\": 33.3}}",
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[512];
        snprintf(text, sizeof text, "{\"dataset\": \"x.vtk\"%s%s", strcmp(cases[i], "{}") ? ", " : "",
                 strcmp(cases[i], "{}") ? cases[i] + 1 : "}");
        sl_scene s;
        sl_err err = {0};
        if (sl_scene_parse(text, &s, &err) != SL_OK) {
            SL_CHECK_MSG(0, "%s: %s", text, err.message);
            continue;
        }
        cJSON *j = sl_camera_to_json(&s.camera);
        SL_CHECK(j && cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(j, "fov_y")));
        const char *const *keys = s.camera.is_orbit ? (const char *const[]){"orbit", NULL}
                                                    : (const char *const[]){"eye", "target", "up", NULL};
        for (int k = 0; keys[k]; k++)
            SL_CHECK_MSG(cJSON_HasObjectItem(j, keys[k]), "%s: no %s written", text, keys[k]);
        char *printed = cJSON_PrintUnformatted(j);
        cJSON *back = cJSON_Parse(printed);
        sl_camera_spec again = {0};
        SL_CHECK_MSG(sl_camera_json_parse(back, &again, &err) == SL_OK, "%s -> %s: %s", text, printed, err.message);
        int same = again.is_orbit == s.camera.is_orbit &&
                   (s.camera.is_orbit
                        ? same_printed(&again.orbit, &s.camera.orbit, sizeof again.orbit / sizeof(double))
                        : same_printed(&again.look_at, &s.camera.look_at, sizeof again.look_at / sizeof(double)));
        SL_CHECK_MSG(same, "%s -> %s does not read back to the same camera", text, printed);
        free(printed);
        cJSON_Delete(back);
        cJSON_Delete(j);
        sl_scene_deinit(&s);
    }
    /* The scene's default is core's. */
    sl_scene s;
    sl_err err = {0};
    SL_CHECK(sl_scene_parse("{\"dataset\": \"x.vtk\"}", &s, &err) == SL_OK);
    SL_CHECK(s.camera.is_orbit && memcmp(&s.camera.orbit, &sl_orbit_default, sizeof s.camera.orbit) == 0);
    sl_scene_deinit(&s);
}

/* ---- --set overrides ------------------------------------------------------ */

static void test_overrides(void)
{
    const char *explicit_cam = "{\"dataset\": \"tornado\", \"camera\": {\"eye\": [0, 0, 5], \"target\": [0, 0, 0],"
                               " \"fov_y\": 50}, \"params\": {\"sides\": 8}}";
    sl_scene s;
    sl_err err = {0};

    /* The two examples of the brief: an orbit replaces eye/target; params are created or merged. */
    const char *sets1[] = {"camera.orbit.azimuth=30", "params.radius=0.5"};
    sl_status st = parse_with(explicit_cam, sets1, 2, &s, &err);
    SL_CHECK_MSG(st == SL_OK, "%s", err.message);
    if (st == SL_OK) {
        SL_CHECK(s.camera.is_orbit && s.camera.orbit.azimuth_deg == 30.0 && s.camera.orbit.elevation_deg == 20.0 &&
                 s.camera.orbit.distance == 2.5);
        SL_CHECK(s.camera.orbit.fov_y_deg == 50.0);
        const cJSON *r = cJSON_GetObjectItemCaseSensitive(s.params, "radius");
        const cJSON *sd = cJSON_GetObjectItemCaseSensitive(s.params, "sides");
        SL_CHECK(cJSON_IsNumber(r) && r->valuedouble == 0.5);
        SL_CHECK(cJSON_IsNumber(sd) && sd->valuedouble == 8);
        sl_scene_deinit(&s);
    }
    /* An orbit field on an eye/target/up camera: the up goes with eye and target
     * (it used to stay and fail as "an orbit camera's up is always +y"). */
    const char *with_up = "{\"dataset\": \"tornado\", \"camera\": {\"eye\": [0, 0, 5], \"target\": [0, 0, 0],"
                          " \"up\": [0, 1, 0], \"fov_y\": 40}}";
    const char *sets_up[] = {"camera.orbit.distance=2"};
    st = parse_with(with_up, sets_up, 1, &s, &err);
    SL_CHECK_MSG(st == SL_OK, "orbit over eye/target/up: %s", err.message);
    if (st == SL_OK) {
        SL_CHECK(s.camera.is_orbit && s.camera.orbit.distance == 2.0 && s.camera.orbit.azimuth_deg == 30.0 &&
                 s.camera.orbit.elevation_deg == 20.0 && s.camera.orbit.fov_y_deg == 40.0);
        sl_scene_deinit(&s);
    }
    const char *sets_up2[] = {"camera.orbit={\"azimuth\": 5}"};
    st = parse_with(with_up, sets_up2, 1, &s, &err);
    SL_CHECK_MSG(st == SL_OK && s.camera.is_orbit && s.camera.orbit.azimuth_deg == 5.0, "camera.orbit={...}: %s",
                 st ? err.message : "wrong orbit");
    if (st == SL_OK)
        sl_scene_deinit(&s);
    /* An up set on an orbit camera is still refused (it cannot apply). */
    const char *sets_up3[] = {"camera.up=[0,0,1]"};
    st = parse_with("{\"dataset\": \"tornado\", \"camera\": {\"orbit\": {}}}", sets_up3, 1, &s, &err);
    SL_CHECK_MSG(st == SL_ERR_INVALID && strstr(err.message, "camera.up"), "up on an orbit: %s",
                 st ? err.message : "accepted");
    if (st == SL_OK)
        sl_scene_deinit(&s);

    const char *sets2[] = {"params.radius=0.5", "camera.orbit.azimuth=-12.5", "camera.orbit.distance=4"};
    st = parse_with("{\"dataset\": \"tornado\"}", sets2, 3, &s, &err);
    SL_CHECK_MSG(st == SL_OK, "%s", err.message);
    if (st == SL_OK) {
        SL_CHECK(s.camera.is_orbit && s.camera.orbit.azimuth_deg == -12.5 && s.camera.orbit.distance == 4.0);
        const cJSON *r = cJSON_GetObjectItemCaseSensitive(s.params, "radius");
        SL_CHECK(cJSON_IsNumber(r) && r->valuedouble == 0.5);
        sl_scene_deinit(&s);
    }

    /* An eye replaces the orbit; values that are not JSON are strings; later sets win. */
    const char *sets3[] = {"camera.eye=[1, 2, 3]", "camera.target=[0,0,0]", "technique=tubes", "width=640",
                           "width=320", "height=200", "background=[0,0,0]", "description=a run of 3 tubes",
                           "dataset={\"generator\":\"abc\",\"lines\":50,\"seed\":2}"};
    st = parse_with("{\"dataset\": \"tornado\", \"camera\": {\"orbit\": {\"azimuth\": 5}}}", sets3, 9, &s, &err);
    SL_CHECK_MSG(st == SL_OK, "%s", err.message);
    if (st == SL_OK) {
        SL_CHECK(!s.camera.is_orbit && s.camera.look_at.eye.x == 1 && s.camera.look_at.eye.y == 2 && s.camera.look_at.eye.z == 3);
        SL_CHECK(strcmp(s.technique, "tubes") == 0);
        SL_CHECK(s.width == 320 && s.height == 200);
        SL_CHECK(s.background[0] == 0.0f && s.background[3] == 1.0f);
        const cJSON *g = cJSON_GetObjectItemCaseSensitive(s.dataset, "generator");
        SL_CHECK(cJSON_IsString(g) && strcmp(g->valuestring, "abc") == 0);
        sl_scene_deinit(&s);
    }

    /* A value is JSON only when all of it is JSON: a file name that starts like
     * a number or a literal stays a string. */
    const char *names[] = {"2024_run.vtk", "true_colour.obj", "null.tck", "1e5.nrrd", "[1].vtk", "{}.json"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        char set[128];
        snprintf(set, sizeof set, "dataset=%s", names[k]);
        const char *sets[] = {set};
        st = parse_with("{\"dataset\": \"tornado\"}", sets, 1, &s, &err);
        SL_CHECK_MSG(st == SL_OK, "--set %s: %s", set, err.message);
        if (st == SL_OK) {
            SL_CHECK_MSG(cJSON_IsString(s.dataset) && strcmp(s.dataset->valuestring, names[k]) == 0,
                         "--set %s: dataset is not that string", set);
            sl_scene_deinit(&s);
        }
    }
    const char *deg[] = {"camera.orbit.azimuth=30deg"};
    st = parse_with("{\"dataset\": \"tornado\"}", deg, 1, &s, &err);
    SL_CHECK_MSG(st == SL_ERR_INVALID && strstr(err.message, "camera.orbit.azimuth"), "30deg: %s",
                 st == SL_OK ? "accepted" : err.message);
    if (st == SL_OK)
        sl_scene_deinit(&s);

    /* NaN, infinities and huge numbers through --set: named errors at parse time. */
    const struct { const char *set, *field; } bad[] = {
        {"camera.orbit.azimuth=NaN", "camera.orbit.azimuth"},
        {"camera.orbit.azimuth=nan", "camera.orbit.azimuth"},
        {"camera.orbit.elevation=1e400", "camera.orbit.elevation"},
        {"camera.orbit.distance=-1e400", "camera.orbit.distance"},
        {"camera.orbit.distance=Infinity", "camera.orbit.distance"},
        {"camera.orbit.distance=0", "camera.orbit.distance"},
        {"camera.fov_y=NaN", "camera.fov_y"},
        {"camera.fov_y=180", "camera.fov_y"},
        {"camera.eye=[NaN,0,0]", "camera"},
        {"width=NaN", "width"},
        {"width=1e400", "width"},
        {"width=0", "width"},
        {"height=100000", "height"},
        {"height=-5", "height"},
        {"params.radius=NaN", "radius"},
        {"params.radius=1e400", "radius"},
        {"params.radius=-1", "radius"},
        {"params.nope=1", "nope"},
        {"technique=nope", "nope"},
        {"background=[0,0,NaN]", "background"},
        {"frobnicate=1", "frobnicate"},
        {"camera.orbit.radius=2", "camera.orbit.radius"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        const char *sets[] = {bad[k].set};
        memset(&err, 0, sizeof err);
        st = parse_with("{\"dataset\": \"tornado\"}", sets, 1, &s, &err);
        SL_CHECK_MSG(st == SL_ERR_INVALID, "--set %s accepted", bad[k].set);
        SL_CHECK_MSG(strstr(err.message, bad[k].field) != NULL, "--set %s: message '%s' lacks '%s'", bad[k].set,
                     err.message, bad[k].field);
        if (st == SL_OK)
            sl_scene_deinit(&s);
    }

    /* Bad assignments: refused by sl_scene_apply_override itself, the document unchanged. */
    const char *bad_sets[] = {"width", "=5", "", "width.x=1", "camera.orbit.azimuth.deg=1", ".=1", "...=1",
                              "dataset.generator=abc"};
    for (size_t k = 0; k < sizeof bad_sets / sizeof bad_sets[0]; k++) {
        cJSON *root = cJSON_Parse("{\"dataset\": \"tornado\", \"width\": 64, \"camera\": {\"orbit\": {\"azimuth\": 1}}}");
        char *before = cJSON_PrintUnformatted(root);
        memset(&err, 0, sizeof err);
        st = sl_scene_apply_override(root, bad_sets[k], &err);
        SL_CHECK_MSG(st == SL_ERR_INVALID, "--set '%s' accepted", bad_sets[k]);
        SL_CHECK_MSG(err.message[0] != '\0', "--set '%s': no message", bad_sets[k]);
        char *after = cJSON_PrintUnformatted(root);
        SL_CHECK_MSG(before && after && strcmp(before, after) == 0, "--set '%s' changed the document: %s", bad_sets[k],
                     after ? after : "?");
        cJSON_free(before);
        cJSON_free(after);
        cJSON_Delete(root);
    }
    /* The offending part is named. */
    cJSON *root = cJSON_Parse("{\"dataset\": \"tornado\", \"width\": 64}");
    SL_CHECK(sl_scene_apply_override(root, "width.x=1", &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "width") != NULL, "%s", err.message);
    SL_CHECK(sl_scene_apply_override(root, "width", &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "key.path=value") != NULL, "%s", err.message);
    char longkey[400];
    memset(longkey, 'k', sizeof longkey);
    memcpy(longkey + 300, "=1", 3);
    SL_CHECK(sl_scene_apply_override(root, longkey, &err) == SL_ERR_INVALID);
    /* A value with '=' in it keeps everything after the first '='. */
    SL_CHECK(sl_scene_apply_override(root, "description=a=b", &err) == SL_OK);
    const cJSON *d = cJSON_GetObjectItemCaseSensitive(root, "description");
    SL_CHECK(cJSON_IsString(d) && strcmp(d->valuestring, "a=b") == 0);
    /* An empty value is the empty string. */
    SL_CHECK(sl_scene_apply_override(root, "description=", &err) == SL_OK);
    d = cJSON_GetObjectItemCaseSensitive(root, "description");
    SL_CHECK(cJSON_IsString(d) && d->valuestring[0] == '\0');
    cJSON_Delete(root);
}

/* ---- datasets and views --------------------------------------------------- */

static void test_open_dataset(void)
{
    sl_scene s;
    sl_dataset *ds = NULL;
    sl_err err = {0};

    /* A built-in name. */
    if (parse_ok("{\"dataset\": \"marschner_lobb\"}", &s)) {
        sl_status st = sl_scene_open_dataset(&s, NULL, &ds, &err);
        SL_CHECK_MSG(st == SL_OK && ds, "marschner_lobb: %s", err.message);
        if (ds) {
            SL_CHECK(ds->kind == SL_DATASET_VOLUME);
            SL_CHECK(ds->volume.dims[0] == 41 && ds->volume.dims[1] == 41 && ds->volume.dims[2] == 41);
        }
        sl_dataset_destroy(ds);
        ds = NULL;
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": \"tornado\"}", &s)) {
        sl_status st = sl_scene_open_dataset(&s, tmpdir, &ds, &err);   /* a data dir does not hide built-ins */
        SL_CHECK_MSG(st == SL_OK && ds, "tornado: %s", err.message);
        if (ds)
            SL_CHECK(ds->kind == SL_DATASET_LINES && ds->lines.line_count == 1000 && ds->lines.vertex_count == 200000);
        sl_dataset_destroy(ds);
        ds = NULL;
        sl_scene_deinit(&s);
    }
    /* A generator call. */
    if (parse_ok("{\"dataset\": {\"generator\": \"tornado\", \"lines\": 5, \"points\": 10, \"seed\": 2}}", &s)) {
        sl_status st = sl_scene_open_dataset(&s, NULL, &ds, &err);
        SL_CHECK_MSG(st == SL_OK && ds, "generator: %s", err.message);
        if (ds)
            SL_CHECK(ds->kind == SL_DATASET_LINES && ds->lines.line_count == 5 && ds->lines.vertex_count == 50);
        sl_dataset_destroy(ds);
        ds = NULL;
        sl_scene_deinit(&s);
    }
    /* A bad generator call parses as a scene but fails to open, naming the key. */
    if (parse_ok("{\"dataset\": {\"generator\": \"tornado\", \"lines\": 0}}", &s)) {
        SL_CHECK(sl_scene_open_dataset(&s, NULL, &ds, &err) != SL_OK && ds == NULL);
        SL_CHECK_MSG(strstr(err.message, "lines") != NULL, "%s", err.message);
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": {\"generator\": \"no_such_family\"}}", &s)) {
        SL_CHECK(sl_scene_open_dataset(&s, NULL, &ds, &err) != SL_OK && ds == NULL);
        SL_CHECK_MSG(strstr(err.message, "no_such_family") != NULL, "%s", err.message);
        sl_scene_deinit(&s);
    }

    /* Inline Hermite data: one segment, two vertices, radii, tangents and
     * bounds that include the radius. */
    char text[1024];
    snprintf(text, sizeof text, "{\"dataset\": %s}", hermite_json);
    if (parse_ok(text, &s)) {
        sl_status st = sl_scene_open_dataset(&s, NULL, &ds, &err);
        SL_CHECK_MSG(st == SL_OK && ds, "inline Hermite: %s", err.message);
        if (ds) {
            SL_CHECK(ds->kind == SL_DATASET_LINES && ds->lines.line_count == 1 && ds->lines.vertex_count == 2);
            const sl_lines *l = &ds->lines;
            SL_CHECK(l->radii && l->tangents);
            if (l->radii && l->tangents) {
                SL_CHECK_NEAR(l->radii[0], 0.1, 1e-7);
                SL_CHECK_NEAR(l->radii[1], 0.1, 1e-7);
                SL_CHECK(l->tangents[0] == 1.0f && l->tangents[1] == 0.0f && l->tangents[3] == 1.0f);
            }
            SL_CHECK_NEAR(ds->origin.x + l->positions[0], 0.0, 1e-7);
            SL_CHECK_NEAR(ds->origin.x + l->positions[3], 1.0, 1e-7);
            SL_CHECK_NEAR(ds->origin.y + l->positions[4], 0.0, 1e-7);
            SL_CHECK_NEAR(ds->bounds_min.x, -0.1, 1e-7);
            SL_CHECK_NEAR(ds->bounds_max.x, 1.1, 1e-7);
            SL_CHECK_NEAR(ds->bounds_min.y, -0.1, 1e-7);
            SL_CHECK_NEAR(ds->bounds_max.z, 0.1, 1e-7);
            SL_CHECK(sl_lines_find_attribute(l, "scalar") >= 0);
        }
        sl_dataset_destroy(ds);
        ds = NULL;
        sl_scene_deinit(&s);
    }
    /* Inline Hermite data with an error: parses as a scene, fails to open naming the JSON path. */
    if (parse_ok("{\"dataset\": {\"nodes\": [{\"p\": [0,0,0], \"t\": [1,0,0], \"r\": 0.1}], \"segments\": [[0, 1]]}}", &s)) {
        SL_CHECK(sl_scene_open_dataset(&s, NULL, &ds, &err) == SL_ERR_INVALID && ds == NULL);
        SL_CHECK_MSG(strstr(err.message, "segments[0][1]") != NULL, "%s", err.message);
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": {\"nodes\": [{\"p\": [0,0], \"t\": [1,0,0], \"r\": 0.1}], \"segments\": []}}", &s)) {
        SL_CHECK(sl_scene_open_dataset(&s, NULL, &ds, &err) == SL_ERR_INVALID && ds == NULL);
        SL_CHECK_MSG(strstr(err.message, "nodes[0].p") != NULL, "%s", err.message);
        sl_scene_deinit(&s);
    }

    /* A file under the data dir, and by absolute path. */
    char path[256];
    snprintf(path, sizeof path, "%s/h.json", tmpdir);
    FILE *f = fopen(path, "wb");
    SL_CHECK(f != NULL);
    if (f) {
        fputs(hermite_json, f);
        fclose(f);
    }
    if (parse_ok("{\"dataset\": \"h.json\"}", &s)) {
        sl_status st = sl_scene_open_dataset(&s, tmpdir, &ds, &err);
        SL_CHECK_MSG(st == SL_OK && ds && ds->lines.line_count == 1, "h.json under the data dir: %s", err.message);
        sl_dataset_destroy(ds);
        ds = NULL;
        /* Without the data dir the relative name is not found. */
        st = sl_scene_open_dataset(&s, NULL, &ds, &err);
        SL_CHECK(st == SL_ERR_IO && ds == NULL);
        sl_scene_deinit(&s);
    }
    snprintf(text, sizeof text, "{\"dataset\": \"%s\"}", path);
    if (parse_ok(text, &s)) {
        sl_status st = sl_scene_open_dataset(&s, "/nonexistent-dir", &ds, &err);
        SL_CHECK_MSG(st == SL_OK && ds, "absolute path: %s", err.message);
        sl_dataset_destroy(ds);
        ds = NULL;
        sl_scene_deinit(&s);
    }

    /* Missing files: SL_ERR_IO naming the path that was tried. */
    if (parse_ok("{\"dataset\": \"missing/nothing.vtk\"}", &s)) {
        ds = (sl_dataset *)&s;   /* must be reset */
        sl_status st = sl_scene_open_dataset(&s, tmpdir, &ds, &err);
        SL_CHECK(st == SL_ERR_IO && ds == NULL);
        char want[256];
        snprintf(want, sizeof want, "%s/missing/nothing.vtk", tmpdir);
        SL_CHECK_MSG(strstr(err.message, want) != NULL, "'%s' lacks '%s'", err.message, want);
        sl_scene_deinit(&s);
    }
    if (parse_ok("{\"dataset\": \"/nonexistent-dir/fibres.trk\"}", &s)) {
        SL_CHECK(sl_scene_open_dataset(&s, NULL, &ds, &err) == SL_ERR_IO && ds == NULL);
        SL_CHECK_MSG(strstr(err.message, "/nonexistent-dir/fibres.trk") != NULL, "%s", err.message);
        sl_scene_deinit(&s);
    }
    /* A name that is neither built in nor a known file type names itself. */
    if (parse_ok("{\"dataset\": \"tornadoo\"}", &s)) {
        SL_CHECK(sl_scene_open_dataset(&s, NULL, &ds, &err) != SL_OK && ds == NULL);
        SL_CHECK_MSG(strstr(err.message, "tornadoo") != NULL, "%s", err.message);
        sl_scene_deinit(&s);
    }
}

static void test_scene_view(void)
{
    sl_scene s;
    sl_dataset *ds = NULL;
    sl_err err = {0};
    char text[1024];
    snprintf(text, sizeof text, "{\"dataset\": %s, \"camera\": {\"orbit\": {\"azimuth\": 0, \"elevation\": 0,"
             " \"distance\": 2}, \"fov_y\": 40}, \"width\": 320, \"height\": 200, \"orbit_frames\": 4,"
             " \"background\": [0.5, 0.25, 0]}", hermite_json);
    if (!parse_ok(text, &s))
        return;
    if (sl_scene_open_dataset(&s, NULL, &ds, &err) != SL_OK) {
        SL_CHECK_MSG(0, "%s", err.message);
        sl_scene_deinit(&s);
        return;
    }
    double r = 0.5 * sqrt(1.2 * 1.2 + 0.2 * 0.2 + 0.2 * 0.2);   /* bounds [-0.1, 1.1] x [-0.1, 0.1]^2 */
    SL_CHECK_NEAR(sl_dataset_radius(ds), r, 1e-6);
    sl_view v;
    /* Frame 0: on +z of the centre (0.5, 0, 0); frame 1 of 4: azimuth 90, on +x. */
    SL_CHECK(sl_scene_view(&s, ds, 0, &v, &err) == SL_OK);
    SL_CHECK(v.width == 320 && v.height == 200 && v.background[0] == 0.5f && v.background[1] == 0.25f);
    SL_CHECK_NEAR(v.camera.eye.x, 0.5, 1e-6);
    SL_CHECK_NEAR(v.camera.eye.z, 2 * r, 1e-6);
    SL_CHECK_NEAR(v.camera.fov_y_deg, 40.0, 0.0);
    SL_CHECK(v.origin.x == ds->origin.x && v.origin.y == ds->origin.y && v.origin.z == ds->origin.z);
    SL_CHECK(v.tan_half_fov > 0 && v.aspect == 1.6);   /* derived fields are filled */
    SL_CHECK(sl_scene_view(&s, ds, 1, &v, &err) == SL_OK);
    SL_CHECK_NEAR(v.camera.eye.x, 0.5 + 2 * r, 1e-6);
    SL_CHECK_NEAR(v.camera.eye.z, 0.0, 1e-6);
    SL_CHECK(sl_scene_view(&s, ds, 2, &v, &err) == SL_OK);
    SL_CHECK_NEAR(v.camera.eye.z, -2 * r, 1e-6);
    sl_scene_deinit(&s);

    /* An explicit camera is used as given. */
    snprintf(text, sizeof text, "{\"dataset\": \"x.vtk\", \"camera\": {\"eye\": [3, 4, 5], \"target\": [0, 1, 0],"
             " \"fov_y\": 70}}");
    if (parse_ok(text, &s)) {
        SL_CHECK(sl_scene_view(&s, ds, 7, &v, &err) == SL_OK);
        SL_CHECK(v.camera.eye.x == 3 && v.camera.eye.y == 4 && v.camera.eye.z == 5 && v.camera.target.y == 1);
        SL_CHECK(v.camera.fov_y_deg == 70.0 && v.width == 256);
        sl_scene_deinit(&s);
    }
    sl_dataset_destroy(ds);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/sl_test_scene_XXXXXX");
    if (!mkdtemp(tmpdir)) {
        fprintf(stderr, "cannot create a temporary folder\n");
        return 1;
    }
    test_defaults();
    test_valid();
    test_invalid();
    test_nan_in_memory();
    test_camera_json();
    test_overrides();
    test_open_dataset();
    test_scene_view();
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", tmpdir);
    SL_TEST_END();
}
