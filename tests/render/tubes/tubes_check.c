/* tubes_check.c — accuracy check of the `tubes` technique against the CPU reference.
 *
 * usage: tubes-check --scene S.json [--set key.path=value ...] [--gpu-depth G.pfm]
 *          [--out-gpu G.pfm] [--out-png G.png] [--out-ref R.pfm] [--out-radius R.pfm] [--cubic-ref C.pfm]
 *          [--tol 1e-3] [--max-mismatch-pct 0.5] [--ref-samples N] [--data-dir DIR]
 *          [--random-segments N --seed S]
 * Loads the scene's dataset (explicit Hermite JSON, inline or as a .json file,
 * is read by sl_hermite_dataset_from_json; everything else as sightline-render
 * does), renders the GPU distance map (or reads --gpu-depth, e.g. from
 * `sightline-render --depth`), computes the double-precision reference
 * (tubes_reference.c) and checks: on pixels both hit, |error| <= tol x the
 * local sweep radius; exceptions (beyond tol, or hit by one side only) only
 * next to a reference silhouette (coverage, segment or depth jump in the
 * 3x3 neighbourhood) and <= max-mismatch-pct % of the pixels hit by either; no
 * NaN or Inf anywhere.
 * --cubic-ref also renders the true cubic Hermite sweep and prints how far the
 * quadratic surface lies from it. --random-segments replaces the scene's
 * dataset by N random Hermite segments (chains and bifurcations, varying
 * radius and tangents) from --seed. Exit 0 pass, 1 fail, 2 bad input, 3 GPU.
 */
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "line_style/sl_line_style.h"
#include "data/sl_load.h"
#include "gpu/sl_gpu.h"
#include "image/sl_image.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "sl_scene.h"
#include "tubes/tubes_nodes.h"
#include "tubes_reference.h"

#define MAX_SETS 32

typedef struct options {
    const char *scene, *gpu_depth, *out_png, *out_gpu, *out_ref, *out_radius, *cubic_ref, *data_dir;
    const char *sets[MAX_SETS];
    int set_count, ref_samples, random_segments;
    unsigned long long seed;
    double tol, max_mismatch_pct;
} options;

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.tol = 1e-3, .max_mismatch_pct = 0.5};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (i + 1 >= argc) { fprintf(stderr, "tubes-check: missing value after %s\n", a); return -1; }
        const char *v = argv[++i];
        if (strcmp(a, "--scene") == 0) o->scene = v;
        else if (strcmp(a, "--gpu-depth") == 0) o->gpu_depth = v;
        else if (strcmp(a, "--out-gpu") == 0) o->out_gpu = v;
        else if (strcmp(a, "--out-png") == 0) o->out_png = v;
        else if (strcmp(a, "--out-ref") == 0) o->out_ref = v;
        else if (strcmp(a, "--out-radius") == 0) o->out_radius = v;
        else if (strcmp(a, "--cubic-ref") == 0) o->cubic_ref = v;
        else if (strcmp(a, "--data-dir") == 0) o->data_dir = v;
        else if (strcmp(a, "--tol") == 0) o->tol = atof(v);
        else if (strcmp(a, "--max-mismatch-pct") == 0) o->max_mismatch_pct = atof(v);
        else if (strcmp(a, "--ref-samples") == 0) o->ref_samples = atoi(v);
        else if (strcmp(a, "--random-segments") == 0) o->random_segments = atoi(v);
        else if (strcmp(a, "--seed") == 0) o->seed = strtoull(v, NULL, 10);
        else if (strcmp(a, "--set") == 0 && o->set_count < MAX_SETS) o->sets[o->set_count++] = v;
        else { fprintf(stderr, "tubes-check: unknown option %s\n", a); return -1; }
    }
    if (!o->scene) { fprintf(stderr, "tubes-check: --scene is required\n"); return -1; }
    return 0;
}

static double rnd(unsigned long long *state, double lo, double hi)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(*state >> 11) / 9007199254740992.0;
}

static cJSON *vec3_json(double x, double y, double z)
{
    const double v[3] = {x, y, z};
    return cJSON_CreateDoubleArray(v, 3);
}

/* N random segments: node k+1 follows node k (chains), every fifth segment
 * starts again from an earlier node (bifurcations). */
