/* test_particles_cache.c — what a prepare of `particles` recomputes, through
 * the pipeline in process: a camera move re-renders without a prepare; a
 * style parameter (stipple_size) re-renders without a prepare; adding a
 * second isovalue prepares again but takes the first set from the cache
 * (particles_cache.h: sets_cached 1, and its exported rows byte-equal to
 * the first prepare's); going back to the first isovalue alone is a cache
 * hit too; a changed repulsion radius misses. Exit 0 pass, 1 fail; needs an
 * OpenGL 4.5 context (llvmpipe is fine).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "sl_test.h"

static double extra(const sl_frame_stats *st, const char *name)
{
    for (int i = 0; i < st->prepare.extra_count; i++)
        if (strcmp(st->prepare.extra[i].name, name) == 0)
            return st->prepare.extra[i].value;
    return -1.0;
}

/* Applies a JSON patch of parameters; renders one frame of an orbit. */
static int frame(sl_pipeline *p, const sl_technique *t, sl_params *params, const char *patch, double azimuth,
                 sl_frame_stats *st)
{
    sl_err err = {0};
    if (patch) {
        cJSON *j = cJSON_Parse(patch);
        sl_status s = sl_params_apply_json(params, j, &err);
        cJSON_Delete(j);
        if (s != SL_OK || sl_pipeline_set_technique(p, t, params, &err) != SL_OK) {
            fprintf(stderr, "test_particles_cache: %s\n", err.message);
            return -1;
        }
    }
    const sl_dataset *ds = sl_pipeline_dataset(p);
    sl_view view;
    memset(&view, 0, sizeof view);
    view.width = view.height = 64;
    view.origin = ds->origin;
    sl_orbit orbit = {azimuth, 20.0, 2.5, 45.0};
    if (sl_camera_from_orbit(&orbit, ds->bounds_min, ds->bounds_max, &view.camera, &err) != SL_OK ||
        sl_view_init(&view, sl_dataset_radius(ds), &err) != SL_OK ||
        sl_pipeline_render(p, &view, 1, st, &err) != SL_OK) {
        fprintf(stderr, "test_particles_cache: %s\n", err.message);
        return -1;
    }
    return 0;
}

static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = '\0';
    fclose(f);
    return s;
}

/* The rows of set `set` in an export, as one string. */
static char *set_rows(const char *csv, int set)
{
    char *out = calloc(strlen(csv) + 1, 1), prefix[8];
    snprintf(prefix, sizeof prefix, "%d,", set);
    size_t k = 0;
    for (const char *line = csv; *line;) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line + 1) : strlen(line);
        if (strncmp(line, prefix, strlen(prefix)) == 0) {
            memcpy(out + k, line, len);
            k += len;
        }
        line += len;
    }
    return out;
}

int main(void)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_pipeline *p = NULL;
    sl_dataset *ds = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK ||
        sl_pipeline_create(gpu, &p, &err) != SL_OK ||
        sl_generate_json("{\"generator\":\"torus\",\"size\":48,\"minor\":0.25,\"sphere\":0.01}", &ds, &err) !=
            SL_OK) {
        fprintf(stderr, "test_particles_cache: %s\n", err.message);
        return 1;
    }
    sl_pipeline_set_dataset(p, ds);
    const sl_technique *t = sl_technique_find("particles");
    SL_CHECK(t != NULL);
    sl_params params;
    sl_params_init(&params, t->params, t->param_count);
    sl_frame_stats st;
    const char *first_csv = "build-particles-cache-a.csv", *second_csv = "build-particles-cache-b.csv";

    SL_CHECK(frame(p, t, &params, "{\"isovalues\":[0]}", 30, &st) == 0);
    SL_CHECK_MSG(st.prepared && extra(&st, "sets_cached") == 0, "first prepare: prepared %d, cached %.0f",
                 st.prepared, extra(&st, "sets_cached"));
    SL_CHECK(sl_pipeline_export(p, first_csv, &err) == SL_OK);

    SL_CHECK(frame(p, t, &params, NULL, 80, &st) == 0);
    SL_CHECK_MSG(!st.prepared, "a camera move re-prepared");
    SL_CHECK(frame(p, t, &params, "{\"stipple_size\":1.5}", 80, &st) == 0);
    SL_CHECK_MSG(!st.prepared, "a style parameter re-prepared");

    SL_CHECK(frame(p, t, &params, "{\"isovalues\":[0,0.05]}", 80, &st) == 0);
    SL_CHECK_MSG(st.prepared && extra(&st, "sets_cached") == 1, "a second isovalue: prepared %d, cached %.0f",
                 st.prepared, extra(&st, "sets_cached"));
    SL_CHECK(sl_pipeline_export(p, second_csv, &err) == SL_OK);
    char *a = read_all(first_csv), *b = read_all(second_csv);
    SL_CHECK(a && b);
    if (a && b) {
        char *ra = set_rows(a, 0), *rb = set_rows(b, 0), *rb1 = set_rows(b, 1);
        SL_CHECK_MSG(strlen(ra) > 1000 && strcmp(ra, rb) == 0, "the cached set 0 differs from the computed one");
        SL_CHECK_MSG(strlen(rb1) > 1000, "the new set 1 has no particles");
        free(ra), free(rb), free(rb1);
    }
    free(a), free(b);

    SL_CHECK(frame(p, t, &params, "{\"isovalues\":[0]}", 80, &st) == 0);
    SL_CHECK_MSG(st.prepared && extra(&st, "sets_cached") == 1, "back to one isovalue: cached %.0f",
                 extra(&st, "sets_cached"));
    SL_CHECK(frame(p, t, &params, "{\"repulsion_radius\":1.4}", 80, &st) == 0);
    SL_CHECK_MSG(st.prepared && extra(&st, "sets_cached") == 0, "a new repulsion radius: cached %.0f",
                 extra(&st, "sets_cached"));
    remove(first_csv);
    remove(second_csv);
    sl_pipeline_destroy(p);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
