/* test_diff.c — image comparison metrics (renderer/image/diff.c) and the sightline-diff tool.
 *
 * Metrics are checked on constructed images whose answers are known in closed
 * form (one pixel off by 40, a constant offset of 10, hand-placed coverage
 * holes, +5 on every drawn pixel of a mostly background frame) and on random images against an independent brute-force reference
 * in double (bound: 1e-9 relative). The tool is run as a process from
 * $SIGHTLINE_BINARY_DIR/bin/sightline-diff: exit codes 0/1/2 and its JSON are
 * checked. Temporary files go to a mkdtemp folder under /tmp. Single-threaded.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "image/sl_diff.h"
#include "image/sl_image.h"
#include "sl_test.h"

static char tmpdir[64];

static const char *tmp_path(const char *name)
{
    static char buf[8][256];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 256, "%s/%s", tmpdir, name);
    return p;
}

static uint32_t rng = 777u;
static uint32_t rand_u32(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

static sl_image make_image(int w, int h, uint8_t grey)
{
    sl_image img = {w, h, malloc((size_t)w * h * 4)};
    for (int i = 0; i < w * h; i++) {
        img.rgba[i * 4 + 0] = img.rgba[i * 4 + 1] = img.rgba[i * 4 + 2] = grey;
        img.rgba[i * 4 + 3] = 255;
    }
    return img;
}

static sl_depth_image make_depth(int w, int h, float v)
{
    sl_depth_image img = {w, h, malloc((size_t)w * h * sizeof(float))};
    for (int i = 0; i < w * h; i++)
        img.values[i] = v;
    return img;
}

static void test_colour_one_pixel(void)
{
    enum { W = 16, H = 8, N = W * H };
    sl_image a = make_image(W, H, 100), b = make_image(W, H, 100);
    b.rgba[(3 * W + 5) * 4 + 1] = 140;                 /* G of one pixel +40 */
    b.rgba[(3 * W + 5) * 4 + 0] = 110;                 /* R +10: the max over RGB is 40 */
    b.rgba[(0 * W + 0) * 4 + 3] = 0;                   /* alpha is ignored */
    sl_diff_result r;
    sl_err err = {0};
    uint8_t *heat = NULL;
    SL_CHECK(sl_diff_images(&a, &b, 8.0, &r, &heat, &err) == SL_OK);
    SL_CHECK(r.width == W && r.height == H);
    SL_CHECK_NEAR(r.max_abs, 40.0, 0.0);
    SL_CHECK_NEAR(r.mean_abs, 40.0 / N, 1e-12);
    SL_CHECK(r.bad_count == 1 && r.compared == N);
    SL_CHECK_NEAR(r.bad_pct, 100.0 / N, 1e-12);
    double mse = (40.0 * 40.0 + 10.0 * 10.0) / (3.0 * N);
    SL_CHECK_NEAR(r.psnr_db, 10.0 * log10(255.0 * 255.0 / mse), 1e-9);
    SL_CHECK(r.coverage_mismatch == 0);

    /* Heat: equal pixels black (opaque), the one differing pixel white (it is the max). */
    SL_CHECK(heat != NULL);
    if (heat) {
        int black = 1;
        for (int i = 0; i < N; i++)
            if (i != 3 * W + 5)
                black &= heat[i * 4] == 0 && heat[i * 4 + 1] == 0 && heat[i * 4 + 2] == 0 && heat[i * 4 + 3] == 255;
        SL_CHECK_MSG(black, "equal pixels must be black in the heat map");
        const uint8_t *p = heat + (3 * W + 5) * 4;
        SL_CHECK(p[0] == 255 && p[1] == 255 && p[2] == 255);
    }
    free(heat);

    /* Threshold equal to the difference: not bad (strictly greater). */
    SL_CHECK(sl_diff_images(&a, &b, 40.0, &r, NULL, &err) == SL_OK);
    SL_CHECK(r.bad_count == 0 && r.bad_pct == 0.0);
    SL_CHECK(sl_diff_images(&a, &b, 39.5, &r, NULL, &err) == SL_OK && r.bad_count == 1);

    /* Threshold above the max: the heat map is scaled by the threshold, so the pixel is red, not white. */
    SL_CHECK(sl_diff_images(&a, &b, 160.0, &r, &heat, &err) == SL_OK);
    if (heat) {
        const uint8_t *p = heat + (3 * W + 5) * 4;
        SL_CHECK_MSG(p[0] > 100 && p[1] < 255 && p[2] == 0, "heat (%d,%d,%d)", p[0], p[1], p[2]);
    }
    free(heat);
    sl_image_deinit(&a);
    sl_image_deinit(&b);
}

