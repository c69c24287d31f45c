/* test_tubes_backend.c — the backend rule (core/sl_backend.h) and tubes' two executions.
 *
 * The rule on its own: auto picks the CPU execution on a software device when it is built
 * and GL otherwise; an explicit CPU choice in a build without it is an error that names
 * the package. Then `tubes` through the pipeline on this machine's GL device: the backend
 * each choice draws with (stats name it), and with Embree built: the BVH is built once in
 * the prepare and not again for camera moves, colour or light changes, but again when the
 * radius changes (rebuild_ms); SIGHTLINE_THREADS=2 traces on 2 workers; the GL and the
 * Embree frame of the same scene agree over the covered pixels (mean colour difference
 * <= 2 of 255, distance <= 1e-3 x radius on pixels both hit, coverage within 1 %); and
 * they compose the same with GL: lr_volume's streamline tubes inside its volume (the rays
 * end at the tubes' depth) with tube_backend gl and embree, mean <= 2 of 255 over the
 * pixels either frame covers.
 */
#include <stdlib.h>
#include <string.h>

#include "core/sl_backend.h"
#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "pipeline/sl_pipeline.h"
#include "sl_test.h"

enum { W = 160, H = 120 };

static void test_rule(void)
{
    sl_backend_cpu built = {.name = "embree", .built = 1, .missing = "Debian libembree-dev (Embree 3.13)"};
    sl_backend_cpu absent = {.name = "embree", .built = 0, .missing = "Debian libembree-dev (Embree 3.13)"};
    sl_backend b = SL_BACKEND_GL;
    sl_err err = {0};
    SL_CHECK(sl_backend_decide("tubes", SL_BACKEND_AUTO, 1, &built, &b, &err) == SL_OK && b == SL_BACKEND_CPU);
    SL_CHECK(sl_backend_decide("tubes", SL_BACKEND_AUTO, 0, &built, &b, &err) == SL_OK && b == SL_BACKEND_GL);
    SL_CHECK(sl_backend_decide("tubes", SL_BACKEND_AUTO, 1, &absent, &b, &err) == SL_OK && b == SL_BACKEND_GL);
    SL_CHECK(sl_backend_decide("tubes", SL_BACKEND_CHOICE_GL, 1, &built, &b, &err) == SL_OK && b == SL_BACKEND_GL);
    SL_CHECK(sl_backend_decide("tubes", SL_BACKEND_CHOICE_CPU, 0, &built, &b, &err) == SL_OK && b == SL_BACKEND_CPU);
    b = SL_BACKEND_GL;
    SL_CHECK(sl_backend_decide("tubes", SL_BACKEND_CHOICE_CPU, 1, &absent, &b, &err) == SL_ERR_UNSUPPORTED);
    SL_CHECK_MSG(strstr(err.message, "libembree-dev") && strstr(err.message, "backend = embree"), "%s", err.message);
    SL_CHECK(b == SL_BACKEND_GL); /* untouched on failure */
    SL_CHECK(sl_backend_decide("tubes", 7, 1, &built, &b, &err) == SL_ERR_INVALID);
    SL_CHECK(!strcmp(sl_backend_name(SL_BACKEND_CPU, &built), "embree"));
    SL_CHECK(!strcmp(sl_backend_name(SL_BACKEND_GL, &built), "gl"));
}

static sl_status make_view(const sl_dataset *ds, double azimuth, sl_view *view, sl_err *err)
{
    memset(view, 0, sizeof *view);
    view->width = W;
    view->height = H;
    view->origin = ds->origin;
    sl_orbit orbit = {azimuth, 20.0, 2.0, 45.0};
    sl_status st = sl_camera_from_orbit(&orbit, ds->bounds_min, ds->bounds_max, &view->camera, err);
    return st == SL_OK ? sl_view_init(view, sl_dataset_radius(ds), err) : st;
}

typedef struct frame {
    uint8_t rgba[W * H * 4];
    float distance[W * H];
    sl_frame_stats stats;
} frame;

/* One frame of tubes with `backend` (and radius when > 0) at azimuth; SL_OK or the error. */
static sl_status render(sl_pipeline *pipe, const sl_technique *t, const char *backend, double radius,
                        const char *colormap, double azimuth, frame *out, sl_err *err)
{
    sl_params params;
    sl_params_init(&params, t->params, t->param_count);
    sl_status st = sl_params_set_choice(&params, "backend", backend, err);
    if (st == SL_OK && radius > 0)
        st = sl_params_set_numbers(&params, "radius", &radius, 1, err);
    if (st == SL_OK && colormap)
        st = sl_params_set_choice(&params, "colormap", colormap, err);
    if (st == SL_OK)
        st = sl_pipeline_set_technique(pipe, t, &params, err);
    sl_view view;
    if (st == SL_OK)
        st = make_view(sl_pipeline_dataset(pipe), azimuth, &view, err);
    if (st == SL_OK)
        st = sl_pipeline_render(pipe, &view, 1, &out->stats, err);
    if (st == SL_OK) {
        sl_pipeline_read_rgba(pipe, out->rgba, 1);
        sl_pipeline_read_distance(pipe, &view, out->distance);
    }
    return st;
}

