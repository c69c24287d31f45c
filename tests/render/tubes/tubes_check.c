/* tubes_check.c — accuracy check of the `tubes` technique against the CPU reference.
 *
 * usage: tubes-check --scene S.json [--set key.path=value ...] [--gpu-depth G.pfm]
 *          [--out-gpu G.pfm] [--out-png G.png] [--out-ref R.pfm] [--out-radius R.pfm] [--cubic-ref C.pfm]
 *          [--max-cubic-dev X]
 *          [--tol 1e-3] [--rim-tol 0.05] [--max-mismatch-pct 0.5] [--ref-samples N] [--data-dir DIR]
 *          [--random-segments N --seed S] [--random-folds N --fold-axis x|y|z|any --fold-tilt T --seed S]
 *          [--write-scene OUT.json] [--culling-check]
 * Loads the scene's dataset (explicit Hermite JSON, inline or as a .json file,
 * is read by sl_hermite_dataset_from_json; everything else as sightline-render
 * does), renders the GPU distance map (or reads --gpu-depth, e.g. from
 * `sightline-render --depth`), computes the double-precision reference
 * (tubes_reference.c) and checks: on pixels both hit, |error| <= tol x the
 * local sweep radius. Exceptions only next to a reference silhouette
 * (coverage change or a depth jump of more than the radius in the 3x3
 * neighbourhood; not a joint between segments): a pixel hit by one side only,
 * or a depth error in (tol, rim-tol] x the radius; both counted, together
 * <= max-mismatch-pct % of the pixels hit by either. No NaN or Inf anywhere.
 * --cubic-ref also renders the true cubic Hermite sweep and prints how far the
 * quadratic surface lies from it; --max-cubic-dev X fails the check when that
 * distance exceeds X x the local radius on a pixel both hit away from the
 * cubic reference's silhouettes (the approximation bound of the paper's
 * quadratic split, asserted per dataset). --random-segments replaces the scene's
 * dataset by N random Hermite segments (chains and bifurcations, varying
 * radius and tangents) from --seed. --write-scene writes the scene as checked
 * (overrides and random dataset included) for sightline-render.
 * --random-folds replaces it by N segments that fold back on themselves: chord
 * 0.1-0.3 along the axis (or a seeded direction), end tangents +k and -k
 * along it (k 0.8-1.5: the curve runs past its end and returns inside its own
 * tube), radius 0.2-0.4; --fold-tilt T tilts the first tangent by T x k off
 * the line (near-collinear).
 * --culling-check instead renders with frustum culling on and off and checks
 * fewer primitives, identical pixels and no re-prepare. Exit 0 pass,
 * 1 fail, 2 bad input, 3 GPU. */
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/sl_clock.h"
#include "line_style/sl_line_style.h"
#include "data/sl_load.h"
#include "gpu/sl_gpu.h"
#include "image/sl_image.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "sl_scene.h"
#include "tubes_reference.h"
#include "tubes_reference_input.h"

#define MAX_SETS 32

typedef struct options {
    const char *scene, *gpu_depth, *out_png, *out_gpu, *out_ref, *out_radius, *cubic_ref, *data_dir, *write_scene;
    const char *sets[MAX_SETS];
    int set_count, ref_samples, random_segments, random_folds, culling_check;
    char fold_axis;       /* 'x', 'y', 'z' or 'a' (any: a seeded direction) */
    double fold_tilt;
    unsigned long long seed;
    double tol, rim_tol, max_mismatch_pct;
    double max_cubic_dev;  /* < 0: not checked */
} options;

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.tol = 1e-3, .rim_tol = 0.05, .max_mismatch_pct = 0.5, .fold_axis = 'x', .max_cubic_dev = -1.0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--culling-check") == 0) { o->culling_check = 1; continue; }
        if (i + 1 >= argc) { fprintf(stderr, "tubes-check: missing value after %s\n", a); return -1; }
        const char *v = argv[++i];
        if (strcmp(a, "--scene") == 0) o->scene = v;
        else if (strcmp(a, "--gpu-depth") == 0) o->gpu_depth = v;
        else if (strcmp(a, "--out-gpu") == 0) o->out_gpu = v;
        else if (strcmp(a, "--out-png") == 0) o->out_png = v;
        else if (strcmp(a, "--out-ref") == 0) o->out_ref = v;
        else if (strcmp(a, "--out-radius") == 0) o->out_radius = v;
        else if (strcmp(a, "--cubic-ref") == 0) o->cubic_ref = v;
        else if (strcmp(a, "--max-cubic-dev") == 0) o->max_cubic_dev = atof(v);
        else if (strcmp(a, "--data-dir") == 0) o->data_dir = v;
        else if (strcmp(a, "--write-scene") == 0) o->write_scene = v;
        else if (strcmp(a, "--tol") == 0) o->tol = atof(v);
        else if (strcmp(a, "--rim-tol") == 0) o->rim_tol = atof(v);
        else if (strcmp(a, "--max-mismatch-pct") == 0) o->max_mismatch_pct = atof(v);
        else if (strcmp(a, "--ref-samples") == 0) o->ref_samples = atoi(v);
        else if (strcmp(a, "--random-segments") == 0) o->random_segments = atoi(v);
        else if (strcmp(a, "--random-folds") == 0) o->random_folds = atoi(v);
        else if (strcmp(a, "--fold-axis") == 0 && strchr("xyz", v[0]) && v[0] && !v[1]) o->fold_axis = v[0];
        else if (strcmp(a, "--fold-axis") == 0 && strcmp(v, "any") == 0) o->fold_axis = 'a';
        else if (strcmp(a, "--fold-tilt") == 0) o->fold_tilt = atof(v);
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

