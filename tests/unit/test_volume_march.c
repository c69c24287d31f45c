/* test_volume_march.c — the shared ray marcher's focus variant (SL_FOCUS 1) on llvmpipe.
 *
 * Drives sl_volume_marcher_draw directly (no technique uses the focus path
 * yet) on a Marschner-Lobb volume whose z spacing is twice its x and y
 * spacing, so a sphere taken in voxel units instead of world units would be
 * an ellipsoid. 64x64 pixels, no MSAA, jitter off, a transfer function with
 * opacity over the whole value range. Checks:
 *  - a focus sphere enclosing the volume and no opaque depth: the
 *    premultiplied output blended over the background equals the plain
 *    (opaque) path: mean |dRGB| <= 1 (0..255) over covered pixels, max <= 2,
 *    the same depth; composite, mip and iso;
 *  - a small sphere in the volume's middle: pixels whose ray misses it (by
 *    2 % of its radius) keep the background and depth 0 exactly, pixels whose
 *    ray passes within half the radius of its centre are covered;
 *  - an opaque depth plane in front of the volume on the left half (target
 *    colour and depth as marks there would leave them), none on the right:
 *    left pixels unchanged bit for bit, right pixels as over any colour;
 *  - an opaque plane through the middle: the depth written is the plain
 *    path's where alpha reaches 0.5 in front of it, the plane's behind it.
 * Needs a GL 4.5 context (never skipped: no context is a failure).
 * Single-threaded (render thread).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "sl_test.h"
#include "volume/sl_volume.h"

enum { W = 64, H = 64, N = W * H };

static const float background[4] = {0.1f, 0.1f, 0.12f, 1.0f};

typedef struct fixture {
    sl_dataset *ds;
    sl_volume_geometry geom;
    sl_volume_texture volume;
    sl_volume_bricks bricks;
    sl_volume_marcher marcher;
    sl_target target;
    sl_view view;
    sl_transfer_function tf;
    sl_vec3 centre;          /* world: the volume box's centre */
    double half_diagonal;    /* world */
} fixture;

typedef struct frame {
    uint8_t rgba[4 * N];     /* rows top-down */
    float depth[N];
} frame;

static sl_status fixture_init(fixture *f, sl_err *err)
{
    memset(f, 0, sizeof *f);
    sl_status st = sl_generate_json("{\"generator\":\"marschner_lobb\",\"size\":24}", &f->ds, err);
    if (st != SL_OK)
        return st;
    f->ds->volume.spacing[2] = 2.0 * f->ds->volume.spacing[0];
    if ((st = sl_dataset_finish_volume(f->ds, err)) != SL_OK)
        return st;
    sl_volume_geometry_init(f->ds, &f->geom);
    if ((st = sl_volume_texture_create(&f->ds->volume, &f->volume, err)) != SL_OK ||
        (st = sl_volume_bricks_create(&f->ds->volume, &f->bricks, err)) != SL_OK ||
        (st = sl_volume_marcher_init(&f->marcher, &f->ds->volume, err)) != SL_OK ||
        (st = sl_target_init(&f->target, W, H, 0, err)) != SL_OK)
        return st;
    f->centre = sl_v3_scale(sl_v3_add(f->ds->bounds_min, f->ds->bounds_max), 0.5);
    f->half_diagonal = 0.5 * sl_v3_length(sl_v3_sub(f->ds->bounds_max, f->ds->bounds_min));
    f->view.width = W;
    f->view.height = H;
    memcpy(f->view.background, background, sizeof background);
    f->view.origin = f->ds->origin;
    sl_orbit orbit = {30.0, 20.0, 2.0, 60.0}; /* wide: rays far from F test the depth conversion */
    if ((st = sl_camera_from_orbit(&orbit, f->ds->bounds_min, f->ds->bounds_max, &f->view.camera, err)) != SL_OK ||
        (st = sl_view_init(&f->view, sl_dataset_radius(f->ds), err)) != SL_OK)
        return st;
    const double points[3][5] = {{0.0, 1.0, 0.5, 0.2, 0.15}, {0.5, 0.2, 1.0, 0.4, 0.3}, {1.0, 0.2, 0.4, 1.0, 0.5}};
    f->tf.colormap = -1;
    f->tf.count = 3;
    memcpy(f->tf.point, points, sizeof points);
    return SL_OK;
}

static void fixture_deinit(fixture *f)
{
    sl_target_deinit(&f->target);
    sl_volume_marcher_deinit(&f->marcher);
    sl_volume_bricks_destroy(&f->bricks);
    sl_volume_texture_destroy(&f->volume);
    sl_dataset_destroy(f->ds);
}

