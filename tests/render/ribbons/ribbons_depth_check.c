/* ribbons_depth_check.c — a rendered straight ribbon's depth against the analytic elliptic profile.
 *
 * usage: ribbons-depth-check --scene S.json --depth D.pfm --axis X0,Y0,Z0,X1,Y1,Z1 --normal NX,NY,NZ
 *            --radius R --width-ratio W --sides N [--head-on C] [--eps E] [--margin-px M]
 *
 * The scene gives the camera (eye/target/up form; an orbit needs the data's
 * bounds and is refused) and the size; the depth is sightline-render's
 * --depth of it. The analytic ribbon runs from X0 to X1 with face normal
 * NX.. (projected off the axis; the thin semi-axis R W, the wide one R), as
 * the scene's data-normal frame draws it. Every pixel is judged by
 * ribbons_depth_error_measure (tests/support/ribbons_depth_error.h): the
 * depth within [t_ref - E, t_ref + ribbons_ref_polygon_bound + E] wherever
 * the bound is finite (E default 1e-4 world), no pixel missed inside the
 * polygon's incircle profile and none drawn outside the profile (margin M
 * pixels, default 1/64). Prints one summary line (max error / r, mean, max
 * head-on (cos >= C, default 0.9), max error / bound, counts).
 * exit: 0 pass, 1 a limit failed (a "FAIL:" line names the first pixel),
 * 2 bad input. Any thread; no GL.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_load.h"
#include "image/sl_image.h"
#include "ribbons_depth_error.h"
#include "sl_scene.h"

typedef struct options {
    const char *scene, *depth;
    double axis[6], normal[3], radius, width_ratio, head_on, eps, margin_px;
    int sides, have_axis, have_normal;
} options;

static int usage(void)
{
    fprintf(stderr, "usage: ribbons-depth-check --scene S.json --depth D.pfm --axis X0,Y0,Z0,X1,Y1,Z1 "
                    "--normal NX,NY,NZ --radius R --width-ratio W --sides N [--head-on C] [--eps E] "
                    "[--margin-px M]\n");
    return 2;
}

/* Exactly n comma-separated numbers: 1, else 0. */
static int parse_list(const char *text, double *out, int n)
{
    const char *p = text;
    for (int k = 0; k < n; k++) {
        char *end;
        out[k] = strtod(p, &end);
        if (end == p || !isfinite(out[k]))
            return 0;
        p = end;
        if (k + 1 < n && *p++ != ',')
            return 0;
    }
    return *p == 0;
}

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.head_on = 0.9, .eps = 1e-4, .margin_px = 1.0 / 64.0};
    for (int i = 1; i + 1 < argc; i += 2) {
        const char *a = argv[i], *v = argv[i + 1];
        int ok = 1;
        if (strcmp(a, "--scene") == 0) o->scene = v;
        else if (strcmp(a, "--depth") == 0) o->depth = v;
        else if (strcmp(a, "--axis") == 0) ok = o->have_axis = parse_list(v, o->axis, 6);
        else if (strcmp(a, "--normal") == 0) ok = o->have_normal = parse_list(v, o->normal, 3);
        else if (strcmp(a, "--radius") == 0) ok = parse_list(v, &o->radius, 1) && o->radius > 0.0;
        else if (strcmp(a, "--width-ratio") == 0) ok = parse_list(v, &o->width_ratio, 1) && o->width_ratio > 0.0;
        else if (strcmp(a, "--head-on") == 0) ok = parse_list(v, &o->head_on, 1);
        else if (strcmp(a, "--eps") == 0) ok = parse_list(v, &o->eps, 1) && o->eps >= 0.0;
        else if (strcmp(a, "--margin-px") == 0) ok = parse_list(v, &o->margin_px, 1) && o->margin_px >= 0.0;
        else if (strcmp(a, "--sides") == 0) {
            double n = 0.0;
            ok = parse_list(v, &n, 1) && n >= 3.0 && n <= 1024.0 && n == floor(n);
            o->sides = (int)n;
        } else
            ok = 0;
        if (!ok) {
            fprintf(stderr, "ribbons-depth-check: bad option %s %s\n", a, v);
            return 0;
        }
    }
    if (argc % 2 == 0 || !o->scene || !o->depth || !o->have_axis || !o->have_normal || !(o->radius > 0.0) ||
        !(o->width_ratio > 0.0) || !o->sides)
        return 0;
    return 1;
}

