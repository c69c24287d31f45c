/* sightline_diff.c — compares two renders: sightline-diff A B [options].
 *
 * A and B are both PNG (colour) or both PFM (depth), recognised by their magic
 * bytes, not their names. Prints one JSON object on stdout with the metrics of
 * sl_diff.h and the verdict against the limits given; optionally writes a heat
 * map PNG. The metrics themselves live in renderer/image/diff.c; this file only
 * parses arguments, reads files and formats JSON. Single-threaded.
 * Colour with --background R,G,B: mean, max, PSNR and bad_pct are over the
 * covered pixels (either image differs from that colour), so an error on
 * every drawn pixel of a mostly empty frame is not diluted by the empty part;
 * the JSON also gives the pixel count and the whole-frame mean and bad_pct.
 * Depth maps: bad_pct counts every coverage mismatch (hit in one map, missed
 * in the other) as a bad pixel, over the pixels either map hits; mean and max
 * are over pixels both hit. When any limit is given for a depth pair and
 * --max-coverage-pct is not, coverage must match exactly (an implicit
 * --max-coverage-pct 0), so "--max-mean 0" cannot pass two maps that hit
 * different pixels.
 * Exit status: 0 within all limits, 1 when a limit is exceeded, 2 on bad usage
 * or bad input (unreadable file, mixed kinds, size mismatch), with the reason
 * on stderr and nothing on stdout.
 */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/sl_diff.h"
#include "image/sl_image.h"

#define EXIT_PASS 0
#define EXIT_LIMIT 1
#define EXIT_BAD_INPUT 2

typedef enum file_kind { KIND_UNREADABLE, KIND_UNKNOWN, KIND_PNG, KIND_PFM } file_kind;

typedef struct limit {
    const char *option;      /* "--max-mean" */
    const char *name;        /* JSON name: "max_mean" */
    int set;
    double value;
} limit;

enum { LIM_MEAN, LIM_BAD_PCT, LIM_COVERAGE_PCT, LIM_ABS, LIM_COUNT };

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sightline-diff A B [--diff heat.png] [--bad-threshold T] [--background R,G,B]\n"
            "                      [--max-mean X] [--max-bad-pct Y] [--max-coverage-pct Z] [--max-abs M]\n"
            "A and B: both PNG (colour, 0..255 units) or both PFM (depth, world units; 0 = no hit).\n"
            "  mean_abs, max_abs, psnr_db: colour over the compared pixels; depth over pixels hit in both.\n"
            "  compared (colour): all pixels, or with --background R,G,B (0..255 each) the covered\n"
            "    pixels: those whose RGB differs from that colour in A or in B; frame_mean_abs and\n"
            "    frame_bad_pct are then the same metrics over all pixels.\n"
            "  bad_pct: %% of compared pixels that are bad: difference > T; for depth, compared = pixels\n"
            "    hit in either map and every coverage mismatch (hit in one, missed in the other) is bad.\n"
            "  coverage_mismatch_pct (depth): %% of the pixels hit in either map that only one hits.\n"
            "--bad-threshold T defaults to 8 (colour) or 1e-3 (depth).\n"
            "--max-coverage-pct applies to depth only; when a depth pair is given any other limit\n"
            "  and not this one, coverage must match exactly (--max-coverage-pct 0).\n"
            "Prints JSON; exit 0 = within limits, 1 = a limit exceeded, 2 = bad input.\n");
}

static file_kind sniff(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return KIND_UNREADABLE;
    unsigned char m[8] = {0};
    size_t n = fread(m, 1, sizeof m, f);
    fclose(f);
    static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (n == 8 && memcmp(m, png_sig, 8) == 0)
        return KIND_PNG;
    if (n >= 3 && m[0] == 'P' && (m[1] == 'f' || m[1] == 'F') &&
        (m[2] == ' ' || m[2] == '\n' || m[2] == '\r' || m[2] == '\t'))
        return KIND_PFM;
    return KIND_UNKNOWN;
}

static int parse_number(const char *option, const char *text, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = text ? strtod(text, &end) : NAN;
    if (!text || end == text || *end != '\0' || errno == ERANGE || !isfinite(v) || v < 0.0) {
        fprintf(stderr, "sightline-diff: %s needs a finite number >= 0, got \"%s\"\n", option, text ? text : "");
        return 0;
    }
    *out = v;
    return 1;
}

/* "R,G,B", each an integer in 0..255. */
static int parse_background(const char *text, uint8_t out[3])
{
    const char *p = text;
    for (int c = 0; c < 3; c++) {
        char *end = NULL;
        errno = 0;
        long v = (*p >= '0' && *p <= '9') ? strtol(p, &end, 10) : -1;
        if (v < 0 || v > 255 || errno == ERANGE || *end != (c < 2 ? ',' : '\0')) {
            fprintf(stderr, "sightline-diff: --background needs R,G,B with each an integer in 0..255, got \"%s\"\n",
                    text);
            return 0;
        }
        out[c] = (uint8_t)v;
        p = end + 1;
    }
    return 1;
}