static void test_tubes(sl_gpu *gpu)
{
    sl_err err = {0};
    const sl_technique *t = sl_technique_find("tubes");
    SL_CHECK(t && t->backend_cpu);
    if (!t || !t->backend_cpu)
        return;
    sl_backend_cpu cpu;
    t->backend_cpu(&cpu);
    sl_dataset *ds = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"tornado\",\"lines\":40,\"points\":60,\"seed\":2}", &ds, &err) == SL_OK);
    sl_pipeline *pipe = NULL;
    SL_CHECK(sl_pipeline_create(gpu, &pipe, &err) == SL_OK);
    if (!ds || !pipe) {
        sl_dataset_destroy(ds);
        sl_pipeline_destroy(pipe);
        return;
    }
    sl_pipeline_set_dataset(pipe, ds);
    frame *gl = calloc(1, sizeof *gl), *cp = calloc(1, sizeof *cp);
    const double radius = 0.02;
    SL_CHECK(render(pipe, t, "auto", radius, NULL, 30, cp, &err) == SL_OK);
    const char *want_auto = sl_gpu_is_software(gpu) && cpu.built ? "embree" : "gl";
    SL_CHECK_MSG(cp->stats.render.backend && !strcmp(cp->stats.render.backend, want_auto), "auto drew with %s, want %s",
                 cp->stats.render.backend ? cp->stats.render.backend : "(none)", want_auto);
    SL_CHECK(render(pipe, t, "gl", radius, NULL, 30, gl, &err) == SL_OK);
    SL_CHECK(gl->stats.render.backend && !strcmp(gl->stats.render.backend, "gl"));
    sl_status st = render(pipe, t, "embree", radius, NULL, 30, cp, &err);
    if (!cpu.built) {
        SL_CHECK_MSG(st == SL_ERR_UNSUPPORTED && strstr(err.message, "libembree-dev"), "%s", err.message);
        printf("this build has no Embree: backend = embree refused (%s)\n", err.message);
    } else {
        SL_CHECK_MSG(st == SL_OK, "%s", err.message);
        SL_CHECK(cp->stats.render.backend && !strcmp(cp->stats.render.backend, "embree"));
        SL_CHECK(cp->stats.prepared);
        /* the BVH of the prepare is in its stats, with its size */
        double bvh_ms = -1, bvh_bytes = -1;
        for (int i = 0; i < cp->stats.prepare.extra_count; i++) {
            if (!strcmp(cp->stats.prepare.extra[i].name, "embree.bvh_ms"))
                bvh_ms = cp->stats.prepare.extra[i].value;
            if (!strcmp(cp->stats.prepare.extra[i].name, "embree.bvh_bytes"))
                bvh_bytes = cp->stats.prepare.extra[i].value;
        }
        SL_CHECK_MSG(bvh_ms >= 0 && bvh_bytes > 0, "bvh_ms %g bvh_bytes %g", bvh_ms, bvh_bytes);
        /* same picture: colour over the covered pixels, distance where both hit */
        double sum = 0, worst = 0;
        long covered = 0, both = 0, one = 0;
        for (int p = 0; p < W * H; p++) {
            int a = gl->distance[p] > 0, b = cp->distance[p] > 0;
            if (!a && !b)
                continue;
            covered++;
            for (int c = 0; c < 3; c++)
                sum += abs((int)gl->rgba[4 * p + c] - (int)cp->rgba[4 * p + c]) / 3.0;
            if (a && b) {
                both++;
                double e = fabs(gl->distance[p] - cp->distance[p]) / radius;
                worst = e > worst ? e : worst;
            } else {
                one++;
            }
        }
        double mean = covered ? sum / covered : 0;
        printf("gl vs embree: %ld covered, %ld both hit, %ld one only; mean colour %.3f/255; max distance %.2e r\n",
               covered, both, one, mean, worst);
        SL_CHECK(covered > W * H / 50);
        SL_CHECK_MSG(mean <= 2.0, "mean colour difference %.3f", mean);
        SL_CHECK_MSG(one <= covered / 100, "%ld of %ld pixels hit by one backend only", one, covered);
        /* rims: a pixel's depth there is as sensitive as its coverage; allow them, as the accuracy tests do */
        long far = 0;
        for (int p = 0; p < W * H; p++)
            if (gl->distance[p] > 0 && cp->distance[p] > 0 && fabs(gl->distance[p] - cp->distance[p]) > 1e-3 * radius)
                far++;
        SL_CHECK_MSG(far <= both / 100, "%ld of %ld pixels differ in distance by more than 1e-3 r", far, both);

        /* camera, colour and light changes do not rebuild; a radius change does */
        SL_CHECK(render(pipe, t, "embree", radius, NULL, 75, cp, &err) == SL_OK);
        SL_CHECK(!cp->stats.prepared && cp->stats.render.rebuild_ms == 0.0);
        SL_CHECK(render(pipe, t, "embree", radius, "magma", 75, cp, &err) == SL_OK);
        SL_CHECK(!cp->stats.prepared && cp->stats.render.rebuild_ms == 0.0);
        SL_CHECK(render(pipe, t, "embree", 1.5 * radius, "magma", 75, cp, &err) == SL_OK);
        SL_CHECK_MSG(!cp->stats.prepared && cp->stats.render.rebuild_ms > 0.0, "prepared %d rebuild_ms %g",
                     cp->stats.prepared, cp->stats.render.rebuild_ms);
        SL_CHECK(render(pipe, t, "embree", 1.5 * radius, "magma", 120, cp, &err) == SL_OK);
        SL_CHECK(cp->stats.render.rebuild_ms == 0.0);
        /* all the workers asked for trace tiles (SIGHTLINE_THREADS=2 set in main) */
        SL_CHECK_MSG(cp->stats.render.threads == 2, "threads %d", cp->stats.render.threads);
        SL_CHECK(cp->stats.render.primitives == (double)W * H);
    }
    free(gl);
    free(cp);
    sl_pipeline_destroy(pipe);
}

