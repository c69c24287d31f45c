/* sightline_render.c — renders a scene to PNG/JPEG (+ depth PFM, stats JSON) without a server.
 *
 * usage: sightline-render --scene S.json --out frame.png [--depth depth.pfm]
 *          [--frames N] [--stats stats.json] [--set key.path=value ...]
 *          [--samples N] [--data-dir DIR]
 * A thin main over the renderer library: scene -> dataset -> pipeline. The
 * colour frame uses --samples MSAA (default 4); the depth map is rendered
 * without MSAA so every pixel is the exact centre ray of sl_camera.h.
 * Exit codes: 0 ok, 1 usage, 2 bad input (scene, dataset), 3 GPU failure.
 */
#include <cjson/cJSON.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_load.h"
#include "image/sl_image.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "sl_scene.h"

#define MAX_SETS 64

typedef struct options {
    const char *scene, *out, *depth, *stats, *data_dir;
    const char *sets[MAX_SETS];
    int set_count, frames, samples;
} options;

static int usage(const char *msg)
{
    if (msg)
        fprintf(stderr, "sightline-render: %s\n", msg);
    fprintf(stderr, "usage: sightline-render --scene S.json --out frame.png [--depth depth.pfm] [--frames N]\n"
                    "         [--stats stats.json] [--set key.path=value ...] [--samples N] [--data-dir DIR]\n");
    return 1;
}

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->frames = 1;
    o->samples = 4;
    for (int i = 1; i < argc; i += 2) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0)
            return usage(NULL), -1;
        if (!v)
            return usage("missing value after an option");
        if (strcmp(a, "--scene") == 0) o->scene = v;
        else if (strcmp(a, "--out") == 0) o->out = v;
        else if (strcmp(a, "--depth") == 0) o->depth = v;
        else if (strcmp(a, "--stats") == 0) o->stats = v;
        else if (strcmp(a, "--data-dir") == 0) o->data_dir = v;
        else if (strcmp(a, "--frames") == 0) {
            o->frames = atoi(v);
            if (o->frames < 1 || o->frames > 100000)
                return usage("--frames must be in [1, 100000]");
        } else if (strcmp(a, "--samples") == 0) {
            o->samples = atoi(v);
            if (o->samples < 0 || o->samples > 16)
                return usage("--samples must be in [0, 16]");
        } else if (strcmp(a, "--set") == 0) {
            if (o->set_count >= MAX_SETS)
                return usage("too many --set options");
            o->sets[o->set_count++] = v;
        } else
            return usage("unknown option");
    }
    if (!o->scene || !o->out)
        return usage("--scene and --out are required");
    return 0;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static cJSON *summary(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare_doubles);
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "min", v[0]);
    cJSON_AddNumberToObject(o, "median", n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
    cJSON_AddNumberToObject(o, "max", v[n - 1]);
    return o;
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

int main(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc != 0)
        return rc < 0 ? 0 : 1;

    sl_err err = {0};
    uint8_t *text = NULL;
    size_t text_size = 0;
    if (sl_read_file(o.scene, 16u << 20, &text, &text_size, &err) != SL_OK) {
        fprintf(stderr, "sightline-render: %s\n", err.message);
        return 2;
    }
    char *json = malloc(text_size + 1);
    if (!json)
        return 2;
    memcpy(json, text, text_size);
    json[text_size] = '\0';
    free(text);
    cJSON *root = cJSON_Parse(json);
    free(json);
    if (!root) {
        fprintf(stderr, "sightline-render: %s is not valid JSON\n", o.scene);
        return 2;
    }
    for (int i = 0; i < o.set_count; i++)
        if (sl_scene_apply_override(root, o.sets[i], &err) != SL_OK) {
            fprintf(stderr, "sightline-render: %s\n", err.message);
            cJSON_Delete(root);
            return 2;
        }
    sl_scene scene;
    sl_status st = sl_scene_from_json(root, &scene, &err);
    cJSON_Delete(root);
    if (st != SL_OK) {
        fprintf(stderr, "sightline-render: %s: %s\n", o.scene, err.message);
        return 2;
    }

    char scene_dir[4096];
    snprintf(scene_dir, sizeof scene_dir, "%s", o.scene);
    const char *data_dir = o.data_dir ? o.data_dir : dirname(scene_dir);
    sl_dataset *ds = NULL;
    double t0 = sl_now_ms();
    if (sl_scene_open_dataset(&scene, data_dir, &ds, &err) != SL_OK) {
        fprintf(stderr, "sightline-render: dataset: %s\n", err.message);
        sl_scene_deinit(&scene);
        return 2;
    }
    double load_ms = sl_now_ms() - t0;

    const sl_technique *tech = sl_technique_find(scene.technique);
    sl_params params;
    sl_params_init(&params, tech->params, tech->param_count);
    sl_params_apply_json(&params, scene.params, &err); /* validated by sl_scene_from_json */

    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){0}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "sightline-render: GPU: %s\n", err.message);
        sl_dataset_destroy(ds);
        sl_scene_deinit(&scene);
        return 3;
    }
    sl_pipeline *pipe = NULL;
    int exit_code = 0;
    double *gpu_ms = calloc((size_t)o.frames, sizeof(double));
    double *wall_ms = calloc((size_t)o.frames, sizeof(double));
    uint8_t *rgba = malloc((size_t)scene.width * (size_t)scene.height * 4);
    float *depth = o.depth ? malloc((size_t)scene.width * (size_t)scene.height * sizeof(float)) : NULL;
    sl_frame_stats first = {0}, last = {0};
    sl_view view;
    if (!gpu_ms || !wall_ms || !rgba || (o.depth && !depth) || sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        fprintf(stderr, "sightline-render: out of memory\n");
        exit_code = 3;
        goto done;
    }
    sl_pipeline_set_dataset(pipe, ds);
    if (sl_pipeline_set_technique(pipe, tech, &params, &err) != SL_OK) {
        fprintf(stderr, "sightline-render: %s\n", err.message);
        exit_code = 2;
        goto done;
    }
    for (int f = 0; f < o.frames; f++) {
        sl_frame_stats stats;
        if (sl_scene_view(&scene, sl_pipeline_dataset(pipe), f, &view, &err) != SL_OK ||
            sl_pipeline_render(pipe, &view, o.samples, &stats, &err) != SL_OK) {
            fprintf(stderr, "sightline-render: frame %d: %s\n", f, err.message);
            exit_code = err.status == SL_ERR_GPU ? 3 : 2;
            goto done;
        }
        if (f == 0)
            first = stats;
        last = stats;
        gpu_ms[f] = stats.gpu_ms;
        wall_ms[f] = stats.wall_ms;
    }
    sl_pipeline_read_rgba(pipe, rgba, 1);
    st = ends_with(o.out, ".jpg") || ends_with(o.out, ".jpeg")
             ? sl_jpeg_write(o.out, rgba, scene.width, scene.height, 92, &err)
             : sl_png_write(o.out, rgba, scene.width, scene.height, &err);
    if (st != SL_OK) {
        fprintf(stderr, "sightline-render: %s\n", err.message);
        exit_code = 2;
        goto done;
    }
    if (o.depth) {
        sl_frame_stats stats;
        if (sl_pipeline_render(pipe, &view, 1, &stats, &err) != SL_OK) {
            fprintf(stderr, "sightline-render: depth frame: %s\n", err.message);
            exit_code = 3;
            goto done;
        }
        sl_pipeline_read_distance(pipe, &view, depth);
        if (sl_pfm_write(o.depth, depth, scene.width, scene.height, &err) != SL_OK) {
            fprintf(stderr, "sightline-render: %s\n", err.message);
            exit_code = 2;
            goto done;
        }
    }
    if (o.stats) {
        cJSON *s = cJSON_CreateObject();
        cJSON_AddStringToObject(s, "renderer", sl_gpu_renderer(gpu));
        cJSON_AddStringToObject(s, "technique", tech->name);
        cJSON_AddNumberToObject(s, "width", scene.width);
        cJSON_AddNumberToObject(s, "height", scene.height);
        cJSON_AddNumberToObject(s, "frames", o.frames);
        cJSON_AddNumberToObject(s, "samples", o.samples);
        cJSON_AddItemToObject(s, "gpu_ms", summary(gpu_ms, o.frames));
        cJSON_AddItemToObject(s, "wall_ms", summary(wall_ms, o.frames));
        cJSON_AddNumberToObject(s, "dataset_load_ms", load_ms);
        cJSON_AddNumberToObject(s, "prepare_ms", first.prepare_ms);
        cJSON_AddNumberToObject(s, "gpu_bytes", (double)last.gpu_bytes);
        cJSON_AddNumberToObject(s, "primitives", last.render.primitives);
        cJSON_AddNumberToObject(s, "culled", last.render.culled);
        char *out = cJSON_Print(s);
        FILE *f = fopen(o.stats, "w");
        if (!f || !out || fputs(out, f) < 0) {
            fprintf(stderr, "sightline-render: cannot write %s\n", o.stats);
            exit_code = 2;
        }
        if (f)
            fclose(f);
        free(out);
        cJSON_Delete(s);
    }
    printf("wrote %s (%dx%d, %s, %d frame%s)\n", o.out, scene.width, scene.height, tech->name, o.frames,
           o.frames == 1 ? "" : "s");
done:
    free(gpu_ms);
    free(wall_ms);
    free(rgba);
    free(depth);
    if (pipe)
        sl_pipeline_destroy(pipe);
    else
        sl_dataset_destroy(ds);
    sl_gpu_destroy(gpu);
    sl_scene_deinit(&scene);
    return exit_code;
}
