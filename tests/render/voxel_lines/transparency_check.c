/* transparency_check.c — transparent line techniques against the exact CPU
 * compositing reference (tests/support/lines_reference.h), multi-coloured.
 *
 * usage: transparency-check --data SOURCE [--technique NAME]... [--expect-fail NAME]... [--size WxH]
 *            [--radius R | --radius-frac F] [--opacity A] [--orbit AZ,EL,DIST]
 *            [--colors on|off] [--flat on|off] [--grid N] [--quant N] [--sides N]
 *            [--tol-mean F] [--tol-p99 F] [--tol-crossings F] [--out-dir DIR]
 *            [--background R,G,B] [--backend auto|gl|cpu]
 * SOURCE is a file (.trk, .tck, .vtk, ...) or generator JSON. Every polyline
 * gets its own colour (a per-vertex attribute constant along the polyline,
 * spread over the viridis colormap by the golden ratio so neighbours differ;
 * --colors off: the default constant colour; --flat on: white, ambient
 * only, so a pixel's value tells how many crossings it blended). Each technique (default:
 * voxel_lines, lines_oit) renders one still frame at opacity A with the same
 * radius, light and material; the reference composites the exact capsule-
 * union crossings of every ray, with round ends for voxel_lines (capsules)
 * and open ends for the mesh techniques (lines_oit, tubes_mesh with caps
 * off), so each is compared with the tube it means to draw. Over the pixels either image covers (some
 * channel differs from the background) the max-channel |difference| must
 * have mean <= tol-mean and 99th percentile <= tol-p99 (0..255), and the
 * signed mean of the luma difference is printed (> 0: lighter than the
 * reference). With --flat on, a pixel's value v (green channel, 0..1) over
 * the background b gives the number of crossings it blended, N =
 * ln(1 - (v - b) / (1 - b)) / ln(1 - A); the mean |N - N_reference| over the
 * covered pixels must stay <= tol-crossings (signed mean printed too: < 0
 * lost crossings, > 0 crossings blended twice). --out-dir writes NAME.png, reference_round.png, reference_open.png.
 * Prints one line per technique, "ok" or "FAIL"; a technique given with
 * --expect-fail must fail (the test that the limits can tell unsorted
 * blending, e.g. tubes_mesh, from sorted). Exit 0 when every technique
 * meets its expectation, 1 when one does not, 2 bad input, 3 GPU failure,
 * 77 when SOURCE is a file that does not exist (sample data not fetched).
 * --background (0..1 each, default 0.1,0.1,0.12) is the clear colour of the
 * frames and the reference; --backend sets the `backend` parameter of the
 * techniques that have one (voxel_lines: the ray cast on the GPU or the CPU).
 * Render thread = main.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/sl_colormap.h"
#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "gpu/sl_gpu.h"
#include "image/sl_diff.h"
#include "image/sl_image.h"
#include "lines_reference.h"
#include "pipeline/sl_pipeline.h"

#define MAX_TECHNIQUES 4

typedef struct options {
    const char *data, *out_dir, *backend;
    float background[3];
    const char *techniques[MAX_TECHNIQUES];
    int expect_fail[MAX_TECHNIQUES]; /* 1: this technique must fail the limits */
    int technique_count;
    int width, height, grid, quant, sides, colors, flat;
    double radius, radius_frac, opacity, tol_mean, tol_p99, tol_crossings;
    sl_orbit orbit;
} options;

static sl_status set_num(sl_params *p, const char *name, double v, sl_err *err)
{
    if (sl_params_find(p, name) < 0)
        return SL_OK;
    return sl_params_set_numbers(p, name, &v, 1, err);
}

/* The parameters every technique gets: same radius, opacity, colouring,
 * no alpha termination, open tube ends where there is a choice (as lines_oit). */
