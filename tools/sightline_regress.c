/* sightline_regress.c — a frame-diff regression runner: sightline-regress SUITE_DIR [options].
 *
 *   sightline-regress SUITE_DIR [--update] [--junit report.xml] [--jobs N] [--out DIR] [--render EXE]
 *
 * Renders every case of the suite (tools/regress/regress.h: scenes or paths
 * with goldens in SUITE_DIR/golden/ and per-case limits) through
 * sightline-render child processes, compares each frame with its golden by
 * the metrics of sightline-diff (renderer/image/sl_diff.h: colour over the
 * covered pixels when the suite names a background; depth when a case asks),
 * prints one line per case and a summary, writes heat maps of failures and
 * an HTML report (golden, new, heat map side by side) into DIR (default
 * ./sightline-regress-out), and JUnit XML with --junit. --update rewrites
 * the goldens from the new renders and says which changed (any pixel) or
 * were new. EXE defaults to the sightline-render next to this program.
 * Exit: 0 every case passed (or --update finished), 1 a case failed or
 * could not render, 2 bad usage or a bad suite. Single-threaded (the
 * renders run in child processes, --jobs at once).
 */
#include <errno.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/sl_clock.h"
#include "image/sl_diff.h"
#include "image/sl_image.h"
#include "regress/regress.h"

#define EXIT_PASS 0
#define EXIT_FAILED 1
#define EXIT_BAD 2

typedef struct options {
    const char *suite, *junit, *out, *render;
    int update, jobs;
} options;

static int usage(const char *why)
{
    if (why)
        fprintf(stderr, "sightline-regress: %s\n", why);
    fprintf(stderr, "usage: sightline-regress SUITE_DIR [--update] [--junit report.xml] [--jobs N] [--out DIR]\n"
                    "                         [--render path/to/sightline-render]\n"
                    "exit: 0 all passed (or --update done), 1 a case failed or did not render, 2 bad usage or suite\n");
    return EXIT_BAD;
}

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.out = "sightline-regress-out", .jobs = 1};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(NULL);
            return -1;
        }
        if (strcmp(a, "--update") == 0) {
            o->update = 1;
            continue;
        }
        if (strncmp(a, "--", 2) != 0) {
            if (o->suite)
                return usage("one suite folder only");
            o->suite = a;
            continue;
        }
        if (i + 1 >= argc)
            return usage("an option lacks its value");
        const char *v = argv[++i];
        if (strcmp(a, "--junit") == 0)
            o->junit = v;
        else if (strcmp(a, "--out") == 0)
            o->out = v;
        else if (strcmp(a, "--render") == 0)
            o->render = v;
        else if (strcmp(a, "--jobs") == 0) {
            char *end = NULL;
            long n = strtol(v, &end, 10);
            if (!end || *end || n < 1 || n > 64)
                return usage("--jobs must be an integer in [1, 64]");
            o->jobs = (int)n;
        } else
            return usage("unknown option");
    }
    return o->suite ? 0 : usage("the suite folder is required");
}

/* sightline-render next to this program (/proc/self/exe). */
static int default_render(char *out, size_t size)
{
    char self[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0)
        return 0;
    self[n] = '\0';
    snprintf(out, size, "%s/sightline-render", dirname(self));
    return access(out, X_OK) == 0;
}

static int make_dir(const char *path)
{
    return mkdir(path, 0755) == 0 || errno == EEXIST;
}

/* The file of frame f of case c: root/NAME.ext, or root/NAME/%05d.ext for a path. */
static void frame_file(char *out, size_t size, const char *root, const regress_case *c, int f, const char *ext)
{
    if (c->is_path)
        snprintf(out, size, "%s/%s/%05d%s", root, c->name, f, ext);
    else
        snprintf(out, size, "%s/%s%s", root, c->name, ext);
}

