/* sightline_render.c — renders a scene to PNG/JPEG (+ depth PFM, stats JSON) without a server.
 *
 * usage: sightline-render --scene S.json --out frame.png [--depth depth.pfm]
 *          [--frames N] [--stats stats.json] [--set key.path=value ...]
 *          [--samples N] [--data-dir DIR] [--export FILE]
 *        sightline-render --path P.json [--out frames/%05d.png] [--video V.mp4|.webm]
 *          [--crf N] [--stats ...] [--set ...]
 * A scene with a `path` (proto/scene.md "Paths") renders every frame of it,
 * frame k at t = k / fps, to the --out pattern (one %d or %0Nd) and/or into
 * a video (image/sl_video.h: .mp4 H.264, .webm VP9, constant quality --crf);
 * --path is --scene that also requires the path. --video without a path
 * records the --frames N frames (e.g. an orbit_frames turntable) at 24 fps.
 * --export writes the technique's derived geometry after the last frame
 * (sl_pipeline_export), in the one format the technique names (export_ext).
 * A thin main over the renderer library: scene -> dataset -> pipeline. The
 * colour frame uses --samples MSAA (default 4); the depth map is rendered
 * without MSAA so every pixel is the exact centre ray of sl_camera.h.
 * Everything that can be checked before the (possibly long) render is: the
 * arguments, the output paths (known extension, writable: see
 * check_output), the scene, and the GPU's limits
 * for the target size and --samples. It does not retry or fall back.
 * Exit codes (also in --help): 0 ok; 1 usage (bad or missing arguments);
 * 2 bad input (scene, dataset, parameters, output paths, a write that
 * failed, out of memory); 3 GPU (no EGL display or 4.5 context, a bad
 * SIGHTLINE_EGL_DEVICE, a request above the GPU's limits such as --samples,
 * a GL failure). Single-threaded (the render thread is the main thread).
 */
#include <cjson/cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/sl_clock.h"
#include "data/sl_load.h"
#include "image/sl_image.h"
#include "image/sl_video.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "sl_scene.h"

#define MAX_SETS 64
#define SL_RENDER_VIDEO_FPS 24.0 /* --video without a path */

#define EXIT_OK 0
#define EXIT_USAGE 1
#define EXIT_BAD_INPUT 2
#define EXIT_GPU 3

typedef struct options {
    const char *scene, *out, *depth, *stats, *data_dir, *video, *export_path;
    int require_path;           /* --path given */
    int crf;                    /* -1: the codec's default */
    const char *sets[MAX_SETS];
    int set_count, frames, samples, frames_given;
} options;

static void print_usage(FILE *f)
{
    fprintf(f, "usage: sightline-render --scene S.json --out frame.png [--depth depth.pfm] [--frames N]\n"
               "         [--stats stats.json] [--set key.path=value ...] [--samples N] [--data-dir DIR] [--export FILE]\n"
               "       sightline-render --path P.json [--out frames/%%05d.png] [--video V.mp4] [--crf N] [--stats ...]\n"
               "  --path     a scene with a \"path\": every frame of it to the --out pattern (one %%d or %%0Nd)\n"
               "  --video    .mp4 (H.264, CRF 18 by default) or .webm (VP9, CRF 24): every frame, at the path's\n"
               "             fps (24 without a path); even width and height   --crf N  constant quality\n"
               "  --out      .png, or .jpg/.jpeg for JPEG     --depth  .pfm (eye distance, 0 = no hit)\n"
               "  --stats    .json                            --frames N in [1, 100000] (default 1)\n"
               "  --samples  MSAA samples in [0, 16] (default 4; 0 or 1 = none; at most what the GPU offers)\n"
               "  --data-dir where relative dataset paths are looked up (default: the scene's folder)\n"
               "  --export   the technique's derived geometry after the last frame, in the format it names (e.g. .csv)\n"
               "exit: 0 ok, 1 usage, 2 bad input (scene, dataset, parameters, output paths, write failed),\n"
               "      3 GPU (no EGL display or 4.5 context, bad SIGHTLINE_EGL_DEVICE, above a GPU limit such\n"
               "      as --samples, GL failure)\n");
}

