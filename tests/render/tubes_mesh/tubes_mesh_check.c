/* tubes_mesh_check.c — checks for the `tubes_mesh` technique and sightline-render's outputs.
 *
 * usage: tubes-mesh-check image --scene S.json [--set k=v ...] (--png P | --jpeg J) [--depth D.pfm]
 *            [--min-color-pct X] [--min-hit-pct Y] [--expect-empty] [--data-dir DIR]
 *        tubes-mesh-check cylinder --scene S.json [--set k=v ...] [--gpu-depth D.pfm] [--out-gpu G.pfm]
 *            [--out-ref R.pfm] [--out-png P.png] [--eps-rel E] [--min-mantle-pct X] [--min-cap-pct Y]
 *            [--min-inside-pct Z] [--data-dir DIR]
 *        tubes-mesh-check stats --stats s.json --frames N [--technique T] [--expect-primitives P]
 *
 * image: a rendered frame (PNG or JPEG, as written by sightline-render; with
 *   both, the JPEG is checked and must match the PNG within a mean of 4/255) has
 *   the scene's size and at least X % of its pixels away from the background
 *   (or none with --expect-empty); the depth map (PFM) has the scene's size,
 *   only finite values >= 0, at least Y % hits (none with --expect-empty),
 *   every hit inside the eye distance range of the dataset's bounding sphere
 *   (grown by the tube radius), and its hit pixels are drawn (at most 10 %
 *   of them look like background in the colour frame).
 *
 * cylinder: the scene's dataset is one straight inline Hermite segment
 *   (2 nodes, equal radius r, times radius_scale); the technique tessellates
 *   it as a right prism with `sides` = n vertices per ring on the circle of
 *   radius r (inscribed), closed by flat n-gon caps when `caps` is on. The
 *   exact reference, in double, is the ray-cylinder intersection of every
 *   pixel's ray built from the camera by the formula of proto/scene.md (not by
 *   the renderer's matrices). The prism lies between the cylinder C(r) and
 *   C(ri), ri = r cos(pi/n) (the incircle of the n-gon), with the same end
 *   planes, so for every pixel whose ray enters both through the mantle:
 *
 *       t(C(r)) - eps <= t_gpu <= t(C(ri)) + eps,
 *
 *   i.e. 0 <= depth error <= t(C(ri)) - t(C(r)) <= B(c) =
 *   r sin^2(pi/n) / (c + sqrt(c^2 - sin^2(pi/n))), c = |cos| of the incidence
 *   angle on C(r); B(1) = r (1 - cos(pi/n)), the polygonal bound head-on,
 *   and B grows towards silhouettes (B(0.9) = 1.11 B(1) for n = 12). In the
 *   cross-section across the axis, with s <= 1 the ray's component across
 *   it, t(C(ri)) - t(C(r)) = (r^2 - ri^2) / (r c + sqrt(r^2 c^2 - s^2 (r^2 - ri^2))),
 *   and r^2 - ri^2 = r^2 sin^2(pi/n).
 *   Both are checked (B(c) on pixels with c >= 0.5). eps = eps_rel x the
 *   distance (float depth, float vertices; default 1e-5). Caps: where the
 *   ray enters both cylinders through the same end disk the prism's cap lies
 *   in the same plane, so the error must be within eps. Without caps a ray
 *   entering through the open end must hit the inner wall between the exits
 *   of C(ri) and C(r), or miss when it leaves through the other open end.
 *   Coverage: a ray that enters C(ri) (shrunk by a 1/64-pixel margin) must
 *   hit; a ray missing C(r) (grown by the margin) must miss; pixels in
 *   between (the silhouette band of width r - ri and the rims) may do either
 *   but, when hit, must lie within the grown cylinder's span. No NaN/Inf.
 *
 * stats: the --stats JSON of sightline-render has the renderer string, the
 *   technique, frames = N, gpu_ms and wall_ms {min, median, max} (finite,
 *   >= 0, ordered), dataset_load_ms and prepare_ms (finite, >= 0; prepare > 0),
 *   preprocess_ms and upload_ms (> 0, each at most prepare_ms),
 *   gpu_bytes > 0 and primitives > 0 (= P when given).
 *
 * Exit: 0 pass, 1 check failed, 2 bad input, 3 GPU failure.
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

#define MAX_SETS 32
#define PI 3.14159265358979323846

typedef struct options {
    const char *mode, *scene, *png, *jpeg, *depth, *gpu_depth, *out_gpu, *out_ref, *out_png, *stats, *technique,
        *data_dir;
    const char *sets[MAX_SETS];
    int set_count, expect_empty, frames;
    double min_color_pct, min_hit_pct, eps_rel, min_mantle_pct, min_cap_pct, min_inside_pct, expect_primitives;
} options;

static int failures;

static void fail(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "tubes-mesh-check: FAIL: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    failures++;
}

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.min_color_pct = 1.0, .min_hit_pct = 1.0, .eps_rel = 1e-5, .frames = -1,
                   .expect_primitives = -1.0};
    if (argc < 2) {
        fprintf(stderr, "usage: tubes-mesh-check image|cylinder|stats [options] (see the source's header)\n");
        return -1;
    }
    o->mode = argv[1];
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--expect-empty") == 0) { o->expect_empty = 1; continue; }
        if (i + 1 >= argc) { fprintf(stderr, "tubes-mesh-check: missing value after %s\n", a); return -1; }
        const char *v = argv[++i];
        if (strcmp(a, "--scene") == 0) o->scene = v;
        else if (strcmp(a, "--png") == 0) o->png = v;
        else if (strcmp(a, "--jpeg") == 0) o->jpeg = v;
        else if (strcmp(a, "--depth") == 0) o->depth = v;
        else if (strcmp(a, "--gpu-depth") == 0) o->gpu_depth = v;
        else if (strcmp(a, "--out-gpu") == 0) o->out_gpu = v;
        else if (strcmp(a, "--out-ref") == 0) o->out_ref = v;
        else if (strcmp(a, "--out-png") == 0) o->out_png = v;
        else if (strcmp(a, "--stats") == 0) o->stats = v;
        else if (strcmp(a, "--technique") == 0) o->technique = v;
        else if (strcmp(a, "--data-dir") == 0) o->data_dir = v;
        else if (strcmp(a, "--frames") == 0) o->frames = atoi(v);
        else if (strcmp(a, "--min-color-pct") == 0) o->min_color_pct = atof(v);
        else if (strcmp(a, "--min-hit-pct") == 0) o->min_hit_pct = atof(v);
        else if (strcmp(a, "--eps-rel") == 0) o->eps_rel = atof(v);
        else if (strcmp(a, "--min-mantle-pct") == 0) o->min_mantle_pct = atof(v);
        else if (strcmp(a, "--min-cap-pct") == 0) o->min_cap_pct = atof(v);
        else if (strcmp(a, "--min-inside-pct") == 0) o->min_inside_pct = atof(v);
        else if (strcmp(a, "--expect-primitives") == 0) o->expect_primitives = atof(v);
        else if (strcmp(a, "--set") == 0 && o->set_count < MAX_SETS) o->sets[o->set_count++] = v;
        else { fprintf(stderr, "tubes-mesh-check: unknown option %s\n", a); return -1; }
    }
    return 0;
}

/* ---- scene, dataset, view ---- */