static int file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static sl_status copy_png(const char *from, const char *to, sl_err *err)
{
    sl_image img = {0};
    sl_status st = sl_png_read(from, &img, err);
    if (st == SL_OK)
        st = sl_png_write(to, img.rgba, img.width, img.height, err);
    sl_image_deinit(&img);
    return st;
}

static sl_status copy_pfm(const char *from, const char *to, sl_err *err)
{
    sl_depth_image d = {0};
    sl_status st = sl_pfm_read(from, &d, err);
    if (st == SL_OK)
        st = sl_pfm_write(to, d.values, d.width, d.height, err);
    sl_depth_image_deinit(&d);
    return st;
}

/* Colour comparison of one frame; *fails gets which limit (NULL: none). heat written for a failure. */
static sl_status compare_colour(const regress_case *c, const char *golden, const char *fresh, sl_diff_result *d,
                                uint8_t **heat, const char **fails, sl_err *err)
{
    sl_image a = {0}, b = {0};
    sl_status st = sl_png_read(golden, &a, err);
    if (st == SL_OK)
        st = sl_png_read(fresh, &b, err);
    uint8_t bg[3] = {(uint8_t)c->limits.background[0], (uint8_t)c->limits.background[1],
                     (uint8_t)c->limits.background[2]};
    if (st == SL_OK)
        st = sl_diff_images_covered(&a, &b, c->limits.bad_threshold, c->limits.has_background ? bg : NULL, d, heat,
                                    err);
    sl_image_deinit(&a);
    sl_image_deinit(&b);
    *fails = NULL;
    if (st != SL_OK)
        return st;
    if (d->mean_abs > c->limits.max_mean)
        *fails = "max_mean";
    else if (d->bad_pct > c->limits.max_bad_pct)
        *fails = "max_bad_pct";
    else if (c->limits.max_abs >= 0 && d->max_abs > c->limits.max_abs)
        *fails = "max_abs";
    return SL_OK;
}

static sl_status compare_depth(const regress_case *c, const char *golden, const char *fresh, sl_diff_result *d,
                               const char **fails, sl_err *err)
{
    sl_depth_image a = {0}, b = {0};
    sl_status st = sl_pfm_read(golden, &a, err);
    if (st == SL_OK)
        st = sl_pfm_read(fresh, &b, err);
    if (st == SL_OK)
        st = sl_diff_depths(&a, &b, c->limits.depth_bad_threshold, d, NULL, err);
    sl_depth_image_deinit(&a);
    sl_depth_image_deinit(&b);
    *fails = NULL;
    if (st != SL_OK)
        return st;
    if (d->mean_abs > c->limits.depth_max_mean)
        *fails = "depth.max_mean";
    else if (d->bad_pct > c->limits.depth_max_bad_pct)
        *fails = "depth.max_bad_pct";
    else if (d->coverage_mismatch_pct > c->limits.depth_max_coverage_pct)
        *fails = "depth.max_coverage_pct";
    return SL_OK;
}