static int usage(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int usage(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "sightline-render: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    print_usage(stderr);
    return EXIT_USAGE;
}

/* Strict decimal integer in [lo, hi]: the whole text, no sign tricks. */
static int parse_int(const char *text, int lo, int hi, int *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || v < lo || v > hi || text[0] == ' ' || text[0] == '+')
        return 0;
    *out = (int)v;
    return 1;
}

/* Returns 0 to go on, -1 after --help, else the exit code. */
static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->frames = 1;
    o->crf = -1;
    o->samples = 4;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_usage(stdout);
            return -1;
        }
        if (strncmp(a, "--", 2) != 0)
            return usage("unexpected argument '%s' (every value follows its option, e.g. --scene S.json)", a);
        static const char *const known[] = {"--scene", "--path", "--out", "--depth", "--stats", "--data-dir",
                                            "--frames", "--samples", "--set", "--video", "--crf", "--export", NULL};
        int k = 0;
        while (known[k] && strcmp(a, known[k]) != 0)
            k++;
        if (!known[k])
            return usage("unknown option '%s'", a);
        if (i + 1 >= argc)
            return usage("%s needs a value", a);
        const char *v = argv[++i];
        if (strcmp(a, "--scene") == 0 || strcmp(a, "--path") == 0) {
            if (o->scene)
                return usage("give one of --scene or --path, once");
            o->scene = v;
            o->require_path = strcmp(a, "--path") == 0;
        }
        else if (strcmp(a, "--out") == 0) o->out = v;
        else if (strcmp(a, "--video") == 0) o->video = v;
        else if (strcmp(a, "--crf") == 0) {
            if (!parse_int(v, 0, 63, &o->crf))
                return usage("--crf must be an integer in [0, 63], got '%s'", v);
        }
        else if (strcmp(a, "--depth") == 0) o->depth = v;
        else if (strcmp(a, "--stats") == 0) o->stats = v;
        else if (strcmp(a, "--data-dir") == 0) o->data_dir = v;
        else if (strcmp(a, "--export") == 0) o->export_path = v;
        else if (strcmp(a, "--frames") == 0) {
            if (!parse_int(v, 1, 100000, &o->frames))
                return usage("--frames must be an integer in [1, 100000], got '%s'", v);
            o->frames_given = 1;
        } else if (strcmp(a, "--samples") == 0) {
            if (!parse_int(v, 0, 16, &o->samples))
                return usage("--samples must be an integer in [0, 16], got '%s'", v);
        } else {
            if (o->set_count >= MAX_SETS)
                return usage("too many --set options (at most %d)", MAX_SETS);
            o->sets[o->set_count++] = v;
        }
    }
    if (!o->scene || (!o->out && !o->video))
        return usage("--scene (or --path) and --out (or --video) are required");
    if (o->crf >= 0 && !o->video)
        return usage("--crf sets the quality of --video");
    return 0;
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* An output path must end in one of exts (NULL-terminated), not be a
 * folder, and be writable: an existing file is opened for writing (not
 * truncated); a new one is created and removed again, which also holds for
 * root, whom access() does not refuse, and for read-only or special file
 * systems. Checked before rendering so that a bad path does not cost a
 * render. Prints the reason and returns 0 when not. */
static int check_output(const char *option, const char *path, const char *const *exts)
{
    int known = 0;
    char list[64] = "";
    for (int k = 0; exts[k]; k++) {
        known |= ends_with(path, exts[k]);
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? ", " : "", exts[k]);
    }
    if (!known) {
        fprintf(stderr, "sightline-render: %s %s: unknown extension (expected %s)\n", option, path, list);
        return 0;
    }
    struct stat st;
    if (stat(path, &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            fprintf(stderr, "sightline-render: %s %s: is a folder\n", option, path);
            return 0;
        }
        int fd = open(path, O_WRONLY);
        if (fd < 0) {
            fprintf(stderr, "sightline-render: %s %s: not writable: %s\n", option, path, strerror(errno));
            return 0;
        }
        close(fd);
        return 1;
    }
    char copy[4096];
    if (strlen(path) >= sizeof copy) {
        fprintf(stderr, "sightline-render: %s: path longer than %zu bytes\n", option, sizeof copy - 1);
        return 0;
    }
    snprintf(copy, sizeof copy, "%s", path);
    const char *dir = dirname(copy);
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "sightline-render: %s %s: folder %s does not exist\n", option, path, dir);
        return 0;
    }
    /* A probe file of a unique name in that folder (never the output's
     * own name: another run may be creating it at the same time). */
    char probe[4096 + 32];
    snprintf(probe, sizeof probe, "%s/.sightline-render-XXXXXX", dir);
    int fd = mkstemp(probe);
    if (fd < 0) {
        fprintf(stderr, "sightline-render: %s %s: cannot create files in %s: %s\n", option, path, dir, strerror(errno));
        return 0;
    }
    close(fd);
    unlink(probe);
    return 1;
}