typedef struct loaded {
    cJSON *root;          /* the scene document after --set */
    sl_scene scene;
    sl_dataset *ds;       /* owned until handed to a pipeline */
    const sl_technique *tech;
    sl_params params;
    sl_view view;
} loaded;

static void loaded_deinit(loaded *l)
{
    cJSON_Delete(l->root);
    sl_scene_deinit(&l->scene);
    sl_dataset_destroy(l->ds);
    memset(l, 0, sizeof *l);
}

static int load_scene(const options *o, loaded *l)
{
    memset(l, 0, sizeof *l);
    sl_err err = {0};
    uint8_t *text = NULL;
    size_t size = 0;
    if (!o->scene) {
        fprintf(stderr, "tubes-mesh-check: --scene is required\n");
        return 2;
    }
    if (sl_read_file(o->scene, 16u << 20, &text, &size, &err) != SL_OK) {
        fprintf(stderr, "tubes-mesh-check: %s\n", err.message);
        return 2;
    }
    l->root = cJSON_ParseWithLength((const char *)text, size);
    free(text);
    if (!l->root) {
        fprintf(stderr, "tubes-mesh-check: %s is not JSON\n", o->scene);
        return 2;
    }
    for (int k = 0; k < o->set_count; k++)
        if (sl_scene_apply_override(l->root, o->sets[k], &err) != SL_OK) {
            fprintf(stderr, "tubes-mesh-check: %s\n", err.message);
            return 2;
        }
    if (sl_scene_from_json(l->root, &l->scene, &err) != SL_OK) {
        fprintf(stderr, "tubes-mesh-check: scene: %s\n", err.message);
        return 2;
    }
    l->tech = sl_technique_find(l->scene.technique);
    sl_params_init(&l->params, l->tech->params, l->tech->param_count);
    if (sl_params_apply_json(&l->params, l->scene.params, &err) != SL_OK) {
        fprintf(stderr, "tubes-mesh-check: params: %s\n", err.message);
        return 2;
    }
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", o->scene);
    if (sl_scene_open_dataset(&l->scene, o->data_dir ? o->data_dir : dirname(dir), &l->ds, &err) != SL_OK ||
        sl_scene_view(&l->scene, l->ds, 0, &l->view, &err) != SL_OK) {
        fprintf(stderr, "tubes-mesh-check: dataset/view: %s\n", err.message);
        return 2;
    }
    return 0;
}

