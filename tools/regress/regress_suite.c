/* regress_suite.c — loading a sightline-regress suite folder: see regress.h. Single-threaded. */
#include "regress.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_load.h"
#include "sl_scene.h"

static const regress_limits builtin_limits = {
    .max_mean = 0.5, .max_bad_pct = 0.5, .bad_threshold = 16, .max_abs = -1,
    .has_background = 1, .background = {26, 26, 31}, .samples = 4,
    .depth = 0, .depth_max_mean = 1e-4, .depth_max_bad_pct = 0.5, .depth_bad_threshold = 1e-3,
    .depth_max_coverage_pct = 0.0, .timeout_s = 300,
};

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

/* A number >= 0 (or <= hi) from obj[key] into *out when present. */
static sl_status number(const cJSON *obj, const char *key, double hi, double *out, const char *file, sl_err *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return SL_OK;
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || v->valuedouble < 0 || v->valuedouble > hi)
        return sl_err_set(err, SL_ERR_INVALID, "%s: %s must be a number in [0, %g]", file, key, hi);
    *out = v->valuedouble;
    return SL_OK;
}

static sl_status only_keys(const cJSON *obj, const char *const *keys, const char *file, const char *where,
                           sl_err *err)
{
    for (const cJSON *c = obj->child; c; c = c->next) {
        int ok = 0;
        for (int i = 0; keys[i] && !ok; i++)
            ok = c->string && strcmp(c->string, keys[i]) == 0;
        if (!ok)
            return sl_err_set(err, SL_ERR_INVALID, "%s: %s%.64s: unknown field", file, where,
                              c->string ? c->string : "?");
    }
    return SL_OK;
}

/* Applies the limits of one JSON object (suite.json, or NAME.expect.json
 * when expect: it may also hold scene and set) over *l. */
static sl_status apply_limits(const cJSON *obj, int expect, regress_limits *l, const char *file, sl_err *err)
{
    static const char *const keys[] = {"max_mean", "max_bad_pct", "bad_threshold", "max_abs", "background",
                                       "samples", "depth", "timeout_s", "description", NULL};
    static const char *const expect_keys[] = {"max_mean", "max_bad_pct", "bad_threshold", "max_abs", "background",
                                              "samples", "depth", "timeout_s", "description", "scene", "set", NULL};
    static const char *const depth_keys[] = {"max_mean", "max_bad_pct", "bad_threshold", "max_coverage_pct", NULL};
    if (!cJSON_IsObject(obj))
        return sl_err_set(err, SL_ERR_INVALID, "%s: must be a JSON object of limits", file);
    sl_status st = only_keys(obj, expect ? expect_keys : keys, file, "", err);
    double samples = l->samples;
    if (st == SL_OK && (st = number(obj, "max_mean", 255, &l->max_mean, file, err)) == SL_OK &&
        (st = number(obj, "max_bad_pct", 100, &l->max_bad_pct, file, err)) == SL_OK &&
        (st = number(obj, "bad_threshold", 255, &l->bad_threshold, file, err)) == SL_OK &&
        (st = number(obj, "max_abs", 255, &l->max_abs, file, err)) == SL_OK &&
        (st = number(obj, "samples", 16, &samples, file, err)) == SL_OK)
        st = number(obj, "timeout_s", 86400, &l->timeout_s, file, err);
    if (st != SL_OK)
        return st;
    if (samples != floor(samples))
        return sl_err_set(err, SL_ERR_INVALID, "%s: samples must be an integer in [0, 16]", file);
    l->samples = (int)samples;
    const cJSON *bg = cJSON_GetObjectItemCaseSensitive(obj, "background");
    if (cJSON_IsNull(bg)) {
        l->has_background = 0;
    } else if (bg) {
        if (!cJSON_IsArray(bg) || cJSON_GetArraySize(bg) != 3)
            return sl_err_set(err, SL_ERR_INVALID, "%s: background must be [R, G, B] in 0..255 or null", file);
        for (int k = 0; k < 3; k++) {
            const cJSON *e = cJSON_GetArrayItem(bg, k);
            if (!cJSON_IsNumber(e) || e->valuedouble < 0 || e->valuedouble > 255 || e->valuedouble != floor(e->valuedouble))
                return sl_err_set(err, SL_ERR_INVALID, "%s: background must be [R, G, B] in 0..255 or null", file);
            l->background[k] = (int)e->valuedouble;
        }
        l->has_background = 1;
    }
    const cJSON *d = cJSON_GetObjectItemCaseSensitive(obj, "depth");
    if (cJSON_IsNull(d) || cJSON_IsFalse(d)) {
        l->depth = 0;
    } else if (d) {
        if (!cJSON_IsObject(d))
            return sl_err_set(err, SL_ERR_INVALID, "%s: depth must be an object of depth limits or null", file);
        if ((st = only_keys(d, depth_keys, file, "depth.", err)) != SL_OK ||
            (st = number(d, "max_mean", 1e30, &l->depth_max_mean, file, err)) != SL_OK ||
            (st = number(d, "max_bad_pct", 100, &l->depth_max_bad_pct, file, err)) != SL_OK ||
            (st = number(d, "bad_threshold", 1e30, &l->depth_bad_threshold, file, err)) != SL_OK ||
            (st = number(d, "max_coverage_pct", 100, &l->depth_max_coverage_pct, file, err)) != SL_OK)
            return st;
        l->depth = 1;
    }
    return SL_OK;
}

