/* particles_focus_check.c — checks of the focus + context of `particles`
 * (renderer/particles/particles_focus.h) on rendered images and depth maps
 * (sightline-render --out / --depth, the depth as the Euclidean eye distance,
 * 0 = no hit), with the focus sphere analytic along each pixel's centre ray
 * (sl_view_ray_dir of the scene's view).
 *
 * usage: particles-focus-check outside --scene S --image A (--background R,G,B | --reference B)
 *                              --center X,Y,Z --radius R [--margin PX] [--min-inside N]
 *        particles-focus-check front --scene S --image C --marks K --marks-depth KD
 *                              --center X,Y,Z --radius R [--min N]
 *        particles-focus-check behind --image C --marks-depth KD --dvr V --dvr-depth VD [--min N] [--max-abs M]
 *        particles-focus-check depth --image-depth CD --marks-depth KD --dvr-depth VD [--rel E] [--min N]
 *        particles-focus-check inside --scene S --depth D --center X,Y,Z --radius R [--tol T] [--min N] [--max N]
 *
 * outside: pixels whose ray passes the sphere farther than R + PX pixels
 *   (default 1.5) have A's RGB equal to the reference (the background or
 *   image B) exactly; pixels whose ray passes within R - PX pixels of the
 *   centre differ from it at N at least (default 1).
 * front: pixels with a mark (KD > 0) in front of the sphere (the ray misses
 *   it, or the mark is nearer than where the ray enters it) have C's RGB
 *   equal to K's exactly; N such pixels at least. Single-sample images only:
 *   the depth map is always single-sample, and llvmpipe places MSAA point
 *   sprites differently.
 * behind: pixels with a mark behind the volume's depth (0 < VD < KD) have
 *   C's RGB within M (default 1) of V's (V: the volume alone); N at least.
 * depth: CD is the nearer of KD and VD (relative E, default 1e-4; 0 where
 *   both are 0); N pixels at least where the volume's depth is the nearer.
 * inside: the pixels whose depth point (eye + D ray) lies inside the sphere
 *   shrunk by T (world, default 0) number within [N_min, N_max].
 * exit: 0 pass, 1 a limit failed, 2 bad input. Any thread, no GL.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "data/sl_dataset.h"
#include "data/sl_load.h"
#include "image/sl_image.h"
#include "sl_scene.h"

typedef struct options {
    const char *scene, *image, *reference, *marks, *marks_depth, *dvr, *dvr_depth, *image_depth, *depth;
    double center[3], radius, margin, rel, tol, max_abs;
    double min, max;
    int background[3], have_background;
} options;

static int usage(void)
{
    fprintf(stderr, "usage: particles-focus-check outside|front|behind|depth|inside [options] (see the file)\n");
    return 2;
}

static int parse_vec3(const char *s, double v[3])
{
    return sscanf(s, "%lf,%lf,%lf", &v[0], &v[1], &v[2]) == 3;
}

static int parse_args(int argc, char **argv, options *o)
{
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (i + 1 >= argc)
            return 0;
        const char *v = argv[++i];
        if (!strcmp(a, "--scene")) o->scene = v;
        else if (!strcmp(a, "--image")) o->image = v;
        else if (!strcmp(a, "--reference")) o->reference = v;
        else if (!strcmp(a, "--marks")) o->marks = v;
        else if (!strcmp(a, "--marks-depth")) o->marks_depth = v;
        else if (!strcmp(a, "--dvr")) o->dvr = v;
        else if (!strcmp(a, "--dvr-depth")) o->dvr_depth = v;
        else if (!strcmp(a, "--image-depth")) o->image_depth = v;
        else if (!strcmp(a, "--depth")) o->depth = v;
        else if (!strcmp(a, "--center")) { if (!parse_vec3(v, o->center)) return 0; }
        else if (!strcmp(a, "--radius")) o->radius = atof(v);
        else if (!strcmp(a, "--margin")) o->margin = atof(v);
        else if (!strcmp(a, "--rel")) o->rel = atof(v);
        else if (!strcmp(a, "--tol")) o->tol = atof(v);
        else if (!strcmp(a, "--max-abs")) o->max_abs = atof(v);
        else if (!strcmp(a, "--min")) o->min = atof(v);
        else if (!strcmp(a, "--min-inside")) o->min = atof(v);
        else if (!strcmp(a, "--max")) o->max = atof(v);
        else if (!strcmp(a, "--background")) {
            if (sscanf(v, "%d,%d,%d", &o->background[0], &o->background[1], &o->background[2]) != 3)
                return 0;
            o->have_background = 1;
        } else
            return 0;
    }
    return 1;
}

/* The scene's view (camera, size) for its dataset. */
static int load_view(const char *path, sl_view *view)
{
    sl_err err = {0};
    uint8_t *text = NULL;
    size_t size = 0;
    if (sl_read_file(path, 16u << 20, &text, &size, &err) != SL_OK) {
        fprintf(stderr, "particles-focus-check: %s\n", err.message);
        return 0;
    }
    sl_scene scene;
    memset(&scene, 0, sizeof scene);
    cJSON *root = cJSON_ParseWithLength((const char *)text, size);
    free(text);
    if (!root) {
        fprintf(stderr, "particles-focus-check: %s is not valid JSON\n", path);
        return 0;
    }
    sl_status st = sl_scene_from_json(root, &scene, &err);
    cJSON_Delete(root);
    sl_dataset *ds = NULL;
    if (st == SL_OK)
        st = sl_scene_open_dataset(&scene, NULL, &ds, &err);
    if (st == SL_OK)
        st = sl_scene_view(&scene, ds, 0, view, &err);
    sl_dataset_destroy(ds);
    sl_scene_deinit(&scene);
    if (st != SL_OK) {
        fprintf(stderr, "particles-focus-check: %s: %s\n", path, err.message);
        return 0;
    }
    return 1;
}