/* Draws d into the target as it stands (the caller has begun it) and reads it back. */
static int draw(fixture *f, const sl_volume_march_desc *d, frame *out)
{
    sl_render_stats stats = {0};
    sl_err err = {0};
    sl_status st = sl_volume_marcher_draw(&f->marcher, &f->volume, &f->bricks, &f->geom, &f->view, d, &stats, &err);
    SL_CHECK_MSG(st == SL_OK, "draw: %s", err.message);
    sl_target_read_rgba(&f->target, out->rgba, 1);
    sl_target_read_depth(&f->target, out->depth);
    return st == SL_OK;
}

/* The RGBA8 a clear to colour leaves (the GL's rounding, not ours). */
static void cleared_rgba(fixture *f, const float colour[4], uint8_t out[4])
{
    static frame fr;
    sl_target_begin(&f->target, colour);
    sl_target_read_rgba(&f->target, fr.rgba, 1);
    memcpy(out, fr.rgba, 4);
}

static int is_background(const frame *fr, int i, const uint8_t bg[4])
{
    return memcmp(fr->rgba + 4 * i, bg, 4) == 0;
}

/* The distance from the centre to the ray through pixel i (world). */
static double ray_centre_distance(const fixture *f, int i, sl_vec3 centre)
{
    sl_vec3 d = sl_view_ray_dir(&f->view, i % W, i / W);
    sl_vec3 o = sl_v3_sub(centre, f->view.camera.eye);
    double along = sl_v3_dot(o, d);
    return sl_v3_length(sl_v3_sub(o, sl_v3_scale(d, along)));
}

static void check_enclosing_sphere(fixture *f, sl_volume_march_mode mode, const uint8_t bg[4])
{
    static frame plain, focus;
    sl_volume_march_desc d = {.mode = mode, .tf = &f->tf, .step = 0.5, .iso = 0.5, .shading = 1};
    sl_target_begin(&f->target, background);
    if (!draw(f, &d, &plain))
        return;
    d.focus.radius = 1.5 * f->half_diagonal;
    d.focus.centre[0] = f->centre.x;
    d.focus.centre[1] = f->centre.y;
    d.focus.centre[2] = f->centre.z;
    sl_target_begin(&f->target, background);
    if (!draw(f, &d, &focus))
        return;
    double sum = 0.0, depth_err = 0.0;
    int covered = 0, max = 0;
    for (int i = 0; i < N; i++) {
        if (is_background(&plain, i, bg) && is_background(&focus, i, bg))
            continue;
        covered++;
        for (int c = 0; c < 3; c++) {
            int e = abs((int)plain.rgba[4 * i + c] - (int)focus.rgba[4 * i + c]);
            sum += e;
            max = e > max ? e : max;
        }
        depth_err = fmax(depth_err, fabs((double)plain.depth[i] - focus.depth[i]));
    }
    double mean = covered ? sum / (3.0 * covered) : 0.0;
    printf("enclosing sphere, mode %d: %d covered pixels, mean |dRGB| %.4f, max %d, max |ddepth| %.3g\n", (int)mode,
           covered, mean, max, depth_err);
    SL_CHECK_MSG(covered > N / 10, "mode %d: only %d covered pixels", (int)mode, covered);
    SL_CHECK_MSG(mean <= 1.0 && max <= 2, "mode %d: mean %.4f, max %d", (int)mode, mean, max);
    SL_CHECK_MSG(depth_err <= 1e-6, "mode %d: depth differs by %.3g", (int)mode, depth_err);
}

static void check_small_sphere(fixture *f, const uint8_t bg[4])
{
    static frame fr;
    double radius = 0.3 * f->half_diagonal;
    sl_volume_march_desc d = {.tf = &f->tf, .step = 0.5,
                              .focus = {.centre = {f->centre.x, f->centre.y, f->centre.z}, .radius = radius}};
    sl_target_begin(&f->target, background);
    if (!draw(f, &d, &fr))
        return;
    int outside = 0, outside_bad = 0, inside = 0, inside_bad = 0;
    for (int i = 0; i < N; i++) {
        double dist = ray_centre_distance(f, i, f->centre);
        if (dist > 1.02 * radius) {
            outside++;
            outside_bad += !is_background(&fr, i, bg) || fr.depth[i] != 0.0f;
        } else if (dist < 0.5 * radius) {
            inside++;
            inside_bad += is_background(&fr, i, bg);
        }
    }
    printf("small sphere: %d pixels miss it (%d not background), %d through its middle (%d background)\n", outside,
           outside_bad, inside, inside_bad);
    SL_CHECK(outside > N / 2 && inside > 20);
    SL_CHECK_MSG(outside_bad == 0, "%d pixels outside the sphere were drawn", outside_bad);
    SL_CHECK_MSG(inside_bad == 0, "%d pixels through the sphere's middle were not drawn", inside_bad);
}