/* Reads a JSON file (path) into *out; NULL out when the file is absent and optional. */
static sl_status read_json(const char *path, int optional, cJSON **out, sl_err *err)
{
    *out = NULL;
    uint8_t *text = NULL;
    size_t size = 0;
    FILE *probe = fopen(path, "rb");
    if (!probe)
        return optional ? SL_OK : sl_err_set(err, SL_ERR_IO, "%s: cannot open", path);
    fclose(probe);
    sl_status st = sl_read_file(path, 16u << 20, &text, &size, err);
    if (st != SL_OK)
        return st;
    *out = cJSON_ParseWithLength((const char *)text, size);
    free(text);
    return *out ? SL_OK : sl_err_set(err, SL_ERR_INVALID, "%s: not valid JSON", path);
}

/* An expect file's scene (relative to the suite) and set overrides into c. */
static sl_status case_source(const cJSON *expect, const char *dir, regress_case *c, const char *file, sl_err *err)
{
    const cJSON *scene = cJSON_GetObjectItemCaseSensitive(expect, "scene");
    if (scene && c->scene[0])
        return sl_err_set(err, SL_ERR_INVALID, "%s: names a scene, but %s.json is the case's scene already", file,
                          c->name);
    if (scene) {
        if (!cJSON_IsString(scene) || !scene->valuestring[0] ||
            strlen(dir) > 2000 || strlen(scene->valuestring) > 2000)
            return sl_err_set(err, SL_ERR_INVALID, "%s: scene must be a scene file's path relative to the suite",
                              file);
        snprintf(c->scene, sizeof c->scene, "%.2000s/%.2000s", dir, scene->valuestring); /* fits: checked above */
    }
    const cJSON *set = cJSON_GetObjectItemCaseSensitive(expect, "set");
    if (!set)
        return SL_OK;
    int n = cJSON_IsArray(set) ? cJSON_GetArraySize(set) : -1;
    if (n < 0 || n > REGRESS_MAX_SETS)
        return sl_err_set(err, SL_ERR_INVALID, "%s: set must be an array of at most %d \"key.path=value\" strings",
                          file, REGRESS_MAX_SETS);
    c->set_count = 0;
    for (const cJSON *e = set->child; e; e = e->next) {
        if (!cJSON_IsString(e) || !strchr(e->valuestring, '=') || strlen(e->valuestring) >= REGRESS_SET_MAX)
            return sl_err_set(err, SL_ERR_INVALID, "%s: set entries must be \"key.path=value\" strings of < %d bytes",
                              file, REGRESS_SET_MAX);
        snprintf(c->sets[c->set_count++], REGRESS_SET_MAX, "%s", e->valuestring);
    }
    return SL_OK;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(((const regress_case *)a)->name, ((const regress_case *)b)->name);
}

/* Fills c's scene facts (path or not, frame count) by parsing the scene. */
static sl_status inspect_scene(regress_case *c, sl_err *err)
{
    cJSON *root = NULL;
    sl_status st = read_json(c->scene, 0, &root, err);
    if (st != SL_OK)
        return st;
    sl_scene scene;
    st = sl_scene_from_json(root, &scene, err);
    cJSON_Delete(root);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s", c->scene);
        return st;
    }
    c->is_path = scene.path != NULL;
    c->frames = scene.path ? sl_scene_path_frames(scene.path) : 1;
    sl_scene_deinit(&scene);
    if (c->is_path && c->limits.depth)
        return sl_err_set(err, SL_ERR_INVALID, "%s: depth limits do not apply to a path", c->name);
    return SL_OK;
}