static sl_status technique_params(const sl_technique *t, const options *o, double radius, int attribute,
                                  sl_params *p, sl_err *err)
{
    sl_params_init(p, t->params, t->param_count);
    sl_status st = set_num(p, "radius", radius, err);
    if (st == SL_OK)
        st = set_num(p, "opacity", o->opacity, err);
    if (st == SL_OK)
        st = set_num(p, "attribute", attribute, err);
    if (st == SL_OK && attribute >= 0)
        st = sl_params_set_choice(p, "colormap", "viridis", err);
    if (st == SL_OK)
        st = set_num(p, "alpha_threshold", 1.0, err);
    if (st == SL_OK)
        st = set_num(p, "sides", o->sides, err);
    if (st == SL_OK)
        st = set_num(p, "caps", 0, err);
    if (st == SL_OK && o->backend && sl_params_find(p, "backend") >= 0)
        st = sl_params_set_choice(p, "backend", o->backend, err);
    if (st == SL_OK && o->flat) {
        double white[3] = {1.0, 1.0, 1.0};
        st = sl_params_set_numbers(p, "color", white, 3, err);
        if (st == SL_OK)
            st = set_num(p, "ambient", 1.0, err);
        if (st == SL_OK)
            st = set_num(p, "diffuse", 0.0, err);
        if (st == SL_OK)
            st = set_num(p, "specular", 0.0, err);
    }
    if (st == SL_OK && strcmp(t->name, "voxel_lines") == 0) {
        char q[16];
        snprintf(q, sizeof q, "%d", o->quant);
        st = sl_params_set_choice(p, "quantization", q, err);
        if (st == SL_OK)
            st = set_num(p, "grid", o->grid, err);
    }
    return st;
}

/* A per-vertex attribute constant along each polyline: frac(k φ), so
 * neighbouring polylines get distant colours. Returns its index. */
static int add_curve_colours(sl_dataset *ds, sl_err *err)
{
    float *values = sl_lines_add_attribute(&ds->lines, "curve_colour", 0, err);
    if (!values)
        return -1;
    for (size_t k = 0; k < ds->lines.line_count; k++) {
        double t = fmod(0.5 + (double)k * 0.6180339887498949, 1.0);
        for (uint32_t i = ds->lines.line_offsets[k]; i < ds->lines.line_offsets[k + 1]; i++)
            values[i] = (float)t;
    }
    sl_attribute *a = &ds->lines.attributes[ds->lines.attribute_count - 1];
    a->min = 0.0f;
    a->max = 1.0f;
    return ds->lines.attribute_count - 1;
}

static int write_png(const options *o, const char *name, const uint8_t *rgba, int w, int h)
{
    if (!o->out_dir)
        return 0;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.png", o->out_dir, name);
    sl_err err = {0};
    if (sl_png_write(path, rgba, w, h, &err) != SL_OK) {
        fprintf(stderr, "transparency-check: %s\n", err.message);
        return -1;
    }
    return 0;
}

/* Statistics of a against the reference over the pixels either covers. */
/* Crossings a flat (white, ambient-only) pixel blended at opacity alpha. */
static double crossings(uint8_t v, double bg, double alpha)
{
    double covered = ((double)v / 255.0 - bg) / (1.0 - bg);
    double most = 1.0 - 0.5 / 255.0 / (1.0 - bg); /* the last step 8 bits resolve */
    covered = covered < 0.0 ? 0.0 : (covered > most ? most : covered);
    return log(1.0 - covered) / log(1.0 - alpha);
}