/* Renders the distance map (1 sample, the exact pixel-centre rays) and
 * optionally the colour frame through the pipeline, as sightline-render does. */
static int render_gpu(loaded *l, float *distance, const char *png)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_pipeline *pipe = NULL;
    sl_frame_stats stats;
    sl_status st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1, .debug = 1}, &gpu, &err);
    if (st == SL_OK)
        st = sl_pipeline_create(gpu, &pipe, &err);
    if (st == SL_OK) {
        sl_pipeline_set_dataset(pipe, l->ds); /* takes ownership */
        l->ds = NULL;
        st = sl_pipeline_set_technique(pipe, l->tech, &l->params, &err);
    }
    if (st == SL_OK)
        st = sl_pipeline_render(pipe, &l->view, 1, &stats, &err);
    if (st == SL_OK)
        sl_pipeline_read_distance(pipe, &l->view, distance);
    if (st == SL_OK && png) {
        uint8_t *rgba = malloc((size_t)l->view.width * (size_t)l->view.height * 4);
        st = rgba ? SL_OK : sl_err_set(&err, SL_ERR_NOMEM, "out of memory");
        if (rgba) {
            sl_pipeline_read_rgba(pipe, rgba, 1);
            st = sl_png_write(png, rgba, l->view.width, l->view.height, &err);
        }
        free(rgba);
    }
    sl_pipeline_destroy(pipe);
    sl_gpu_destroy(gpu);
    if (st != SL_OK) {
        fprintf(stderr, "tubes-mesh-check: render: %s\n", err.message);
        return st == SL_ERR_GPU ? 3 : 2;
    }
    return 0;
}

/* ---- double-precision vectors and the camera rays of proto/scene.md ---- */