static cJSON *random_hermite(int n, unsigned long long seed)
{
    unsigned long long st = seed * 2654435761ull + 1;
    cJSON *root = cJSON_CreateObject(), *nodes = cJSON_AddArrayToObject(root, "nodes");
    cJSON *segs = cJSON_AddArrayToObject(root, "segments");
    for (int k = 0; k <= n; k++) {
        cJSON *nd = cJSON_CreateObject();
        cJSON_AddItemToObject(nd, "p", vec3_json(rnd(&st, -1, 1), rnd(&st, -1, 1), rnd(&st, -1, 1)));
        cJSON_AddItemToObject(nd, "t", vec3_json(rnd(&st, -1.5, 1.5), rnd(&st, -1.5, 1.5), rnd(&st, -1.5, 1.5)));
        cJSON_AddNumberToObject(nd, "r", rnd(&st, 0.03, 0.12));
        cJSON_AddNumberToObject(nd, "dr", rnd(&st, -0.1, 0.1));
        cJSON_AddNumberToObject(nd, "c", rnd(&st, 0, 1));
        cJSON_AddNumberToObject(nd, "dc", rnd(&st, -1, 1));
        cJSON_AddItemToArray(nodes, nd);
    }
    for (int k = 0; k < n; k++) {
        int a = (k % 5 == 4) ? (int)rnd(&st, 0, k) : k;
        const int pair[2] = {a, k + 1};
        cJSON_AddItemToArray(segs, cJSON_CreateIntArray(pair, 2));
    }
    return root;
}

/* Explicit Hermite data inline ({"nodes":..}) or in a .json file; else the scene's own loader. */
static sl_status open_dataset(const sl_scene *scene, const char *data_dir, sl_dataset **out, sl_err *err)
{
    if (sl_hermite_json_detect(scene->dataset))
        return sl_hermite_dataset_from_json(scene->dataset, "inline", out, err);
    if (cJSON_IsString(scene->dataset)) {
        const char *name = scene->dataset->valuestring;
        size_t n = strlen(name);
        if (n > 5 && strcmp(name + n - 5, ".json") == 0) {
            char path[4096];
            if (name[0] != '/' && data_dir)
                snprintf(path, sizeof path, "%s/%s", data_dir, name);
            else
                snprintf(path, sizeof path, "%s", name);
            uint8_t *data = NULL;
            size_t size = 0;
            sl_status st = sl_read_file(path, 1u << 30, &data, &size, err);
            if (st != SL_OK)
                return st;
            cJSON *root = cJSON_ParseWithLength((const char *)data, size);
            int hermite = sl_hermite_json_detect(root);
            cJSON_Delete(root);
            if (hermite)
                st = sl_load_hermite_json(data, size, path, out, err);
            free(data);
            if (hermite)
                return st;
        }
    }
    return sl_scene_open_dataset(scene, data_dir, out, err);
}

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *t = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (t && fread(t, 1, (size_t)n, f) != (size_t)n) {
        free(t);
        t = NULL;
    }
    if (t)
        t[n] = 0;
    fclose(f);
    return t;
}

/* Renders the GPU distance map through the pipeline, as sightline-render --depth does. */
static sl_status render_gpu(sl_dataset *ds, const sl_technique *tech, const sl_params *params, const sl_view *view,
                            float *distance, const char *png, sl_err *err)
{
    sl_gpu *gpu = NULL;
    sl_pipeline *pipe = NULL;
    sl_status st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1, .debug = 1}, &gpu, err);
    if (st == SL_OK)
        st = sl_pipeline_create(gpu, &pipe, err);
    if (st == SL_OK) {
        sl_pipeline_set_dataset(pipe, ds); /* takes ownership */
        ds = NULL;
        st = sl_pipeline_set_technique(pipe, tech, params, err);
    }
    sl_frame_stats stats;
    if (st == SL_OK)
        st = sl_pipeline_render(pipe, view, 1, &stats, err);
    if (st == SL_OK)
        sl_pipeline_read_distance(pipe, view, distance);
    if (st == SL_OK && png) {
        uint8_t *rgba = malloc((size_t)view->width * (size_t)view->height * 4);
        if (!rgba)
            st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
        else {
            sl_pipeline_read_rgba(pipe, rgba, 1);
            st = sl_png_write(png, rgba, view->width, view->height, err);
            free(rgba);
        }
    }
    sl_dataset_destroy(ds);
    sl_pipeline_destroy(pipe);
    sl_gpu_destroy(gpu);
    return st;
}

/* A reference silhouette: coverage, segment or a depth jump of more than the
 * local radius (a tube in front of another, even of the same segment)
 * within the 3x3 neighbourhood. */
static int is_silhouette(const float *ref, const float *rad, const int *seg, int w, int h, int i, int j)
{
    size_t c = (size_t)j * (size_t)w + (size_t)i;
    for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++) {
            int x = i + di, y = j + dj;
            if (x < 0 || y < 0 || x >= w || y >= h)
                continue;
            size_t n = (size_t)y * (size_t)w + (size_t)x;
            if ((ref[n] > 0.0f) != (ref[c] > 0.0f) || seg[n] != seg[c] || fabsf(ref[n] - ref[c]) > rad[c])
                return 1;
        }
    return 0;
}

