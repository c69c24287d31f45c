/* test_pipeline.c — the pipeline's re-prepare rule, for every registered technique, on llvmpipe.
 *
 * For each technique of sl_technique_list (so a new technique is covered
 * without editing this file) on a small generated dataset of a kind it
 * accepts, 32x24 pixels, no MSAA: the first frame prepares; the same view,
 * a camera move, another view size and MSAA, and re-selecting the technique
 * with the same parameters do not; then every parameter of its schema in
 * turn is moved to another valid value, and the next frame must re-run
 * prepare exactly when that parameter's schema entry says
 * SL_INVALIDATE_PREPARED (or DATASET), and the frame after must not. A new
 * dataset re-prepares. sl_frame_stats.prepared is what is checked.
 * Also: with orbit_frames = 4, frame 2's view and image equal those of a
 * single frame at azimuth + 180 (and differ from frame 0's) — the scene
 * view the CLI's --frames uses. sl_pipeline_export: refused before a
 * prepare and for a technique without the hook (naming the exporters);
 * a private exporting technique gets its own state, the params of the last
 * render and the path. Needs a GL 4.5 context (llvmpipe in CI;
 * never skipped: no context is a failure). Single-threaded (render thread).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "pipeline/sl_pipeline.h"
#include "sl_scene.h"
#include "sl_test.h"

enum { W = 32, H = 24 };

/* A small dataset of each kind a technique may accept; a technique whose
 * kinds have none here fails the test, so that its author adds one. */
static const struct {
    sl_dataset_kind kind;
    const char *json;
} small_datasets[] = {
    {SL_DATASET_LINES, "{\"generator\":\"tornado\",\"lines\":12,\"points\":40,\"seed\":3}"},
    {SL_DATASET_VOLUME, "{\"generator\":\"marschner_lobb\",\"size\":16,\"seed\":1}"},
    /* A vector LR volume, so lr_volume's streamlines trace too (a scalar one refuses them). */
    {SL_DATASET_LR, "{\"generator\":\"lr_field\",\"field\":\"sphere\",\"degree\":2,\"cells\":4,\"components\":\"vector\"}"},
};

static sl_dataset *make_dataset(unsigned kinds, sl_err *err)
{
    for (size_t k = 0; k < sizeof small_datasets / sizeof small_datasets[0]; k++) {
        if (!(kinds & (unsigned)small_datasets[k].kind))
            continue;
        sl_dataset *ds = NULL;
        if (sl_generate_json(small_datasets[k].json, &ds, err) == SL_OK)
            return ds;
        return NULL;
    }
    sl_err_set(err, SL_ERR_UNSUPPORTED, "no small test dataset for dataset kinds 0x%x (add one to small_datasets)",
               kinds);
    return NULL;
}

static sl_status make_view(const sl_dataset *ds, double azimuth, int w, int h, sl_view *view, sl_err *err)
{
    memset(view, 0, sizeof *view);
    view->width = w;
    view->height = h;
    const float bg[4] = {0.1f, 0.1f, 0.12f, 1.0f};
    memcpy(view->background, bg, sizeof bg);
    view->origin = ds->origin;
    sl_orbit orbit = {azimuth, 20.0, 2.5, 45.0};
    sl_status st = sl_camera_from_orbit(&orbit, ds->bounds_min, ds->bounds_max, &view->camera, err);
    return st == SL_OK ? sl_view_init(view, sl_dataset_radius(ds), err) : st;
}

/* Another valid value for one number of a parameter, near the old one so
 * that no change makes the work explode (a grid of 512^3, a radius of 1e8). */
static double moved_number(const sl_param_def *d, double v)
{
    double c[4] = {v * 0.8, v * 1.25, v + 1.0, v - 1.0};
    if (v == 0.0) {
        c[0] = 0.01;
        c[1] = -0.01;
    }
    for (int k = 0; k < 4; k++)
        if (c[k] != v && c[k] >= d->min && c[k] <= d->max)
            return c[k];
    return 0.5 * (d->min + d->max);
}

/* Moves parameter i of p to a different valid value; returns 0 if the
 * setter refused it (a test failure: the value was chosen inside the schema).
 * ds gives an empty VALUES list its first value: the middle of a volume's
 * value range (the schema's middle, 0 of +-1e30, may lie outside the data). */
