/* test_lr_volume_streamlines.c — lr_volume's streamline tubes
 * (renderer/lr_volume/lr_volume_streamlines.c) through the pipeline on
 * llvmpipe, against an independent reference:
 *  - geometry: with a transparent transfer function only the tubes remain;
 *    every pixel they cover, put back in world space from the depth
 *    buffer, lies at the tube radius from the streamlines traced on the CPU
 *    in double (sl_flow_trace: no GL, no tubes code) from the same seeds,
 *    within a bound stated below; and the tubes cover the CPU lines'
 *    projections. Single-sample and 4x MSAA (the nearest-sample depth copy);
 *  - the cache: the first frame prepares and its prepare traces (the
 *    prepare's "streamlines" and "streamline_trace_ms" extras); MSAA, a
 *    camera move, a transfer function, the tube radius or colormap neither
 *    prepare nor trace (rebuild_ms == 0); seeds, solver, precision and
 *    t_max re-prepare and trace; turned on after the prepare, the next
 *    frame traces once (rebuild_ms > 0) and the frames after it do not;
 *  - composition: with a visible volume, pixels no tube covers are the
 *    image without streamlines (blending over the cleared background:
 *    within 1 level of rounding), tube pixels keep a depth at least the
 *    tube's (the volume may only be nearer) and show (differ from the frame
 *    without them);
 *  - the rays end at the tubes: in a medium of constant colour and opacity
 *    each tube pixel is c A + (1 - A) tube with A = 1 - (1 - alpha)^(L / s_min)
 *    over the length L in front of the tube (CPU, double), within 3 levels;
 *  - a scalar volume with streamlines on is refused with a sentence, by the
 *    prepare or, turned on later, by the render (the volume then renders
 *    again with them off).
 * Single-threaded (render thread).
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_camera.h"
#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "flow/sl_flow.h"
#include "gpu/sl_gpu.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "sl_test.h"

enum { W = 96, H = 80, NPIX = W * H };

#define VECTOR_FIELD "{\"generator\":\"lr_field\",\"degree\":2,\"cells\":4,\"components\":\"vector\"}"
#define SCALAR_FIELD "{\"generator\":\"lr_field\",\"degree\":2,\"cells\":4}"
#define CLEAR_TF "\"transfer_function\":[[0,0,0,0,0],[2,0,0,0,0]]"
#define SEEDS "\"seed_min\":[0.3,0.3,0.3],\"seed_max\":[0.7,0.7,0.7],\"seed_count\":12"
#define TRACE "\"solver\":\"rk4\",\"flow_step\":1,\"t_max\":1.5,\"max_samples\":400"
#define RADIUS_FRACTION 0.006

static sl_gpu *gpu;

typedef struct scene {
    sl_pipeline *pipe;
    const sl_technique *t;
    const sl_dataset *ds;    /* owned by pipe */
    sl_view view;
} scene;

static int scene_open(scene *s, const char *dataset)
{
    memset(s, 0, sizeof *s);
    sl_err err = {0};
    sl_dataset *ds = NULL;
    s->t = sl_technique_find("lr_volume");
    if (sl_generate_json(dataset, &ds, &err) != SL_OK || sl_pipeline_create(gpu, &s->pipe, &err) != SL_OK) {
        SL_CHECK_MSG(0, "%s: %s", dataset, err.message);
        sl_dataset_destroy(ds);
        return 0;
    }
    s->ds = ds;
    sl_pipeline_set_dataset(s->pipe, ds);
    return 1;
}

static int scene_view(scene *s, double azimuth, double elevation)
{
    sl_err err = {0};
    memset(&s->view, 0, sizeof s->view);
    s->view.width = W;
    s->view.height = H;
    const float bg[4] = {0.1f, 0.1f, 0.12f, 1.0f};
    memcpy(s->view.background, bg, sizeof bg);
    s->view.origin = s->ds->origin;
    sl_orbit o = {azimuth, elevation, 2.4, 45.0};
    int ok = sl_camera_from_orbit(&o, s->ds->bounds_min, s->ds->bounds_max, &s->view.camera, &err) == SL_OK &&
             sl_view_init(&s->view, sl_dataset_radius(s->ds), &err) == SL_OK;
    SL_CHECK_MSG(ok, "view: %s", err.message);
    return ok;
}

