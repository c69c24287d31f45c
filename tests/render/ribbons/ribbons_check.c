/* ribbons_check.c — image checks of the `ribbons` technique that the shared tools cannot do.
 *
 * usage: ribbons-check edge_on --png P --min-pixels X [--background R,G,B] [--span F]
 *        ribbons-check halo --png P --max-dist D [--background R,G,B] [--span F]
 *        ribbons-check count --png P --min-covered-pct X [--min-halo N] [--max-halo N] [--background R,G,B]
 *        ribbons-check twist_width --png P --reference R --axis-distance D --fov-deg F --alpha-deg A
 *                                  --width W [--background R,G,B] [--span F]
 *
 * edge_on: a frame of one ribbon whose projected axis runs along the image
 *   rows (seen edge-on; tests/render/ribbons/edge_*.json). The columns that
 *   show anything span [first, last]; over the middle fraction F of them
 *   (default 0.9, so the end caps are left out) every column must show at
 *   least X covered pixels (a channel more than 8/255 away from the
 *   background, default 26,26,31), i.e. the ribbon is at least X pixels
 *   thick along its whole length. Render with --samples 1: with MSAA a
 *   partly covered edge pixel would count. Prints the minimum and mean
 *   thickness; the failure line names the first thin column.
 * halo: a frame of one ribbon whose axis runs along the rows, side-on, drawn
 *   with halo_color (1, 0, 0) (tests/render/ribbons/halo_side.json). In each
 *   column of the middle fraction F, the topmost and bottommost covered
 *   pixels are the silhouette: both must have a halo pixel (red > 200, green
 *   and blue < 60) within 1 px in that column, and every halo pixel must lie
 *   within D px of one of them (the halo sits on the outline, not inside).
 *   Prints the share of silhouette ends with a halo and of misplaced halo
 *   pixels.
 * count: halo pixels (as above) and covered pixels of a frame: at least
 *   --min-covered-pct of the pixels covered, and the halo pixel count within
 *   [--min-halo, --max-halo] (halo.inside_*: a camera inside a ribbon's
 *   elliptic cylinder has no silhouette, so no halo at all).
 * twist_width: a straight circular ribbon along the image rows, its
 *   tangent pointing to screen right, seen side-on from distance
 *   --axis-distance D (eye to axis, in units of the radius, looking at the
 *   axis perpendicularly, vertical field of view --fov-deg), drawn with twist
 *   lines (--png) and without (--reference, same scene otherwise). A pixel
 *   is a stripe pixel where its luminance is below half the reference's
 *   (the 50 % cover edge of the anti-aliased band). In each column of the
 *   middle --span the covered extent gives the silhouettes; a screen offset
 *   u from the axis maps back to the angle phi on the circle exactly by
 *   u = sin(phi) / (D - cos(phi)) (scaled so the silhouette is at
 *   1 / sqrt(D^2 - 1)). Every stripe run whose two ends lie within
 *   |phi| <= 1.2 (and not on a silhouette) gives its width in the stripe
 *   coordinate a = phi - f h s: a column at screen x = X (tangent units)
 *   meets the tube at s = X r (D - cos phi), so the run spans
 *   da = dphi - tan(alpha) X (cos phi0 - cos phi1). The median of them times
 *   cos(--alpha-deg) (the stripe's angle to the axis) must be --width (the
 *   twist_width w_r, radians = units of r) within 5 %, or the angle one
 *   pixel spans at the front, whichever is larger. Needs >= 5 runs.
 * exit: 0 pass, 1 a limit failed, 2 bad input (usage, unreadable PNG).
 * Any thread, no GL.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/sl_image.h"

static int usage(void)
{
    fprintf(stderr, "usage: ribbons-check edge_on --png P --min-pixels X [--background R,G,B] [--span F]\n"
                    "       ribbons-check halo --png P --max-dist D [--background R,G,B] [--span F]\n"
                    "       ribbons-check count --png P --min-covered-pct X [--min-halo N] [--max-halo N]\n"
                    "                           [--background R,G,B]\n"
                    "       ribbons-check twist_width --png P --reference R --axis-distance D --fov-deg F\n"
                    "                                 --alpha-deg A --width W [--background R,G,B] [--span F]\n");
    return 2;
}

static int is_covered(const uint8_t *p, const int bg[3])
{
    int covered = 0;
    for (int k = 0; k < 3; k++)
        covered |= abs((int)p[k] - bg[k]) > 8;
    return covered;
}

static int is_halo(const uint8_t *p)
{
    return p[0] > 200 && p[1] < 60 && p[2] < 60;
}

/* The halo subcommand on a decoded image; see the header. */
static int check_halo(const sl_image *img, const int bg[3], double span, double max_dist)
{
    int first = -1, last = -1;
    for (int x = 0; x < img->width; x++)
        for (int y = 0; y < img->height; y++)
            if (is_covered(img->rgba + 4 * ((size_t)y * img->width + x), bg)) {
                if (first < 0)
                    first = x;
                last = x;
                break;
            }
    if (first < 0) {
        fprintf(stderr, "FAIL: nothing drawn\n");
        return 1;
    }
    int margin = (int)((1.0 - span) * 0.5 * (last - first));
    long ends = 0, ends_ok = 0, halo = 0, misplaced = 0;
    int first_bad = -1;
    for (int x = first + margin; x <= last - margin; x++) {
        int top = -1, bottom = -1;
        for (int y = 0; y < img->height; y++)
            if (is_covered(img->rgba + 4 * ((size_t)y * img->width + x), bg)) {
                if (top < 0)
                    top = y;
                bottom = y;
            }
        if (top < 0)
            continue;
        const int edge[2] = {top, bottom};
        for (int e = 0; e < 2; e++) {
            int ok = 0;
            for (int y = edge[e] - 1; y <= edge[e] + 1; y++)
                if (y >= 0 && y < img->height && is_halo(img->rgba + 4 * ((size_t)y * img->width + x)))
                    ok = 1;
            ends++;
            ends_ok += ok;
            if (!ok && first_bad < 0)
                first_bad = x;
        }
        for (int y = top; y <= bottom; y++)
            if (is_halo(img->rgba + 4 * ((size_t)y * img->width + x))) {
                halo++;
                if (y - top > max_dist && bottom - y > max_dist)
                    misplaced++;
            }
    }
    printf("halo: %ld of %ld silhouette ends outlined, %ld halo pixels, %ld farther than %g px from the outline\n",
           ends_ok, ends, halo, misplaced, max_dist);
    if (ends_ok < ends) {
        fprintf(stderr, "FAIL: column %d has a silhouette end without halo\n", first_bad);
        return 1;
    }
    if (misplaced) {
        fprintf(stderr, "FAIL: %ld halo pixels inside the ribbon\n", misplaced);
        return 1;
    }
    return 0;
}