sl_status regress_suite_load(const char *dir, regress_suite *s, sl_err *err)
{
    memset(s, 0, sizeof *s);
    if (strlen(dir) >= sizeof s->dir - REGRESS_NAME_MAX - 32)
        return sl_err_set(err, SL_ERR_INVALID, "suite folder path too long");
    snprintf(s->dir, sizeof s->dir, "%s", dir);
    const char *slash = strrchr(dir, '/');
    snprintf(s->name, sizeof s->name, "%s", slash && slash[1] ? slash + 1 : dir);
    regress_limits defaults = builtin_limits;
    char path[REGRESS_PATH_MAX + 256];
    snprintf(path, sizeof path, "%s/suite.json", dir);
    cJSON *suite_json = NULL;
    sl_status st = read_json(path, 1, &suite_json, err);
    if (st == SL_OK && suite_json)
        st = apply_limits(suite_json, 0, &defaults, path, err);
    cJSON_Delete(suite_json);
    if (st != SL_OK)
        return st;
    DIR *d = opendir(dir);
    if (!d)
        return sl_err_set(err, SL_ERR_IO, "suite %s: not a readable folder", dir);
    s->cases = calloc(REGRESS_MAX_CASES, sizeof *s->cases);
    if (!s->cases) {
        closedir(d);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    }
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        const char *n = e->d_name;
        if (n[0] == '.' || !ends_with(n, ".json") || ends_with(n, ".expect.json") || strcmp(n, "suite.json") == 0)
            continue;
        size_t len = strlen(n) - 5;
        if (len >= REGRESS_NAME_MAX) {
            st = sl_err_set(err, SL_ERR_INVALID, "suite %s: case name %s is too long", dir, n);
            break;
        }
        if (s->count == REGRESS_MAX_CASES) {
            st = sl_err_set(err, SL_ERR_LIMIT, "suite %s: more than %d cases", dir, REGRESS_MAX_CASES);
            break;
        }
        regress_case *c = &s->cases[s->count++];
        snprintf(c->name, sizeof c->name, "%.*s", (int)len, n);
        snprintf(c->scene, sizeof c->scene, "%s/%s", dir, n);
        c->limits = defaults;
    }
    /* An expect file without its NAME.json is a case of its own when it names
     * a scene (checked below); a typo in a name must not drop its limits. */
    rewinddir(d);
    int scene_cases = s->count;
    for (struct dirent *e; st == SL_OK && (e = readdir(d)) != NULL;) {
        const char *n = e->d_name;
        if (n[0] == '.' || !ends_with(n, ".expect.json"))
            continue;
        size_t len = strlen(n) - 12;
        int found = 0;
        for (int i = 0; i < scene_cases && !found; i++)
            found = strlen(s->cases[i].name) == len && strncmp(s->cases[i].name, n, len) == 0;
        if (found)
            continue;
        if (len >= REGRESS_NAME_MAX || s->count == REGRESS_MAX_CASES) {
            st = sl_err_set(err, SL_ERR_LIMIT, "suite %s: case %s: name too long or more than %d cases", dir, n,
                            REGRESS_MAX_CASES);
            break;
        }
        regress_case *c = &s->cases[s->count++];
        snprintf(c->name, sizeof c->name, "%.*s", (int)len, n);
        c->scene[0] = '\0'; /* must come from the expect file */
        c->limits = defaults;
    }
    closedir(d);
    if (st == SL_OK && s->count == 0)
        st = sl_err_set(err, SL_ERR_INVALID, "suite %s: no case (*.json scenes besides suite.json)", dir);
    if (st == SL_OK)
        qsort(s->cases, (size_t)s->count, sizeof *s->cases, by_name);
    for (int i = 0; st == SL_OK && i < s->count; i++) {
        regress_case *c = &s->cases[i];
        snprintf(path, sizeof path, "%s/%s.expect.json", dir, c->name);
        cJSON *expect = NULL;
        st = read_json(path, 1, &expect, err);
        if (st == SL_OK && expect)
            st = apply_limits(expect, 1, &c->limits, path, err);
        if (st == SL_OK && expect)
            st = case_source(expect, dir, c, path, err);
        cJSON_Delete(expect);
        if (st == SL_OK && !c->scene[0])
            st = sl_err_set(err, SL_ERR_INVALID, "suite %s: %s.expect.json has no case %s.json and names no scene",
                            dir, c->name, c->name);
        if (st == SL_OK)
            st = inspect_scene(c, err);
    }
    if (st != SL_OK)
        regress_suite_free(s);
    return st;
}

void regress_suite_free(regress_suite *s)
{
    free(s->cases);
    s->cases = NULL;
    s->count = 0;
}