static int compare(const options *o, const char *name, const uint8_t *a, const uint8_t *ref, size_t n,
                   const float bg[4])
{
    double dn_abs = 0.0, dn_signed = 0.0;
    uint8_t g[3];
    for (int c = 0; c < 3; c++)
        g[c] = (uint8_t)lround(bg[c] * 255.0);
    /* Mean, p99 and max of the max-channel difference over the covered pixels. */
    sl_image ia = {.width = o->width, .height = o->height, .rgba = (uint8_t *)a};
    sl_image ir = {.width = o->width, .height = o->height, .rgba = (uint8_t *)ref};
    sl_diff_result r;
    sl_err err;
    if (sl_diff_images_covered(&ia, &ir, 8.0, g, &r, NULL, &err) != SL_OK) {
        printf("%s: %s: FAIL\n", name, err.message);
        return 1;
    }
    /* What sl_diff does not report: one-sided coverage, signed luma, crossings. */
    size_t covered = (size_t)r.compared, only_a = 0, only_ref = 0;
    double luma = 0.0;
    for (size_t i = 0; i < n; i++) {
        int in_a = 0, in_ref = 0;
        for (int c = 0; c < 3; c++) {
            in_a |= a[4 * i + c] != g[c];
            in_ref |= ref[4 * i + c] != g[c];
        }
        if (!in_a && !in_ref)
            continue;
        only_a += in_a && !in_ref;
        only_ref += in_ref && !in_a;
        if (o->flat) {
            double dn = crossings(a[4 * i + 1], bg[1], o->opacity) - crossings(ref[4 * i + 1], bg[1], o->opacity);
            dn_abs += fabs(dn);
            dn_signed += dn;
        }
        luma += 0.2126 * (a[4 * i] - ref[4 * i]) + 0.7152 * (a[4 * i + 1] - ref[4 * i + 1]) +
                0.0722 * (a[4 * i + 2] - ref[4 * i + 2]);
    }
    if (covered < n / 100) {
        printf("%s: only %zu of %zu pixels covered: FAIL (the scene misses the data)\n", name, covered, n);
        return 1;
    }
    double mean = r.mean_abs, p99 = r.p99_abs;
    int ok = mean <= o->tol_mean && p99 <= o->tol_p99;
    if (o->flat) {
        double dn = dn_abs / (double)covered;
        int ok_n = !(o->tol_crossings > 0.0) || dn <= o->tol_crossings;
        printf("%s vs reference: crossings per pixel |dN| mean %.3f (limit %.3f), signed %+.3f: %s\n", name, dn,
               o->tol_crossings, dn_signed / (double)covered, ok_n ? "ok" : "FAIL");
        ok = ok && ok_n;
    }
    printf("%s vs reference: %zu pixels covered (%zu only in %s, %zu only in the reference); max-channel |diff| "
           "mean %.2f p99 %.0f max %.0f, signed luma mean %+.2f (limits %.2f, %.0f): %s\n",
           name, covered, only_a, name, only_ref, mean, p99, r.max_abs, luma / (double)covered,
           o->tol_mean, o->tol_p99, ok ? "ok" : "FAIL");
    return ok ? 0 : 1;
}

/* Renders the reference and prints its statistics. */
static int reference(const options *o, const lines_ref_desc *desc, uint8_t *ref)
{
    lines_ref_stats rs;
    if (lines_ref_render(desc, ref, &rs) != 0) {
        fprintf(stderr, "transparency-check: reference failed\n");
        return -1;
    }
    const sl_lines *L = &desc->lines->lines;
    printf("reference (%s ends): %zu polylines, radius %.4g, opacity %.2f, %dx%d: %zu pixels hit, %.2f crossings "
           "per hit pixel (max %zu), %zu crossings of a polyline already crossing that ray\n",
           desc->open_ends ? "open" : "round", L->line_count, desc->radius, desc->opacity, o->width, o->height,
           rs.pixels_hit, rs.pixels_hit ? (double)rs.crossings / (double)rs.pixels_hit : 0.0, rs.max_crossings,
           rs.repeat_crossings);
    return write_png(o, desc->open_ends ? "reference_open" : "reference_round", ref, o->width, o->height);
}