static void test_colour_identical_and_offset(void)
{
    sl_image a = make_image(10, 7, 50), b = make_image(10, 7, 50);
    sl_diff_result r;
    sl_err err = {0};
    SL_CHECK(sl_diff_images(&a, &b, 8.0, &r, NULL, &err) == SL_OK);
    SL_CHECK(isinf(r.psnr_db) && r.psnr_db > 0);
    SL_CHECK(r.mean_abs == 0.0 && r.max_abs == 0.0 && r.bad_count == 0);

    for (int i = 0; i < 10 * 7 * 4; i++)
        if (i % 4 != 3)
            b.rgba[i] = 60;
    SL_CHECK(sl_diff_images(&a, &b, 8.0, &r, NULL, &err) == SL_OK);
    SL_CHECK_NEAR(r.psnr_db, 20.0 * log10(255.0 / 10.0), 1e-9);
    SL_CHECK_NEAR(r.mean_abs, 10.0, 1e-12);
    SL_CHECK(r.bad_count == 70);
    SL_CHECK_NEAR(r.bad_pct, 100.0, 1e-12);

    /* Size mismatch and bad arguments. */
    sl_image c = make_image(7, 10, 50);
    uint8_t *heat = (uint8_t *)&r;
    SL_CHECK(sl_diff_images(&a, &c, 8.0, &r, &heat, &err) == SL_ERR_INVALID);
    SL_CHECK(heat == NULL);
    SL_CHECK(strstr(err.message, "10x7") && strstr(err.message, "7x10"));
    SL_CHECK(sl_diff_images(&a, &b, -1.0, &r, NULL, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_diff_images(&a, &b, NAN, &r, NULL, &err) == SL_ERR_INVALID);
    sl_image empty = {0};
    SL_CHECK(sl_diff_images(&a, &empty, 8.0, &r, NULL, &err) == SL_ERR_INVALID);
    sl_image_deinit(&a);
    sl_image_deinit(&b);
    sl_image_deinit(&c);
}

/* Covered pixels (a background colour given): a 10x10 frame of background
 * with 10 drawn pixels, +5 on each in b: the whole-frame mean is 0.5, the
 * covered mean 5. A pixel drawn in one image only is covered; a pixel equal
 * to the background in both is not, even where the other channels of the
 * background would be close. */
static void test_colour_covered(void)
{
    enum { W = 10, H = 10, N = W * H };
    static const uint8_t bg[3] = {26, 26, 31};
    sl_image a = make_image(W, H, 0), b = make_image(W, H, 0);
    for (int i = 0; i < N; i++)
        for (int c = 0; c < 3; c++)
            a.rgba[i * 4 + c] = b.rgba[i * 4 + c] = bg[c];
    for (int k = 0; k < 10; k++) {
        for (int c = 0; c < 3; c++) {
            a.rgba[(7 * k) * 4 + c] = 100;
            b.rgba[(7 * k) * 4 + c] = 105;
        }
    }
    sl_diff_result r;
    sl_err err = {0};
    SL_CHECK(sl_diff_images_covered(&a, &b, 4.0, bg, &r, NULL, &err) == SL_OK);
    SL_CHECK(r.compared == 10 && r.both_hit == 10 && r.pixels == N);
    SL_CHECK_NEAR(r.mean_abs, 5.0, 1e-12);
    SL_CHECK_NEAR(r.frame_mean_abs, 0.5, 1e-12);
    SL_CHECK(r.bad_count == 10);
    SL_CHECK_NEAR(r.bad_pct, 100.0, 1e-12);
    SL_CHECK_NEAR(r.frame_bad_pct, 10.0, 1e-12);
    SL_CHECK_NEAR(r.psnr_db, 20.0 * log10(255.0 / 5.0), 1e-9);
    /* Without a background: the whole frame, as sl_diff_images. */
    SL_CHECK(sl_diff_images_covered(&a, &b, 4.0, NULL, &r, NULL, &err) == SL_OK);
    SL_CHECK(r.compared == N);
    SL_CHECK_NEAR(r.mean_abs, 0.5, 1e-12);
    SL_CHECK_NEAR(r.bad_pct, 10.0, 1e-12);
    SL_CHECK(sl_diff_images(&a, &b, 4.0, &r, NULL, &err) == SL_OK && r.compared == N);
    /* Drawn in b only (a missing line): covered, off by |100 - 26| = 74 in R. */
    for (int c = 0; c < 3; c++)
        b.rgba[(5 * W + 5) * 4 + c] = 100;
    SL_CHECK(sl_diff_images_covered(&a, &b, 4.0, bg, &r, NULL, &err) == SL_OK);
    SL_CHECK(r.compared == 11 && r.max_abs == 74.0);
    /* Both all background: nothing compared, a pass with mean 0. */
    sl_image c = make_image(W, H, 0);
    for (int i = 0; i < N; i++)
        for (int k = 0; k < 3; k++)
            c.rgba[i * 4 + k] = bg[k];
    SL_CHECK(sl_diff_images_covered(&c, &c, 4.0, bg, &r, NULL, &err) == SL_OK);
    SL_CHECK(r.compared == 0 && r.mean_abs == 0.0 && r.bad_pct == 0.0 && isinf(r.psnr_db) && r.pixels == N);
    /* One channel off the background (alpha does not count) is covered. */
    c.rgba[3] = 0;
    c.rgba[4 + 2] = 32;
    SL_CHECK(sl_diff_images_covered(&c, &c, 4.0, bg, &r, NULL, &err) == SL_OK && r.compared == 1);
    sl_image_deinit(&a);
    sl_image_deinit(&b);
    sl_image_deinit(&c);
}

/* Independent reference: per-channel differences kept in an array, then reduced. */
static void test_colour_random_reference(void)
{
    enum { W = 31, H = 17, N = W * H };
    sl_image a = make_image(W, H, 0), b = make_image(W, H, 0);
    for (int i = 0; i < N * 4; i++) {
        a.rgba[i] = (uint8_t)rand_u32();
        b.rgba[i] = (uint8_t)(a.rgba[i] + (int)(rand_u32() % 21) - 10);
    }
    static double diffs[N][3];
    for (int i = 0; i < N; i++)
        for (int c = 0; c < 3; c++)
            diffs[i][c] = fabs((double)a.rgba[i * 4 + c] - (double)b.rgba[i * 4 + c]);
    double mean = 0, max = 0, sse = 0;
    long bad = 0;
    for (int i = 0; i < N; i++) {
        double d = fmax(diffs[i][0], fmax(diffs[i][1], diffs[i][2]));
        mean += d / N;
        max = fmax(max, d);
        bad += d > 5.0;
        sse += diffs[i][0] * diffs[i][0] + diffs[i][1] * diffs[i][1] + diffs[i][2] * diffs[i][2];
    }
    double psnr = 20.0 * log10(255.0) - 10.0 * log10(sse / (3.0 * N));
    sl_diff_result r;
    sl_err err = {0};
    SL_CHECK(sl_diff_images(&a, &b, 5.0, &r, NULL, &err) == SL_OK);
    SL_CHECK_NEAR(r.mean_abs, mean, 1e-9 * mean);
    SL_CHECK_NEAR(r.max_abs, max, 0.0);
    SL_CHECK_NEAR(r.psnr_db, psnr, 1e-9 * psnr);
    SL_CHECK(r.bad_count == bad);
    sl_image_deinit(&a);
    sl_image_deinit(&b);
}

static void test_depth(void)
{
    enum { W = 10, H = 10 };
    sl_depth_image a = make_depth(W, H, 1.0f), b = make_depth(W, H, 1.0f);
    const int only_a_miss[5] = {0, 1, 2, 3, 4};        /* hit in b only */
    const int only_b_miss[3] = {50, 51, 99};           /* hit in a only */
    for (int i = 0; i < 5; i++)
        a.values[only_a_miss[i]] = 0.0f;
    for (int i = 0; i < 3; i++)
        b.values[only_b_miss[i]] = 0.0f;
    a.values[60] = b.values[60] = 0.0f;                /* hit in neither */
    b.values[70] = NAN;                                /* not a hit either */
    b.values[80] = 1.5f;                               /* compared, differs by 0.5 */
    b.values[81] = 1.0005f;                            /* differs by ~5e-4, under 1e-3 */
    a.values[82] = -2.0f;                              /* negative = no hit: mismatch */

    sl_diff_result r;
    sl_err err = {0};
    uint8_t *heat = NULL;
    SL_CHECK(sl_diff_depths(&a, &b, 1e-3, &r, &heat, &err) == SL_OK);
    long mismatch = 5 + 3 + 1 + 1;                     /* + NaN (70) + negative (82) */
    long either = 100 - 1;                             /* all but pixel 60 */
    long both = either - mismatch;
    SL_CHECK_MSG(r.coverage_mismatch == mismatch, "mismatch %ld", r.coverage_mismatch);
    SL_CHECK_NEAR(r.coverage_mismatch_pct, 100.0 * mismatch / either, 1e-12);
    SL_CHECK_MSG(r.compared == either && r.both_hit == both, "compared %ld, both_hit %ld", r.compared, r.both_hit);
    double d81 = fabs((double)1.0005f - 1.0);
    SL_CHECK_NEAR(r.max_abs, 0.5, 0.0);
    SL_CHECK_NEAR(r.mean_abs, (0.5 + d81) / both, 1e-15);
    /* Bad: pixel 80 (0.5 > 1e-3) and every coverage mismatch, over the pixels hit in either. */
    SL_CHECK_MSG(r.bad_count == 1 + mismatch, "bad_count %ld", r.bad_count);
    SL_CHECK_NEAR(r.bad_pct, 100.0 * (1 + mismatch) / either, 1e-12);
    double mse = (0.25 + d81 * d81) / both;
    SL_CHECK_NEAR(r.psnr_db, 10.0 * log10(1.5 * 1.5 / mse), 1e-9);
    if (heat) {
        const uint8_t *p = heat + 0 * 4;
        SL_CHECK(p[0] == 255 && p[1] == 0 && p[2] == 255 && p[3] == 255);   /* magenta */
        p = heat + 51 * 4;
        SL_CHECK(p[0] == 255 && p[1] == 0 && p[2] == 255);
        p = heat + 60 * 4;
        SL_CHECK(p[0] == 0 && p[1] == 0 && p[2] == 0 && p[3] == 255);       /* neither: black */
        p = heat + 10 * 4;
        SL_CHECK(p[0] == 0 && p[1] == 0 && p[2] == 0);                      /* equal: black */
        p = heat + 80 * 4;
        SL_CHECK(p[0] == 255 && p[1] == 255 && p[2] == 255);                /* the max: white */
        p = heat + 81 * 4;
        SL_CHECK(p[0] > 0 && p[2] == 0);                                    /* small: red */
    } else {
        SL_CHECK_MSG(0, "no heat map");
    }
    free(heat);

    /* Identical, and nothing hit at all. */
    SL_CHECK(sl_diff_depths(&a, &a, 1e-3, &r, NULL, &err) == SL_OK);
    SL_CHECK(isinf(r.psnr_db) && r.max_abs == 0.0 && r.coverage_mismatch == 0);
    sl_depth_image z1 = make_depth(4, 4, 0.0f), z2 = make_depth(4, 4, 0.0f);
    SL_CHECK(sl_diff_depths(&z1, &z2, 1e-3, &r, NULL, &err) == SL_OK);
    SL_CHECK(r.compared == 0 && r.coverage_mismatch_pct == 0.0 && r.bad_pct == 0.0 && r.mean_abs == 0.0);

    /* Nothing hit in a, everything in b: no pixel is hit in both, so mean and
     * max are 0 over nothing, but every pixel is bad and a coverage mismatch. */
    sl_depth_image full = make_depth(4, 4, 3.0f);
    SL_CHECK(sl_diff_depths(&z1, &full, 1e-3, &r, NULL, &err) == SL_OK);
    SL_CHECK(r.both_hit == 0 && r.compared == 16 && r.coverage_mismatch == 16);
    SL_CHECK(r.bad_count == 16 && r.bad_pct == 100.0 && r.coverage_mismatch_pct == 100.0);
    SL_CHECK(r.mean_abs == 0.0 && r.max_abs == 0.0);
    /* Half the pixels hit in both (equal), the other half only in b: 50 % bad
     * even with a threshold that no difference exceeds. */
    for (int i = 0; i < 8; i++)
        z1.values[i] = 3.0f;
    SL_CHECK(sl_diff_depths(&z1, &full, 1e9, &r, NULL, &err) == SL_OK);
    SL_CHECK(r.both_hit == 8 && r.compared == 16 && r.bad_count == 8);
    SL_CHECK_NEAR(r.bad_pct, 50.0, 0.0);
    SL_CHECK_NEAR(r.coverage_mismatch_pct, 50.0, 0.0);
    sl_depth_image_deinit(&full);

    SL_CHECK(sl_diff_depths(&a, &z1, 1e-3, &r, NULL, &err) == SL_ERR_INVALID);
    SL_CHECK(strstr(err.message, "sizes differ") != NULL);
    sl_depth_image_deinit(&z1);
    sl_depth_image_deinit(&z2);
    sl_depth_image_deinit(&a);
    sl_depth_image_deinit(&b);
}

/* ---- the sightline-diff process ----------------------------------------- */

static char tool[512];

/* Runs the tool with args; returns the exit status (-1 if it did not exit
 * normally) and the parsed stdout JSON in *json (NULL when not JSON). */
static int run_tool(const char *args, cJSON **json)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s' %s 2>'%s/stderr.txt'", tool, args, tmpdir);
    FILE *p = popen(cmd, "r");
    if (!p)
        return -1;
    static char out[16384];
    size_t n = fread(out, 1, sizeof out - 1, p);
    out[n] = '\0';
    int status = pclose(p);
    *json = n ? cJSON_Parse(out) : NULL;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static int json_has_failed(const cJSON *json, const char *name)
{
    const cJSON *failed = cJSON_GetObjectItemCaseSensitive(json, "failed");
    const cJSON *it;
    cJSON_ArrayForEach(it, failed)
        if (cJSON_IsString(it) && strcmp(it->valuestring, name) == 0)
            return 1;
    return 0;
}

static double json_number(const cJSON *json, const char *name)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(json, name);
    return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

static void test_tool(void)
{
    const char *dir = getenv("SIGHTLINE_BINARY_DIR");
    SL_CHECK_MSG(dir != NULL, "SIGHTLINE_BINARY_DIR is not set (run through ctest)");
    if (!dir)
        return;
    snprintf(tool, sizeof tool, "%s/bin/sightline-diff", dir);

    sl_err err = {0};
    sl_image a = make_image(20, 10, 100), b = make_image(20, 10, 100), c = make_image(10, 20, 100);
    b.rgba[(2 * 20 + 3) * 4] = 140;
    SL_CHECK(sl_png_write(tmp_path("a.png"), a.rgba, 20, 10, &err) == SL_OK);
    SL_CHECK(sl_png_write(tmp_path("b.png"), b.rgba, 20, 10, &err) == SL_OK);
    SL_CHECK(sl_png_write(tmp_path("c.png"), c.rgba, 10, 20, &err) == SL_OK);
    sl_depth_image da = make_depth(8, 8, 2.0f), db = make_depth(8, 8, 2.0f);
    db.values[5] = 0.0f;
    db.values[6] = 2.25f;
    SL_CHECK(sl_pfm_write(tmp_path("a.pfm"), da.values, 8, 8, &err) == SL_OK);
    SL_CHECK(sl_pfm_write(tmp_path("b.pfm"), db.values, 8, 8, &err) == SL_OK);
    FILE *f = fopen(tmp_path("trunc.png"), "wb");
    if (f) {
        fwrite("\x89PNG\r\n\x1a\n\0\0", 1, 10, f);
        fclose(f);
    }

    char args[1024];
    cJSON *j = NULL;
    snprintf(args, sizeof args, "%s/a.png %s/a.png", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    SL_CHECK_MSG(j != NULL, "identical: stdout is not JSON");
    SL_CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(j, "psnr_db")));
    SL_CHECK(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(j, "pass")));
    const cJSON *kind = cJSON_GetObjectItemCaseSensitive(j, "kind");
    SL_CHECK(cJSON_IsString(kind) && strcmp(kind->valuestring, "color") == 0);
    cJSON_Delete(j);

    snprintf(args, sizeof args, "%s/a.png %s/b.png --max-abs 10 --max-mean 1 --diff %s/heat.png",
             tmpdir, tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 1);
    SL_CHECK_MSG(j != NULL, "limit exceeded: stdout is not JSON");
    SL_CHECK(cJSON_IsFalse(cJSON_GetObjectItemCaseSensitive(j, "pass")));
    SL_CHECK(json_has_failed(j, "max_abs") && !json_has_failed(j, "max_mean"));
    SL_CHECK_NEAR(json_number(j, "max_abs"), 40.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "mean_abs"), 40.0 / 200.0, 1e-12);
    SL_CHECK_NEAR(json_number(j, "bad_count"), 1.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "compared"), 200.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "bad_threshold"), 8.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "width"), 20.0, 0.0);
    cJSON_Delete(j);
    sl_image heat = {0};
    SL_CHECK_MSG(sl_png_read(tmp_path("heat.png"), &heat, &err) == SL_OK, "%s", err.message);
    SL_CHECK(heat.width == 20 && heat.height == 10);
    SL_CHECK(heat.rgba && heat.rgba[(2 * 20 + 3) * 4] == 255 && heat.rgba[0] == 0);
    sl_image_deinit(&heat);

    snprintf(args, sizeof args, "%s/a.png %s/b.png --max-abs 50 --bad-threshold 50 --max-bad-pct 0", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    SL_CHECK(j && cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(j, "pass")));
    SL_CHECK_NEAR(json_number(j, "bad_threshold"), 50.0, 0.0);
    cJSON_Delete(j);

    /* --background 100,100,100 (a's colour everywhere): only the one pixel b
     * changed is covered, so the mean over covered pixels is its 40. */
    snprintf(args, sizeof args, "%s/a.png %s/b.png --background 100,100,100 --max-mean 39", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 1);
    SL_CHECK(j && json_has_failed(j, "max_mean"));
    SL_CHECK_NEAR(json_number(j, "mean_abs"), 40.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "covered"), 1.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "compared"), 1.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "pixels"), 200.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "frame_mean_abs"), 40.0 / 200.0, 1e-12);
    SL_CHECK_NEAR(json_number(j, "bad_pct"), 100.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "frame_bad_pct"), 0.5, 1e-12);
    const cJSON *bgj = cJSON_GetObjectItemCaseSensitive(j, "background");
    SL_CHECK(cJSON_IsArray(bgj) && cJSON_GetArraySize(bgj) == 3 && cJSON_GetArrayItem(bgj, 2)->valuedouble == 100.0);
    cJSON_Delete(j);
    /* Without it the same pair passes --max-mean 39 (40 / 200 pixels). */
    snprintf(args, sizeof args, "%s/a.png %s/b.png --max-mean 39", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    SL_CHECK(j && cJSON_GetObjectItemCaseSensitive(j, "covered") == NULL);
    cJSON_Delete(j);
    const char *bad_backgrounds[] = {"1,2", "1,2,3,4", "1,2,256", "-1,2,3", "a,b,c", "1,,3", "1, 2,3", ""};
    for (size_t k = 0; k < sizeof bad_backgrounds / sizeof bad_backgrounds[0]; k++) {
        snprintf(args, sizeof args, "%s/a.png %s/b.png --background '%s'", tmpdir, tmpdir, bad_backgrounds[k]);
        SL_CHECK_MSG(run_tool(args, &j) == 2 && j == NULL, "--background '%s' must be bad usage", bad_backgrounds[k]);
        cJSON_Delete(j);
    }

    /* Depth: kind by magic bytes (the names end in .pfm, but that is not what counts). */
    snprintf(args, sizeof args, "%s/a.pfm %s/b.pfm --max-coverage-pct 1", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 1);
    SL_CHECK_MSG(j != NULL, "depth: stdout is not JSON");
    kind = cJSON_GetObjectItemCaseSensitive(j, "kind");
    SL_CHECK(cJSON_IsString(kind) && strcmp(kind->valuestring, "depth") == 0);
    SL_CHECK_NEAR(json_number(j, "coverage_mismatch"), 1.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "coverage_mismatch_pct"), 100.0 / 64.0, 1e-12);
    SL_CHECK_NEAR(json_number(j, "compared"), 64.0, 0.0);   /* hit in either */
    SL_CHECK_NEAR(json_number(j, "both_hit"), 63.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "bad_count"), 2.0, 0.0);   /* pixel 6 (0.25) + the mismatch */
    SL_CHECK_NEAR(json_number(j, "bad_pct"), 200.0 / 64.0, 1e-12);
    SL_CHECK_NEAR(json_number(j, "max_abs"), 0.25, 0.0);
    SL_CHECK_NEAR(json_number(j, "bad_threshold"), 1e-3, 0.0);
    SL_CHECK(json_has_failed(j, "max_coverage_pct"));
    cJSON_Delete(j);
    snprintf(args, sizeof args, "%s/a.pfm %s/b.pfm --max-coverage-pct 2 --max-abs 0.3", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    cJSON_Delete(j);
    /* --max-bad-pct sees the mismatch as well as the 0.25 difference: 2 of 64 bad (3.125 %). */
    snprintf(args, sizeof args, "%s/a.pfm %s/b.pfm --max-coverage-pct 2 --max-bad-pct 3.2", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    cJSON_Delete(j);
    snprintf(args, sizeof args, "%s/a.pfm %s/b.pfm --max-coverage-pct 2 --max-bad-pct 3", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 1);
    SL_CHECK(j && json_has_failed(j, "max_bad_pct"));
    cJSON_Delete(j);
    snprintf(args, sizeof args, "%s/a.pfm %s/b.pfm --max-coverage-pct 2 --max-bad-pct 3 --bad-threshold 0.5",
             tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    SL_CHECK(j && json_number(j, "bad_count") == 1.0);      /* the mismatch alone */
    cJSON_Delete(j);
    snprintf(args, sizeof args, "%s/a.pfm %s/b.pfm --max-coverage-pct 2 --max-bad-pct 1.5 --bad-threshold 0.5",
             tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 1);
    SL_CHECK(j && json_has_failed(j, "max_bad_pct") && !json_has_failed(j, "max_coverage_pct"));
    cJSON_Delete(j);

    /* An empty depth map against one with hits: the audit's false pass. Mean
     * and max see no pixel hit in both (0), so --max-mean 0 alone must fail
     * through the implicit coverage limit, and --max-bad-pct through the
     * mismatches counted as bad. */
    sl_depth_image empty = make_depth(8, 8, 0.0f);
    SL_CHECK(sl_pfm_write(tmp_path("empty.pfm"), empty.values, 8, 8, &err) == SL_OK);
    snprintf(args, sizeof args, "%s/empty.pfm %s/a.pfm --max-mean 0", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 1);
    SL_CHECK_MSG(j != NULL, "empty vs full: stdout is not JSON");
    SL_CHECK(cJSON_IsFalse(cJSON_GetObjectItemCaseSensitive(j, "pass")));
    SL_CHECK(json_has_failed(j, "max_coverage_pct") && !json_has_failed(j, "max_mean"));
    SL_CHECK_NEAR(json_number(j, "bad_pct"), 100.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "both_hit"), 0.0, 0.0);
    SL_CHECK_NEAR(json_number(j, "coverage_mismatch_pct"), 100.0, 0.0);
    const cJSON *lims = cJSON_GetObjectItemCaseSensitive(j, "limits");
    SL_CHECK(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(lims, "max_coverage_pct_implicit")));
    SL_CHECK(json_number(lims, "max_coverage_pct") == 0.0);
    cJSON_Delete(j);
    snprintf(args, sizeof args, "%s/empty.pfm %s/a.pfm --max-coverage-pct 100 --max-bad-pct 99", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 1);
    SL_CHECK(j && json_has_failed(j, "max_bad_pct") && !json_has_failed(j, "max_coverage_pct"));
    cJSON_Delete(j);
    /* A coverage limit given explicitly replaces the implicit one. */
    snprintf(args, sizeof args, "%s/empty.pfm %s/a.pfm --max-coverage-pct 100 --max-mean 0", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    SL_CHECK(j && !cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(j, "limits"),
                                                    "max_coverage_pct_implicit"));
    cJSON_Delete(j);
    /* No limit at all: metrics only, exit 0. */
    snprintf(args, sizeof args, "%s/empty.pfm %s/a.pfm", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    cJSON_Delete(j);
    /* Identical coverage: the implicit limit does not get in the way. */
    snprintf(args, sizeof args, "%s/a.pfm %s/a.pfm --max-mean 0 --max-abs 0", tmpdir, tmpdir);
    SL_CHECK(run_tool(args, &j) == 0);
    cJSON_Delete(j);
    sl_depth_image_deinit(&empty);

    /* Bad input: exit 2, nothing on stdout. */
    const char *bad[] = {
        "%s/a.png %s/a.pfm",                /* mixed kinds */
        "%s/a.png %s/c.png",                /* size mismatch */
        "%s/a.png %s/missing.png",          /* unreadable */
        "%s/a.png %s/trunc.png",            /* truncated PNG */
        "%s/a.png %s/stderr.txt",           /* neither kind */
        "%s/a.png %s/a.png --max-abs",      /* missing value */
        "%s/a.png %s/a.png --max-abs x",    /* not a number */
        "%s/a.png %s/a.png --frobnicate 1", /* unknown option */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(args, sizeof args, bad[i], tmpdir, tmpdir);
        int code = run_tool(args, &j);
        SL_CHECK_MSG(code == 2, "'%s': exit %d, want 2", bad[i], code);
        SL_CHECK_MSG(j == NULL, "'%s': unexpected JSON on stdout", bad[i]);
        cJSON_Delete(j);
    }
    snprintf(args, sizeof args, "%s/a.png", tmpdir);
    SL_CHECK(run_tool(args, &j) == 2);
    cJSON_Delete(j);

    sl_image_deinit(&a);
    sl_image_deinit(&b);
    sl_image_deinit(&c);
    sl_depth_image_deinit(&da);
    sl_depth_image_deinit(&db);
}

/* p99_abs: the difference at rank floor(0.99 (n - 1)) of the covered pixels
 * sorted; 200 covered pixels with differences 0..199 (over a 0 background,
 * 56 background pixels not counted) give rank 197, difference 197. */
static void test_colour_p99(void)
{
    sl_image a = {.width = 16, .height = 16, .rgba = calloc(16 * 16, 4)}, b = {.width = 16, .height = 16, .rgba = calloc(16 * 16, 4)};
    SL_CHECK(a.rgba && b.rgba);
    if (!a.rgba || !b.rgba)
        return;
    for (int i = 0; i < 200; i++) {
        a.rgba[4 * i] = 255;                   /* covered in a */
        b.rgba[4 * i] = (uint8_t)(255 - i);    /* red differs by i */
    }
    uint8_t bg[3] = {0, 0, 0};
    sl_diff_result r;
    sl_err err;
    SL_CHECK(sl_diff_images_covered(&a, &b, 8.0, bg, &r, NULL, &err) == SL_OK);
    SL_CHECK_MSG(r.compared == 200 && r.p99_abs == 197 && r.max_abs == 199, "compared %ld p99 %g max %g", r.compared,
                 r.p99_abs, r.max_abs);
    free(a.rgba);
    free(b.rgba);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/sl_test_diff_XXXXXX");
    if (!mkdtemp(tmpdir)) {
        fprintf(stderr, "cannot create a temporary folder\n");
        return 1;
    }
    test_colour_one_pixel();
    test_colour_identical_and_offset();
    test_colour_random_reference();
    test_colour_covered();
    test_depth();
    test_tool();
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", tmpdir);
    test_colour_p99();
    SL_TEST_END();
}