static int read_png(const char *path, sl_image *img)
{
    sl_err err = {0};
    if (!path || sl_png_read(path, img, &err) != SL_OK) {
        fprintf(stderr, "particles-focus-check: %s\n", path ? err.message : "an image is missing");
        return 0;
    }
    return 1;
}

static int read_pfm(const char *path, sl_depth_image *img)
{
    sl_err err = {0};
    if (!path || sl_pfm_read(path, img, &err) != SL_OK) {
        fprintf(stderr, "particles-focus-check: %s\n", path ? err.message : "a depth map is missing");
        return 0;
    }
    return 1;
}

/* The pixel's ray against the sphere: closest distance of the ray's line
 * to the centre, the parameter there, and the entry (t_in, NAN on a miss). */
typedef struct ray_sphere {
    sl_vec3 eye, dir;
    double closest, t_closest, t_in;
} ray_sphere;

static ray_sphere pixel_ray(const sl_view *view, const options *o, int i, int j)
{
    ray_sphere r;
    r.eye = view->camera.eye;
    r.dir = sl_view_ray_dir(view, i, j);
    sl_vec3 oc = sl_v3_sub(r.eye, sl_v3(o->center[0], o->center[1], o->center[2]));
    double b = sl_v3_dot(oc, r.dir), c = sl_v3_dot(oc, oc) - o->radius * o->radius;
    r.t_closest = -b;
    r.closest = sqrt(fmax(sl_v3_dot(oc, oc) - b * b, 0.0));
    double disc = b * b - c;
    r.t_in = disc >= 0.0 && -b + sqrt(disc) > 0.0 ? fmax(-b - sqrt(disc), 0.0) : NAN;
    return r;
}

static int rgb_diff(const uint8_t *a, const uint8_t *b)
{
    int m = 0;
    for (int c = 0; c < 3; c++)
        m = abs(a[c] - b[c]) > m ? abs(a[c] - b[c]) : m;
    return m;
}

static int same_size(int w, int h, int w2, int h2, const char *what)
{
    if (w == w2 && h == h2)
        return 1;
    fprintf(stderr, "particles-focus-check: %s is %dx%d, expected %dx%d\n", what, w2, h2, w, h);
    return 0;
}