/* One frame with params (JSON over the defaults); SL_OK or the render's code (err filled). */
static sl_status scene_render(scene *s, const char *params, int samples, sl_frame_stats *st, sl_err *err)
{
    sl_params p;
    sl_params_init(&p, s->t->params, s->t->param_count);
    cJSON *patch = cJSON_Parse(params);
    sl_status rc = patch ? sl_params_apply_json(&p, patch, err) : SL_ERR_INVALID;
    cJSON_Delete(patch);
    SL_CHECK_MSG(rc == SL_OK, "params %s: %s", params, err->message);
    if (rc == SL_OK)
        rc = sl_pipeline_set_technique(s->pipe, s->t, &p, err);
    if (rc == SL_OK)
        rc = sl_pipeline_render(s->pipe, &s->view, samples, st, err);
    return rc;
}

/* The prepare's extra `name` of a frame that prepared; -1 when absent. */
static double prepare_extra(const sl_frame_stats *st, const char *name)
{
    for (int i = 0; st->prepared && i < st->prepare.extra_count; i++)
        if (strcmp(st->prepare.extra[i].name, name) == 0)
            return st->prepare.extra[i].value;
    return -1.0;
}

/* A frame that prepared and traced in its prepare (no render-time trace). */
static int traced_in_prepare(const sl_frame_stats *st)
{
    return st->prepared == 1 && prepare_extra(st, "streamlines") > 0 && prepare_extra(st, "streamline_trace_ms") > 0 &&
           st->render.rebuild_ms == 0;
}

/* A frame that neither prepared nor traced. */
static int cached(const sl_frame_stats *st)
{
    return st->prepared == 0 && st->render.rebuild_ms == 0;
}