static int move_param(sl_params *p, int i, const sl_dataset *ds, sl_err *err)
{
    const sl_param_def *d = &p->schema[i];
    double v[SL_PARAM_VALUES_MAX] = {p->value[i][0], p->value[i][1], p->value[i][2], p->value[i][3]};
    int n = 1;
    switch (d->type) {
    case SL_PARAM_BOOL:
        v[0] = v[0] != 0.0 ? 0.0 : 1.0;
        break;
    case SL_PARAM_ENUM: {
        int count = 0;
        while (d->choices[count])
            count++;
        v[0] = (double)(((int)v[0] + 1) % count);
        break;
    }
    case SL_PARAM_INT:
    case SL_PARAM_ATTRIBUTE:
        /* Down first: attribute indices (attribute 0 -> -1) stay valid on
         * a dataset with one attribute. */
        v[0] = v[0] - 1.0 >= d->min ? v[0] - 1.0 : v[0] + 1.0;
        break;
    case SL_PARAM_FLOAT:
        v[0] = moved_number(d, v[0]);
        break;
    case SL_PARAM_VEC3:
        v[0] = moved_number(d, v[0]);
        n = 3;
        break;
    case SL_PARAM_TRANSFER: {
        /* Another opacity at the last point of the ramp or point list (an
         * automatic ramp becomes an explicit one). */
        sl_transfer_function tf = *sl_params_transfer(p, d->name);
        if (tf.auto_opacity) {
            tf.auto_opacity = 0;
            tf.count = 2;
            tf.point[1][0] = 1.0;
        }
        int last = tf.count - 1, alpha = tf.colormap >= 0 ? 1 : 4;
        tf.point[last][alpha] = tf.point[last][alpha] > 0.5 ? 0.25 : 0.75;
        return sl_params_set_transfer(p, d->name, &tf, err) == SL_OK;
    }
    case SL_PARAM_VALUES:
        /* An empty list (auto) becomes one value; else the first value moves like a number. */
        n = p->value_count[i];
        if (n == 0) {
            v[0] = ds->kind == SL_DATASET_LINES ? 0.5 * (d->min + d->max)
                                                : 0.5 * (ds->volume.value_min + ds->volume.value_max);
            n = 1;
        } else {
            v[0] = moved_number(d, v[0]);
        }
        break;
    case SL_PARAM_TRANSFER_2D: {
        sl_transfer_function_2d tf = *sl_params_transfer_2d(p, d->name);
        double *alpha = &tf.widget[tf.count - 1][6];
        *alpha = *alpha > 0.5 ? 0.25 : 0.75;
        return sl_params_set_transfer_2d(p, d->name, &tf, err) == SL_OK;
    }
    }
    return sl_params_set_numbers(p, d->name, v, n, err) == SL_OK;
}