/* The analytic segment of the options: 1, or 0 when axis or normal are degenerate. */
static int segment_of(const options *o, ribbons_ref_segment *seg)
{
    double len = 0.0, nt = 0.0, nl = 0.0;
    memset(seg, 0, sizeof *seg);
    for (int k = 0; k < 3; k++) {
        seg->x0[k] = 0.5 * (o->axis[k] + o->axis[3 + k]);
        seg->t[k] = o->axis[3 + k] - o->axis[k];
        len += seg->t[k] * seg->t[k];
    }
    len = sqrt(len);
    if (!(len > 0.0))
        return 0;
    for (int k = 0; k < 3; k++) {
        seg->t[k] /= len;
        nt += o->normal[k] * seg->t[k];
    }
    for (int k = 0; k < 3; k++) {
        seg->n[k] = o->normal[k] - nt * seg->t[k];
        nl += seg->n[k] * seg->n[k];
    }
    nl = sqrt(nl);
    if (!(nl > 1e-9))
        return 0;
    for (int k = 0; k < 3; k++)
        seg->n[k] /= nl;
    /* b = t x n, so that n x b = t. */
    seg->b[0] = seg->t[1] * seg->n[2] - seg->t[2] * seg->n[1];
    seg->b[1] = seg->t[2] * seg->n[0] - seg->t[0] * seg->n[2];
    seg->b[2] = seg->t[0] * seg->n[1] - seg->t[1] * seg->n[0];
    seg->r = o->radius;
    seg->w = o->width_ratio;
    seg->half_len = 0.5 * len;
    return 1;
}

/* The scene's camera (eye/target/up form) and size: 1, or 0 with a message. */
static int camera_of(const char *path, ref_camera *cam)
{
    sl_err err = {0};
    uint8_t *text = NULL;
    size_t size = 0;
    if (sl_read_file(path, 16u << 20, &text, &size, &err) != SL_OK) {
        fprintf(stderr, "ribbons-depth-check: %s\n", err.message);
        return 0;
    }
    cJSON *root = cJSON_ParseWithLength((const char *)text, size);
    free(text);
    sl_scene scene;
    if (!root || sl_scene_from_json(root, &scene, &err) != SL_OK) {
        fprintf(stderr, "ribbons-depth-check: %s: %s\n", path, root ? err.message : "not JSON");
        cJSON_Delete(root);
        return 0;
    }
    cJSON_Delete(root);
    int ok = !scene.camera.is_orbit;
    if (ok) {
        const sl_camera *c = &scene.camera.look_at;
        const double eye[3] = {c->eye.x, c->eye.y, c->eye.z}, target[3] = {c->target.x, c->target.y, c->target.z};
        const double up[3] = {c->up.x, c->up.y, c->up.z};
        ok = ref_camera_init(cam, eye, target, up, c->fov_y_deg, scene.width, scene.height) == 0;
    }
    if (!ok)
        fprintf(stderr, "ribbons-depth-check: %s: want an eye/target/up camera\n", path);
    sl_scene_deinit(&scene);
    return ok;
}

int main(int argc, char **argv)
{
    options o;
    if (!parse_args(argc, argv, &o))
        return usage();
    ribbons_ref_segment seg;
    if (!segment_of(&o, &seg)) {
        fprintf(stderr, "ribbons-depth-check: degenerate --axis or --normal\n");
        return 2;
    }
    ref_camera cam;
    if (!camera_of(o.scene, &cam))
        return 2;
    sl_err err = {0};
    sl_depth_image depth = {0};
    if (sl_pfm_read(o.depth, &depth, &err) != SL_OK) {
        fprintf(stderr, "ribbons-depth-check: %s\n", err.message);
        return 2;
    }
    if (depth.width != cam.width || depth.height != cam.height) {
        fprintf(stderr, "ribbons-depth-check: %s is %dx%d, the scene %dx%d\n", o.depth, depth.width, depth.height,
                cam.width, cam.height);
        sl_depth_image_deinit(&depth);
        return 2;
    }
    const ribbons_depth_limits limits = {.sides = o.sides, .head_on_cos = o.head_on, .eps = o.eps,
                                         .margin_px = o.margin_px};
    ribbons_depth_error e;
    ribbons_depth_error_measure(depth.values, &cam, &seg, &limits, &e);
    sl_depth_image_deinit(&depth);
    printf("ribbons-depth-check: N %d, w %g: %zu pixels both hit (ours %zu, reference %zu); max |error| / r %.3e, "
           "mean %.3e, head-on max %.3e; %zu held to the bound (max bound / r %.3e), max error / bound %.3f; "
           "outside the bound %zu, missed %zu, spurious %zu, mismatch %zu\n",
           o.sides, o.width_ratio, e.both, e.gpu_hits, e.ref_hits, e.max_err, e.mean_err, e.max_head_on, e.checked,
           e.max_bound, e.max_over_bound, e.outside_bound, e.missed, e.spurious, e.mismatch);
    if (e.checked == 0 || e.outside_bound || e.missed || e.spurious) {
        if (e.bad_i >= 0)
            fprintf(stderr, "FAIL: pixel (%d, %d): ours %.7g, reference %.7g, bound %.3g (%zu outside the bound, "
                    "%zu missed, %zu spurious)\n", e.bad_i, e.bad_j, e.bad_gpu, e.bad_ref, e.bad_bound,
                    e.outside_bound, e.missed, e.spurious);
        else
            fprintf(stderr, "FAIL: no pixel held to the bound\n");
        return 1;
    }
    return 0;
}