static int check_outputs(const options *o)
{
    static const char *const image_exts[] = {".png", ".jpg", ".jpeg", NULL};
    static const char *const depth_exts[] = {".pfm", NULL};
    static const char *const stats_exts[] = {".json", NULL};
    /* The extension sets are disjoint, so no two outputs can name the same file. */
    static const char *const video_exts[] = {".mp4", ".webm", NULL};
    return (!o->out || check_output("--out", o->out, image_exts)) &&
           (!o->video || check_output("--video", o->video, video_exts)) &&
           (!o->depth || check_output("--depth", o->depth, depth_exts)) &&
           (!o->stats || check_output("--stats", o->stats, stats_exts));
}

/* --export, once the technique is known: it must export, in its own
 * extension (usage errors: 1), to a writable path (bad input: 2). Prints the
 * reason; returns 0 when all hold, else the exit code. */
static int check_export(const options *o, const sl_technique *tech)
{
    if (!o->export_path)
        return 0;
    if (!sl_technique_exports(tech)) {
        char list[256];
        sl_technique_exporters(list, sizeof list);
        fprintf(stderr, "sightline-render: technique '%s' exports nothing (--export is offered by: %s)\n", tech->name,
                list);
        return EXIT_USAGE;
    }
    if (!ends_with(o->export_path, tech->export_ext)) {
        fprintf(stderr, "sightline-render: --export %s: technique '%s' exports %s files (the path must end in %s)\n",
                o->export_path, tech->name, tech->export_ext, tech->export_ext);
        return EXIT_USAGE;
    }
    const char *const others[] = {o->out, o->depth, o->stats, o->video};
    for (int k = 0; k < 4; k++)
        if (others[k] && strcmp(others[k], o->export_path) == 0) {
            fprintf(stderr, "sightline-render: --export %s: also named by another output\n", o->export_path);
            return EXIT_USAGE;
        }
    const char *const exts[] = {tech->export_ext, NULL};
    return check_output("--export", o->export_path, exts) ? 0 : EXIT_BAD_INPUT;
}

/* Exit code of a pipeline (GPU-side) failure: the GPU's (3: GL failure, or
 * a request beyond this GPU's limits) or the input's (2). */
static int exit_for(sl_status st)
{
    return st == SL_ERR_GPU || st == SL_ERR_UNSUPPORTED ? EXIT_GPU : EXIT_BAD_INPUT;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static cJSON *summary(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare_doubles);
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "min", v[0]);
    cJSON_AddNumberToObject(o, "median", n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
    cJSON_AddNumberToObject(o, "max", v[n - 1]);
    return o;
}

/* 1 when the document's camera is in the orbit form, 0 when eye/target, -1 without a camera. */
static int camera_form(const cJSON *root)
{
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    if (!cJSON_IsObject(cam))
        return -1;
    if (cJSON_GetObjectItemCaseSensitive(cam, "orbit"))
        return 1;
    return cJSON_GetObjectItemCaseSensitive(cam, "eye") || cJSON_GetObjectItemCaseSensitive(cam, "target") ? 0 : -1;
}