/* Renders one frame; returns stats.prepared, or -1 on failure (reported). */
static int render(sl_pipeline *pipe, const sl_view *view, int samples, const char *what, const char *tech)
{
    sl_frame_stats stats;
    sl_err err = {0};
    sl_status st = sl_pipeline_render(pipe, view, samples, &stats, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s: render failed: %s", tech, what, err.message);
    if (st != SL_OK)
        return -1;
    SL_CHECK_MSG(stats.prepared == 0 || stats.prepare_ms >= 0.0, "%s: %s: prepare_ms %g", tech, what,
                 stats.prepare_ms);
    return stats.prepared;
}

static void test_technique(sl_gpu *gpu, const sl_technique *t)
{
    sl_err err = {0};
    sl_dataset *ds = make_dataset(t->dataset_kinds, &err);
    SL_CHECK_MSG(ds != NULL, "%s: %s", t->name, err.message);
    if (!ds)
        return;
    sl_pipeline *pipe = NULL;
    SL_CHECK(sl_pipeline_create(gpu, &pipe, &err) == SL_OK);
    if (!pipe) {
        sl_dataset_destroy(ds);
        return;
    }
    sl_pipeline_set_dataset(pipe, ds);
    const sl_dataset *pds = sl_pipeline_dataset(pipe);
    sl_params params;
    sl_params_init(&params, t->params, t->param_count);
    SL_CHECK_MSG(sl_pipeline_set_technique(pipe, t, &params, &err) == SL_OK, "%s: %s", t->name, err.message);

    sl_view view, moved, small;
    SL_CHECK(make_view(pds, 30.0, W, H, &view, &err) == SL_OK);
    SL_CHECK(make_view(pds, 75.0, W, H, &moved, &err) == SL_OK);
    moved.camera.fov_y_deg = 30.0;
    SL_CHECK(sl_view_init(&moved, sl_dataset_radius(pds), &err) == SL_OK);
    SL_CHECK(make_view(pds, 30.0, W / 2, H / 2, &small, &err) == SL_OK);

    SL_CHECK_MSG(sl_pipeline_needs_prepare(pipe), "%s: nothing prepared yet, but no prepare due", t->name);
    SL_CHECK_MSG(render(pipe, &view, 1, "first frame", t->name) == 1, "%s: the first frame must prepare", t->name);
    SL_CHECK_MSG(!sl_pipeline_needs_prepare(pipe), "%s: a prepare is due after the first frame", t->name);
    SL_CHECK_MSG(render(pipe, &view, 1, "same view", t->name) == 0, "%s: the same view re-prepared", t->name);
    SL_CHECK_MSG(render(pipe, &moved, 1, "camera move", t->name) == 0, "%s: a camera move re-prepared", t->name);
    SL_CHECK_MSG(render(pipe, &small, 1, "smaller view", t->name) == 0, "%s: a view size change re-prepared",
                 t->name);
    SL_CHECK_MSG(render(pipe, &view, 4, "4x MSAA", t->name) == 0, "%s: MSAA re-prepared", t->name);
    SL_CHECK(sl_pipeline_set_technique(pipe, t, &params, &err) == SL_OK);
    SL_CHECK_MSG(render(pipe, &view, 1, "same parameters again", t->name) == 0,
                 "%s: re-selecting it with the same parameters re-prepared", t->name);

    int frame_level = 0, prepared_level = 0, single_choice = 0;
    for (int i = 0; i < t->param_count; i++) {
        const sl_param_def *d = &t->params[i];
        if (d->type == SL_PARAM_ENUM && d->choices[0] && !d->choices[1]) {
            single_choice++; /* an enum of one choice (ribbons' pipeline today) has nothing to move to */
            continue;
        }
        if (!move_param(&params, i, pds, &err)) {
            SL_CHECK_MSG(0, "%s: cannot move parameter '%s': %s", t->name, d->name, err.message);
            continue;
        }
        SL_CHECK(sl_pipeline_set_technique(pipe, t, &params, &err) == SL_OK);
        int want = d->invalidates >= SL_INVALIDATE_PREPARED;
        SL_CHECK_MSG(sl_pipeline_needs_prepare(pipe) == want, "%s: changing '%s': needs_prepare %d", t->name, d->name,
                     sl_pipeline_needs_prepare(pipe));
        int got = render(pipe, &view, 1, d->name, t->name);
        SL_CHECK_MSG(got == want, "%s: changing '%s' (%s) %s prepare", t->name, d->name,
                     want ? "invalidates PREPARED" : "invalidates FRAME only", got ? "re-ran" : "did not re-run");
        got = render(pipe, &moved, 1, d->name, t->name);
        SL_CHECK_MSG(got == 0, "%s: after changing '%s', a camera move re-prepared", t->name, d->name);
        want ? prepared_level++ : frame_level++;
    }
    printf("%s: %d parameters re-render only, %d re-prepare, %d of one choice\n", t->name, frame_level,
           prepared_level, single_choice);
    SL_CHECK_MSG(frame_level > 0, "%s: no frame-level parameter was exercised", t->name);

    /* A new dataset re-prepares (and the old one is destroyed by the pipeline). */
    sl_dataset *ds2 = make_dataset(t->dataset_kinds, &err);
    if (ds2) {
        sl_pipeline_set_dataset(pipe, ds2);
        /* An explicit prepare (the server announces it first); the render after it does not prepare again. */
        sl_frame_stats ps;
        memset(&ps, 0, sizeof ps);
        SL_CHECK(sl_pipeline_needs_prepare(pipe));
        SL_CHECK_MSG(sl_pipeline_prepare(pipe, &ps, &err) == SL_OK && ps.prepared == 1 && ps.prepare_ms >= 0,
                     "%s: prepare of a new dataset: %s", t->name, err.message);
        SL_CHECK_MSG(render(pipe, &view, 1, "new dataset", t->name) == 0, "%s: the render after a prepare prepared",
                     t->name);
    }
    sl_pipeline_destroy(pipe);
}

/* ---- orbit_frames ------------------------------------------------------------ */

static int scene_from(const char *json, sl_scene *s)
{
    sl_err err = {0};
    sl_status st = sl_scene_parse(json, s, &err);
    SL_CHECK_MSG(st == SL_OK, "scene: %s", err.message);
    return st == SL_OK;
}

static int render_scene_frame(sl_pipeline *pipe, const sl_scene *s, int frame, sl_view *view, uint8_t *rgba)
{
    sl_err err = {0};
    sl_frame_stats stats;
    if (sl_scene_view(s, sl_pipeline_dataset(pipe), frame, view, &err) != SL_OK ||
        sl_pipeline_render(pipe, view, 1, &stats, &err) != SL_OK) {
        SL_CHECK_MSG(0, "orbit frame %d: %s", frame, err.message);
        return 0;
    }
    sl_pipeline_read_rgba(pipe, rgba, 1);
    return 1;
}

/* A GL out-of-memory during prepare is an error naming the technique, not a
 * frame drawn from buffers that do not exist; nothing is kept, and the next
 * frame prepares again and succeeds (the error is injected: it cannot be
 * provoked on demand; every technique must check its allocations). */
static void test_prepare_gl_error(sl_gpu *gpu, const sl_technique *t)
{
    sl_err err = {0};
    sl_dataset *ds = make_dataset(t->dataset_kinds, &err);
    sl_pipeline *pipe = NULL;
    if (!ds || sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        SL_CHECK_MSG(0, "%s: setup: %s", t->name, err.message);
        sl_dataset_destroy(ds);
        return;
    }
    sl_pipeline_set_dataset(pipe, ds);
    sl_params params;
    sl_params_init(&params, t->params, t->param_count);
    sl_view view;
    SL_CHECK(sl_pipeline_set_technique(pipe, t, &params, &err) == SL_OK);
    SL_CHECK(make_view(sl_pipeline_dataset(pipe), 30.0, W, H, &view, &err) == SL_OK);
    sl_frame_stats stats;
    sl_gl_inject_error(GL_OUT_OF_MEMORY);
    sl_status st = sl_pipeline_render(pipe, &view, 1, &stats, &err);
    SL_CHECK_MSG(st == SL_ERR_GPU && strstr(err.message, "out of GPU memory") && strstr(err.message, t->name),
                 "%s: an injected GL_OUT_OF_MEMORY in prepare gave status %d: %s", t->name, (int)st, err.message);
    sl_gl_inject_error(GL_NO_ERROR);
    SL_CHECK_MSG(render(pipe, &view, 1, "after the out-of-memory", t->name) == 1,
                 "%s: the frame after a failed prepare must prepare again", t->name);
    sl_pipeline_destroy(pipe);
}

static void test_orbit_frames(sl_gpu *gpu)
{
    const char *orbiting = "{\"dataset\": \"tornado\", \"orbit_frames\": 4, \"width\": 48, \"height\": 32,"
                           " \"camera\": {\"orbit\": {\"azimuth\": 10, \"elevation\": 15, \"distance\": 2}}}";
    const char *turned = "{\"dataset\": \"tornado\", \"width\": 48, \"height\": 32,"
                         " \"camera\": {\"orbit\": {\"azimuth\": 190, \"elevation\": 15, \"distance\": 2}}}";
    sl_scene a, b;
    if (!scene_from(orbiting, &a))
        return;
    if (!scene_from(turned, &b)) {
        sl_scene_deinit(&a);
        return;
    }
    sl_err err = {0};
    sl_dataset *ds = make_dataset(SL_DATASET_LINES, &err);
    sl_pipeline *pipe = NULL;
    SL_CHECK(ds && sl_pipeline_create(gpu, &pipe, &err) == SL_OK);
    if (!ds || !pipe) {
        sl_dataset_destroy(ds);
        sl_scene_deinit(&a);
        sl_scene_deinit(&b);
        return;
    }
    sl_pipeline_set_dataset(pipe, ds);
    const sl_technique *t = sl_technique_find("tubes_mesh");
    sl_params params;
    sl_params_init(&params, t->params, t->param_count);
    SL_CHECK(sl_pipeline_set_technique(pipe, t, &params, &err) == SL_OK);

    size_t bytes = (size_t)a.width * (size_t)a.height * 4;
    uint8_t *f0 = malloc(bytes), *f2 = malloc(bytes), *single = malloc(bytes);
    sl_view v0, v2, vs;
    if (f0 && f2 && single && render_scene_frame(pipe, &a, 0, &v0, f0) && render_scene_frame(pipe, &a, 2, &v2, f2) &&
        render_scene_frame(pipe, &b, 0, &vs, single)) {
        /* Frame 2 of 4 is the camera at azimuth + 180, exactly (360 * 2 / 4 is exact in double). */
        SL_CHECK(memcmp(&v2.camera, &vs.camera, sizeof v2.camera) == 0);
        SL_CHECK_MSG(memcmp(f2, single, bytes) == 0, "frame 2 of orbit_frames 4 differs from azimuth + 180");
        /* Control: the orbit did move the camera. */
        long differ = 0;
        for (size_t i = 0; i < bytes; i++)
            differ += f0[i] != f2[i];
        SL_CHECK_MSG(differ > 100, "frame 0 and frame 2 are (nearly) the same image: %ld bytes differ", differ);
        /* The orbit turns about the bounds centre at a constant distance. */
        SL_CHECK_NEAR(sl_v3_length(sl_v3_sub(v0.camera.eye, v0.camera.target)),
                      sl_v3_length(sl_v3_sub(v2.camera.eye, v2.camera.target)), 1e-9);
    }
    free(f0);
    free(f2);
    free(single);
    sl_pipeline_destroy(pipe);
    sl_scene_deinit(&a);
    sl_scene_deinit(&b);
}

/* ---- sl_pipeline_export ------------------------------------------------------ */

/* A private technique that draws nothing and exports what it was given; its
 * schema also holds the list and 2D types no registered technique uses yet,
 * so test_technique's moves cover them. */
static const sl_param_def exporter_params[] = {
    {"level", SL_PARAM_FLOAT, 0, 10, {1}, NULL, "", "a frame-level number the export reads", SL_INVALIDATE_FRAME},
    {"isovalues", SL_PARAM_VALUES, -1e30, 1e30, {0}, NULL, "data", "a list, [] = auto", SL_INVALIDATE_PREPARED},
    {"curvature_tf", SL_PARAM_TRANSFER_2D, 0, 0, {SL_TF2D_PRESET_RIDGES_VALLEYS}, NULL, "1/voxel", "a 2D function",
     SL_INVALIDATE_FRAME},
};
typedef struct exporter_state {
    int exports;
    double level;
    char path[256];
} exporter_state;

static sl_status exporter_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **state, sl_err *err)
{
    (void)gpu, (void)ds, (void)params;
    *state = calloc(1, sizeof(exporter_state));
    return *state ? SL_OK : sl_err_set(err, SL_ERR_NOMEM, "out of memory");
}