/* Compares (or, with update, refreshes) every frame of case c; fills r. */
static void check_case(const options *o, const regress_suite *s, const regress_case *c, regress_result *r)
{
    char golden[REGRESS_PATH_MAX + 256], fresh[REGRESS_PATH_MAX + 256], gdir[REGRESS_PATH_MAX + 64];
    sl_err err = {0};
    snprintf(gdir, sizeof gdir, "%s/golden", s->dir);
    char ndir[REGRESS_PATH_MAX + 64];
    snprintf(ndir, sizeof ndir, "%s/new", o->out);
    double worst = -1.0;
    int changed = 0, created = 0;
    r->outcome = o->update ? REGRESS_UNCHANGED : REGRESS_PASS;
    if (o->update) {
        make_dir(gdir);
        snprintf(golden, sizeof golden, "%s/%s", gdir, c->name);
        if (c->is_path)
            make_dir(golden);
    }
    for (int f = 0; f < c->frames; f++) {
        frame_file(golden, sizeof golden, gdir, c, f, ".png");
        frame_file(fresh, sizeof fresh, ndir, c, f, ".png");
        if (!file_exists(golden)) {
            if (!o->update) {
                r->outcome = REGRESS_FAIL;
                snprintf(r->message, sizeof r->message, "no golden %.440s (run with --update to make it)", golden);
                return;
            }
            created = 1;
        }
        sl_diff_result d = {0};
        uint8_t *heat = NULL;
        const char *fails = NULL;
        if (!created && compare_colour(c, golden, fresh, &d, &heat, &fails, &err) != SL_OK) {
            r->outcome = REGRESS_ERROR;
            snprintf(r->message, sizeof r->message, "frame %d: %.480s", f, err.message);
            free(heat);
            return;
        }
        if (o->update) {
            free(heat);
            if (created || d.max_abs > 0) {
                changed |= !created;
                if (copy_png(fresh, golden, &err) != SL_OK) {
                    r->outcome = REGRESS_ERROR;
                    snprintf(r->message, sizeof r->message, "%.500s", err.message);
                    return;
                }
            }
            if (d.mean_abs > worst) {
                worst = d.mean_abs;
                r->worst_frame = f;
                r->mean = d.mean_abs;
            }
            continue;
        }
        int worse = fails ? (r->outcome != REGRESS_FAIL || d.mean_abs > r->mean) : (r->outcome == REGRESS_PASS && d.mean_abs > worst);
        if (worse) {
            worst = d.mean_abs;
            r->worst_frame = f;
            r->mean = d.mean_abs;
            r->max = d.max_abs;
            r->bad_pct = d.bad_pct;
            if (fails) {
                r->outcome = REGRESS_FAIL;
                snprintf(r->message, sizeof r->message, "frame %d: %s exceeded (mean %.3f, max %.0f, bad %.3f %%)", f,
                         fails, d.mean_abs, d.max_abs, d.bad_pct);
                char heat_path[REGRESS_PATH_MAX + 128], copy[REGRESS_PATH_MAX + 128];
                snprintf(heat_path, sizeof heat_path, "%s/heat/%s.png", o->out, c->name);
                sl_png_write(heat_path, heat, d.width, d.height, &err);
                snprintf(copy, sizeof copy, "%s/golden/%s.png", o->out, c->name); /* beside the report */
                copy_png(golden, copy, &err);
            }
        }
        free(heat);
        created = 0;
    }
    if (c->limits.depth) {
        frame_file(golden, sizeof golden, gdir, c, 0, ".pfm");
        frame_file(fresh, sizeof fresh, ndir, c, 0, ".pfm");
        if (o->update) {
            sl_diff_result d = {0};
            const char *fails = NULL;
            int same = file_exists(golden) && compare_depth(c, golden, fresh, &d, &fails, &err) == SL_OK &&
                       d.max_abs == 0 && d.coverage_mismatch == 0;
            if (!file_exists(golden))
                created = 1;
            else if (!same)
                changed = 1;
            if (!same && copy_pfm(fresh, golden, &err) != SL_OK) {
                r->outcome = REGRESS_ERROR;
                snprintf(r->message, sizeof r->message, "%.500s", err.message);
                return;
            }
        } else if (!file_exists(golden)) {
            r->outcome = REGRESS_FAIL;
            snprintf(r->message, sizeof r->message, "no golden %.440s (run with --update to make it)", golden);
            return;
        } else {
            sl_diff_result d = {0};
            const char *fails = NULL;
            if (compare_depth(c, golden, fresh, &d, &fails, &err) != SL_OK) {
                r->outcome = REGRESS_ERROR;
                snprintf(r->message, sizeof r->message, "depth: %.490s", err.message);
                return;
            }
            r->depth_mean = d.mean_abs;
            r->depth_bad_pct = d.bad_pct;
            r->depth_coverage_pct = d.coverage_mismatch_pct;
            if (fails && r->outcome == REGRESS_PASS) {
                r->outcome = REGRESS_FAIL;
                snprintf(r->message, sizeof r->message, "depth: %s exceeded (mean %.3g, bad %.3f %%, coverage %.3f %%)",
                         fails, d.mean_abs, d.bad_pct, d.coverage_mismatch_pct);
            }
        }
    }
    if (o->update) {
        r->outcome = changed || created || worst < 0 ? REGRESS_UPDATED : REGRESS_UNCHANGED;
        snprintf(r->message, sizeof r->message, "%s",
                 changed ? "golden changed" : r->outcome == REGRESS_UPDATED ? "golden written (new)" : "golden unchanged");
    } else if (r->outcome == REGRESS_PASS) {
        snprintf(r->message, sizeof r->message, "mean %.3f, max %.0f, bad %.3f %%", r->mean, r->max, r->bad_pct);
    }
}