/* Reads and parses the scene with the overrides applied; prints the reason. */
static int load_scene(const options *o, sl_scene *scene)
{
    sl_err err = {0};
    uint8_t *text = NULL;
    size_t text_size = 0;
    if (sl_read_file(o->scene, 16u << 20, &text, &text_size, &err) != SL_OK) {
        fprintf(stderr, "sightline-render: %s\n", err.message);
        return 0;
    }
    cJSON *root = cJSON_ParseWithLength((const char *)text, text_size);
    free(text);
    if (!root) {
        fprintf(stderr, "sightline-render: %s is not valid JSON\n", o->scene);
        return 0;
    }
    for (int i = 0; i < o->set_count; i++) {
        int before = camera_form(root);
        if (sl_scene_apply_override(root, o->sets[i], &err) != SL_OK) {
            fprintf(stderr, "sightline-render: %s\n", err.message);
            cJSON_Delete(root);
            return 0;
        }
        int after = camera_form(root);
        if (before == 0 && after == 1)
            fprintf(stderr, "sightline-render: note: --set %s replaces the scene's eye/target/up camera with an orbit "
                            "(orbit fields not set take their defaults)\n", o->sets[i]);
        else if (before == 1 && after == 0)
            fprintf(stderr, "sightline-render: note: --set %s replaces the scene's orbit camera with eye/target/up\n",
                    o->sets[i]);
    }
    sl_status st = sl_scene_from_json(root, scene, &err);
    cJSON_Delete(root);
    if (st != SL_OK) {
        fprintf(stderr, "sightline-render: %s: %s\n", o->scene, err.message);
        return 0;
    }
    return 1;
}

static int write_stats(const options *o, const sl_scene *scene, const sl_gpu *gpu, const sl_technique *tech,
                       double *gpu_ms, double *wall_ms, double load_ms, const sl_frame_stats *first,
                       const sl_frame_stats *last)
{
    cJSON *s = cJSON_CreateObject();
    cJSON_AddStringToObject(s, "renderer", sl_gpu_renderer(gpu));
    cJSON_AddStringToObject(s, "technique", tech->name);
    cJSON_AddNumberToObject(s, "width", scene->width);
    cJSON_AddNumberToObject(s, "height", scene->height);
    cJSON_AddNumberToObject(s, "frames", o->frames);
    cJSON_AddNumberToObject(s, "samples", o->samples);
    cJSON_AddItemToObject(s, "gpu_ms", summary(gpu_ms, o->frames));
    cJSON_AddItemToObject(s, "wall_ms", summary(wall_ms, o->frames));
    cJSON_AddNumberToObject(s, "dataset_load_ms", load_ms);
    cJSON_AddNumberToObject(s, "prepare_ms", first->prepare_ms);
    /* The technique's split of prepare_ms (null where it reports none). */
    const char *split[] = {"preprocess_ms", "upload_ms", "gpu_preprocess_ms"};
    double split_ms[] = {first->prepare.preprocess_ms, first->prepare.upload_ms, first->prepare.gpu_ms};
    for (int i = 0; i < 3; i++) {
        if (first->prepare_reported)
            cJSON_AddNumberToObject(s, split[i], split_ms[i]);
        else
            cJSON_AddNullToObject(s, split[i]);
    }
    /* The technique's own named numbers of that prepare ({} when none). */
    cJSON *extra = cJSON_AddObjectToObject(s, "prepare_extra");
    int extra_count = first->prepare.extra_count;
    for (int i = 0; extra && i < extra_count && i < SL_STATS_EXTRA_MAX; i++) {
        const sl_stat_value *e = &first->prepare.extra[i];
        char name[sizeof e->name + 1];
        snprintf(name, sizeof name, "%.*s", (int)sizeof e->name, e->name); /* terminated even if a technique forgot */
        cJSON_AddNumberToObject(extra, name, e->value);
    }
    cJSON_AddNumberToObject(s, "gpu_bytes", (double)last->gpu_bytes);
    /* Techniques with two executions: the one that drew the frames (core/sl_backend.h). */
    if (last->render.backend)
        cJSON_AddStringToObject(s, "backend", last->render.backend);
    else
        cJSON_AddNullToObject(s, "backend");
    cJSON_AddNumberToObject(s, "threads", last->render.threads);
    cJSON_AddNumberToObject(s, "primitives", last->render.primitives);
    cJSON_AddNumberToObject(s, "culled", last->render.culled);
    cJSON_AddNumberToObject(s, "dropped", last->render.dropped);
    /* Ray marchers: samples evaluated and jumped over (empty-space skipping). */
    double all = last->render.samples + last->render.samples_skipped;
    cJSON_AddNumberToObject(s, "ray_samples", last->render.samples);
    cJSON_AddNumberToObject(s, "ray_samples_skipped", last->render.samples_skipped);
    cJSON_AddNumberToObject(s, "skipped_fraction", all > 0.0 ? last->render.samples_skipped / all : 0.0);
    /* Derived data rebuilt inside renders (lr_volume's streamlines): the first frame's, the last one's. */
    cJSON_AddNumberToObject(s, "rebuild_ms_first", first->render.rebuild_ms);
    cJSON_AddNumberToObject(s, "rebuild_ms_last", last->render.rebuild_ms);
    char *out = cJSON_Print(s);
    cJSON_Delete(s);
    errno = 0;
    FILE *f = out ? fopen(o->stats, "w") : NULL;
    int ok = f && fputs(out, f) >= 0 && fputc('\n', f) != EOF;
    if (f && fclose(f) != 0)
        ok = 0;
    if (!ok)
        fprintf(stderr, "sightline-render: cannot write %s%s%s\n", o->stats, errno ? ": " : "",
                errno ? strerror(errno) : "");
    free(out);
    return ok;
}