static void check_opaque_plane(fixture *f)
{
    static frame plain, before, fr;
    static float marks[N];   /* GL rows: bottom-up */
    const float mark_colour[4] = {0.8f, 0.3f, 0.2f, 1.0f};
    uint8_t mark_rgba[4];
    cleared_rgba(f, mark_colour, mark_rgba);
    /* In front of the whole volume: eye distance along F below its nearest point. */
    double z_front = sl_v3_dot(sl_v3_sub(f->centre, f->view.camera.eye), f->view.forward) - 1.2 * f->half_diagonal;
    float front = (float)(f->view.near_plane / z_front);
    SL_CHECK(z_front > f->view.near_plane);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            marks[y * W + x] = x < W / 2 ? front : 0.0f;
    GLuint tex = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, GL_DEPTH_COMPONENT32F, W, H);
    glTextureSubImage2D(tex, 0, 0, 0, W, H, GL_DEPTH_COMPONENT, GL_FLOAT, marks);

    /* The plain path composites over the view's background: the marks' colour here. */
    memcpy(f->view.background, mark_colour, sizeof mark_colour);
    sl_volume_march_desc d = {.tf = &f->tf, .step = 0.5};
    sl_target_begin(&f->target, mark_colour);
    if (!draw(f, &d, &plain))
        goto done;
    d.focus.radius = 1.5 * f->half_diagonal;
    d.focus.centre[0] = f->centre.x;
    d.focus.centre[1] = f->centre.y;
    d.focus.centre[2] = f->centre.z;
    d.focus.opaque_depth_tex = tex;
    /* The target as marks would leave it: their colour everywhere, their depth on the left. */
    sl_target_begin(&f->target, mark_colour);
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, W / 2, H);
    glClearNamedFramebufferfv(f->target.fbo, GL_DEPTH, 0, &front);
    glDisable(GL_SCISSOR_TEST);
    /* (llvmpipe's depth clear does not keep `front` to the last bit: compare with the target itself.) */
    sl_target_read_rgba(&f->target, before.rgba, 1);
    sl_target_read_depth(&f->target, before.depth);
    if (!draw(f, &d, &fr))
        goto done;
    int left_changed = 0, left_covered = 0, left_unmarked = 0, right_covered = 0, right_mismatch = 0;
    double right_sum = 0.0;
    for (int i = 0; i < N; i++) {
        int x = i % W;
        if (x < W / 2) {
            left_covered += !is_background(&plain, i, mark_rgba);
            left_unmarked += !(fabsf(before.depth[i] - front) <= 1e-4f * front);
            left_changed += memcmp(fr.rgba + 4 * i, before.rgba + 4 * i, 4) != 0 ||
                            memcmp(&fr.depth[i], &before.depth[i], sizeof fr.depth[i]) != 0;
        } else if (!is_background(&plain, i, mark_rgba)) {
            right_covered++;
            for (int c = 0; c < 3; c++)
                right_sum += abs((int)plain.rgba[4 * i + c] - (int)fr.rgba[4 * i + c]);
            right_mismatch += fabsf(plain.depth[i] - fr.depth[i]) > 1e-6f;
        }
    }
    double right_mean = right_covered ? right_sum / (3.0 * right_covered) : 0.0;
    printf("opaque plane: %d left pixels changed (%d covered without the plane); right: %d covered, "
           "mean |dRGB| %.4f against the plain path, %d depths differ\n",
           left_changed, left_covered, right_covered, right_mean, right_mismatch);
    SL_CHECK(left_covered > N / 20 && left_unmarked == 0);
    SL_CHECK_MSG(left_changed == 0, "%d pixels behind the opaque plane's depth changed", left_changed);
    SL_CHECK(right_covered > N / 20);
    SL_CHECK_MSG(right_mean <= 1.0 && right_mismatch == 0, "right half: mean %.4f, %d depths", right_mean,
                 right_mismatch);
done:
    memcpy(f->view.background, background, sizeof background);
    glDeleteTextures(1, &tex);
}

/* An opaque plane through the volume's centre (normal F): where the plain
 * composite's depth (alpha > 0.5) lies more than two steps in front of it,
 * the focus pass writes that same depth; where it lies more than two steps
 * behind it (or nowhere), the ray ends at the plane before alpha reaches 0.5:
 * the depth written is the plane's (max of mark and marcher; or the pass
 * discards, where nothing is composited in front of it), and where the plain path reaches 0.5 behind it the
 * colour is not the plain path's. A ray cut at the plane's distance along F
 * instead of along the ray ends up to 1/cos - 1 too early and fails the
 * first class at the image's edges. */
