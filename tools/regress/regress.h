/* regress.h — the parts of sightline-regress (tools/sightline_regress.c): a suite, its cases, their results.
 *
 * A suite is a folder: every *.json in it except suite.json and *.expect.json
 * is a case (a scene, or a scene with a path), and so is every
 * NAME.expect.json that names a scene elsewhere ("scene": a path relative to
 * the suite, e.g. "../tornado.json", with optional "set": ["params.sides=6",
 * ...], sightline-render's overrides), with its golden image(s) in
 * golden/: NAME.png (and NAME.pfm when the case checks depth), or for a
 * path golden/NAME/00000.png, 00001.png ... one a frame. suite.json (optional)
 * holds the defaults of the limits, NAME.expect.json (optional) a case's
 * own; keys: max_mean, max_bad_pct, bad_threshold, max_abs (colour, 0..255,
 * over the covered pixels when background is set), background [R, G, B]
 * or null, samples (MSAA, 0..16), depth {max_mean, max_bad_pct,
 * bad_threshold, max_coverage_pct} (depth is checked only when given; not
 * for paths), timeout_s; an expect file also scene and set. Unknown keys are
 * errors (a typo must not loosen a limit), and so is an expect file that
 * names neither a NAME.json beside it nor a scene. Single-threaded.
 */
#ifndef REGRESS_H
#define REGRESS_H

#include <stddef.h>

#include "core/sl_status.h"

#define REGRESS_MAX_CASES 4096
#define REGRESS_NAME_MAX 128
#define REGRESS_PATH_MAX 4096
#define REGRESS_MAX_SETS 8
#define REGRESS_SET_MAX 256

typedef struct regress_limits {
    double max_mean, max_bad_pct, bad_threshold, max_abs; /* max_abs < 0: no limit */
    int has_background, background[3];
    int samples;
    int depth;                                             /* check depth */
    double depth_max_mean, depth_max_bad_pct, depth_bad_threshold, depth_max_coverage_pct;
    double timeout_s;
} regress_limits;

typedef struct regress_case {
    char name[REGRESS_NAME_MAX];        /* file name without .json */
    char scene[REGRESS_PATH_MAX];       /* the scene file */
    char sets[REGRESS_MAX_SETS][REGRESS_SET_MAX]; /* --set overrides (expect file "set") */
    int set_count;
    int is_path;                        /* the scene has a "path" */
    int frames;                         /* 1, or the path's frame count */
    regress_limits limits;
} regress_case;

typedef struct regress_suite {
    char dir[REGRESS_PATH_MAX];
    char name[REGRESS_NAME_MAX];        /* the folder's last component */
    regress_case *cases;                /* owned, sorted by name */
    int count;
} regress_suite;

/* Loads the folder's suite.json, cases and expect files. SL_ERR_INVALID /
 * SL_ERR_IO naming the file and field on a bad suite; no cases is an error. */
sl_status regress_suite_load(const char *dir, regress_suite *suite, sl_err *err);
void regress_suite_free(regress_suite *suite);

/* What happened to one case. */
typedef enum regress_outcome { REGRESS_PASS, REGRESS_FAIL, REGRESS_ERROR, REGRESS_UPDATED, REGRESS_UNCHANGED } regress_outcome;

typedef struct regress_result {
    regress_outcome outcome;
    double seconds;                     /* render wall time */
    int worst_frame;                    /* the frame the metrics below are of */
    double mean, max, bad_pct;          /* colour, of the worst frame */
    double depth_mean, depth_bad_pct, depth_coverage_pct;
    char message[512];                  /* why it failed or erred; what --update did */
} regress_result;

/* Renders every case with sightline-render (render_exe) as child processes,
 * at most jobs at once, each killed after its timeout: new images go to
 * out_dir/new/NAME.png (.pfm; NAME/%05d.png for paths), logs to
 * out_dir/logs/NAME.log. results[i].outcome is REGRESS_ERROR (message set)
 * for a render that failed, else left REGRESS_PASS for comparison. */
void regress_render_all(const regress_suite *suite, const char *render_exe, const char *out_dir, int jobs,
                        regress_result *results);

/* The JUnit XML report (one testcase a case; failure / error elements). */
sl_status regress_write_junit(const regress_suite *suite, const regress_result *results, double seconds,
                              const char *path, sl_err *err);
/* out_dir/index.html: a row per case, golden / new / heat map side by side for failures. */
sl_status regress_write_html(const regress_suite *suite, const regress_result *results, const char *out_dir,
                             sl_err *err);

#endif