/* 1 when pattern has exactly one frame-number conversion, %d or %0Nd
 * (N in 1..9), and no other '%' except "%%". */
static int frame_pattern_ok(const char *pattern)
{
    int conversions = 0;
    for (const char *c = pattern; *c; c++) {
        if (*c != '%')
            continue;
        if (c[1] == '%') {
            c++;
            continue;
        }
        const char *d = c + 1;
        if (*d == '0' && d[1] >= '1' && d[1] <= '9')
            d += 2;
        if (*d != 'd')
            return 0;
        conversions++;
        c = d;
    }
    return conversions == 1;
}

/* The path's checks on the options, once the scene is read: prints the reason and returns 0 when they fail. */
static int check_path_options(options *o, const sl_scene *scene, const sl_technique *tech)
{
    if (!scene->path) {
        if (o->require_path)
            fprintf(stderr, "sightline-render: --path %s: the scene has no \"path\" (proto/scene.md, Paths)\n",
                    o->scene);
        return !o->require_path;
    }
    if (o->frames_given || o->depth) {
        fprintf(stderr, "sightline-render: %s: a scene with a path renders its own frames; --%s does not apply\n",
                o->scene, o->frames_given ? "frames" : "depth (not written for paths)");
        return 0;
    }
    if (o->out && !frame_pattern_ok(o->out)) {
        fprintf(stderr, "sightline-render: --out %s: a path needs a file name pattern with one %%d or %%0Nd for the "
                        "frame number, e.g. frames/%%05d.png\n", o->out);
        return 0;
    }
    o->frames = sl_scene_path_frames(scene->path);
    char costly[256];
    if (sl_scene_path_prepared_params(scene->path, tech, costly, sizeof costly) > 0)
        fprintf(stderr, "sightline-render: note: the path changes %s, which re-prepares %s on every frame it changes "
                        "(costly)\n", costly, tech->name);
    return 1;
}

/* The technique's params at frame f of the scene's path (or its plain params without one). */
static sl_status frame_params(const sl_scene *scene, const sl_technique *tech, int f, sl_params *params, sl_err *err)
{
    sl_params_init(params, tech->params, tech->param_count);
    if (!scene->path)
        return sl_params_apply_json(params, scene->params, err); /* validated by sl_scene_from_json */
    cJSON *at = sl_scene_path_params(scene->path, f / scene->path->fps, scene->params, tech);
    if (!at)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    sl_status st = sl_params_apply_json(params, at, err);
    cJSON_Delete(at);
    return st;
}

static sl_status write_image(const char *path, const uint8_t *rgba, int width, int height, sl_err *err)
{
    return ends_with(path, ".jpg") || ends_with(path, ".jpeg") ? sl_jpeg_write(path, rgba, width, height, 92, err)
                                                               : sl_png_write(path, rgba, width, height, err);
}