/* lr_volume with streamlines: the tubes drawn by either backend, the volume after them. */
static void test_composes(sl_gpu *gpu)
{
    sl_err err = {0};
    const sl_technique *t = sl_technique_find("lr_volume");
    const sl_technique *tubes = sl_technique_find("tubes");
    sl_backend_cpu cpu;
    tubes->backend_cpu(&cpu);
    if (!t || !cpu.built)
        return;
    sl_dataset *ds = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"lr_field\",\"field\":\"sphere\",\"degree\":2,\"cells\":4,"
                              "\"components\":\"vector\"}",
                              &ds, &err) == SL_OK);
    sl_pipeline *pipe = NULL;
    SL_CHECK(sl_pipeline_create(gpu, &pipe, &err) == SL_OK);
    if (!ds || !pipe) {
        sl_dataset_destroy(ds);
        sl_pipeline_destroy(pipe);
        return;
    }
    sl_pipeline_set_dataset(pipe, ds);
    uint8_t *img[2] = {malloc(W * H * 4), malloc(W * H * 4)};
    const char *names[2] = {"gl", "embree"};
    for (int k = 0; k < 2; k++) {
        sl_params params;
        sl_params_init(&params, t->params, t->param_count);
        double on = 1.0, radius = 0.01;
        SL_CHECK(sl_params_set_numbers(&params, "streamlines", &on, 1, &err) == SL_OK);
        SL_CHECK(sl_params_set_numbers(&params, "tube_radius", &radius, 1, &err) == SL_OK);
        SL_CHECK(sl_params_set_choice(&params, "tube_backend", names[k], &err) == SL_OK);
        SL_CHECK(sl_pipeline_set_technique(pipe, t, &params, &err) == SL_OK);
        sl_view view;
        sl_frame_stats fs;
        SL_CHECK(make_view(ds, 30, &view, &err) == SL_OK);
        sl_status st = sl_pipeline_render(pipe, &view, 1, &fs, &err);
        SL_CHECK_MSG(st == SL_OK, "%s", err.message);
        sl_pipeline_read_rgba(pipe, img[k], 1);
    }
    double sum = 0;
    long covered = 0;
    for (int p = 0; p < W * H; p++) {
        int bg0 = !img[0][4 * p] && !img[0][4 * p + 1] && !img[0][4 * p + 2];
        int bg1 = !img[1][4 * p] && !img[1][4 * p + 1] && !img[1][4 * p + 2];
        if (bg0 && bg1)
            continue;
        covered++;
        for (int c = 0; c < 3; c++)
            sum += abs((int)img[0][4 * p + c] - (int)img[1][4 * p + c]) / 3.0;
    }
    double mean = covered ? sum / covered : 0;
    printf("lr_volume streamlines, tube_backend gl vs embree: %ld covered, mean %.3f/255\n", covered, mean);
    SL_CHECK(covered > W * H / 20);
    SL_CHECK_MSG(mean <= 2.0, "mean %.3f", mean);
    free(img[0]);
    free(img[1]);
    sl_pipeline_destroy(pipe);
}

int main(void)
{
    setenv("SIGHTLINE_THREADS", "2", 1);
    test_rule();
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_status st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err);
    SL_CHECK_MSG(st == SL_OK, "no GL 4.5 context: %s", err.message);
    if (st == SL_OK) {
        test_tubes(gpu);
        test_composes(gpu);
        sl_gpu_destroy(gpu);
    }
    SL_TEST_END();
}