static int check_outside(const options *o)
{
    sl_view view;
    sl_image a = {0}, ref = {0};
    if (!load_view(o->scene, &view) || !read_png(o->image, &a))
        return 2;
    if (o->reference && (!read_png(o->reference, &ref) || !same_size(a.width, a.height, ref.width, ref.height,
                                                                      o->reference)))
        return 2;
    if (!o->reference && !o->have_background)
        return usage();
    if (!same_size(view.width, view.height, a.width, a.height, o->image))
        return 2;
    long outside = 0, bad_outside = 0, inside = 0, differ_inside = 0;
    int worst = 0;
    double px_angle = 2.0 * view.tan_half_fov / view.height;
    for (int j = 0; j < a.height; j++)
        for (int i = 0; i < a.width; i++) {
            const uint8_t *p = a.rgba + 4 * ((size_t)j * a.width + i);
            uint8_t bg[3] = {(uint8_t)o->background[0], (uint8_t)o->background[1], (uint8_t)o->background[2]};
            const uint8_t *q = o->reference ? ref.rgba + 4 * ((size_t)j * a.width + i) : bg;
            ray_sphere r = pixel_ray(&view, o, i, j);
            double px = o->margin * px_angle * fmax(r.t_closest, 0.0);
            int d = rgb_diff(p, q);
            if (r.t_closest <= 0.0 || r.closest > o->radius + px) {
                outside++;
                if (d > 0)
                    bad_outside++;
                worst = d > worst ? d : worst;
            } else if (r.closest < o->radius - px) {
                inside++;
                differ_inside += d > 0;
            }
        }
    printf("outside: %ld pixels, %ld differ (max %d); inside: %ld pixels, %ld differ\n", outside, bad_outside, worst,
           inside, differ_inside);
    sl_image_deinit(&a);
    sl_image_deinit(&ref);
    if (bad_outside > 0) {
        printf("FAIL: %ld pixels outside the focus sphere's projection differ from the reference\n", bad_outside);
        return 1;
    }
    if (differ_inside < o->min) {
        printf("FAIL: only %ld pixels inside the projection differ from the reference (min %g)\n", differ_inside,
               o->min);
        return 1;
    }
    return 0;
}

static int check_front(const options *o)
{
    sl_view view;
    sl_image c = {0}, k = {0};
    sl_depth_image kd = {0};
    if (!load_view(o->scene, &view) || !read_png(o->image, &c) || !read_png(o->marks, &k) ||
        !read_pfm(o->marks_depth, &kd))
        return 2;
    if (!same_size(c.width, c.height, k.width, k.height, o->marks) ||
        !same_size(c.width, c.height, kd.width, kd.height, o->marks_depth) ||
        !same_size(view.width, view.height, c.width, c.height, o->image))
        return 2;
    long front = 0, front_in_disc = 0, bad = 0;
    int worst = 0;
    for (int j = 0; j < c.height; j++)
        for (int i = 0; i < c.width; i++) {
            size_t n = (size_t)j * c.width + i;
            double t = kd.values[n];
            if (!(t > 0.0))
                continue;
            ray_sphere r = pixel_ray(&view, o, i, j);
            int in_disc = !isnan(r.t_in);
            if (in_disc && !(t < r.t_in * (1.0 - 1e-4)))
                continue;
            front++;
            front_in_disc += in_disc;
            int d = rgb_diff(c.rgba + 4 * n, k.rgba + 4 * n);
            if (d > 0 && bad++ == 0)
                printf("first at (%d, %d): %d,%d,%d, the marks' %d,%d,%d; mark at %g, sphere entry %g\n", i, j,
                       c.rgba[4 * n], c.rgba[4 * n + 1], c.rgba[4 * n + 2], k.rgba[4 * n], k.rgba[4 * n + 1],
                       k.rgba[4 * n + 2], t, r.t_in);
            worst = d > worst ? d : worst;
        }
    printf("front: %ld mark pixels in front of the sphere (%ld over its projection), %ld differ (max %d)\n", front,
           front_in_disc, bad, worst);
    sl_image_deinit(&c);
    sl_image_deinit(&k);
    sl_depth_image_deinit(&kd);
    if (bad > 0) {
        printf("FAIL: %ld pixels with a mark in front of the sphere are not the marks-only image's\n", bad);
        return 1;
    }
    if (front_in_disc < o->min) {
        printf("FAIL: only %ld mark pixels in front of the sphere over its projection (min %g)\n", front_in_disc,
               o->min);
        return 1;
    }
    return 0;
}

static int check_behind(const options *o)
{
    sl_image c = {0}, v = {0};
    sl_depth_image kd = {0}, vd = {0};
    if (!read_png(o->image, &c) || !read_png(o->dvr, &v) || !read_pfm(o->marks_depth, &kd) ||
        !read_pfm(o->dvr_depth, &vd))
        return 2;
    if (!same_size(c.width, c.height, v.width, v.height, o->dvr) ||
        !same_size(c.width, c.height, kd.width, kd.height, o->marks_depth) ||
        !same_size(c.width, c.height, vd.width, vd.height, o->dvr_depth))
        return 2;
    long behind = 0, bad = 0;
    int worst = 0;
    for (size_t n = 0; n < (size_t)c.width * c.height; n++) {
        double tk = kd.values[n], tv = vd.values[n];
        if (!(tk > 0.0 && tv > 0.0 && tv < tk * (1.0 - 1e-4)))
            continue;
        behind++;
        int d = rgb_diff(c.rgba + 4 * n, v.rgba + 4 * n);
        bad += d > o->max_abs;
        worst = d > worst ? d : worst;
    }
    printf("behind: %ld mark pixels behind the volume's depth, %ld differ by more than %g (max %d)\n", behind, bad,
           o->max_abs, worst);
    sl_image_deinit(&c);
    sl_image_deinit(&v);
    sl_depth_image_deinit(&kd);
    sl_depth_image_deinit(&vd);
    if (bad > 0) {
        printf("FAIL: %ld pixels with a mark behind the volume are not covered by it\n", bad);
        return 1;
    }
    if (behind < o->min) {
        printf("FAIL: only %ld mark pixels behind the volume (min %g)\n", behind, o->min);
        return 1;
    }
    return 0;
}