static void check_mid_plane(fixture *f, const uint8_t bg[4])
{
    static frame plain, fr;
    static float marks[N];
    double z_mid = sl_v3_dot(sl_v3_sub(f->centre, f->view.camera.eye), f->view.forward);
    float mid = (float)(f->view.near_plane / z_mid);
    for (int i = 0; i < N; i++)
        marks[i] = mid;
    GLuint tex = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, GL_DEPTH_COMPONENT32F, W, H);
    glTextureSubImage2D(tex, 0, 0, 0, W, H, GL_DEPTH_COMPONENT, GL_FLOAT, marks);
    sl_volume_march_desc d = {.tf = &f->tf, .step = 0.5};
    sl_target_begin(&f->target, background);
    if (!draw(f, &d, &plain))
        goto done;
    d.focus = (sl_volume_march_focus){.centre = {f->centre.x, f->centre.y, f->centre.z},
                                      .radius = 1.5 * f->half_diagonal, .opaque_depth_tex = tex};
    /* A target depth that neither the plane nor "nothing" (0) has: where the
     * pass discards it stays, everywhere else the pass wrote its own. */
    static frame before;
    const float sentinel = 0.5f * mid;
    sl_target_begin(&f->target, background);
    glClearNamedFramebufferfv(f->target.fbo, GL_DEPTH, 0, &sentinel);
    sl_target_read_rgba(&f->target, before.rgba, 1);
    sl_target_read_depth(&f->target, before.depth);
    if (!draw(f, &d, &fr))
        goto done;
    double margin = 2.0 * 0.5 * f->geom.min_spacing;
    int in_front = 0, front_bad = 0, behind = 0, behind_bad = 0, behind_hit = 0, behind_same = 0;
    for (int i = 0; i < N; i++) {
        if (is_background(&plain, i, bg))
            continue;
        double z = plain.depth[i] > 0.0f ? f->view.near_plane / plain.depth[i] : INFINITY;
        if (z < z_mid - margin) {
            in_front++;
            front_bad += !(fabsf(fr.depth[i] - plain.depth[i]) <= 1e-6f * plain.depth[i]);
        } else if (z > z_mid + margin) {
            behind++;
            int discarded = fr.depth[i] == before.depth[i] && memcmp(fr.rgba + 4 * i, before.rgba + 4 * i, 4) == 0;
            behind_bad += fr.depth[i] != mid && !discarded;
            if (plain.depth[i] > 0.0f) { /* opacity 0.5 behind the plane: the cut must show */
                behind_hit++;
                behind_same += memcmp(fr.rgba + 4 * i, plain.rgba + 4 * i, 3) == 0;
            }
        }
    }
    printf("mid plane: %d pixels reach alpha 0.5 in front of it (%d wrong depth), %d behind (%d wrong depth; "
           "%d of the %d reaching it coloured as without the plane)\n", in_front, front_bad, behind, behind_bad,
           behind_same, behind_hit);
    SL_CHECK(in_front > 50 && behind_hit > 50);
    SL_CHECK_MSG(behind_same == 0, "%d of %d pixels behind the plane unchanged by it", behind_same, behind_hit);
    SL_CHECK_MSG(front_bad == 0 && behind_bad == 0, "%d in front, %d behind with the wrong depth", front_bad,
                 behind_bad);
done:
    glDeleteTextures(1, &tex);
}

int main(void)
{
    sl_gpu *gpu = NULL;
    sl_err err = {0};
    sl_status st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err);
    SL_CHECK_MSG(st == SL_OK, "no GL 4.5 context: %s", err.message);
    if (st != SL_OK)
        SL_TEST_END();
    static fixture f;
    st = fixture_init(&f, &err);
    SL_CHECK_MSG(st == SL_OK, "setup: %s", err.message);
    if (st == SL_OK) {
        uint8_t bg[4];
        cleared_rgba(&f, background, bg);
        check_enclosing_sphere(&f, SL_VOLUME_MARCH_COMPOSITE, bg);
        check_enclosing_sphere(&f, SL_VOLUME_MARCH_MIP, bg);
        check_enclosing_sphere(&f, SL_VOLUME_MARCH_ISO, bg);
        check_small_sphere(&f, bg);
        check_opaque_plane(&f);
        check_mid_plane(&f, bg);
    }
    fixture_deinit(&f);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