static sl_status exporter_render(void *state, const sl_view *view, const sl_params *params, sl_target *target,
                                 sl_render_stats *stats, sl_err *err)
{
    (void)state, (void)view, (void)params, (void)target, (void)stats, (void)err;
    return SL_OK;
}

static sl_status exporter_export(void *state, const sl_params *params, const char *path, sl_err *err)
{
    exporter_state *s = state;
    if (strstr(path, "unwritable"))
        return sl_err_set(err, SL_ERR_IO, "cannot write %s", path);
    s->exports++;
    s->level = sl_params_float(params, "level");
    snprintf(s->path, sizeof s->path, "%s", path);
    return SL_OK;
}

static exporter_state *last_exporter_state;
static void exporter_release(void *state)
{
    if (state == last_exporter_state)
        last_exporter_state = NULL;
    free(state);
}

static void exporter_stats(const void *state, sl_prepare_stats *out)
{
    last_exporter_state = (exporter_state *)state; /* the test's window on the state */
    *out = (sl_prepare_stats){0};
    sl_prepare_stats_add(out, "exporter.prepared", 1.0);
}

static const sl_technique exporter = {
    .name = "exporter", .description = "test-only: exports what it is given", .dataset_kinds = SL_DATASET_VOLUME,
    .params = exporter_params, .param_count = 3, .prepare = exporter_prepare, .render = exporter_render,
    .release = exporter_release, .prepare_stats = exporter_stats, .export_ext = ".txt",
    .export_geometry = exporter_export,
};