typedef struct d3 { double x, y, z; } d3;
static d3 d3v(sl_vec3 v) { return (d3){v.x, v.y, v.z}; }
static d3 add(d3 a, d3 b) { return (d3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static d3 sub(d3 a, d3 b) { return (d3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static d3 mul(d3 a, double s) { return (d3){a.x * s, a.y * s, a.z * s}; }
static double dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static d3 cross(d3 a, d3 b) { return (d3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static double len(d3 a) { return sqrt(dot(a, a)); }
static d3 unit(d3 a) { return mul(a, 1.0 / len(a)); }

typedef struct rays { d3 eye, f, r, u; double tan_half, aspect; int w, h; } rays;

static rays rays_of(const sl_camera *c, int w, int h)
{
    rays k;
    k.eye = d3v(c->eye);
    k.f = unit(sub(d3v(c->target), k.eye));
    k.r = unit(cross(k.f, d3v(c->up)));
    k.u = cross(k.r, k.f);
    k.tan_half = tan(c->fov_y_deg * PI / 360.0);
    k.aspect = (double)w / (double)h;
    k.w = w;
    k.h = h;
    return k;
}

static d3 ray_dir(const rays *k, int i, int j)
{
    double sx = (2.0 * (i + 0.5) / k->w - 1.0) * k->tan_half * k->aspect;
    double sy = (1.0 - 2.0 * (j + 0.5) / k->h) * k->tan_half;
    return unit(add(k->f, add(mul(k->r, sx), mul(k->u, sy))));
}

/* ---- image ---- */

static int run_image(const options *o)
{
    loaded l;
    int rc = load_scene(o, &l);
    if (rc) {
        loaded_deinit(&l);
        return rc;
    }
    const int w = l.scene.width, h = l.scene.height;
    const size_t n = (size_t)w * (size_t)h;
    sl_err err = {0};
    sl_image img = {0};
    sl_depth_image dep = {0};
    int jpeg = o->jpeg != NULL;
    sl_status st = SL_OK;
    if (jpeg) {
        uint8_t *data = NULL;
        size_t size = 0;
        st = sl_read_file(o->jpeg, 64u << 20, &data, &size, &err);
        if (st == SL_OK)
            st = sl_jpeg_decode(data, size, &img, &err);
        free(data);
    } else if (o->png) {
        st = sl_png_read(o->png, &img, &err);
    } else {
        fprintf(stderr, "tubes-mesh-check: image needs --png or --jpeg\n");
        loaded_deinit(&l);
        return 2;
    }
    if (st == SL_OK && o->depth)
        st = sl_pfm_read(o->depth, &dep, &err);
    if (st != SL_OK) {
        fprintf(stderr, "tubes-mesh-check: %s\n", err.message);
        loaded_deinit(&l);
        sl_image_deinit(&img);
        return 2;
    }
    if (img.width != w || img.height != h)
        fail("frame is %dx%d, the scene says %dx%d", img.width, img.height, w, h);
    if (jpeg && o->png && !failures) {
        /* The JPEG must show the PNG's picture: mean |difference| <= 4 of 255 at quality 92. */
        sl_image same = {0};
        if (sl_png_read(o->png, &same, &err) != SL_OK || same.width != w || same.height != h) {
            fail("%s: %s", o->png, same.rgba ? "size differs from the scene" : err.message);
        } else {
            double sum = 0.0;
            for (size_t p = 0; p < n; p++)
                for (int c = 0; c < 3; c++)
                    sum += abs((int)img.rgba[4 * p + (size_t)c] - (int)same.rgba[4 * p + (size_t)c]);
            double mean = sum / (3.0 * (double)n);
            printf("{\"jpeg_vs_png_mean_abs\": %.3f}\n", mean);
            if (mean > 4.0)
                fail("the JPEG differs from %s by %.2f on average (> 4 of 255)", o->png, mean);
        }
        sl_image_deinit(&same);
    }
    if (o->depth && (dep.width != w || dep.height != h))
        fail("depth map is %dx%d, the scene says %dx%d", dep.width, dep.height, w, h);
    if (failures)
        goto done;

    /* Colour: pixels away from the background (JPEG: beyond its ringing). */
    const int bg_tol = jpeg ? 16 : 4;
    uint8_t *drawn = calloc(n, 1);
    size_t colored = 0;
    for (size_t p = 0; p < n && drawn; p++) {
        int far = 0;
        for (int c = 0; c < 3; c++) {
            int bg = (int)lround(l.scene.background[c] * 255.0);
            far |= abs((int)img.rgba[4 * p + (size_t)c] - bg) > bg_tol;
        }
        drawn[p] = (uint8_t)far;
        colored += (size_t)far;
    }
    double color_pct = 100.0 * (double)colored / (double)n;
    if (o->expect_empty ? colored != 0 : color_pct < o->min_color_pct)
        fail("%.2f %% of the pixels differ from the background (expected %s %g %%)", color_pct,
             o->expect_empty ? "exactly" : ">=", o->expect_empty ? 0.0 : o->min_color_pct);

    size_t hits = 0, bad = 0, out_of_range = 0, undrawn = 0;
    double dmin = INFINITY, dmax = 0.0;
    if (o->depth) {
        /* Eye distance range of the bounding sphere grown by the tube radius. */
        sl_line_style style;
        sl_line_style_read(&l.params, l.ds, &style);
        double max_data_r = 0.0;
        for (size_t v = 0; l.ds->lines.radii && v < l.ds->lines.vertex_count; v++)
            max_data_r = fmax(max_data_r, l.ds->lines.radii[v]);
        double grow = fmax(style.radius, max_data_r * style.radius_scale);
        d3 centre = mul(add(d3v(l.ds->bounds_min), d3v(l.ds->bounds_max)), 0.5);
        double sphere = sl_dataset_radius(l.ds) + grow;
        double dist = len(sub(d3v(l.view.camera.eye), centre));
        double lo = fmax(0.0, dist - sphere) * (1 - 1e-5), hi = (dist + sphere) * (1 + 1e-5);
        for (size_t p = 0; p < n; p++) {
            float d = dep.values[p];
            if (!isfinite(d) || d < 0.0f) {
                if (bad++ < 5)
                    fail("depth[%zu, %zu] = %g is not a finite distance >= 0", p % (size_t)w, p / (size_t)w, d);
                continue;
            }
            if (d == 0.0f)
                continue;
            hits++;
            dmin = fmin(dmin, d);
            dmax = fmax(dmax, d);
            if (d < lo || d > hi)
                out_of_range++;
            if (drawn && !drawn[p])
                undrawn++;
        }
        double hit_pct = 100.0 * (double)hits / (double)n;
        if (o->expect_empty ? hits != 0 : hit_pct < o->min_hit_pct)
            fail("%.2f %% of the depth pixels are hits (expected %s %g %%)", hit_pct,
                 o->expect_empty ? "exactly" : ">=", o->expect_empty ? 0.0 : o->min_hit_pct);
        if (out_of_range)
            fail("%zu hits lie outside the eye distance range [%g, %g] of the bounds (seen [%g, %g])", out_of_range,
                 lo, hi, dmin, dmax);
        if (hits && (double)undrawn > 0.10 * (double)hits)
            fail("%zu of %zu depth hits look like background in the colour frame (> 10 %%)", undrawn, hits);
    }
    printf("{\"mode\": \"image\", \"width\": %d, \"height\": %d, \"color_pct\": %.3f, \"depth_hits\": %zu, "
           "\"depth_min\": %g, \"depth_max\": %g, \"hits_not_drawn\": %zu, \"non_finite\": %zu, \"pass\": %s}\n",
           w, h, color_pct, hits, hits ? dmin : 0.0, dmax, undrawn, bad, failures ? "false" : "true");
    free(drawn);
done:
    sl_image_deinit(&img);
    sl_depth_image_deinit(&dep);
    loaded_deinit(&l);
    return failures ? 1 : 0;
}

/* ---- cylinder ---- */

enum { K_MANTLE = 0, K_CAP = 1 };

/* The ray's span inside the solid capped cylinder of radius rad about the
 * axis p0 + s a, s in [s_lo, s_hi]: entry t0 and exit t1 with the kind of
 * surface and the axial coordinate s there. */
typedef struct span { int hit; double t0, t1; int k0, k1; double s0, s1, rho0, rho1; } span;

static span solid(d3 o, d3 d, d3 p0, d3 a, double rad, double s_lo, double s_hi)
{
    span r = {0};
    d3 w = sub(o, p0);
    double dpar = dot(d, a), wpar = dot(w, a);
    d3 dp = sub(d, mul(a, dpar)), wp = sub(w, mul(a, wpar));
    double A = dot(dp, dp), B = dot(wp, dp), C = dot(wp, wp) - rad * rad;
    double tc0, tc1;
    if (A < 1e-300) {
        if (C > 0.0)
            return r;
        tc0 = -INFINITY;
        tc1 = INFINITY;
    } else {
        double disc = B * B - A * C;
        if (disc < 0.0)
            return r;
        double q = sqrt(disc);
        tc0 = (-B - q) / A;
        tc1 = (-B + q) / A;
    }
    double ts0, ts1;
    if (fabs(dpar) < 1e-300) {
        if (wpar < s_lo || wpar > s_hi)
            return r;
        ts0 = -INFINITY;
        ts1 = INFINITY;
    } else {
        double ta = (s_lo - wpar) / dpar, tb = (s_hi - wpar) / dpar;
        ts0 = fmin(ta, tb);
        ts1 = fmax(ta, tb);
    }
    r.t0 = fmax(tc0, ts0);
    r.t1 = fmin(tc1, ts1);
    if (!(r.t0 <= r.t1) || r.t1 <= 0.0)
        return r;
    r.hit = 1;
    r.k0 = ts0 > tc0 ? K_CAP : K_MANTLE;
    r.k1 = ts1 < tc1 ? K_CAP : K_MANTLE;
    r.s0 = wpar + r.t0 * dpar;
    r.s1 = wpar + r.t1 * dpar;
    r.rho0 = len(add(wp, mul(dp, r.t0)));
    r.rho1 = len(add(wp, mul(dp, r.t1)));
    return r;
}

/* Reads the one straight segment of the scene's inline Hermite data. */
static int read_segment(const cJSON *root, d3 *p0, d3 *p1, double *r)
{
    const cJSON *ds = cJSON_GetObjectItemCaseSensitive(root, "dataset");
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(ds, "nodes");
    const cJSON *segs = cJSON_GetObjectItemCaseSensitive(ds, "segments");
    if (cJSON_GetArraySize(nodes) != 2 || cJSON_GetArraySize(segs) != 1) {
        fprintf(stderr, "tubes-mesh-check: cylinder needs inline Hermite data with 2 nodes and 1 segment\n");
        return 0;
    }
    double rr[2];
    d3 *p[2] = {p0, p1};
    for (int k = 0; k < 2; k++) {
        const cJSON *nd = cJSON_GetArrayItem(nodes, k);
        const cJSON *pos = cJSON_GetObjectItemCaseSensitive(nd, "p");
        const cJSON *rad = cJSON_GetObjectItemCaseSensitive(nd, "r");
        if (cJSON_GetArraySize(pos) != 3 || !cJSON_IsNumber(rad))
            return 0;
        *p[k] = (d3){cJSON_GetArrayItem(pos, 0)->valuedouble, cJSON_GetArrayItem(pos, 1)->valuedouble,
                     cJSON_GetArrayItem(pos, 2)->valuedouble};
        rr[k] = rad->valuedouble;
    }
    if (rr[0] != rr[1] || !(rr[0] > 0.0)) {
        fprintf(stderr, "tubes-mesh-check: cylinder needs one radius > 0 at both nodes\n");
        return 0;
    }
    *r = rr[0];
    return 1;
}

enum { C_OUTSIDE, C_MANTLE, C_CAP, C_INSIDE, C_THROUGH, C_EDGE, C_COUNT };
static const char *const class_names[C_COUNT] = {"outside", "mantle", "cap", "inside", "through", "edge"};

static int run_cylinder(const options *o)
{
    loaded l;
    int rc = load_scene(o, &l);
    if (rc) {
        loaded_deinit(&l);
        return rc;
    }
    d3 p0, p1;
    double r0;
    if (!read_segment(l.root, &p0, &p1, &r0)) {
        loaded_deinit(&l);
        return 2;
    }
    const int sides = sl_params_int(&l.params, "sides"), caps = sl_params_bool(&l.params, "caps");
    const double R = r0 * sl_params_float(&l.params, "radius_scale");
    const double Ri = R * cos(PI / sides), sin_n = sin(PI / sides);
    const double delta = R * (1.0 - cos(PI / sides)); /* the polygonal bound, head-on */
    const d3 axis = unit(sub(p1, p0));
    const double L = len(sub(p1, p0));
    const int w = l.view.width, h = l.view.height;
    const size_t n = (size_t)w * (size_t)h;
    rays k = rays_of(&l.view.camera, w, h);
    /* Rasterization margin: 1/64 of a pixel's footprint at the farthest point of the tube. */
    double far = fmax(len(sub(p0, k.eye)), len(sub(p1, k.eye))) + R;
    double m = 2.0 * k.tan_half / h * far / 64.0;

    float *gpu = calloc(n, sizeof *gpu), *ref = calloc(n, sizeof *ref);
    if (!gpu || !ref) {
        free(gpu);
        free(ref);
        loaded_deinit(&l);
        return 2;
    }
    if (o->gpu_depth) {
        sl_depth_image dep = {0};
        sl_err err = {0};
        if (sl_pfm_read(o->gpu_depth, &dep, &err) != SL_OK || dep.width != w || dep.height != h) {
            fprintf(stderr, "tubes-mesh-check: %s: %s\n", o->gpu_depth, dep.values ? "size differs from the scene" : err.message);
            sl_depth_image_deinit(&dep);
            free(gpu);
            free(ref);
            loaded_deinit(&l);
            return 2;
        }
        memcpy(gpu, dep.values, n * sizeof *gpu);
        sl_depth_image_deinit(&dep);
    } else if ((rc = render_gpu(&l, gpu, o->out_png)) != 0) {
        free(gpu);
        free(ref);
        loaded_deinit(&l);
        return rc;
    }

    size_t count[C_COUNT] = {0}, wrong_cover = 0, out_of_bracket = 0, over_bound = 0, non_finite = 0;
    double max_err_over_delta = 0.0, max_err_c90 = 0.0, min_err = 0.0, max_cap_err = 0.0, max_inside_err = 0.0;
    double max_bound_use = 0.0; /* err / B(c) */
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            size_t p = (size_t)j * (size_t)w + (size_t)i;
            d3 d = ray_dir(&k, i, j);
            double t = gpu[p];
            if (!isfinite(t) || t < 0.0) {
                if (non_finite++ < 5)
                    fail("pixel (%d, %d): GPU distance %g is not finite and >= 0", i, j, t);
                continue;
            }
            int hit = t > 0.0;
            span O = solid(k.eye, d, p0, axis, R, 0.0, L);
            span I = solid(k.eye, d, p0, axis, Ri, 0.0, L);
            span Is = solid(k.eye, d, p0, axis, Ri - m, m, L - m);
            span Ol = solid(k.eye, d, p0, axis, R + m, -m, L + m);
            if (O.hit && O.t0 <= 0.0) {
                fprintf(stderr, "tubes-mesh-check: the eye is inside the cylinder; move the camera\n");
                free(gpu);
                free(ref);
                loaded_deinit(&l);
                return 2;
            }
            double eps = o->eps_rel * (O.hit ? O.t1 : far);
            int cls = C_EDGE, must_hit = 0;
            double lo = 0.0, hi = 0.0;
            /* Robust cases only: the crossing of an end plane counts when it lies a margin
             * inside the n-gon as seen on screen (grazing caps are thin slivers). */
            double along = fabs(dot(d, axis));
            int mantle_in = Is.hit && O.hit && I.k0 == K_MANTLE && O.k0 == K_MANTLE &&
                            fmin(I.s0, O.s0) >= m && fmax(I.s0, O.s0) <= L - m;
            int cap_in = O.hit && O.k0 == K_CAP && (Ri - O.rho0) * along > m; /* then I enters there too */
            if (!Ol.hit) {
                cls = C_OUTSIDE;
            } else if (mantle_in) {
                cls = C_MANTLE, must_hit = 1, lo = O.t0, hi = I.t0;
            } else if (cap_in && caps) {
                cls = C_CAP, must_hit = 1, lo = O.t0, hi = I.t0;
            } else if (cap_in && !caps) {
                /* Through the open end: the inner wall between the exits, or out of the other end. */
                int wall = I.k1 == K_MANTLE && O.k1 == K_MANTLE && fmin(I.s1, O.s1) >= m && fmax(I.s1, O.s1) <= L - m;
                int through = O.k1 == K_CAP && (Ri - O.rho1) * along > m;
                if (wall)
                    cls = C_INSIDE, must_hit = 1, lo = I.t1, hi = O.t1;
                else if (through)
                    cls = C_THROUGH;
            } else if (caps && Is.hit) {
                /* Enters C(ri) (shrunk) but near a rim: still inside the prism's solid. */
                cls = C_EDGE, must_hit = 1, lo = O.t0, hi = I.t0;
            }
            count[cls]++;
            if (O.hit)
                ref[p] = (float)(caps || O.k0 == K_MANTLE ? O.t0 : (O.k1 == K_MANTLE ? O.t1 : 0.0));
            if (cls == C_OUTSIDE || cls == C_THROUGH) {
                if (hit && wrong_cover++ < 5)
                    fail("pixel (%d, %d): GPU hit at %.9g where the ray %s", i, j, t,
                         cls == C_OUTSIDE ? "misses the cylinder" : "passes through the open tube");
                continue;
            }
            if (must_hit && !hit) {
                if (wrong_cover++ < 5)
                    fail("pixel (%d, %d) (%s): GPU missed, the ray enters the incircle cylinder at %.9g", i, j,
                         class_names[cls], lo);
                continue;
            }
            if (!hit)
                continue;
            if (!must_hit) {
                /* Band and rims: anything inside the grown cylinder. */
                if ((t < Ol.t0 - eps || t > Ol.t1 + eps) && out_of_bracket++ < 5)
                    fail("pixel (%d, %d) (edge): GPU %.9g outside the cylinder span [%.9g, %.9g]", i, j, t, Ol.t0,
                         Ol.t1);
                continue;
            }
            if ((t < lo - eps || t > hi + eps) && out_of_bracket++ < 5)
                fail("pixel (%d, %d) (%s): GPU %.9g outside [%.9g, %.9g] (+-%.2g)", i, j, class_names[cls], t, lo, hi,
                     eps);
            if (cls == C_MANTLE) {
                double err = t - O.t0;
                d3 nrm = unit(sub(add(sub(k.eye, p0), mul(d, O.t0)), mul(axis, O.s0)));
                double c = fabs(dot(d, nrm));
                min_err = fmin(min_err, err);
                max_err_over_delta = fmax(max_err_over_delta, err / delta);
                if (c >= 0.9)
                    max_err_c90 = fmax(max_err_c90, err / delta);
                if (c >= 0.5) {
                    double B = R * sin_n * sin_n / (c + sqrt(fmax(0.0, c * c - sin_n * sin_n)));
                    max_bound_use = fmax(max_bound_use, err / B);
                    if (err > B + eps && over_bound++ < 5)
                        fail("pixel (%d, %d): depth error %.3g > B(c = %.3f) = %.3g (delta = %.3g)", i, j, err, c, B,
                             delta);
                }
            } else if (cls == C_CAP) {
                max_cap_err = fmax(max_cap_err, fabs(t - O.t0));
            } else if (cls == C_INSIDE) {
                max_inside_err = fmax(max_inside_err, fabs(t - O.t1));
            }
        }
    double pct[C_COUNT];
    for (int c = 0; c < C_COUNT; c++)
        pct[c] = 100.0 * (double)count[c] / (double)n;
    if (pct[C_MANTLE] < o->min_mantle_pct)
        fail("only %.2f %% mantle pixels (need %g %%): the camera misses the tube", pct[C_MANTLE], o->min_mantle_pct);
    if (pct[C_CAP] < o->min_cap_pct)
        fail("only %.2f %% cap pixels (need %g %%)", pct[C_CAP], o->min_cap_pct);
    if (pct[C_INSIDE] < o->min_inside_pct)
        fail("only %.2f %% pixels see the inner wall through the open end (need %g %%)", pct[C_INSIDE],
             o->min_inside_pct);
    if (wrong_cover > 5 || out_of_bracket > 5 || over_bound > 5 || non_finite > 5)
        fprintf(stderr, "tubes-mesh-check: (%zu coverage, %zu bracket, %zu bound, %zu non-finite failures in all)\n",
                wrong_cover, out_of_bracket, over_bound, non_finite);

    sl_err err = {0};
    if (o->out_gpu && sl_pfm_write(o->out_gpu, gpu, w, h, &err) != SL_OK)
        fprintf(stderr, "tubes-mesh-check: %s\n", err.message);
    if (o->out_ref && sl_pfm_write(o->out_ref, ref, w, h, &err) != SL_OK)
        fprintf(stderr, "tubes-mesh-check: %s\n", err.message);
    printf("{\"mode\": \"cylinder\", \"sides\": %d, \"caps\": %s, \"radius\": %g, \"delta\": %.6g, \"margin\": %.3g,\n"
           " \"pixels\": {", sides, caps ? "true" : "false", R, delta, m);
    for (int c = 0; c < C_COUNT; c++)
        printf("\"%s\": %zu%s", class_names[c], count[c], c + 1 < C_COUNT ? ", " : "},\n");
    printf(" \"max_err_over_delta\": %.4f, \"max_err_over_delta_c90\": %.4f, \"max_err_over_B\": %.4f,\n"
           " \"min_err\": %.3g, \"max_cap_err\": %.3g, \"max_inside_err\": %.3g, \"pass\": %s}\n",
           max_err_over_delta, max_err_c90, max_bound_use, min_err, max_cap_err, max_inside_err,
           failures ? "false" : "true");
    free(gpu);
    free(ref);
    loaded_deinit(&l);
    return failures ? 1 : 0;
}

/* ---- stats ---- */

static const cJSON *need_number(const cJSON *obj, const char *path, const char *key, double min)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!cJSON_IsNumber(v))
        fail("stats: %s%s is missing or not a number", path, key);
    else if (!isfinite(v->valuedouble) || v->valuedouble < min)
        fail("stats: %s%s = %g is not finite and >= %g", path, key, v->valuedouble, min);
    else
        return v;
    return NULL;
}

static void need_summary(const cJSON *root, const char *key)
{
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(root, key);
    if (!cJSON_IsObject(s)) {
        fail("stats: %s is missing or not an object", key);
        return;
    }
    char path[64];
    snprintf(path, sizeof path, "%s.", key);
    const cJSON *lo = need_number(s, path, "min", 0.0), *mid = need_number(s, path, "median", 0.0),
                *hi = need_number(s, path, "max", 0.0);
    if (lo && mid && hi && !(lo->valuedouble <= mid->valuedouble && mid->valuedouble <= hi->valuedouble))
        fail("stats: %s is not ordered: min %g, median %g, max %g", key, lo->valuedouble, mid->valuedouble,
             hi->valuedouble);
}

static int run_stats(const options *o)
{
    uint8_t *text = NULL;
    size_t size = 0;
    sl_err err = {0};
    if (!o->stats || sl_read_file(o->stats, 1u << 20, &text, &size, &err) != SL_OK) {
        fprintf(stderr, "tubes-mesh-check: stats: %s\n", o->stats ? err.message : "--stats is required");
        return 2;
    }
    cJSON *root = cJSON_ParseWithLength((const char *)text, size);
    free(text);
    if (!cJSON_IsObject(root)) {
        fail("stats: %s is not a JSON object", o->stats);
        cJSON_Delete(root);
        return 1;
    }
    const cJSON *renderer = cJSON_GetObjectItemCaseSensitive(root, "renderer");
    if (!cJSON_IsString(renderer) || !renderer->valuestring[0])
        fail("stats: renderer is missing or empty");
    const cJSON *tech = cJSON_GetObjectItemCaseSensitive(root, "technique");
    if (!cJSON_IsString(tech) || (o->technique && strcmp(tech->valuestring, o->technique) != 0))
        fail("stats: technique is not \"%s\"", o->technique ? o->technique : "a string");
    const cJSON *frames = need_number(root, "", "frames", 1.0);
    if (frames && o->frames > 0 && frames->valuedouble != o->frames)
        fail("stats: frames = %g, expected %d", frames->valuedouble, o->frames);
    need_number(root, "", "width", 1.0);
    need_number(root, "", "height", 1.0);
    need_summary(root, "gpu_ms");
    need_summary(root, "wall_ms");
    need_number(root, "", "dataset_load_ms", 0.0);
    const cJSON *prep = need_number(root, "", "prepare_ms", 0.0);
    if (prep && !(prep->valuedouble > 0.0))
        fail("stats: prepare_ms is 0: the first frame's prepare was not timed");
    const cJSON *bytes = need_number(root, "", "gpu_bytes", 0.0);
    if (bytes && !(bytes->valuedouble > 0.0))
        fail("stats: gpu_bytes is 0: the technique reports no GPU memory");
    const cJSON *prims = need_number(root, "", "primitives", 0.0);
    if (prims && !(prims->valuedouble > 0.0))
        fail("stats: primitives is 0");
    if (prims && o->expect_primitives >= 0.0 && prims->valuedouble != o->expect_primitives)
        fail("stats: primitives = %.0f, expected %.0f", prims->valuedouble, o->expect_primitives);
    /* The technique's split of prepare_ms: the mesh build and the upload,
     * each timed (> 0) and each a part of the whole. */
    const char *parts[] = {"preprocess_ms", "upload_ms"};
    for (int i = 0; i < 2; i++) {
        const cJSON *part = need_number(root, "", parts[i], 0.0);
        if (part && !(part->valuedouble > 0.0))
            fail("stats: %s is 0: not timed", parts[i]);
        if (part && prep && part->valuedouble > prep->valuedouble)
            fail("stats: %s = %g exceeds prepare_ms = %g", parts[i], part->valuedouble, prep->valuedouble);
    }
    printf("{\"mode\": \"stats\", \"file\": \"%s\", \"pass\": %s}\n", o->stats, failures ? "false" : "true");
    cJSON_Delete(root);
    return failures ? 1 : 0;
}

int main(int argc, char **argv)
{
    options o;
    if (parse_args(argc, argv, &o) != 0)
        return 2;
    if (strcmp(o.mode, "image") == 0)
        return run_image(&o);
    if (strcmp(o.mode, "cylinder") == 0)
        return run_cylinder(&o);
    if (strcmp(o.mode, "stats") == 0)
        return run_stats(&o);
    fprintf(stderr, "tubes-mesh-check: unknown mode '%s' (image, cylinder, stats)\n", o.mode);
    return 2;
}