/* Distance from p to the polyline x[0..n-1] (double). */
static double polyline_distance(const double *x, size_t n, const double p[3])
{
    double best = INFINITY;
    for (size_t i = 0; i + 1 < n; i++) {
        const double *a = x + 3 * i, *b = x + 3 * i + 3;
        double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
        double len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
        double u = len2 > 0 ? (ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / len2 : 0.0;
        u = u < 0 ? 0 : u > 1 ? 1 : u;
        double d[3] = {ap[0] - u * ab[0], ap[1] - u * ab[1], ap[2] - u * ab[2]};
        best = fmin(best, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
    return best;
}

/* The CPU double reference of the lines the technique traces for SEEDS/TRACE. */
static int reference_lines(const sl_dataset *ds, sl_flow_result *ref)
{
    sl_err err = {0};
    sl_flow_field f;
    const sl_lr_volume *lr = ds->lr;
    char spec[256];
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        double ext = lr->domain_hi[a] - lr->domain_lo[a];
        lo[a] = lr->domain_lo[a] + 0.3 * ext;
        hi[a] = lr->domain_lo[a] + 0.7 * ext;
    }
    snprintf(spec, sizeof spec, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,12", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    double *seeds = NULL;
    size_t n = 0;
    sl_flow_options o = {.solver = SL_FLOW_RK4, .mode = SL_FLOW_STEP_HEURISTIC, .step = 1.0, .t_max = 1.5,
                         .max_samples = 400};
    int ok = sl_flow_field_from_dataset(&f, ds, &err) == SL_OK && sl_flow_seeds_box(spec, &seeds, &n, &err) == SL_OK &&
             sl_flow_trace(&f, seeds, n, &o, ref, &err) == SL_OK;
    free(seeds);
    SL_CHECK_MSG(ok, "reference trace: %s", err.message);
    return ok;
}

static double domain_diagonal(const sl_dataset *ds)
{
    double s = 0;
    for (int a = 0; a < 3; a++) {
        double e = ds->lr->domain_hi[a] - ds->lr->domain_lo[a];
        s += e * e;
    }
    return sqrt(s);
}

/* Every tube pixel at the tube radius from the CPU lines; the lines' sample
 * points that project inside the image mostly covered. */
static void check_geometry(scene *s, const sl_flow_result *ref, double radius, int msaa, const char *what)
{
    static float dist[NPIX];
    sl_pipeline_read_distance(s->pipe, &s->view, dist);
    int covered = 0;
    double worst = 0.0, excess = -INFINITY; /* max | d - r |, max (| d - r | - allowed) */
    sl_vec3 eye = s->view.camera.eye;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float t = dist[j * W + i];
            if (!(t > 0))
                continue;
            covered++;
            sl_vec3 d = sl_view_ray_dir(&s->view, i, j);
            double p[3] = {eye.x + t * d.x, eye.y + t * d.y, eye.z + t * d.z};
            double best = INFINITY;
            for (size_t l = 0; l < ref->line_count; l++)
                best = fmin(best, polyline_distance(ref->lines[l].x, ref->lines[l].count, p));
            /* The tube surface is at the radius from the Hermite centreline;
             * the CPU polyline is its chord (samples 1/4 element apart) and
             * the GPU trace is mixed precision: 8 % of the radius holds it at
             * the pixel centre (2.2 % measured). With MSAA the resolved depth may come
             * from a sample up to a pixel away from the centre's ray: one
             * pixel's footprint at that distance more. */
            double allowed = 0.08 * radius + (msaa ? 2.0 * s->view.tan_half_fov * t / H : 0.0);
            worst = fmax(worst, fabs(best - radius));
            excess = fmax(excess, fabs(best - radius) - allowed);
        }
    printf("%s: %d tube pixels, max | distance to CPU lines - radius | = %.3g (radius %.3g; largest excess over "
           "the bound %.3g)\n", what, covered, worst, radius, excess);
    SL_CHECK_MSG(covered > 80, "%s: only %d tube pixels", what, covered);
    SL_CHECK_MSG(excess <= 0.0, "%s: a tube pixel lies %.3g beyond its bound (radius %.3g)", what, excess, radius);
    /* Projections of the CPU samples in front of the camera and inside the image are on tube pixels. */
    int inside = 0, hit = 0;
    for (size_t l = 0; l < ref->line_count; l++)
        for (size_t k = 0; k < ref->lines[l].count; k += 2) {
            const double *x = ref->lines[l].x + 3 * k;
            sl_vec3 r = sl_v3_sub(sl_v3(x[0], x[1], x[2]), eye);
            double z = sl_v3_dot(r, s->view.forward);
            if (z <= 0)
                continue;
            double u = sl_v3_dot(r, s->view.right) / (z * s->view.tan_half_fov * s->view.aspect);
            double v = sl_v3_dot(r, s->view.upv) / (z * s->view.tan_half_fov);
            int pi = (int)floor((u + 1) * 0.5 * W), pj = (int)floor((1 - v) * 0.5 * H);
            if (pi < 1 || pj < 1 || pi >= W - 1 || pj >= H - 1)
                continue;
            inside++;
            int any = 0;
            for (int dj = -1; dj <= 1; dj++)
                for (int di = -1; di <= 1; di++)
                    any |= dist[(pj + dj) * W + pi + di] > 0;
            hit += any;
        }
    printf("%s: %d of %d CPU samples land on tube pixels\n", what, hit, inside);
    SL_CHECK_MSG(inside > 40 && hit >= 0.95 * inside, "%s: %d of %d CPU samples on tubes", what, hit, inside);
}

static void test_geometry_and_cache(void)
{
    scene s;
    if (!scene_open(&s, VECTOR_FIELD) || !scene_view(&s, 30, 20))
        return;
    sl_flow_result ref = {0};
    if (!reference_lines(s.ds, &ref))
        return;
    double radius = RADIUS_FRACTION * domain_diagonal(s.ds);
    char params[512];
    snprintf(params, sizeof params, "{\"streamlines\":true,%s,%s,%s,\"tube_radius\":%g}", CLEAR_TF, SEEDS, TRACE,
             RADIUS_FRACTION);
    sl_frame_stats st;
    sl_err err = {0};
    SL_CHECK_MSG(scene_render(&s, params, 1, &st, &err) == SL_OK, "%s", err.message);
    SL_CHECK_MSG(traced_in_prepare(&st), "the first frame did not trace in its prepare (prepared %d, rebuild %g ms)",
                 st.prepared, st.render.rebuild_ms);
    printf("prepare: %.0f lines, %.0f samples, trace %.1f ms (dispatch %.1f ms), tubes prepare %.1f ms\n",
           prepare_extra(&st, "streamlines"), prepare_extra(&st, "streamline_samples"),
           prepare_extra(&st, "streamline_trace_ms"), prepare_extra(&st, "streamline_compute_ms"),
           prepare_extra(&st, "streamline_tubes_ms"));
    check_geometry(&s, &ref, radius, 0, "single-sample");
    SL_CHECK_MSG(scene_render(&s, params, 4, &st, &err) == SL_OK, "%s", err.message);
    SL_CHECK_MSG(cached(&st), "4x MSAA prepared or traced again");
    check_geometry(&s, &ref, radius, 1, "4x MSAA");
    /* Frame-level changes that do not shape the lines: no prepare, no trace. */
    scene_view(&s, 70, -10);
    SL_CHECK(scene_render(&s, params, 1, &st, &err) == SL_OK);
    SL_CHECK_MSG(cached(&st), "a camera move prepared or traced again");
    check_geometry(&s, &ref, radius, 0, "another camera");
    snprintf(params, sizeof params,
             "{\"streamlines\":true,\"transfer_function\":[[0,0,0,0,0],[1,1,1,1,0.2]],%s,%s,\"tube_radius\":%g,"
             "\"tube_colormap\":\"magma\"}", SEEDS, TRACE, 2 * RADIUS_FRACTION);
    SL_CHECK(scene_render(&s, params, 1, &st, &err) == SL_OK);
    SL_CHECK_MSG(cached(&st), "the transfer function, radius or colormap prepared or traced again");
    /* What shapes the lines: another prepared state, traced (the change
     * comes last in the object, and sl_params_apply_json applies members in
     * order). */
    const char *changes[] = {"\"seed_count\":13", "\"seed_min\":[0.25,0.3,0.3]", "\"solver\":\"rk3\"",
                             "\"precision\":\"double\"", "\"t_max\":1.4"};
    for (size_t k = 0; k < sizeof changes / sizeof changes[0]; k++) {
        snprintf(params, sizeof params, "{\"streamlines\":true,%s,%s,%s,%s}", CLEAR_TF, SEEDS, TRACE, changes[k]);
        SL_CHECK_MSG(scene_render(&s, params, 1, &st, &err) == SL_OK, "%s: %s", changes[k], err.message);
        SL_CHECK_MSG(traced_in_prepare(&st), "%s did not re-prepare and trace", changes[k]);
        scene_view(&s, 30, 20);
        SL_CHECK(scene_render(&s, params, 1, &st, &err) == SL_OK);
        SL_CHECK_MSG(cached(&st), "after %s a camera move prepared or traced again", changes[k]);
    }
    sl_flow_result_free(&ref);
    sl_pipeline_destroy(s.pipe);
}

/* `streamlines` is FRAME level: off at the prepare, then on: that frame
 * traces (rebuild_ms), the next frames and turning it off and on again do
 * not; the lines are those of a prepare with it on (same geometry check). */
static void test_turned_on_later(void)
{
    scene s;
    if (!scene_open(&s, VECTOR_FIELD) || !scene_view(&s, 30, 20))
        return;
    sl_flow_result ref = {0};
    if (!reference_lines(s.ds, &ref))
        return;
    char off[512], on[512];
    snprintf(off, sizeof off, "{\"streamlines\":false,%s,%s,%s,\"tube_radius\":%g}", CLEAR_TF, SEEDS, TRACE,
             RADIUS_FRACTION);
    snprintf(on, sizeof on, "{\"streamlines\":true,%s,%s,%s,\"tube_radius\":%g}", CLEAR_TF, SEEDS, TRACE,
             RADIUS_FRACTION);
    sl_frame_stats st;
    sl_err err = {0};
    SL_CHECK(scene_render(&s, off, 1, &st, &err) == SL_OK);
    SL_CHECK_MSG(st.prepared == 1 && prepare_extra(&st, "streamlines") < 0 && st.render.rebuild_ms == 0,
                 "off: prepared %d, streamlines extra %g, rebuild %g ms", st.prepared,
                 prepare_extra(&st, "streamlines"), st.render.rebuild_ms);
    SL_CHECK(scene_render(&s, on, 1, &st, &err) == SL_OK);
    SL_CHECK_MSG(st.prepared == 0 && st.render.rebuild_ms > 0, "turned on: prepared %d, rebuild %g ms", st.prepared,
                 st.render.rebuild_ms);
    check_geometry(&s, &ref, RADIUS_FRACTION * domain_diagonal(s.ds), 0, "turned on later");
    const char *again[] = {on, off, on};
    for (int k = 0; k < 3; k++) {
        SL_CHECK(scene_render(&s, again[k], 1, &st, &err) == SL_OK);
        SL_CHECK_MSG(cached(&st), "frame %d after turning on: prepared %d, rebuild %g ms", k, st.prepared,
                     st.render.rebuild_ms);
    }
    sl_flow_result_free(&ref);
    sl_pipeline_destroy(s.pipe);
}

/* Pixels without a tube: the frame without streamlines, up to blending's rounding. */
static void test_composition(void)
{
    scene s;
    if (!scene_open(&s, VECTOR_FIELD) || !scene_view(&s, 30, 20))
        return;
    const char *tf = "\"transfer_function\":[[0,0,0,0,0],[0.3,1,0.5,0.2,0.05],[1.2,0.2,0.6,1,0.3]]";
    char params[512];
    static uint8_t off[4 * NPIX], on[4 * NPIX];
    static float tubes[NPIX], depth_on[NPIX];
    sl_frame_stats st;
    sl_err err = {0};
    snprintf(params, sizeof params, "{%s}", tf);
    SL_CHECK(scene_render(&s, params, 1, &st, &err) == SL_OK);
    sl_pipeline_read_rgba(s.pipe, off, 1);
    snprintf(params, sizeof params, "{\"streamlines\":true,%s,%s,%s}", CLEAR_TF, SEEDS, TRACE);
    SL_CHECK(scene_render(&s, params, 1, &st, &err) == SL_OK);
    sl_pipeline_read_distance(s.pipe, &s.view, tubes);
    snprintf(params, sizeof params, "{\"streamlines\":true,%s,%s,%s}", tf, SEEDS, TRACE);
    SL_CHECK(scene_render(&s, params, 1, &st, &err) == SL_OK);
    sl_pipeline_read_rgba(s.pipe, on, 1);
    sl_pipeline_read_distance(s.pipe, &s.view, depth_on);
    int free_px = 0, worst = 0, tube_px = 0, behind = 0, volume_px = 0, shows = 0;
    for (int i = 0; i < NPIX; i++) {
        if (tubes[i] > 0) {
            tube_px++;
            behind += !(depth_on[i] > 0 && depth_on[i] <= tubes[i] * (1 + 1e-5));
            shows += memcmp(off + 4 * i, on + 4 * i, 3) != 0;
            continue;
        }
        free_px++;
        volume_px += memcmp(off + 4 * i, on + 4 * i, 3) != 0 || off[4 * i] > 40;
        for (int c = 0; c < 3; c++)
            worst = abs((int)off[4 * i + c] - (int)on[4 * i + c]) > worst ? abs((int)off[4 * i + c] - (int)on[4 * i + c])
                                                                         : worst;
    }
    printf("composition: %d pixels without tubes differ by at most %d from the frame without streamlines; "
           "%d tube pixels, %d of them with a depth behind the tube\n", free_px, worst, tube_px, behind);
    SL_CHECK_MSG(volume_px > 100 && tube_px > 40, "%d volume pixels, %d tube pixels", volume_px, tube_px);
    SL_CHECK_MSG(worst <= 1, "a pixel without tubes differs by %d", worst);
    SL_CHECK_MSG(behind == 0, "%d tube pixels ended up behind their tube", behind);
    SL_CHECK_MSG(shows >= 0.9 * tube_px, "the tubes show through the volume on %d of %d pixels", shows, tube_px);
    sl_pipeline_destroy(s.pipe);
}

/* The ray's entry into the box [lo, hi] from eye along d (0 when the eye is inside). */
static double box_entry(const double eye[3], const double d[3], const double lo[3], const double hi[3])
{
    double t0 = 0.0;
    for (int a = 0; a < 3; a++) {
        if (d[a] == 0.0)
            continue;
        double ta = (lo[a] - eye[a]) / d[a], tb = (hi[a] - eye[a]) / d[a];
        t0 = fmax(t0, fmin(ta, tb));
    }
    return t0;
}

/* A medium of one colour and opacity (a constant transfer function,
 * shading off): in front of a tube, emission-absorption gives exactly
 * A = 1 - (1 - alpha)^(L / s_min) over the length L from the domain's entry
 * to the tube, whatever the steps, so each tube pixel must be
 * c A + (1 - A) tube, the tube's colour taken from the frame without the
 * medium and L from its depth, in double on the CPU. A ray that went on
 * behind the tube would add the medium there too. */
static void test_constant_medium(void)
{
    scene s;
    if (!scene_open(&s, VECTOR_FIELD) || !scene_view(&s, 30, 20))
        return;
    const double c = 0.9, alpha = 0.1;
    char params[640];
    static uint8_t tubes_rgb[4 * NPIX], on[4 * NPIX];
    static float tubes[NPIX];
    sl_frame_stats st;
    sl_err err = {0};
    snprintf(params, sizeof params, "{\"streamlines\":true,%s,%s,%s}", CLEAR_TF, SEEDS, TRACE);
    SL_CHECK(scene_render(&s, params, 1, &st, &err) == SL_OK);
    sl_pipeline_read_rgba(s.pipe, tubes_rgb, 1);
    sl_pipeline_read_distance(s.pipe, &s.view, tubes);
    snprintf(params, sizeof params,
             "{\"streamlines\":true,\"shading\":false,\"step_mode\":\"uniform\",\"step\":0.25,"
             "\"transfer_function\":[[-10,%g,%g,%g,%g],[10,%g,%g,%g,%g]],%s,%s}", c, c, c, alpha, c, c, c, alpha, SEEDS,
             TRACE);
    SL_CHECK_MSG(scene_render(&s, params, 1, &st, &err) == SL_OK, "%s", err.message);
    sl_pipeline_read_rgba(s.pipe, on, 1);
    const sl_lr_volume *lr = s.ds->lr;
    double ref = fmin(fmin(lr->min_side[0], lr->min_side[1]), lr->min_side[2]);
    double eye[3] = {s.view.camera.eye.x, s.view.camera.eye.y, s.view.camera.eye.z};
    int n = 0, worst = 0;
    double min_a = 1, max_a = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float t = tubes[j * W + i];
            if (!(t > 0))
                continue;
            sl_vec3 dv = sl_view_ray_dir(&s.view, i, j);
            double d[3] = {dv.x, dv.y, dv.z};
            double len = t - box_entry(eye, d, lr->domain_lo, lr->domain_hi);
            double a = 1.0 - pow(1.0 - alpha, fmax(len, 0.0) / ref);
            min_a = fmin(min_a, a);
            max_a = fmax(max_a, a);
            for (int k = 0; k < 3; k++) {
                double want = 255.0 * (c * a + (1.0 - a) * tubes_rgb[4 * (j * W + i) + k] / 255.0);
                int e = (int)fabs(want - on[4 * (j * W + i) + k] + 0.0);
                worst = e > worst ? e : worst;
            }
            n++;
        }
    printf("constant medium: %d tube pixels, opacity in front %.3f..%.3f, largest difference %d levels\n", n, min_a,
           max_a, worst);
    SL_CHECK_MSG(n > 40 && max_a > 0.2, "%d tube pixels, opacity up to %.3f", n, max_a);
    SL_CHECK_MSG(worst <= 3, "a tube pixel is %d levels off c A + (1 - A) tube", worst);
    sl_pipeline_destroy(s.pipe);
}

static void test_scalar_refused(void)
{
    scene s;
    if (!scene_open(&s, SCALAR_FIELD) || !scene_view(&s, 30, 20))
        return;
    sl_frame_stats st;
    sl_err err = {0};
    /* On at the prepare: the prepare refuses; then off: the volume renders. */
    sl_status rc = scene_render(&s, "{\"streamlines\":true}", 1, &st, &err);
    SL_CHECK_MSG(rc == SL_ERR_INVALID && strstr(err.message, "vector"), "scalar + streamlines: %d %s", rc,
                 err.message);
    printf("scalar + streamlines: %s\n", err.message);
    SL_CHECK(scene_render(&s, "{\"streamlines\":false}", 1, &st, &err) == SL_OK && st.prepared == 1);
    /* Turned on after the prepare (FRAME level): that render refuses, the state stays, off renders again. */
    memset(&err, 0, sizeof err);
    rc = scene_render(&s, "{\"streamlines\":true,\"tube_radius\":0.01}", 1, &st, &err);
    SL_CHECK_MSG(rc == SL_ERR_INVALID && strstr(err.message, "vector"), "scalar, streamlines turned on: %d %s", rc,
                 err.message);
    SL_CHECK(scene_render(&s, "{\"streamlines\":false}", 1, &st, &err) == SL_OK && st.prepared == 0);
    sl_pipeline_destroy(s.pipe);
}

int main(void)
{
    sl_err err = {0};
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "test_lr_volume_streamlines: %s\n", err.message);
        return 1;
    }
    test_geometry_and_cache();
    test_turned_on_later();
    test_composition();
    test_constant_medium();
    test_scalar_refused();
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