int main(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc != 0)
        return rc < 0 ? EXIT_PASS : rc;
    char render[PATH_MAX];
    if (o.render)
        snprintf(render, sizeof render, "%s", o.render);
    else if (!default_render(render, sizeof render))
        return usage("no sightline-render next to this program (give --render)");
    regress_suite suite;
    sl_err err = {0};
    if (regress_suite_load(o.suite, &suite, &err) != SL_OK) {
        fprintf(stderr, "sightline-regress: %s\n", err.message);
        return EXIT_BAD;
    }
    const char *sub[] = {"", "/new", "/logs", "/heat", "/golden"};
    for (size_t k = 0; k < sizeof sub / sizeof sub[0]; k++) {
        char dir[PATH_MAX];
        snprintf(dir, sizeof dir, "%s%s", o.out, sub[k]);
        if (!make_dir(dir)) {
            fprintf(stderr, "sightline-regress: cannot create %s: %s\n", dir, strerror(errno));
            regress_suite_free(&suite);
            return EXIT_BAD;
        }
    }
    regress_result *results = calloc((size_t)suite.count, sizeof *results);
    if (!results) {
        regress_suite_free(&suite);
        return usage("out of memory");
    }
    double t0 = sl_clock_ms();
    regress_render_all(&suite, render, o.out, o.jobs, results);
    int passed = 0, failed = 0, errors = 0, updated = 0;
    for (int i = 0; i < suite.count; i++) {
        if (results[i].outcome != REGRESS_ERROR)
            check_case(&o, &suite, &suite.cases[i], &results[i]);
        const regress_result *r = &results[i];
        static const char *const label[] = {"PASS", "FAIL", "ERROR", "UPDATED", "same"};
        printf("%-7s %s: %s (%.1f s)\n", label[r->outcome], suite.cases[i].name, r->message, r->seconds);
        passed += r->outcome == REGRESS_PASS || r->outcome == REGRESS_UNCHANGED;
        failed += r->outcome == REGRESS_FAIL;
        errors += r->outcome == REGRESS_ERROR;
        updated += r->outcome == REGRESS_UPDATED;
    }
    double seconds = (sl_clock_ms() - t0) / 1000.0;
    if (o.update)
        printf("sightline-regress %s: %d cases, %d goldens updated, %d unchanged, %d errors in %.1f s\n", suite.name,
               suite.count, updated, passed, errors, seconds);
    else
        printf("sightline-regress %s: %d cases, %d passed, %d failed, %d errors in %.1f s (report: %s/index.html)\n",
               suite.name, suite.count, passed, failed, errors, seconds, o.out);
    int exit_code = failed || errors ? EXIT_FAILED : EXIT_PASS;
    if (regress_write_html(&suite, results, o.out, &err) != SL_OK ||
        (o.junit && regress_write_junit(&suite, results, seconds, o.junit, &err) != SL_OK)) {
        fprintf(stderr, "sightline-regress: %s\n", err.message);
        exit_code = EXIT_BAD;
    }
    free(results);
    regress_suite_free(&suite);
    return exit_code;
}