/* The count subcommand; see the header. */
static int check_count(const sl_image *img, const int bg[3], double min_covered_pct, long min_halo, long max_halo)
{
    long covered = 0, halo = 0, total = (long)img->width * img->height;
    for (long i = 0; i < total; i++) {
        covered += is_covered(img->rgba + 4 * i, bg);
        halo += is_halo(img->rgba + 4 * i);
    }
    double pct = 100.0 * (double)covered / (double)total;
    printf("count: %.2f %% covered, %ld halo pixels\n", pct, halo);
    if (pct < min_covered_pct) {
        fprintf(stderr, "FAIL: %.2f %% covered, below %g %%\n", pct, min_covered_pct);
        return 1;
    }
    if (halo < min_halo || (max_halo >= 0 && halo > max_halo)) {
        fprintf(stderr, "FAIL: %ld halo pixels, outside [%ld, %ld]\n", halo, min_halo, max_halo);
        return 1;
    }
    return 0;
}

/* The edge_on subcommand; see the header. */
static int check_edge_on(const sl_image *img, const int bg[3], double span, double min_pixels)
{
    int first = -1, last = -1, thin = -1, lo = img->height;
    int *count = calloc((size_t)img->width, sizeof *count);
    if (!count)
        return 2;
    for (int x = 0; x < img->width; x++) {
        for (int y = 0; y < img->height; y++)
            count[x] += is_covered(img->rgba + 4 * ((size_t)y * img->width + x), bg);
        if (count[x]) {
            if (first < 0)
                first = x;
            last = x;
        }
    }
    if (first < 0) {
        free(count);
        fprintf(stderr, "FAIL: nothing drawn\n");
        return 1;
    }
    int margin = (int)((1.0 - span) * 0.5 * (last - first));
    int x0 = first + margin, x1 = last - margin;
    double sum = 0.0;
    for (int x = x0; x <= x1; x++) {
        if (count[x] < lo)
            lo = count[x];
        sum += count[x];
        if (count[x] < min_pixels && thin < 0)
            thin = x;
    }
    printf("edge_on: columns %d..%d of %d..%d, thickness min %d mean %.2f px (need >= %g)\n", x0, x1, first, last, lo,
           sum / (x1 - x0 + 1), min_pixels);
    int rc = 0;
    if (thin >= 0) {
        fprintf(stderr, "FAIL: column %d is %d px thick, below %g\n", thin, count[thin], min_pixels);
        rc = 1;
    }
    free(count);
    return rc;
}