static cJSON *add_number(cJSON *obj, const char *name, double v)
{
    return isfinite(v) ? cJSON_AddNumberToObject(obj, name, v) : cJSON_AddNullToObject(obj, name);
}

int main(int argc, char **argv)
{
    limit limits[LIM_COUNT] = {
        [LIM_MEAN] = {"--max-mean", "max_mean", 0, 0.0},
        [LIM_BAD_PCT] = {"--max-bad-pct", "max_bad_pct", 0, 0.0},
        [LIM_COVERAGE_PCT] = {"--max-coverage-pct", "max_coverage_pct", 0, 0.0},
        [LIM_ABS] = {"--max-abs", "max_abs", 0, 0.0},
    };
    const char *paths[2] = {NULL, NULL};
    const char *heat_path = NULL;
    int npaths = 0, threshold_set = 0, background_set = 0;
    double threshold = 0.0;
    uint8_t background[3] = {0, 0, 0};

    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            usage(stdout);
            return EXIT_PASS;
        }
        if (strncmp(arg, "--", 2) != 0) {
            if (npaths == 2) {
                fprintf(stderr, "sightline-diff: unexpected third file \"%s\"\n", arg);
                return EXIT_BAD_INPUT;
            }
            paths[npaths++] = arg;
            continue;
        }
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        if (!value) {
            fprintf(stderr, "sightline-diff: %s needs a value\n", arg);
            return EXIT_BAD_INPUT;
        }
        i++;
        if (strcmp(arg, "--diff") == 0) {
            heat_path = value;
            continue;
        }
        if (strcmp(arg, "--background") == 0) {
            if (!parse_background(value, background))
                return EXIT_BAD_INPUT;
            background_set = 1;
            continue;
        }
        if (strcmp(arg, "--bad-threshold") == 0) {
            if (!parse_number(arg, value, &threshold))
                return EXIT_BAD_INPUT;
            threshold_set = 1;
            continue;
        }
        int known = 0;
        for (int k = 0; k < LIM_COUNT; k++) {
            if (strcmp(arg, limits[k].option) == 0) {
                if (!parse_number(arg, value, &limits[k].value))
                    return EXIT_BAD_INPUT;
                limits[k].set = known = 1;
            }
        }
        if (!known) {
            fprintf(stderr, "sightline-diff: unknown option %s\n", arg);
            usage(stderr);
            return EXIT_BAD_INPUT;
        }
    }
    if (npaths != 2) {
        usage(stderr);
        return EXIT_BAD_INPUT;
    }

    file_kind kinds[2];
    for (int k = 0; k < 2; k++) {
        errno = 0;
        kinds[k] = sniff(paths[k]);
        if (kinds[k] == KIND_UNREADABLE) {
            fprintf(stderr, "sightline-diff: %s: cannot open: %s\n", paths[k], strerror(errno));
            return EXIT_BAD_INPUT;
        }
        if (kinds[k] == KIND_UNKNOWN) {
            fprintf(stderr, "sightline-diff: %s: neither PNG nor PFM (by its magic bytes)\n", paths[k]);
            return EXIT_BAD_INPUT;
        }
    }
    if (kinds[0] != kinds[1]) {
        fprintf(stderr, "sightline-diff: cannot compare %s (%s) with %s (%s): both must be PNG or both PFM\n",
                paths[0], kinds[0] == KIND_PNG ? "PNG" : "PFM", paths[1], kinds[1] == KIND_PNG ? "PNG" : "PFM");
        return EXIT_BAD_INPUT;
    }
    int depth = kinds[0] == KIND_PFM;
    if (!depth && limits[LIM_COVERAGE_PCT].set)
        fprintf(stderr, "sightline-diff: note: --max-coverage-pct applies to depth maps only; ignored for PNG\n");
    if (depth && background_set)
        fprintf(stderr, "sightline-diff: note: --background applies to colour images only; ignored for PFM\n");
    if (!threshold_set)
        threshold = depth ? 1e-3 : 8.0;
    /* A depth limit without a coverage limit must not pass maps that hit
     * different pixels: mean and max only see pixels both maps hit. */
    int coverage_implicit = 0;
    if (depth && !limits[LIM_COVERAGE_PCT].set &&
        (limits[LIM_MEAN].set || limits[LIM_BAD_PCT].set || limits[LIM_ABS].set)) {
        limits[LIM_COVERAGE_PCT].set = 1;
        limits[LIM_COVERAGE_PCT].value = 0.0;
        coverage_implicit = 1;
    }

    sl_err err = {0};
    sl_status st = SL_OK;
    sl_image img[2] = {{0}};
    sl_depth_image dep[2] = {{0}};
    sl_diff_result r = {0};
    uint8_t *heat = NULL;
    int code = EXIT_BAD_INPUT;
    for (int k = 0; k < 2 && st == SL_OK; k++)
        st = depth ? sl_pfm_read(paths[k], &dep[k], &err) : sl_png_read(paths[k], &img[k], &err);
    if (st == SL_OK) {
        int aw = depth ? dep[0].width : img[0].width, ah = depth ? dep[0].height : img[0].height;
        int bw = depth ? dep[1].width : img[1].width, bh = depth ? dep[1].height : img[1].height;
        if (aw != bw || ah != bh)
            st = sl_err_set(&err, SL_ERR_INVALID, "size mismatch: %s is %dx%d, %s is %dx%d",
                            paths[0], aw, ah, paths[1], bw, bh);
    }
    if (st == SL_OK)
        st = depth ? sl_diff_depths(&dep[0], &dep[1], threshold, &r, heat_path ? &heat : NULL, &err)
                   : sl_diff_images_covered(&img[0], &img[1], threshold, background_set ? background : NULL, &r,
                                            heat_path ? &heat : NULL, &err);
    if (st == SL_OK && heat_path)
        st = sl_png_write(heat_path, heat, r.width, r.height, &err);
    if (st != SL_OK) {
        fprintf(stderr, "sightline-diff: %s\n", err.message);
        goto done;
    }

    cJSON *json = cJSON_CreateObject();
    cJSON *failed = NULL;
    if (!json)
        goto oom;
    cJSON_AddStringToObject(json, "kind", depth ? "depth" : "color");
    cJSON_AddStringToObject(json, "a", paths[0]);
    cJSON_AddStringToObject(json, "b", paths[1]);
    cJSON_AddNumberToObject(json, "width", r.width);
    cJSON_AddNumberToObject(json, "height", r.height);
    add_number(json, "mean_abs", r.mean_abs);
    add_number(json, "max_abs", r.max_abs);
    add_number(json, "psnr_db", r.psnr_db);
    add_number(json, "bad_threshold", threshold);
    add_number(json, "bad_pct", r.bad_pct);
    cJSON_AddNumberToObject(json, "bad_count", (double)r.bad_count);
    cJSON_AddNumberToObject(json, "compared", (double)r.compared);
    cJSON_AddNumberToObject(json, "pixels", (double)r.pixels);
    if (!depth && background_set) {
        cJSON *bg = cJSON_AddArrayToObject(json, "background");
        for (int c = 0; c < 3 && bg; c++)
            cJSON_AddItemToArray(bg, cJSON_CreateNumber(background[c]));
        cJSON_AddNumberToObject(json, "covered", (double)r.compared);
        add_number(json, "frame_mean_abs", r.frame_mean_abs);
        add_number(json, "frame_bad_pct", r.frame_bad_pct);
        if (r.compared == r.pixels)
            fprintf(stderr, "sightline-diff: note: no pixel is background %d,%d,%d in both images; "
                            "every pixel is compared\n", background[0], background[1], background[2]);
    }
    if (depth) {
        cJSON_AddNumberToObject(json, "both_hit", (double)r.both_hit);
        cJSON_AddNumberToObject(json, "coverage_mismatch", (double)r.coverage_mismatch);
        add_number(json, "coverage_mismatch_pct", r.coverage_mismatch_pct);
    }
    if (heat_path)
        cJSON_AddStringToObject(json, "diff", heat_path);

    const double measured[LIM_COUNT] = {
        [LIM_MEAN] = r.mean_abs, [LIM_BAD_PCT] = r.bad_pct,
        [LIM_COVERAGE_PCT] = r.coverage_mismatch_pct, [LIM_ABS] = r.max_abs,
    };
    cJSON *lims = cJSON_AddObjectToObject(json, "limits");
    failed = cJSON_CreateArray();
    if (!lims || !failed)
        goto oom;
    for (int k = 0; k < LIM_COUNT; k++) {
        if (!limits[k].set || (k == LIM_COVERAGE_PCT && !depth))
            continue;
        cJSON_AddNumberToObject(lims, limits[k].name, limits[k].value);
        if (measured[k] > limits[k].value)
            cJSON_AddItemToArray(failed, cJSON_CreateString(limits[k].name));
    }
    if (coverage_implicit)
        cJSON_AddBoolToObject(lims, "max_coverage_pct_implicit", 1);
    int pass = cJSON_GetArraySize(failed) == 0;
    cJSON_AddBoolToObject(json, "pass", pass);
    cJSON_AddItemToObject(json, "failed", failed);
    failed = NULL;
    char *text = cJSON_Print(json);
    if (!text)
        goto oom;
    printf("%s\n", text);
    cJSON_free(text);
    cJSON_Delete(json);
    code = pass ? EXIT_PASS : EXIT_LIMIT;
    goto done;
oom:
    fprintf(stderr, "sightline-diff: out of memory formatting JSON\n");
    cJSON_Delete(failed);
    cJSON_Delete(json);
done:
    free(heat);
    for (int k = 0; k < 2; k++) {
        sl_image_deinit(&img[k]);
        sl_depth_image_deinit(&dep[k]);
    }
    return code;
}