/* N folded segments (see --random-folds): each its own pair of nodes. */
static cJSON *random_folds(int n, unsigned long long seed, char axis, double tilt)
{
    unsigned long long st = seed * 2654435761ull + 7;
    cJSON *root = cJSON_CreateObject(), *nodes = cJSON_AddArrayToObject(root, "nodes");
    cJSON *segs = cJSON_AddArrayToObject(root, "segments");
    for (int k = 0; k < n; k++) {
        double dir[3] = {axis == 'x', axis == 'y', axis == 'z'};
        if (axis == 'a') {
            double len = 0.0;
            while (len < 0.1) {
                for (int c = 0; c < 3; c++)
                    dir[c] = rnd(&st, -1, 1);
                len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
            }
            for (int c = 0; c < 3; c++)
                dir[c] /= len;
        }
        /* A unit vector off the line, for the tilt. */
        double off[3] = {fabs(dir[0]) < 0.9 ? 1.0 : 0.0, fabs(dir[0]) < 0.9 ? 0.0 : 1.0, 0.0};
        double dot = off[0] * dir[0] + off[1] * dir[1];
        double ol = 0.0;
        for (int c = 0; c < 3; c++) {
            off[c] -= dot * dir[c];
            ol += off[c] * off[c];
        }
        ol = sqrt(ol);
        double chord = rnd(&st, 0.1, 0.3), kk = rnd(&st, 0.8, 1.5), r = rnd(&st, 0.2, 0.4);
        double p0[3] = {rnd(&st, -1, 1), rnd(&st, -1, 1), rnd(&st, -1, 1)};
        cJSON *a = cJSON_CreateObject(), *b = cJSON_CreateObject();
        cJSON_AddItemToObject(a, "p", vec3_json(p0[0], p0[1], p0[2]));
        cJSON_AddItemToObject(a, "t", vec3_json(kk * (dir[0] + tilt * off[0] / ol), kk * (dir[1] + tilt * off[1] / ol),
                                               kk * (dir[2] + tilt * off[2] / ol)));
        cJSON_AddNumberToObject(a, "r", r);
        cJSON_AddItemToObject(b, "p", vec3_json(p0[0] + chord * dir[0], p0[1] + chord * dir[1], p0[2] + chord * dir[2]));
        cJSON_AddItemToObject(b, "t", vec3_json(-kk * dir[0], -kk * dir[1], -kk * dir[2]));
        cJSON_AddNumberToObject(b, "r", r);
        cJSON_AddItemToArray(nodes, a);
        cJSON_AddItemToArray(nodes, b);
        const int pair[2] = {2 * k, 2 * k + 1};
        cJSON_AddItemToArray(segs, cJSON_CreateIntArray(pair, 2));
    }
    return root;
}

static char *read_text(const char *path);

/* The scene's explicit Hermite JSON (inline, or a .json file holding it), parsed
 * for the reference; NULL when the dataset is anything else. Caller deletes. */