static int check_depth(const options *o)
{
    sl_depth_image cd = {0}, kd = {0}, vd = {0};
    if (!read_pfm(o->image_depth, &cd) || !read_pfm(o->marks_depth, &kd) || !read_pfm(o->dvr_depth, &vd))
        return 2;
    if (!same_size(cd.width, cd.height, kd.width, kd.height, o->marks_depth) ||
        !same_size(cd.width, cd.height, vd.width, vd.height, o->dvr_depth))
        return 2;
    long bad = 0, volume_nearer = 0, mark_nearer = 0;
    double worst = 0.0;
    for (size_t n = 0; n < (size_t)cd.width * cd.height; n++) {
        double tk = kd.values[n], tv = vd.values[n], tc = cd.values[n];
        double want = tk > 0.0 && (!(tv > 0.0) || tk <= tv) ? tk : tv > 0.0 ? tv : 0.0;
        if (want > 0.0 && want == tv && (!(tk > 0.0) || tv < tk))
            volume_nearer++;
        else if (want > 0.0)
            mark_nearer++;
        double e = want > 0.0 ? fabs(tc - want) / want : (tc != 0.0 ? INFINITY : 0.0);
        if (!(e <= o->rel))
            bad++;
        worst = e > worst ? e : worst;
    }
    printf("depth: %ld pixels the volume's, %ld a mark's; %ld off by more than %g (max relative %g)\n",
           volume_nearer, mark_nearer, bad, o->rel, worst);
    sl_depth_image_deinit(&cd);
    sl_depth_image_deinit(&kd);
    sl_depth_image_deinit(&vd);
    if (bad > 0) {
        printf("FAIL: %ld depth pixels are not the nearer of mark and volume\n", bad);
        return 1;
    }
    if (volume_nearer < o->min || mark_nearer < o->min) {
        printf("FAIL: too few pixels of either kind (min %g)\n", o->min);
        return 1;
    }
    return 0;
}

static int check_inside(const options *o)
{
    sl_view view;
    sl_depth_image d = {0};
    if (!load_view(o->scene, &view) || !read_pfm(o->depth, &d))
        return 2;
    if (!same_size(view.width, view.height, d.width, d.height, o->depth))
        return 2;
    long inside = 0;
    sl_vec3 c = sl_v3(o->center[0], o->center[1], o->center[2]);
    for (int j = 0; j < d.height; j++)
        for (int i = 0; i < d.width; i++) {
            double t = d.values[(size_t)j * d.width + i];
            if (!(t > 0.0))
                continue;
            sl_vec3 p = sl_v3_add(view.camera.eye, sl_v3_scale(sl_view_ray_dir(&view, i, j), t));
            inside += sl_v3_length(sl_v3_sub(p, c)) < o->radius - o->tol;
        }
    printf("inside: %ld depth pixels inside the focus sphere (shrunk by %g)\n", inside, o->tol);
    sl_depth_image_deinit(&d);
    if (inside < o->min || inside > o->max) {
        printf("FAIL: %ld depth pixels inside the sphere, expected [%g, %g]\n", inside, o->min, o->max);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2)
        return usage();
    options o = {.margin = 1.5, .rel = 1e-4, .max_abs = 1, .min = 1, .max = INFINITY};
    if (!parse_args(argc, argv, &o))
        return usage();
    const char *cmd = argv[1];
    if (!strcmp(cmd, "outside")) return check_outside(&o);
    if (!strcmp(cmd, "front")) return check_front(&o);
    if (!strcmp(cmd, "behind")) return check_behind(&o);
    if (!strcmp(cmd, "depth")) return check_depth(&o);
    if (!strcmp(cmd, "inside")) return check_inside(&o);
    return usage();
}