static int parse_args(int argc, char **argv, options *o)
{
    for (int i = 1; i < argc; i++) {
        const char *k = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v) {
            fprintf(stderr, "transparency-check: %s needs a value\n", k);
            return 2;
        }
        i++;
        if (strcmp(k, "--data") == 0) o->data = v;
        else if (strcmp(k, "--out-dir") == 0) o->out_dir = v;
        else if ((strcmp(k, "--technique") == 0 || strcmp(k, "--expect-fail") == 0) &&
                 o->technique_count < MAX_TECHNIQUES) {
            o->expect_fail[o->technique_count] = strcmp(k, "--expect-fail") == 0;
            o->techniques[o->technique_count++] = v;
        }
        else if (strcmp(k, "--size") == 0) {
            if (sscanf(v, "%dx%d", &o->width, &o->height) != 2) {
                fprintf(stderr, "transparency-check: --size wants WxH, got %s\n", v);
                return 2;
            }
        } else if (strcmp(k, "--orbit") == 0) {
            if (sscanf(v, "%lf,%lf,%lf", &o->orbit.azimuth_deg, &o->orbit.elevation_deg, &o->orbit.distance) != 3) {
                fprintf(stderr, "transparency-check: --orbit wants AZ,EL,DIST, got %s\n", v);
                return 2;
            }
        } else if (strcmp(k, "--background") == 0) {
            if (sscanf(v, "%f,%f,%f", &o->background[0], &o->background[1], &o->background[2]) != 3) {
                fprintf(stderr, "transparency-check: --background wants R,G,B in 0..1, got %s\n", v);
                return 2;
            }
        } else if (strcmp(k, "--backend") == 0) o->backend = v;
        else if (strcmp(k, "--colors") == 0) o->colors = strcmp(v, "off") != 0;
        else if (strcmp(k, "--flat") == 0) o->flat = strcmp(v, "off") != 0;
        else if (strcmp(k, "--radius") == 0) o->radius = atof(v);
        else if (strcmp(k, "--radius-frac") == 0) o->radius_frac = atof(v);
        else if (strcmp(k, "--opacity") == 0) o->opacity = atof(v);
        else if (strcmp(k, "--grid") == 0) o->grid = atoi(v);
        else if (strcmp(k, "--quant") == 0) o->quant = atoi(v);
        else if (strcmp(k, "--sides") == 0) o->sides = atoi(v);
        else if (strcmp(k, "--tol-mean") == 0) o->tol_mean = atof(v);
        else if (strcmp(k, "--tol-p99") == 0) o->tol_p99 = atof(v);
        else if (strcmp(k, "--tol-crossings") == 0) o->tol_crossings = atof(v);
        else {
            fprintf(stderr, "transparency-check: unknown option %s\n", k);
            return 2;
        }
    }
    if (!o->data || o->width < 16 || o->height < 16 || o->width > 640 || o->height > 480 || !(o->opacity > 0.0) ||
        o->opacity > 1.0) {
        fprintf(stderr, "transparency-check: need --data, a size within 16x16..640x480 and opacity in (0, 1]\n");
        return 2;
    }
    if (o->technique_count == 0) {
        o->techniques[o->technique_count++] = "voxel_lines";
        o->techniques[o->technique_count++] = "lines_oit";
    }
    return 0;
}

static sl_status open_dataset(const char *source, sl_dataset **out, sl_err *err)
{
    const char *s = source;
    while (*s == ' ')
        s++;
    return *s == '{' ? sl_generate_json(source, out, err) : sl_load_file(source, out, err);
}