static void test_export(sl_gpu *gpu)
{
    sl_err err = {0};
    sl_pipeline *pipe = NULL;
    sl_dataset *ds = make_dataset(SL_DATASET_VOLUME, &err);
    SL_CHECK(ds && sl_pipeline_create(gpu, &pipe, &err) == SL_OK);
    if (!ds || !pipe) {
        sl_dataset_destroy(ds);
        return;
    }
    SL_CHECK(sl_pipeline_export(pipe, "x.txt", &err) == SL_ERR_INVALID && strstr(err.message, "no technique"));
    sl_pipeline_set_dataset(pipe, ds);
    sl_view view;
    SL_CHECK(make_view(sl_pipeline_dataset(pipe), 30.0, W, H, &view, &err) == SL_OK);

    /* A registered technique without the hook: refused, naming the ones that export. */
    const sl_technique *dvr = sl_technique_find("volume_dvr");
    sl_params params;
    sl_params_init(&params, dvr->params, dvr->param_count);
    SL_CHECK(sl_pipeline_set_technique(pipe, dvr, &params, &err) == SL_OK);
    SL_CHECK(render(pipe, &view, 1, "before export", dvr->name) == 1);
    sl_status st = sl_pipeline_export(pipe, "x.csv", &err);
    SL_CHECK_MSG(st == SL_ERR_UNSUPPORTED && strstr(err.message, "technique 'volume_dvr' exports nothing") &&
                 strstr(err.message, "export is offered by: "), "%d: %s", (int)st, err.message);

    /* The private exporter: nothing prepared yet, then the state, the params and the path. */
    sl_params_init(&params, exporter_params, 3);
    SL_CHECK(sl_pipeline_set_technique(pipe, &exporter, &params, &err) == SL_OK);
    SL_CHECK(sl_pipeline_export(pipe, "x.txt", &err) == SL_ERR_INVALID && strstr(err.message, "render a frame first"));
    sl_frame_stats stats;
    SL_CHECK(sl_pipeline_render(pipe, &view, 1, &stats, &err) == SL_OK && stats.prepared);
    SL_CHECK(stats.prepare_reported && stats.prepare.extra_count == 1 &&
             strcmp(stats.prepare.extra[0].name, "exporter.prepared") == 0 && stats.prepare.extra[0].value == 1.0);
    exporter_state *s = last_exporter_state;
    SL_CHECK(s != NULL);
    SL_CHECK(sl_params_set_numbers(&params, "level", (double[]){2.5}, 1, &err) == SL_OK);
    SL_CHECK(sl_pipeline_set_technique(pipe, &exporter, &params, &err) == SL_OK); /* frame level: no prepare due */
    SL_CHECK_MSG(sl_pipeline_export(pipe, "out/geometry.txt", &err) == SL_OK, "%s", err.message);
    SL_CHECK(s && s->exports == 1 && s->level == 2.5 && strcmp(s->path, "out/geometry.txt") == 0);
    SL_CHECK(sl_pipeline_export(pipe, "unwritable.txt", &err) == SL_ERR_IO && strstr(err.message, "unwritable.txt"));
    SL_CHECK(s && s->exports == 1);
    sl_pipeline_destroy(pipe);
    SL_CHECK(last_exporter_state == NULL); /* released with the pipeline */
}

int main(void)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_status st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err);
    SL_CHECK_MSG(st == SL_OK, "no GL 4.5 context: %s", err.message);
    if (st != SL_OK)
        SL_TEST_END();
    int n = 0;
    const sl_technique *const *list = sl_technique_list(&n);
    SL_CHECK(n > 0);
    for (int i = 0; i < n; i++) {
        test_technique(gpu, list[i]);
        test_prepare_gl_error(gpu, list[i]);
    }
    test_orbit_frames(gpu);
    test_export(gpu);
    test_technique(gpu, &exporter); /* the re-prepare rule for values and transfer_2d */
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
