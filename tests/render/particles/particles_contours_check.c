/* particles_contours_check.c — image checks of the contours and splats of
 * `particles` on a sphere of radius R at the dataset's bounds centre, seen
 * by an orbit camera: the silhouette is the circle of pixel radius
 * r = tan(asin(R / D)) / tan(fov / 2) * H / 2 about the image centre
 * (D = the eye's distance to the centre), computed here from the camera.
 *
 * usage: particles-contours-check width|near|splat --png P --dataset D --radius R
 *            [--azimuth A] [--elevation E] [--distance d] [--fov F]
 *            [--ink r,g,b] [--light x,y,z]
 *            width: --width W
 *            near:  [--far-px K] [--max-far-share S]
 *            splat: [--min-cover C] [--min-corr X]
 *
 * Ink coverage of a pixel: (L - L_bg) / (L_ink - L_bg) clamped to [0, 1],
 * L the luminance, the background taken from the corner pixel (0, 0), the
 * ink from --ink (default 0.05 grey).
 * width: at 360 angles, the ink across the circle: the coverage
 *   (bilinear) integrated along the radius over r -+ (2 W + 4) px. The
 *   median must lie within max(25 %, 1 px) of W. Prints median, p10, p90.
 * near: the share of ink pixels (coverage >= 0.25) farther than K px
 *   (default 3) from the circle must be at most S (default 0.02), and there
 *   must be ink along at least half the circle's length.
 * splat: inside the disk (r - 1.5 px) the share of pixels that differ from
 *   the background (a channel by more than 10 of 255) must be at least C
 *   (default 0.95); over the covered ones the correlation of the
 *   luminance with max(0, n.l) (n the sphere's normal at the pixel's ray
 *   hit, l = --light in eye space, x right, y up, z towards the viewer;
 *   default 0.3,0.5,1 as the technique's) must be at least X (default 0.9).
 * exit: 0 pass, 1 a limit failed, 2 bad input. Any thread, no GL.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_camera.h"
#include "data/sl_dataset_open.h"
#include "image/sl_image.h"

typedef struct options {
    const char *png, *dataset;
    double radius, azimuth, elevation, distance, fov, width, far_px, max_far_share, min_cover, min_corr;
    double ink[3], light[3];
} options;

static int usage(void)
{
    fprintf(stderr, "usage: particles-contours-check width|near|splat --png P --dataset D --radius R "
                    "[--azimuth A] [--elevation E] [--distance d] [--fov F] [--ink r,g,b] [--light x,y,z] "
                    "[--width W] [--far-px K] [--max-far-share S] [--min-cover C] [--min-corr X]\n");
    return 2;
}

static int parse_vec3(const char *s, double v[3])
{
    char *end;
    for (int c = 0; c < 3; c++) {
        v[c] = strtod(s, &end);
        if (end == s || (c < 2 && *end != ',') || (c == 2 && *end != '\0'))
            return 0;
        s = end + 1;
    }
    return 1;
}

static int parse_options(int argc, char **argv, options *o)
{
    *o = (options){.azimuth = 0, .distance = 2.5, .fov = 45, .far_px = 3, .max_far_share = 0.02,
                   .min_cover = 0.95, .min_corr = 0.9, .ink = {0.05, 0.05, 0.05}, .light = {0.3, 0.5, 1.0}};
    for (int i = 2; i < argc; i += 2) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        double *num = NULL;
        if (!v)
            return 0;
        if (strcmp(a, "--png") == 0)
            o->png = v;
        else if (strcmp(a, "--dataset") == 0)
            o->dataset = v;
        else if (strcmp(a, "--ink") == 0 || strcmp(a, "--light") == 0) {
            if (!parse_vec3(v, a[2] == 'i' ? o->ink : o->light))
                return 0;
        } else if (strcmp(a, "--radius") == 0) num = &o->radius;
        else if (strcmp(a, "--azimuth") == 0) num = &o->azimuth;
        else if (strcmp(a, "--elevation") == 0) num = &o->elevation;
        else if (strcmp(a, "--distance") == 0) num = &o->distance;
        else if (strcmp(a, "--fov") == 0) num = &o->fov;
        else if (strcmp(a, "--width") == 0) num = &o->width;
        else if (strcmp(a, "--far-px") == 0) num = &o->far_px;
        else if (strcmp(a, "--max-far-share") == 0) num = &o->max_far_share;
        else if (strcmp(a, "--min-cover") == 0) num = &o->min_cover;
        else if (strcmp(a, "--min-corr") == 0) num = &o->min_corr;
        else
            return 0;
        if (num) {
            char *end;
            *num = strtod(v, &end);
            if (end == v || *end)
                return 0;
        }
    }
    return o->png && o->dataset && o->radius > 0;
}

/* The picture and the sphere's silhouette circle in it. */
typedef struct scene {
    sl_image img;
    sl_view view;
    sl_vec3 centre;
    double r_px, cx, cy, bg_lum, ink_lum;
} scene;