int main(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    if (!check_outputs(&o))
        return EXIT_BAD_INPUT;
    sl_scene scene;
    if (!load_scene(&o, &scene))
        return EXIT_BAD_INPUT;
    const sl_technique *tech = sl_technique_find(scene.technique);
    if (!check_path_options(&o, &scene, tech)) {
        sl_scene_deinit(&scene);
        return EXIT_USAGE;
    }
    if ((rc = check_export(&o, tech)) != 0) {
        sl_scene_deinit(&scene);
        return rc;
    }
    sl_err verr = {0};
    if (o.video && sl_video_check(&(sl_video_desc){o.video, scene.width, scene.height,
                                                   scene.path ? scene.path->fps : SL_RENDER_VIDEO_FPS, o.crf},
                                  &verr) != SL_OK) {
        fprintf(stderr, "sightline-render: %s\n", verr.message);
        sl_scene_deinit(&scene);
        return EXIT_BAD_INPUT;
    }

    /* The GPU and its limits first: cheap, and a failure there should not
     * wait for a dataset load. */
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_status st = sl_gpu_create(&(sl_gpu_desc){0}, &gpu, &err);
    if (st == SL_OK)
        st = sl_target_check(scene.width, scene.height, o.samples, &err);
    if (st != SL_OK) {
        fprintf(stderr, "sightline-render: GPU: %s\n", err.message);
        if (o.samples > 1 && strstr(err.message, "MSAA"))
            fprintf(stderr, "sightline-render: lower --samples (0 or 1 = no MSAA)\n");
        sl_gpu_destroy(gpu);
        sl_scene_deinit(&scene);
        return EXIT_GPU;
    }

    char scene_dir[4096];
    snprintf(scene_dir, sizeof scene_dir, "%s", o.scene);
    const char *data_dir = o.data_dir ? o.data_dir : dirname(scene_dir);
    sl_dataset *ds = NULL;
    double t0 = sl_clock_ms();
    if ((st = sl_scene_open_dataset(&scene, data_dir, &ds, &err)) != SL_OK) {
        fprintf(stderr, "sightline-render: dataset: %s\n", err.message);
        sl_gpu_destroy(gpu);
        sl_scene_deinit(&scene);
        return EXIT_BAD_INPUT; /* loaders never touch the GPU: an unsupported file variant is bad input */
    }
    double load_ms = sl_clock_ms() - t0;

    sl_params params;

    sl_pipeline *pipe = NULL;
    sl_video_writer *video = NULL;
    int exit_code = EXIT_OK;
    double *gpu_ms = calloc((size_t)o.frames, sizeof(double));
    double *wall_ms = calloc((size_t)o.frames, sizeof(double));
    uint8_t *rgba = malloc((size_t)scene.width * (size_t)scene.height * 4);
    float *depth = o.depth ? malloc((size_t)scene.width * (size_t)scene.height * sizeof(float)) : NULL;
    sl_frame_stats first = {0}, last = {0};
    sl_view view;
    if (!gpu_ms || !wall_ms || !rgba || (o.depth && !depth) || sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        fprintf(stderr, "sightline-render: out of memory\n");
        exit_code = EXIT_BAD_INPUT;
        goto done;
    }
    sl_pipeline_set_dataset(pipe, ds);
    ds = NULL; /* owned by the pipeline now */
    double video_fps = scene.path ? scene.path->fps : SL_RENDER_VIDEO_FPS;
    if (o.video && (st = sl_video_open(&(sl_video_desc){o.video, scene.width, scene.height, video_fps, o.crf}, &video,
                                       &err)) != SL_OK) {
        fprintf(stderr, "sightline-render: %s\n", err.message);
        exit_code = st == SL_ERR_UNSUPPORTED ? EXIT_GPU : EXIT_BAD_INPUT;
        goto done;
    }
    int every_frame = scene.path || video; /* each frame leaves the GPU (files, video) */
    int progress = every_frame && o.frames > 1 && isatty(STDERR_FILENO);
    double t_start = sl_clock_ms();
    for (int f = 0; f < o.frames; f++) {
        sl_frame_stats stats;
        if (f == 0 || scene.path) {
            if ((st = frame_params(&scene, tech, f, &params, &err)) == SL_OK)
                st = sl_pipeline_set_technique(pipe, tech, &params, &err);
            if (st != SL_OK) {
                fprintf(stderr, "sightline-render: frame %d: %s\n", f, err.message);
                exit_code = exit_for(st);
                goto done;
            }
        }
        if ((st = sl_scene_view(&scene, sl_pipeline_dataset(pipe), f, &view, &err)) != SL_OK ||
            (st = sl_pipeline_render(pipe, &view, o.samples, &stats, &err)) != SL_OK) {
            fprintf(stderr, "sightline-render: frame %d: %s\n", f, err.message);
            exit_code = exit_for(st);
            goto done;
        }
        if (f == 0)
            first = stats;
        last = stats;
        gpu_ms[f] = stats.gpu_ms;
        wall_ms[f] = stats.wall_ms;
        if (every_frame) {
            sl_pipeline_read_rgba(pipe, rgba, 1);
            char name[4096] = "";
            if (scene.path && o.out)
                snprintf(name, sizeof name, o.out, f);
            if ((name[0] && (st = write_image(name, rgba, scene.width, scene.height, &err)) != SL_OK) ||
                (video && (st = sl_video_write_rgba(video, rgba, &err)) != SL_OK)) {
                fprintf(stderr, "%ssightline-render: frame %d: %s\n", progress ? "\n" : "", f, err.message);
                exit_code = EXIT_BAD_INPUT;
                goto done;
            }
            if (progress) {
                double spent = (sl_clock_ms() - t_start) / 1000.0;
                fprintf(stderr, "\rsightline-render: frame %d of %d, %.1f s, about %.0f s left   ", f + 1, o.frames,
                        spent, spent / (f + 1) * (o.frames - f - 1));
            }
        }
    }
    if (progress)
        fputc('\n', stderr);
    if (!scene.path && o.out) {
        if (!every_frame)
            sl_pipeline_read_rgba(pipe, rgba, 1);
        if ((st = write_image(o.out, rgba, scene.width, scene.height, &err)) != SL_OK) {
            fprintf(stderr, "sightline-render: %s\n", err.message);
            exit_code = EXIT_BAD_INPUT;
            goto done;
        }
    }
    if (o.depth) {
        sl_frame_stats stats;
        if ((st = sl_pipeline_render(pipe, &view, 1, &stats, &err)) != SL_OK) {
            fprintf(stderr, "sightline-render: depth frame: %s\n", err.message);
            exit_code = exit_for(st);
            goto done;
        }
        sl_pipeline_read_distance(pipe, &view, depth);
        if (sl_pfm_write(o.depth, depth, scene.width, scene.height, &err) != SL_OK) {
            fprintf(stderr, "sightline-render: %s\n", err.message);
            exit_code = EXIT_BAD_INPUT;
            goto done;
        }
    }
    if (o.export_path) {
        if ((st = sl_pipeline_export(pipe, o.export_path, &err)) != SL_OK) {
            fprintf(stderr, "sightline-render: --export: %s\n", err.message);
            exit_code = exit_for(st);
            goto done;
        }
        printf("exported %s (%s)\n", o.export_path, tech->name);
    }
    if (o.stats && !write_stats(&o, &scene, gpu, tech, gpu_ms, wall_ms, load_ms, &first, &last)) {
        exit_code = EXIT_BAD_INPUT;
        goto done;
    }
    if (video) {
        sl_video_summary vs;
        st = sl_video_close(video, &vs, &err);
        video = NULL;
        if (st != SL_OK) {
            fprintf(stderr, "sightline-render: %s\n", err.message);
            exit_code = EXIT_BAD_INPUT;
            goto done;
        }
        printf("wrote video %s: %ld frames, %.2f s at %g fps, %s CRF %d, %zu bytes\n", o.video, vs.frames, vs.seconds,
               video_fps, vs.codec, vs.crf, vs.bytes);
    }
    if (o.out && scene.path)
        printf("wrote %d frames %s (%dx%d, %s, %.2f s of path at %g fps) in %.1f s\n", o.frames, o.out, scene.width,
               scene.height, tech->name, (o.frames - 1) / scene.path->fps, scene.path->fps,
               (sl_clock_ms() - t_start) / 1000.0);
    else if (o.out)
        printf("wrote %s (%dx%d, %s, %d frame%s)\n", o.out, scene.width, scene.height, tech->name, o.frames,
               o.frames == 1 ? "" : "s");
done:
    sl_video_abort(video); /* only after a failure: removes the partial file */
    free(gpu_ms);
    free(wall_ms);
    free(rgba);
    free(depth);
    sl_pipeline_destroy(pipe);
    sl_dataset_destroy(ds);
    sl_gpu_destroy(gpu);
    sl_scene_deinit(&scene);
    return exit_code;
}