int main(int argc, char **argv)
{
    options o = {.width = 320, .height = 240, .grid = 128, .quant = 256, .sides = 24, .colors = 1,
                 .radius_frac = 0.004, .opacity = 0.6, .background = {0.1f, 0.1f, 0.12f}, .tol_mean = 3.0, .tol_p99 = 30.0,
                 .orbit = {.azimuth_deg = 40, .elevation_deg = 25, .distance = 1.6, .fov_y_deg = 45}};
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc;
    sl_err err = {0};
    sl_dataset *ds = NULL;
    if (o.data[strspn(o.data, " ")] != '{' && access(o.data, F_OK) != 0) {
        fprintf(stderr, "transparency-check: %s does not exist (scripts/fetch-sample-data fetches the samples)\n",
                o.data);
        return 77;
    }
    if (open_dataset(o.data, &ds, &err) != SL_OK) {
        fprintf(stderr, "transparency-check: %s\n", err.message);
        return 2;
    }
    if (ds->kind != SL_DATASET_LINES) {
        fprintf(stderr, "transparency-check: %s is not a line set\n", o.data);
        sl_dataset_destroy(ds);
        return 2;
    }
    int attribute = o.colors ? add_curve_colours(ds, &err) : -1;
    if (o.colors && attribute < 0) {
        fprintf(stderr, "transparency-check: %s\n", err.message);
        sl_dataset_destroy(ds);
        return 2;
    }
    double radius = o.radius > 0.0 ? o.radius : o.radius_frac * sl_dataset_radius(ds);
    sl_view view = {.width = o.width, .height = o.height, .quality = SL_QUALITY_STILL,
                    .background = {o.background[0], o.background[1], o.background[2], 1.0f}, .origin = ds->origin};
    if (sl_camera_from_orbit(&o.orbit, ds->bounds_min, ds->bounds_max, &view.camera, &err) != SL_OK ||
        sl_view_init(&view, sl_dataset_radius(ds), &err) != SL_OK) {
        fprintf(stderr, "transparency-check: camera: %s\n", err.message);
        sl_dataset_destroy(ds);
        return 2;
    }

    /* The reference, with the light and material of the shared line style. */
    const sl_technique *first = sl_technique_find(o.techniques[0]);
    if (!first) {
        fprintf(stderr, "transparency-check: technique %s is not registered\n", o.techniques[0]);
        sl_dataset_destroy(ds);
        return 2;
    }
    sl_params style;
    if (technique_params(first, &o, radius, attribute, &style, &err) != SL_OK) {
        fprintf(stderr, "transparency-check: %s\n", err.message);
        sl_dataset_destroy(ds);
        return 2;
    }
    size_t n = (size_t)o.width * o.height;
    float *curve_rgb = malloc((ds->lines.line_count ? ds->lines.line_count : 1) * 3 * sizeof *curve_rgb);
    uint8_t *ref = malloc(n * 4), *img = malloc(n * 4);
    if (!curve_rgb || !ref || !img) {
        fprintf(stderr, "transparency-check: out of memory\n");
        return 3;
    }
    float color[3], light[3];
    sl_params_vec3(&style, "color", color);
    sl_params_vec3(&style, "light_direction", light);
    for (size_t k = 0; k < ds->lines.line_count; k++) {
        if (attribute >= 0)
            sl_colormap_sample(sl_params_choice(&style, "colormap"),
                               ds->lines.attributes[attribute].values[ds->lines.line_offsets[k]], curve_rgb + 3 * k);
        else
            memcpy(curve_rgb + 3 * k, color, sizeof color);
    }
    double ll = sqrt((double)light[0] * light[0] + (double)light[1] * light[1] + (double)light[2] * light[2]);
    lines_ref_desc desc = {.view = &view, .lines = ds, .radius = radius, .curve_rgb = curve_rgb,
                           .opacity = o.opacity, .alpha_stop = 1.0,
                           .light_eye = {light[0] / ll, light[1] / ll, light[2] / ll},
                           .ambient = sl_params_float(&style, "ambient"), .diffuse = sl_params_float(&style, "diffuse"),
                           .specular = sl_params_float(&style, "specular"),
                           .shininess = sl_params_float(&style, "shininess")};
    int ref_ends = -1; /* which ends ref holds: 0 round, 1 open, -1 none yet */

    sl_gpu *gpu = NULL;
    sl_pipeline *pipe = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK ||
        sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        fprintf(stderr, "transparency-check: GPU: %s\n", err.message);
        return 3;
    }
    sl_pipeline_set_dataset(pipe, ds); /* owned by the pipeline from here */
    rc = 0;
    for (int k = 0; k < o.technique_count && rc != 3; k++) {
        const sl_technique *t = sl_technique_find(o.techniques[k]);
        sl_params p;
        sl_frame_stats stats = {0};
        if (!t) {
            fprintf(stderr, "transparency-check: technique %s is not registered\n", o.techniques[k]);
            rc = 2;
            break;
        }
        if (technique_params(t, &o, radius, attribute, &p, &err) != SL_OK ||
            sl_pipeline_set_technique(pipe, t, &p, &err) != SL_OK ||
            sl_pipeline_render(pipe, &view, 1, &stats, &err) != SL_OK) {
            fprintf(stderr, "transparency-check: %s: %s\n", t->name, err.message);
            rc = 3;
            break;
        }
        sl_pipeline_read_rgba(pipe, img, 1);
        int open_ends = strcmp(t->name, "voxel_lines") != 0;
        if (ref_ends != open_ends) {
            desc.open_ends = open_ends;
            if (reference(&o, &desc, ref) != 0) {
                rc = 3;
                break;
            }
            ref_ends = open_ends;
        }
        if (write_png(&o, t->name, img, o.width, o.height) != 0)
            rc = 2;
        int r = compare(&o, t->name, img, ref, n, view.background);
        if (o.expect_fail[k]) {
            printf("%s: %s\n", t->name, r ? "fails the limits, as expected" : "FAIL: meets the limits but was expected to fail");
            r = !r;
        }
        rc = rc ? rc : r;
    }
    sl_pipeline_destroy(pipe);
    sl_gpu_destroy(gpu);
    free(curve_rgb);
    free(ref);
    free(img);
    return rc;
}