static double lum(const uint8_t *p)
{
    return (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
}

static int open_scene(const options *o, scene *s)
{
    memset(s, 0, sizeof *s);
    sl_err err = {0};
    if (sl_png_read(o->png, &s->img, &err) != SL_OK) {
        fprintf(stderr, "particles-contours-check: %s: %s\n", o->png, err.message);
        return 0;
    }
    sl_dataset *ds = NULL;
    sl_dataset_dirs dirs = {0};
    if (sl_dataset_open(o->dataset, &dirs, &ds, &err) != SL_OK) {
        fprintf(stderr, "particles-contours-check: dataset %s: %s\n", o->dataset, err.message);
        return 0;
    }
    sl_vec3 lo = ds->bounds_min, hi = ds->bounds_max;
    sl_dataset_destroy(ds);
    sl_orbit orbit = {.azimuth_deg = o->azimuth, .elevation_deg = o->elevation, .distance = o->distance,
                      .fov_y_deg = o->fov};
    s->view.width = s->img.width;
    s->view.height = s->img.height;
    if (sl_camera_from_orbit(&orbit, lo, hi, &s->view.camera, &err) != SL_OK ||
        sl_view_init(&s->view, 1.0, &err) != SL_OK) {
        fprintf(stderr, "particles-contours-check: camera: %s\n", err.message);
        return 0;
    }
    s->centre = sl_v3_scale(sl_v3_add(lo, hi), 0.5);
    double d = sl_v3_length(sl_v3_sub(s->view.camera.eye, s->centre));
    if (!(d > o->radius)) {
        fprintf(stderr, "particles-contours-check: the eye is inside the sphere\n");
        return 0;
    }
    s->r_px = tan(asin(o->radius / d)) / s->view.tan_half_fov * 0.5 * s->img.height;
    s->cx = 0.5 * s->img.width;
    s->cy = 0.5 * s->img.height;
    s->bg_lum = lum(s->img.rgba);
    s->ink_lum = 0.2126 * o->ink[0] + 0.7152 * o->ink[1] + 0.0722 * o->ink[2];
    if (fabs(s->ink_lum - s->bg_lum) < 0.2) {
        fprintf(stderr, "particles-contours-check: ink and background too alike (%.3f, %.3f)\n", s->ink_lum,
                s->bg_lum);
        return 0;
    }
    printf("silhouette: radius %.2f px about (%.1f, %.1f)\n", s->r_px, s->cx, s->cy);
    return 1;
}

static double coverage_at(const scene *s, int i, int j)
{
    if (i < 0 || j < 0 || i >= s->img.width || j >= s->img.height)
        return 0.0;
    double a = (lum(s->img.rgba + 4 * ((size_t)j * s->img.width + i)) - s->bg_lum) / (s->ink_lum - s->bg_lum);
    return a < 0 ? 0 : a > 1 ? 1 : a;
}

/* Bilinear coverage at image position (x, y), pixel centres at .5. */
static double coverage_bilinear(const scene *s, double x, double y)
{
    double fx = x - 0.5, fy = y - 0.5;
    int i = (int)floor(fx), j = (int)floor(fy);
    double tx = fx - i, ty = fy - j;
    return (1 - ty) * ((1 - tx) * coverage_at(s, i, j) + tx * coverage_at(s, i + 1, j)) +
           ty * ((1 - tx) * coverage_at(s, i, j + 1) + tx * coverage_at(s, i + 1, j + 1));
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int check_width(const options *o, const scene *s)
{
    if (!(o->width > 0))
        return usage();
    enum { ANGLES = 360 };
    double runs[ANGLES];
    double win = 2.0 * o->width + 4.0, step = 0.05;
    for (int k = 0; k < ANGLES; k++) {
        double th = 2.0 * M_PI * (k + 0.5) / ANGLES, run = 0.0;
        for (double t = s->r_px - win; t <= s->r_px + win; t += step)
            run += step * coverage_bilinear(s, s->cx + t * cos(th), s->cy + t * sin(th));
        runs[k] = run;
    }
    qsort(runs, ANGLES, sizeof runs[0], cmp_double);
    double median = 0.5 * (runs[ANGLES / 2 - 1] + runs[ANGLES / 2]);
    double tol = fmax(0.25 * o->width, 1.0);
    printf("ink run across the silhouette: median %.3f px (p10 %.3f, p90 %.3f), wanted %.3f +- %.3f\n", median,
           runs[ANGLES / 10], runs[ANGLES * 9 / 10], o->width, tol);
    if (!(fabs(median - o->width) <= tol)) {
        fprintf(stderr, "FAIL: contour width %.3f px is not %.3f +- %.3f\n", median, o->width, tol);
        return 1;
    }
    return 0;
}

static int check_near(const options *o, const scene *s)
{
    long ink = 0, far = 0;
    for (int j = 0; j < s->img.height; j++)
        for (int i = 0; i < s->img.width; i++) {
            if (coverage_at(s, i, j) < 0.25)
                continue;
            ink++;
            double r = hypot(i + 0.5 - s->cx, j + 0.5 - s->cy);
            if (fabs(r - s->r_px) > o->far_px)
                far++;
        }
    double share = ink ? (double)far / ink : 0.0;
    printf("ink pixels %ld, farther than %.1f px from the silhouette %ld (%.4f)\n", ink, o->far_px, far, share);
    if (ink < M_PI * s->r_px) {
        fprintf(stderr, "FAIL: ink along less than half the silhouette (%ld pixels)\n", ink);
        return 1;
    }
    if (!(share <= o->max_far_share)) {
        fprintf(stderr, "FAIL: ink away from the silhouette: share %.4f above %.4f\n", share, o->max_far_share);
        return 1;
    }
    return 0;
}

static int check_splat(const options *o, const scene *s)
{
    const sl_view *v = &s->view;
    double ll = sqrt(o->light[0] * o->light[0] + o->light[1] * o->light[1] + o->light[2] * o->light[2]);
    if (!(ll > 0))
        return usage();
    sl_vec3 l = sl_v3_add(sl_v3_add(sl_v3_scale(v->right, o->light[0] / ll), sl_v3_scale(v->upv, o->light[1] / ll)),
                          sl_v3_scale(v->forward, -o->light[2] / ll));
    const uint8_t *bg = s->img.rgba;
    long inside = 0, covered = 0;
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0, dark = 0, bright = 0;
    long n_dark = 0, n_bright = 0;
    sl_vec3 eye = v->camera.eye;
    for (int j = 0; j < s->img.height; j++)
        for (int i = 0; i < s->img.width; i++) {
            if (hypot(i + 0.5 - s->cx, j + 0.5 - s->cy) > s->r_px - 1.5)
                continue;
            inside++;
            const uint8_t *p = s->img.rgba + 4 * ((size_t)j * s->img.width + i);
            int differs = 0;
            for (int c = 0; c < 3; c++)
                differs |= abs((int)p[c] - (int)bg[c]) > 10;
            if (!differs)
                continue;
            covered++;
            /* The ray's first hit on the sphere and its normal there. */
            sl_vec3 d = sl_view_ray_dir(v, i, j);
            sl_vec3 oc = sl_v3_sub(eye, s->centre);
            double b = sl_v3_dot(oc, d), c = sl_v3_dot(oc, oc) - o->radius * o->radius, disc = b * b - c;
            if (disc < 0)
                continue;
            sl_vec3 hit = sl_v3_add(oc, sl_v3_scale(d, -b - sqrt(disc)));
            double x = fmax(0.0, sl_v3_dot(sl_v3_scale(hit, 1.0 / o->radius), l)), y = lum(p);
            sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y;
            if (x < 0.25)
                dark += y, n_dark++;
            if (x > 0.75)
                bright += y, n_bright++;
        }
    double cover = inside ? (double)covered / inside : 0.0;
    double n = (double)covered;
    double var_x = sxx - sx * sx / n, var_y = syy - sy * sy / n;
    double corr = covered > 1 && var_x > 0 && var_y > 0 ? (sxy - sx * sy / n) / sqrt(var_x * var_y) : 0.0;
    printf("disk pixels %ld, covered %ld (%.4f); luminance vs max(0, n.l): correlation %.4f, mean %.3f where "
           "n.l < 0.25 (%ld px), %.3f where n.l > 0.75 (%ld px)\n",
           inside, covered, cover, corr, n_dark ? dark / n_dark : 0.0, n_dark, n_bright ? bright / n_bright : 0.0,
           n_bright);
    if (!(cover >= o->min_cover)) {
        fprintf(stderr, "FAIL: splats cover %.4f of the sphere's disk, below %.4f\n", cover, o->min_cover);
        return 1;
    }
    if (!(corr >= o->min_corr)) {
        fprintf(stderr, "FAIL: shading correlation %.4f with n.l below %.4f\n", corr, o->min_corr);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    options o;
    if (argc < 2 || !parse_options(argc, argv, &o))
        return usage();
    int (*check)(const options *, const scene *) = NULL;
    if (strcmp(argv[1], "width") == 0)
        check = check_width;
    else if (strcmp(argv[1], "near") == 0)
        check = check_near;
    else if (strcmp(argv[1], "splat") == 0)
        check = check_splat;
    else
        return usage();
    scene s;
    if (!open_scene(&o, &s)) {
        sl_image_deinit(&s.img);
        return 2;
    }
    int rc = check(&o, &s);
    sl_image_deinit(&s.img);
    return rc;
}