int main(int argc, char **argv)
{
    options o;
    if (parse_args(argc, argv, &o) != 0)
        return 2;
    sl_err err = {0};
    char *text = read_text(o.scene);
    if (!text) {
        fprintf(stderr, "tubes-check: cannot read %s\n", o.scene);
        return 2;
    }
    cJSON *root = cJSON_Parse(text);
    free(text);
    for (int k = 0; root && k < o.set_count; k++)
        if (sl_scene_apply_override(root, o.sets[k], &err) != SL_OK) {
            fprintf(stderr, "tubes-check: %s\n", err.message);
            cJSON_Delete(root);
            return 2;
        }
    if (root && o.random_segments > 0) {
        cJSON_DeleteItemFromObjectCaseSensitive(root, "dataset");
        cJSON_AddItemToObject(root, "dataset", random_hermite(o.random_segments, o.seed));
    }
    sl_scene scene;
    if (!root || sl_scene_from_json(root, &scene, &err) != SL_OK) {
        fprintf(stderr, "tubes-check: scene: %s\n", root ? err.message : "not JSON");
        cJSON_Delete(root);
        return 2;
    }
    cJSON_Delete(root);
    char scene_dir[4096];
    snprintf(scene_dir, sizeof scene_dir, "%s", o.scene);
    const char *data_dir = o.data_dir ? o.data_dir : dirname(scene_dir);
    sl_dataset *ds = NULL;
    if (open_dataset(&scene, data_dir, &ds, &err) != SL_OK) {
        fprintf(stderr, "tubes-check: dataset: %s\n", err.message);
        sl_scene_deinit(&scene);
        return 2;
    }
    const sl_technique *tech = sl_technique_find(scene.technique);
    sl_params params;
    sl_params_init(&params, tech->params, tech->param_count);
    sl_params_apply_json(&params, scene.params, &err);
    sl_view view;
    if (strcmp(tech->name, "tubes") != 0 || sl_scene_view(&scene, ds, 0, &view, &err) != SL_OK) {
        fprintf(stderr, "tubes-check: %s\n", strcmp(tech->name, "tubes") ? "the scene's technique must be tubes" : err.message);
        sl_dataset_destroy(ds);
        sl_scene_deinit(&scene);
        return 2;
    }
    int w = view.width, h = view.height;
    size_t np = (size_t)w * (size_t)h;
    float *ref = calloc(np, sizeof *ref), *rad = calloc(np, sizeof *rad), *gpu = calloc(np, sizeof *gpu);
    int *seg = calloc(np, sizeof *seg);
    sl_tubes_nodes nodes = {0};
    sl_line_style style;
    sl_line_style_read(&params, ds, &style);
    int rc = 0;
    if (!ref || !rad || !gpu || !seg ||
        sl_tubes_nodes_build(&ds->lines, (sl_tubes_tangents)sl_params_choice(&params, "tangents"), -1, &nodes, &err) != SL_OK) {
        fprintf(stderr, "tubes-check: %s\n", err.message[0] ? err.message : "out of memory");
        rc = 2;
        goto done;
    }
    tubes_ref_desc rd = {.view = &view, .origin = ds->origin, .nodes = &nodes, .radius = style.radius,
                         .radius_scale = style.radius_scale, .cubic = 0, .samples = o.ref_samples};
    double t0 = sl_now_ms();
    tubes_ref_render(&rd, ref, rad, seg);
    double ref_ms = sl_now_ms() - t0;
    float *cubic = NULL;
    if (o.cubic_ref) {
        cubic = calloc(np, sizeof *cubic);
        float *crad = calloc(np, sizeof *crad);
        rd.cubic = 1;
        if (cubic && crad)
            tubes_ref_render(&rd, cubic, crad, NULL);
        /* Quadratic vs cubic sweep, on pixels both hit, in units of the local radius. */
        double mx = 0.0, mean = 0.0;
        long both = 0, mism = 0, hit = 0;
        for (size_t k = 0; cubic && crad && k < np; k++) {
            int a = ref[k] > 0.0f, b = cubic[k] > 0.0f;
            hit += a || b;
            mism += a != b;
            if (a && b) {
                double e = fabs((double)ref[k] - cubic[k]) / fmax(crad[k], 1e-30);
                mx = fmax(mx, e);
                mean += e;
                both++;
            }
        }
        printf("quadratic_vs_cubic: max %.4g mean %.4g (x local radius) over %ld pixels, coverage mismatch %ld (%.3f%%)\n",
               mx, both ? mean / both : 0.0, both, mism, hit ? 100.0 * mism / hit : 0.0);
        if (cubic && sl_pfm_write(o.cubic_ref, cubic, w, h, &err) != SL_OK)
            fprintf(stderr, "tubes-check: %s\n", err.message);
        free(crad);
    }
    if (o.gpu_depth) {
        sl_depth_image img = {0};
        if (sl_pfm_read(o.gpu_depth, &img, &err) != SL_OK || img.width != w || img.height != h) {
            fprintf(stderr, "tubes-check: %s: %s\n", o.gpu_depth, err.message[0] ? err.message : "size differs from the scene");
            sl_depth_image_deinit(&img);
            rc = 2;
            goto done;
        }
        memcpy(gpu, img.values, np * sizeof *gpu);
        sl_depth_image_deinit(&img);
    } else {
        sl_dataset *copy = NULL;
        /* The pipeline owns its dataset: open a second copy for it. */
        if (open_dataset(&scene, data_dir, &copy, &err) != SL_OK ||
            render_gpu(copy, tech, &params, &view, gpu, o.out_png, &err) != SL_OK) {
            fprintf(stderr, "tubes-check: GPU: %s\n", err.message);
            rc = 3;
            goto done;
        }
    }
    /* Pixels within tol pass. A pixel beyond it (or hit by one side only)
     * is a silhouette exception when the reference changes coverage or
     * segment in its 3x3 neighbourhood: there float32 ray set-up error
     * (~16 ulp of the eye distance sideways) moves the rim, and depth near a
     * rim is infinitely sensitive to it. Exceptions are limited to
     * max-mismatch-pct % of the pixels hit; anything else fails. */
    double max_rel = 0.0, mean_rel = 0.0, max_abs = 0.0, max_rel_inner = 0.0;
    long both = 0, mismatch = 0, hit_either = 0, inner_fail = 0, nonfinite = 0, exceptions = 0;
    int worst_i = -1, worst_j = -1;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            size_t k = (size_t)j * (size_t)w + (size_t)i;
            if (!isfinite(gpu[k]) || gpu[k] < 0.0f) {
                nonfinite++;
                continue;
            }
            int a = gpu[k] > 0.0f, b = ref[k] > 0.0f;
            hit_either += a || b;
            int sil = is_silhouette(ref, rad, seg, w, h, i, j);
            if (a != b) {
                mismatch++;
                if (sil)
                    exceptions++;
                else
                    inner_fail++;
                continue;
            }
            if (!a)
                continue;
            double e = fabs((double)gpu[k] - ref[k]);
            double rel = e / fmax(rad[k], 1e-30);
            both++;
            mean_rel += rel;
            if (rel > max_rel) {
                max_rel = rel;
                worst_i = i;
                worst_j = j;
            }
            if (!sil)
                max_rel_inner = fmax(max_rel_inner, rel);
            max_abs = fmax(max_abs, e);
            if (rel > o.tol) {
                if (sil) {
                    exceptions++;
                } else {
                    if (inner_fail < 5)
                        fprintf(stderr, "  pixel (%d,%d): gpu %.7g ref %.7g radius %.4g segment %d\n", i, j, gpu[k],
                                ref[k], rad[k], seg[k]);
                    inner_fail++;
                }
            }
        }
    double exception_pct = hit_either ? 100.0 * (double)exceptions / (double)hit_either : 0.0;
    printf("tubes-check %s: %ld pixels both hit; depth error max %.4g x local radius (%.4g world) at (%d,%d), "
           "away from silhouettes max %.4g, mean %.4g; coverage mismatch %ld; silhouette exceptions %ld (%.3f%% of %ld hit); "
           "failures away from silhouettes %ld; non-finite %ld; reference %.0f ms\n",
           o.scene, both, max_rel, max_abs, worst_i, worst_j, max_rel_inner, both ? mean_rel / both : 0.0, mismatch,
           exceptions, exception_pct, hit_either, inner_fail, nonfinite, ref_ms);
    if (o.out_gpu && sl_pfm_write(o.out_gpu, gpu, w, h, &err) != SL_OK)
        fprintf(stderr, "tubes-check: %s\n", err.message);
    if (o.out_ref && sl_pfm_write(o.out_ref, ref, w, h, &err) != SL_OK)
        fprintf(stderr, "tubes-check: %s\n", err.message);
    if (o.out_radius && sl_pfm_write(o.out_radius, rad, w, h, &err) != SL_OK)
        fprintf(stderr, "tubes-check: %s\n", err.message);
    if (nonfinite || inner_fail || exception_pct > o.max_mismatch_pct || hit_either == 0) {
        printf("FAIL%s\n", hit_either == 0 ? " (nothing hit: the scene tests nothing)" : "");
        rc = 1;
    } else {
        printf("PASS\n");
    }
    free(cubic);
done:
    sl_tubes_nodes_deinit(&nodes);
    free(ref);
    free(rad);
    free(gpu);
    free(seg);
    sl_dataset_destroy(ds);
    sl_scene_deinit(&scene);
    return rc;
}