static double luminance(const uint8_t *p)
{
    return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
}

/* phi in [-phi_s, phi_s] with sin(phi) / (D - cos(phi)) = u, by bisection (monotonic there). */
static double angle_of_offset(double u, double D)
{
    double lo = -acos(1.0 / D), hi = acos(1.0 / D);
    for (int i = 0; i < 100; i++) {
        double mid = 0.5 * (lo + hi);
        if (sin(mid) / (D - cos(mid)) < u)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The twist_width subcommand; see the header. */
static int check_twist_width(const sl_image *img, const sl_image *ref, const int bg[3], double span, double D,
                             double fov_deg, double alpha_deg, double width)
{
    if (ref->width != img->width || ref->height != img->height) {
        fprintf(stderr, "ribbons-check: --reference is %dx%d, --png %dx%d\n", ref->width, ref->height, img->width,
                img->height);
        return 2;
    }
    int first = -1, last = -1;
    for (int x = 0; x < ref->width; x++)
        for (int y = 0; y < ref->height; y++)
            if (is_covered(ref->rgba + 4 * ((size_t)y * ref->width + x), bg)) {
                if (first < 0)
                    first = x;
                last = x;
                break;
            }
    if (first < 0) {
        fprintf(stderr, "FAIL: nothing drawn\n");
        return 1;
    }
    const double u_s = 1.0 / sqrt(D * D - 1.0), cos_a = cos(alpha_deg * M_PI / 180.0);
    const double tan_a = tan(alpha_deg * M_PI / 180.0), tan_half_fov = tan(0.5 * fov_deg * M_PI / 180.0);
    size_t cap = (size_t)img->width * 4, n = 0;
    double *widths = malloc(cap * sizeof *widths), px_angle = 0.0;
    if (!widths)
        return 2;
    int margin = (int)((1.0 - span) * 0.5 * (last - first));
    for (int x = first + margin; x <= last - margin; x++) {
        int top = -1, bottom = -1;
        for (int y = 0; y < ref->height; y++)
            if (is_covered(ref->rgba + 4 * ((size_t)y * ref->width + x), bg)) {
                if (top < 0)
                    top = y;
                bottom = y;
            }
        if (top < 0 || bottom - top < 8)
            continue;
        double yc = 0.5 * (top + bottom + 1), R = 0.5 * (bottom + 1 - top);
        px_angle = fmax(px_angle, angle_of_offset(u_s / R, D));
        /* The column's screen x in tangent units: world x = X depth on the tube. */
        double X = (x + 0.5 - 0.5 * img->width) / (0.5 * img->height) * tan_half_fov;
        int run = -1;
        for (int y = top; y <= bottom + 1; y++) {
            int stripe = 0;
            if (y <= bottom) {
                const uint8_t *p = img->rgba + 4 * ((size_t)y * img->width + x);
                const uint8_t *q = ref->rgba + 4 * ((size_t)y * ref->width + x);
                stripe = luminance(q) > 20.0 && luminance(p) < 0.5 * luminance(q);
            }
            if (stripe && run < 0)
                run = y;
            if (!stripe && run >= 0) {
                double phi0 = angle_of_offset((run - yc) / R * u_s, D);
                double phi1 = angle_of_offset((y - yc) / R * u_s, D);
                /* a = phi - f h s with s = X r (D - cos phi) + const along the column, f h r = tan(alpha) */
                double da = (phi1 - phi0) - tan_a * X * (cos(phi0) - cos(phi1));
                if (run > top && y <= bottom && fabs(phi0) <= 1.2 && fabs(phi1) <= 1.2 && n < cap)
                    widths[n++] = da;
                run = -1;
            }
        }
    }
    if (n < 5) {
        fprintf(stderr, "FAIL: %zu stripe runs near the front, need >= 5\n", n);
        free(widths);
        return 1;
    }
    qsort(widths, n, sizeof *widths, cmp_double);
    double median = widths[n / 2], perpendicular = median * cos_a;
    double tolerance = fmax(0.05 * width, px_angle * cos_a);
    printf("twist_width: %zu runs, median %.4f rad along phi, x cos(%g deg) = %.4f (want %.4f +- %.4f; min %.4f max %.4f)\n",
           n, median, alpha_deg, perpendicular, width, tolerance, widths[0] * cos_a, widths[n - 1] * cos_a);
    free(widths);
    if (fabs(perpendicular - width) > tolerance) {
        fprintf(stderr, "FAIL: stripe width %.4f, want %.4f +- %.4f\n", perpendicular, width, tolerance);
        return 1;
    }
    return 0;
}

typedef struct check_args {
    const char *png, *reference;
    double min_pixels, span, max_dist, min_covered_pct, axis_distance, fov_deg, alpha_deg, width;
    long min_halo, max_halo;
    int bg[3];
} check_args;

static int parse(int argc, char **argv, check_args *a)
{
    *a = (check_args){.min_pixels = -1.0, .span = 0.9, .max_dist = -1.0, .min_covered_pct = -1.0,
                      .axis_distance = -1.0, .fov_deg = -1.0, .alpha_deg = -1.0, .width = -1.0, .max_halo = -1,
                      .bg = {26, 26, 31}};
    for (int i = 2; i < argc; i++) {
        if (i + 1 >= argc)
            return 0;
        const char *o = argv[i], *v = argv[++i];
        if (strcmp(o, "--png") == 0)
            a->png = v;
        else if (strcmp(o, "--reference") == 0)
            a->reference = v;
        else if (strcmp(o, "--min-pixels") == 0)
            a->min_pixels = atof(v);
        else if (strcmp(o, "--max-dist") == 0)
            a->max_dist = atof(v);
        else if (strcmp(o, "--span") == 0)
            a->span = atof(v);
        else if (strcmp(o, "--min-covered-pct") == 0)
            a->min_covered_pct = atof(v);
        else if (strcmp(o, "--min-halo") == 0)
            a->min_halo = atol(v);
        else if (strcmp(o, "--max-halo") == 0)
            a->max_halo = atol(v);
        else if (strcmp(o, "--axis-distance") == 0)
            a->axis_distance = atof(v);
        else if (strcmp(o, "--fov-deg") == 0)
            a->fov_deg = atof(v);
        else if (strcmp(o, "--alpha-deg") == 0)
            a->alpha_deg = atof(v);
        else if (strcmp(o, "--width") == 0)
            a->width = atof(v);
        else if (strcmp(o, "--background") == 0) {
            if (sscanf(v, "%d,%d,%d", &a->bg[0], &a->bg[1], &a->bg[2]) != 3)
                return 0;
        } else
            return 0;
    }
    return a->png && a->span > 0.0 && a->span <= 1.0;
}

int main(int argc, char **argv)
{
    check_args a;
    if (argc < 2 || !parse(argc, argv, &a))
        return usage();
    const char *cmd = argv[1];
    int edge_on = strcmp(cmd, "edge_on") == 0, halo = strcmp(cmd, "halo") == 0, count = strcmp(cmd, "count") == 0;
    int twist = strcmp(cmd, "twist_width") == 0;
    if ((edge_on && a.min_pixels < 0.0) || (halo && a.max_dist < 0.0) || (count && a.min_covered_pct < 0.0) ||
        (twist && (!a.reference || !(a.axis_distance > 1.0) || !(a.fov_deg > 0.0 && a.fov_deg < 180.0) || !(a.alpha_deg >= 0.0 && a.alpha_deg < 89.0) ||
                   !(a.width > 0.0))) ||
        !(edge_on || halo || count || twist))
        return usage();
    sl_image img = {0}, ref = {0};
    sl_err err;
    if (sl_png_read(a.png, &img, &err) != SL_OK || (twist && sl_png_read(a.reference, &ref, &err) != SL_OK)) {
        fprintf(stderr, "ribbons-check: %s\n", err.message);
        sl_image_deinit(&img);
        return 2;
    }
    int rc = edge_on ? check_edge_on(&img, a.bg, a.span, a.min_pixels)
             : halo  ? check_halo(&img, a.bg, a.span, a.max_dist)
             : count ? check_count(&img, a.bg, a.min_covered_pct, a.min_halo, a.max_halo)
                     : check_twist_width(&img, &ref, a.bg, a.span, a.axis_distance, a.fov_deg, a.alpha_deg,
                                         a.width);
    sl_image_deinit(&img);
    sl_image_deinit(&ref);
    return rc;
}