static cJSON *hermite_root(const sl_scene *scene, const char *data_dir)
{
    if (tubes_ref_is_hermite_json(scene->dataset))
        return cJSON_Duplicate(scene->dataset, 1);
    if (!cJSON_IsString(scene->dataset))
        return NULL;
    const char *name = scene->dataset->valuestring;
    size_t n = strlen(name);
    if (n <= 5 || strcmp(name + n - 5, ".json") != 0)
        return NULL;
    char path[4096];
    snprintf(path, sizeof path, "%s%s%s", name[0] != '/' && data_dir ? data_dir : "",
             name[0] != '/' && data_dir ? "/" : "", name);
    char *text = read_text(path);
    cJSON *root = text ? cJSON_Parse(text) : NULL;
    free(text);
    if (!tubes_ref_is_hermite_json(root)) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

/* The reference's own segments: from the scene's Hermite JSON where it has
 * one (unless Catmull-Rom tangents are asked for, which only the line set
 * has), else from the loaded polylines — never through tubes_nodes.c. */
static int reference_input(const sl_scene *scene, const char *data_dir, const sl_dataset *ds, const sl_params *params,
                           const sl_line_style *style, tubes_ref_input *in, char *msg, size_t size)
{
    const char *mode = sl_params_choice_name(params, "tangents");
    tubes_ref_tangents tangents = strcmp(mode, "catmull_rom") == 0  ? TUBES_REF_TANGENTS_CATMULL_ROM
                                  : strcmp(mode, "data_exact") == 0 ? TUBES_REF_TANGENTS_DATA
                                                                    : TUBES_REF_TANGENTS_AUTO;
    cJSON *root = tangents != TUBES_REF_TANGENTS_CATMULL_ROM ? hermite_root(scene, data_dir) : NULL;
    int rc;
    if (root) {
        int ra = style->radius_attribute;
        int from_scalar = ra >= 0 && strcmp(ds->lines.attributes[ra].name, "scalar") == 0;
        if (ra >= 0 && !from_scalar) {
            snprintf(msg, size, "radius_attribute %d of Hermite JSON must be the colour scalar", ra);
            rc = -1;
        } else
            rc = tubes_ref_input_hermite_json(root, from_scalar, style->radius, style->radius_scale, in, msg, size);
        cJSON_Delete(root);
        return rc;
    }
    return tubes_ref_input_lines(ds, tangents, style->radius_attribute, style->radius, style->radius_scale, in, msg,
                                 size);
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

/* --culling-check: renders the view with frustum culling on and off through
 * one pipeline and checks that culling draws fewer primitives (the view must
 * leave part of the data outside the frustum), changes no pixel of the
 * distance map or the colour image, and re-prepares nothing (it is a frame
 * parameter). Returns 0 pass, 1 fail, 3 GPU. */
static int culling_check(sl_dataset *ds, const sl_technique *tech, const sl_params *params, const sl_view *view)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_pipeline *pipe = NULL;
    size_t np = (size_t)view->width * (size_t)view->height;
    float *dist[2] = {calloc(np, sizeof(float)), calloc(np, sizeof(float))};
    uint8_t *rgba[2] = {malloc(np * 4), malloc(np * 4)};
    double prims[2] = {0, 0};
    int prepared = 0, rc = 3;
    sl_params p = *params;
    sl_status st = dist[0] && dist[1] && rgba[0] && rgba[1] ? SL_OK : sl_err_set(&err, SL_ERR_NOMEM, "out of memory");
    if (st == SL_OK)
        st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1, .debug = 1}, &gpu, &err);
    if (st == SL_OK)
        st = sl_pipeline_create(gpu, &pipe, &err);
    if (st == SL_OK) {
        sl_pipeline_set_dataset(pipe, ds); /* takes ownership */
        ds = NULL;
    }
    for (int k = 0; k < 2 && st == SL_OK; k++) {
        double on = k == 0 ? 1.0 : 0.0;
        sl_frame_stats stats;
        if ((st = sl_params_set_numbers(&p, "frustum_culling", &on, 1, &err)) == SL_OK &&
            (st = sl_pipeline_set_technique(pipe, tech, &p, &err)) == SL_OK &&
            (st = sl_pipeline_render(pipe, view, 1, &stats, &err)) == SL_OK) {
            sl_pipeline_read_distance(pipe, view, dist[k]);
            sl_pipeline_read_rgba(pipe, rgba[k], 1);
            prims[k] = stats.render.primitives;
            if (k == 1)
                prepared = stats.prepared;
        }
    }
    if (st == SL_OK) {
        long ddiff = 0, cdiff = 0, hits = 0;
        for (size_t i = 0; i < np; i++) {
            ddiff += memcmp(&dist[0][i], &dist[1][i], sizeof(float)) != 0;
            cdiff += memcmp(rgba[0] + 4 * i, rgba[1] + 4 * i, 4) != 0;
            hits += dist[0][i] > 0.0f;
        }
        printf("tubes-check culling: primitives %.0f with culling, %.0f without; %ld distance and %ld colour pixels "
               "differ; %ld pixels hit; re-prepared %d\n", prims[0], prims[1], ddiff, cdiff, hits, prepared);
        int ok = prims[0] < prims[1] && ddiff == 0 && cdiff == 0 && hits > 0 && !prepared;
        printf("%s\n", ok ? "PASS" : "FAIL");
        rc = ok ? 0 : 1;
    } else {
        fprintf(stderr, "tubes-check: GPU: %s\n", err.message);
    }
    sl_dataset_destroy(ds);
    sl_pipeline_destroy(pipe);
    sl_gpu_destroy(gpu);
    free(dist[0]); free(dist[1]); free(rgba[0]); free(rgba[1]);
    return rc;
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
    if (root && o.random_folds > 0) {
        cJSON_DeleteItemFromObjectCaseSensitive(root, "dataset");
        cJSON_AddItemToObject(root, "dataset", random_folds(o.random_folds, o.seed, o.fold_axis, o.fold_tilt));
    }
    if (root && o.write_scene) {
        /* The scene as checked (overrides applied, random dataset inline), for
         * sightline-render: the command-line path renders exactly this. */
        char *out = cJSON_Print(root);
        FILE *f = out ? fopen(o.write_scene, "wb") : NULL;
        int ok = f && fputs(out, f) >= 0;
        if (f && fclose(f) != 0)
            ok = 0;
        free(out);
        if (!ok) {
            fprintf(stderr, "tubes-check: cannot write %s\n", o.write_scene);
            cJSON_Delete(root);
            return 2;
        }
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
    if (sl_scene_open_dataset(&scene, data_dir, &ds, &err) != SL_OK) {
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
    if (o.culling_check) {
        int crc = culling_check(ds, tech, &params, &view); /* takes ds */
        sl_scene_deinit(&scene);
        return crc;
    }
    int w = view.width, h = view.height;
    size_t np = (size_t)w * (size_t)h;
    float *ref = calloc(np, sizeof *ref), *rad = calloc(np, sizeof *rad), *gpu = calloc(np, sizeof *gpu);
    int *seg = calloc(np, sizeof *seg);
    tubes_ref_input input = {0};
    char input_msg[256] = "";
    sl_line_style style;
    sl_line_style_read(&params, ds, &style);
    int rc = 0;
    if (!ref || !rad || !gpu || !seg ||
        sl_line_style_check(&params, ds, &err) != SL_OK ||
        reference_input(&scene, data_dir, ds, &params, &style, &input, input_msg, sizeof input_msg) != 0) {
        fprintf(stderr, "tubes-check: %s\n", err.message[0] ? err.message : input_msg[0] ? input_msg : "out of memory");
        rc = 2;
        goto done;
    }
    tubes_ref_desc rd = {.view = &view, .origin = input.origin, .segments = input.segments,
                         .segment_count = input.count, .cubic = 0, .samples = o.ref_samples};
    double t0 = sl_clock_ms();
    tubes_ref_render(&rd, ref, rad, seg);
    double ref_ms = sl_clock_ms() - t0;
    float *cubic = NULL;
    int cubic_failed = 0;
    if (o.cubic_ref) {
        cubic = calloc(np, sizeof *cubic);
        float *crad = calloc(np, sizeof *crad);
        rd.cubic = 1;
        if (cubic && crad)
            tubes_ref_render(&rd, cubic, crad, NULL);
        /* Quadratic vs cubic sweep, on pixels both hit, in units of the local radius. */
        double mx = 0.0, mean = 0.0, mx_away = 0.0;
        long both = 0, mism = 0, hit = 0, away = 0;
        for (size_t k = 0; cubic && crad && k < np; k++) {
            int a = ref[k] > 0.0f, b = cubic[k] > 0.0f;
            hit += a || b;
            mism += a != b;
            if (a && b) {
                double e = fabs((double)ref[k] - cubic[k]) / fmax(crad[k], 1e-30);
                mx = fmax(mx, e);
                mean += e;
                both++;
                if (!tubes_ref_silhouette(cubic, crad, w, h, (int)(k % (size_t)w), (int)(k / (size_t)w))) {
                    mx_away = fmax(mx_away, e);
                    away++;
                }
            }
        }
        printf("quadratic_vs_cubic: max %.4g mean %.4g (x local radius) over %ld pixels, coverage mismatch %ld (%.3f%%); "
               "away from silhouettes max %.4g over %ld pixels\n",
               mx, both ? mean / both : 0.0, both, mism, hit ? 100.0 * mism / hit : 0.0, mx_away, away);
        if (o.max_cubic_dev >= 0.0 && (!cubic || !crad || away == 0 || !(mx_away <= o.max_cubic_dev))) {
            printf("quadratic_vs_cubic: FAIL: %.4g x r away from silhouettes exceeds --max-cubic-dev %g (%ld pixels)\n",
                   mx_away, o.max_cubic_dev, away);
            cubic_failed = 1;
        }
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
        if (sl_scene_open_dataset(&scene, data_dir, &copy, &err) != SL_OK ||
            render_gpu(copy, tech, &params, &view, gpu, o.out_png, &err) != SL_OK) {
            fprintf(stderr, "tubes-check: GPU: %s\n", err.message);
            rc = 3;
            goto done;
        }
    }
    /* Pixels within tol pass. Exceptions are allowed only at a reference
     * silhouette (tubes_ref_silhouette: coverage change or a depth jump of
     * more than the local radius in the 3x3 neighbourhood; a joint between
     * segments is not one), where the float32 ray set-up (~16 ulp of the eye
     * distance sideways) moves the rim and the depth near a rim is infinitely
     * sensitive to it:
     *   - coverage exceptions: hit by one side only;
     *   - depth exceptions: both hit, tol < error <= rim_tol x the radius.
     * Together they are limited to max-mismatch-pct % of the pixels hit;
     * anything else (a mismatch or an error beyond tol away from a
     * silhouette, an error beyond rim_tol anywhere) fails. */
    double max_rel = 0.0, mean_rel = 0.0, max_abs = 0.0, max_rel_inner = 0.0;
    long both = 0, mismatch = 0, hit_either = 0, inner_fail = 0, nonfinite = 0, cover_exc = 0, depth_exc = 0;
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
            int sil = tubes_ref_silhouette(ref, rad, w, h, i, j);
            if (a != b) {
                mismatch++;
                if (sil) {
                    cover_exc++;
                } else {
                    if (inner_fail < 5)
                        fprintf(stderr, "  pixel (%d,%d): coverage gpu %.7g ref %.7g, not at a silhouette\n", i, j,
                                gpu[k], ref[k]);
                    inner_fail++;
                }
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
                if (sil && rel <= o.rim_tol) {
                    depth_exc++;
                } else {
                    if (inner_fail < 5)
                        fprintf(stderr, "  pixel (%d,%d): gpu %.7g ref %.7g radius %.4g segment %d (%.3g x r%s)\n", i, j,
                                gpu[k], ref[k], rad[k], seg[k], rel, sil ? ", beyond the rim bound" : "");
                    inner_fail++;
                }
            }
        }
    long exceptions = cover_exc + depth_exc;
    double exception_pct = hit_either ? 100.0 * (double)exceptions / (double)hit_either : 0.0;
    printf("tubes-check %s: %ld pixels both hit; depth error max %.4g x local radius (%.4g world) at (%d,%d), "
           "away from silhouettes max %.4g, mean %.4g; coverage mismatch %ld; silhouette exceptions %ld "
           "(coverage %ld, depth <= %.3g x r %ld; %.3f%% of %ld hit); failures %ld; non-finite %ld; reference %.0f ms\n",
           o.scene, both, max_rel, max_abs, worst_i, worst_j, max_rel_inner, both ? mean_rel / both : 0.0, mismatch,
           exceptions, cover_exc, o.rim_tol, depth_exc, exception_pct, hit_either, inner_fail, nonfinite, ref_ms);
    if (o.out_gpu && sl_pfm_write(o.out_gpu, gpu, w, h, &err) != SL_OK)
        fprintf(stderr, "tubes-check: %s\n", err.message);
    if (o.out_ref && sl_pfm_write(o.out_ref, ref, w, h, &err) != SL_OK)
        fprintf(stderr, "tubes-check: %s\n", err.message);
    if (o.out_radius && sl_pfm_write(o.out_radius, rad, w, h, &err) != SL_OK)
        fprintf(stderr, "tubes-check: %s\n", err.message);
    if (nonfinite || inner_fail || exception_pct > o.max_mismatch_pct || hit_either == 0 || cubic_failed) {
        printf("FAIL%s\n", hit_either == 0 ? " (nothing hit: the scene tests nothing)"
                            : cubic_failed ? " (quadratic pair too far from the cubic)" : "");
        rc = 1;
    } else {
        printf("PASS\n");
    }
    free(cubic);
done:
    tubes_ref_input_free(&input);
    free(ref);
    free(rad);
    free(gpu);
    free(seg);
    sl_dataset_destroy(ds);
    sl_scene_deinit(&scene);
    return rc;
}
