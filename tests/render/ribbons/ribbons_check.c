/* ribbons_check.c — image checks of the `ribbons` technique that the shared tools cannot do.
 *
 * usage: ribbons-check edge_on --png P --min-pixels X [--background R,G,B] [--span F]
 *        ribbons-check halo --png P --max-dist D [--background R,G,B] [--span F]
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
 * exit: 0 pass, 1 a limit failed, 2 bad input (usage, unreadable PNG).
 * Any thread, no GL.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/sl_image.h"

static int usage(void)
{
    fprintf(stderr, "usage: ribbons-check edge_on --png P --min-pixels X [--background R,G,B] [--span F]\n"
                    "       ribbons-check halo --png P --max-dist D [--background R,G,B] [--span F]\n");
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

int main(int argc, char **argv)
{
    if (argc < 2 || (strcmp(argv[1], "edge_on") != 0 && strcmp(argv[1], "halo") != 0))
        return usage();
    int halo = strcmp(argv[1], "halo") == 0;
    const char *png = NULL;
    double min_pixels = -1.0, span = 0.9, max_dist = -1.0;
    int bg[3] = {26, 26, 31};
    for (int i = 2; i < argc; i++) {
        if (i + 1 >= argc)
            return usage();
        if (strcmp(argv[i], "--png") == 0)
            png = argv[++i];
        else if (strcmp(argv[i], "--min-pixels") == 0)
            min_pixels = atof(argv[++i]);
        else if (strcmp(argv[i], "--max-dist") == 0)
            max_dist = atof(argv[++i]);
        else if (strcmp(argv[i], "--span") == 0)
            span = atof(argv[++i]);
        else if (strcmp(argv[i], "--background") == 0) {
            if (sscanf(argv[++i], "%d,%d,%d", &bg[0], &bg[1], &bg[2]) != 3)
                return usage();
        } else
            return usage();
    }
    if (!png || (halo ? max_dist < 0.0 : min_pixels < 0.0) || !(span > 0.0 && span <= 1.0))
        return usage();
    sl_image img = {0};
    sl_err err;
    if (sl_png_read(png, &img, &err) != SL_OK) {
        fprintf(stderr, "ribbons-check: %s\n", err.message);
        return 2;
    }
    if (halo) {
        int rc = check_halo(&img, bg, span, max_dist);
        sl_image_deinit(&img);
        return rc;
    }
    int *count = calloc((size_t)img.width, sizeof *count);
    if (!count) {
        sl_image_deinit(&img);
        return 2;
    }
    int first = -1, last = -1;
    for (int x = 0; x < img.width; x++) {
        for (int y = 0; y < img.height; y++) {
            count[x] += is_covered(img.rgba + 4 * ((size_t)y * img.width + x), bg);
        }
        if (count[x]) {
            if (first < 0)
                first = x;
            last = x;
        }
    }
    int rc = 0;
    if (first < 0) {
        fprintf(stderr, "FAIL: nothing drawn in %s\n", png);
        rc = 1;
    } else {
        int margin = (int)((1.0 - span) * 0.5 * (last - first));
        int x0 = first + margin, x1 = last - margin, thin = -1, lo = img.height;
        double sum = 0.0;
        for (int x = x0; x <= x1; x++) {
            if (count[x] < lo)
                lo = count[x];
            sum += count[x];
            if (count[x] < min_pixels && thin < 0)
                thin = x;
        }
        printf("edge_on: columns %d..%d of %d..%d, thickness min %d mean %.2f px (need >= %g)\n", x0, x1, first,
               last, lo, sum / (x1 - x0 + 1), min_pixels);
        if (thin >= 0) {
            fprintf(stderr, "FAIL: column %d is %d px thick, below %g\n", thin, count[thin], min_pixels);
            rc = 1;
        }
    }
    free(count);
    sl_image_deinit(&img);
    return rc;
}
