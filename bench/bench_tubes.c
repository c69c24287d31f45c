/* bench_tubes.c — the experiment of Russig et al. (4, Fig. 5) for `tubes`, plus accuracy tables.
 *
 *   bench-tubes [--size WxH] [--frames N] [--datasets fibers,hotroom,bundle,brain,furball]
 *               [--skip-perf] [--skip-error] [--skip-cubic] [--skip-vtk] [--vtk-png PREFIX]
 *
 * 1. Speed: generated stand-ins for the paper's five datasets (about 3.5k,
 *    31k, 106k, 114k, 787k segments) in a far view (the bounding sphere fits
 *    the 45 degree view) and a close view (1/3 of that distance), an orbit of
 *    N frames each: median frame ms of tubes, tubes with the empty fragment
 *    shader (silhouette_only), tubes_mesh; ratio; triangles; GPU memory.
 *    Then the same lines through what users would otherwise pick, VTK's tube
 *    filter (bench/vtk_tubes.py: same radius, tubes_mesh's default sides and
 *    caps, same image size, cameras and orbit), run as
 *    `xvfb-run -a /usr/bin/python3 SOURCE/bench/vtk_tubes.py` on a temporary
 *    legacy-VTK copy of the lines (Debian's VTK is X11-only; scripts/bench
 *    installs bench/packages.txt): its median frame ms (wall, render +
 *    glFinish), tube filter ms, and our ratio to it. When VTK or xvfb-run is
 *    missing the table says "VTK: not available (reason)". SOURCE is
 *    $SIGHTLINE_SOURCE_DIR, else the source tree this was built from.
 * 2. Error against time: every root method x iterations 2..12, 16, 20, 24, 32,
 *    depth error against the CPU reference (tests/render/tubes/tubes_reference.c) and ms.
 * 3. How far the quadratic pair lies from the true cubic Hermite sweep
 *    (both by the reference) on smaller versions of the five datasets.
 * Defaults (160x90, 3 frames) take a few minutes on llvmpipe; --size
 * 1920x1080 --frames 1000 is the paper's setting. --skip-vtk leaves VTK
 * out; --vtk-png PREFIX keeps VTK's first orbit frame of each dataset and view
 * as PREFIX-DATASET-VIEW.png. Prints Markdown; checks nothing. Render thread = main.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "line_style/sl_line_style.h"
#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "pipeline/sl_pipeline.h"
#include "tubes/tubes_nodes.h"

/* The reference intersector is test code kept apart from the renderer library
 * (it must share nothing with the shader path); compiled into this program. */
#include "../tests/render/tubes/tubes_reference.c"

typedef struct bench_dataset {
    const char *name;       /* the paper's dataset it stands in for */
    const char *json;       /* full size */
    const char *json_small; /* for the cubic-vs-quadratic table */
} bench_dataset;

static const bench_dataset datasets[] = {
    {"fibers", "{\"generator\":\"tornado\",\"lines\":241,\"points\":16,\"seed\":1}",
     "{\"generator\":\"tornado\",\"lines\":60,\"points\":16,\"seed\":1}"},
    {"hotroom", "{\"generator\":\"hotroom\",\"lines\":12400,\"seed\":1}",
     "{\"generator\":\"hotroom\",\"lines\":1000,\"seed\":1}"},
    {"bundle", "{\"generator\":\"bundle\",\"lines\":1250,\"points\":85,\"seed\":1}",
     "{\"generator\":\"bundle\",\"lines\":40,\"points\":85,\"seed\":1}"},
    {"brain", "{\"generator\":\"abc\",\"lines\":1701,\"points\":68,\"seed\":1}",
     "{\"generator\":\"abc\",\"lines\":40,\"points\":68,\"seed\":1}"},
    {"furball", "{\"generator\":\"furball\",\"segments\":787327,\"seed\":1}",
     "{\"generator\":\"furball\",\"segments\":3000,\"seed\":1}"},
};
#define DATASET_COUNT ((int)(sizeof datasets / sizeof datasets[0]))

typedef struct options {
    int width, height, frames, skip_perf, skip_error, skip_cubic, skip_vtk;
    const char *only;
    const char *vtk_png; /* prefix of VTK's saved frames, or NULL */
} options;

#ifndef SIGHTLINE_SOURCE_DIR
#define SIGHTLINE_SOURCE_DIR "."
#endif

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n ? (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2])) : 0.0;
}

static size_t segment_count(const sl_dataset *ds)
{
    size_t n = 0;
    for (size_t k = 0; k < ds->lines.line_count; k++) {
        size_t len = ds->lines.line_offsets[k + 1] - ds->lines.line_offsets[k];
        n += len >= 2 ? len - 1 : 0;
    }
    return n;
}

static sl_status make_view(const sl_dataset *ds, double azimuth, double distance, int w, int h, sl_view *view,
                           sl_err *err)
{
    memset(view, 0, sizeof *view);
    view->width = w;
    view->height = h;
    view->origin = ds->origin;
    view->background[3] = 1.0f;
    sl_orbit o = {azimuth, 20.0, distance, 45.0};
    sl_status st = sl_camera_from_orbit(&o, ds->bounds_min, ds->bounds_max, &view->camera, err);
    return st == SL_OK ? sl_view_init(view, sl_dataset_radius(ds), err) : st;
}

typedef struct run_result { double ms, wall_ms, prepare_ms, primitives; size_t bytes; } run_result;

/* Median frame ms over an orbit of `frames` frames (the first frame, which
 * prepares, is rendered once before timing). */
static sl_status run_orbit(sl_pipeline *p, const sl_technique *t, const sl_params *params, double distance,
                           const options *o, run_result *out, sl_err *err)
{
    sl_status st = sl_pipeline_set_technique(p, t, params, err);
    if (st != SL_OK)
        return st;
    const sl_dataset *ds = sl_pipeline_dataset(p);
    double *ms = calloc(2 * (size_t)o->frames, sizeof *ms), *wall = ms + o->frames;
    if (!ms)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    sl_view view;
    sl_frame_stats stats = {0};
    if ((st = make_view(ds, 0.0, distance, o->width, o->height, &view, err)) == SL_OK)
        st = sl_pipeline_render(p, &view, 1, &stats, err);
    out->prepare_ms = stats.prepare_ms;
    for (int f = 0; st == SL_OK && f < o->frames; f++) {
        if ((st = make_view(ds, 360.0 * f / o->frames, distance, o->width, o->height, &view, err)) != SL_OK ||
            (st = sl_pipeline_render(p, &view, 1, &stats, err)) != SL_OK)
            break;
        ms[f] = stats.gpu_ms > 0.0 ? stats.gpu_ms : stats.wall_ms;
        wall[f] = stats.wall_ms;
    }
    out->ms = median(ms, o->frames);
    out->wall_ms = median(wall, o->frames);
    out->primitives = stats.render.primitives;
    out->bytes = stats.gpu_bytes;
    free(ms);
    return st;
}

/* ---- VTK's tube filter, the baseline users would otherwise pick (bench/vtk_tubes.py) ---- */

#define VTK_VIEWS 2

typedef struct vtk_result {
    int ok;
    char reason[240];         /* when !ok */
    double filter_ms, first_frame_ms, triangles, seconds;
    double ms[VTK_VIEWS];     /* median frame ms per view */
    char gl[128], version[32];
} vtk_result;

static void put_be32(uint32_t v, FILE *f)
{
    unsigned char b[4] = {(unsigned char)(v >> 24), (unsigned char)(v >> 16), (unsigned char)(v >> 8), (unsigned char)v};
    fwrite(b, 1, 4, f);
}

static void put_be_float(float x, FILE *f)
{
    uint32_t v;
    memcpy(&v, &x, sizeof v);
    put_be32(v, f);
}

/* The lines as legacy VTK POLYDATA (binary, big-endian), in the dataset's
 * float coordinates (world - origin); data radii (x radius_scale) as point scalars. */
static int write_vtk_lines(const sl_dataset *ds, float radius_scale, const char *path)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    const sl_lines *l = &ds->lines;
    fprintf(f, "# vtk DataFile Version 3.0\nsightline bench-tubes %s\nBINARY\nDATASET POLYDATA\nPOINTS %zu float\n",
            ds->name, l->vertex_count);
    for (size_t k = 0; k < 3 * l->vertex_count; k++)
        put_be_float(l->positions[k], f);
    fprintf(f, "\nLINES %zu %zu\n", l->line_count, l->line_count + l->vertex_count);
    for (size_t k = 0; k < l->line_count; k++) {
        put_be32(l->line_offsets[k + 1] - l->line_offsets[k], f);
        for (uint32_t i = l->line_offsets[k]; i < l->line_offsets[k + 1]; i++)
            put_be32(i, f);
    }
    if (l->radii) {
        fprintf(f, "\nPOINT_DATA %zu\nSCALARS radius float 1\nLOOKUP_TABLE default\n", l->vertex_count);
        for (size_t k = 0; k < l->vertex_count; k++)
            put_be_float(l->radii[k] * radius_scale, f);
    }
    fputc('\n', f);
    int bad = ferror(f);
    return fclose(f) == 0 && !bad ? 0 : -1;
}

/* One line a frame: VIEW INDEX eye target up fov (relative to the dataset origin);
 * INDEX -1 is the untimed first frame run_orbit also renders. */
static sl_status write_vtk_cameras(const sl_dataset *ds, const double *dists, const char *const *names,
                                   const options *o, const char *path, sl_err *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "cannot write %s", path);
    sl_status st = SL_OK;
    for (int v = 0; v < VTK_VIEWS && st == SL_OK; v++)
        for (int fr = -1; fr < o->frames && st == SL_OK; fr++) {
            sl_view view;
            if ((st = make_view(ds, fr < 0 ? 0.0 : 360.0 * fr / o->frames, dists[v], o->width, o->height, &view,
                                err)) != SL_OK)
                break;
            const sl_camera *c = &view.camera;
            fprintf(f, "%s %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", names[v], fr,
                    c->eye.x - ds->origin.x, c->eye.y - ds->origin.y, c->eye.z - ds->origin.z,
                    c->target.x - ds->origin.x, c->target.y - ds->origin.y, c->target.z - ds->origin.z, c->up.x,
                    c->up.y, c->up.z, c->fov_y_deg);
        }
    if (fclose(f) != 0 && st == SL_OK)
        st = sl_err_set(err, SL_ERR_IO, "cannot write %s", path);
    return st;
}

static int executable_on_path(const char *name)
{
    const char *path = getenv("PATH");
    if (!path || !*path)
        path = "/usr/local/bin:/usr/bin:/bin";
    while (*path) {
        size_t n = strcspn(path, ":");
        char full[4096];
        if (n > 0 && n + strlen(name) + 2 < sizeof full) {
            snprintf(full, sizeof full, "%.*s/%s", (int)n, path, name);
            if (access(full, X_OK) == 0)
                return 1;
        }
        path += n + (path[n] == ':');
    }
    return 0;
}

/* Appends s to the shell command in single quotes. */
static void append_quoted(char *cmd, size_t size, const char *s)
{
    size_t n = strlen(cmd);
    if (n + 1 < size)
        cmd[n++] = '\'';
    for (; *s && n + 5 < size; s++) {
        if (*s == '\'') {
            memcpy(cmd + n, "'\\''", 4);
            n += 4;
        } else
            cmd[n++] = *s;
    }
    if (n + 1 < size)
        cmd[n++] = '\'';
    cmd[n] = 0;
}

static void set_reason(vtk_result *r, const char *what)
{
    r->ok = 0;
    size_t n = 0;
    for (const char *c = what; *c && n + 1 < sizeof r->reason; c++)
        r->reason[n++] = (*c == '|' || *c == '\n' || *c == '\r') ? ' ' : *c;
    r->reason[n] = 0;
}

/* Why VTK cannot run here (written to reason), or 0 when it may. */
static int vtk_missing(const char *script, char *reason, size_t size)
{
    if (access(script, R_OK) != 0)
        snprintf(reason, size, "no %.400s; set SIGHTLINE_SOURCE_DIR", script);
    else if (access("/usr/bin/python3", X_OK) != 0)
        snprintf(reason, size, "no /usr/bin/python3");
    else if (!executable_on_path("xvfb-run"))
        snprintf(reason, size, "no xvfb-run on PATH; scripts/bench installs bench/packages.txt");
    else
        return 0;
    return 1;
}

static double json_number(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : 0.0;
}

/* Runs bench/vtk_tubes.py on ds for both views; fills r (r->ok = 0 with a reason on any failure). */
static void run_vtk(const sl_dataset *ds, const char *dataset_name, const double *dists, const char *const *names,
                    const options *o, vtk_result *r)
{
    memset(r, 0, sizeof *r);
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    char script[4096], reason[512];
    snprintf(script, sizeof script, "%s/bench/vtk_tubes.py", src && *src ? src : SIGHTLINE_SOURCE_DIR);
    if (vtk_missing(script, reason, sizeof reason)) {
        set_reason(r, reason);
        return;
    }
    const sl_technique *mesh = sl_technique_find("tubes_mesh");
    sl_params mp;
    sl_params_init(&mp, mesh->params, mesh->param_count);
    sl_line_style style;
    sl_line_style_read(&mp, ds, &style);
    char dir[] = "/tmp/sightline-vtk-XXXXXX", lines[64], cams[64];
    if (!mkdtemp(dir)) {
        set_reason(r, "cannot create a temporary directory");
        return;
    }
    snprintf(lines, sizeof lines, "%s/lines.vtk", dir);
    snprintf(cams, sizeof cams, "%s/cameras.txt", dir);
    sl_err err = {0};
    if (write_vtk_lines(ds, style.radius_scale, lines) != 0) {
        set_reason(r, "cannot write the lines file");
        goto done;
    }
    if (write_vtk_cameras(ds, dists, names, o, cams, &err) != SL_OK) {
        set_reason(r, err.message);
        goto done;
    }
    char cmd[16384];
    snprintf(cmd, sizeof cmd, "xvfb-run -a -s '-screen 0 %dx%dx24' /usr/bin/python3 ",
             o->width > 1280 ? o->width : 1280, o->height > 1024 ? o->height : 1024);
    append_quoted(cmd, sizeof cmd, script);
    size_t n = strlen(cmd);
    snprintf(cmd + n, sizeof cmd - n, " --lines %s --cameras %s --size %dx%d --radius %.9g --sides %d --caps %d",
             lines, cams, o->width, o->height, (double)style.radius, sl_params_int(&mp, "sides"),
             sl_params_bool(&mp, "caps") ? 1 : 0);
    if (o->vtk_png) {
        char prefix[4096];
        snprintf(prefix, sizeof prefix, "%s-%s", o->vtk_png, dataset_name);
        strncat(cmd, " --png ", sizeof cmd - strlen(cmd) - 1);
        append_quoted(cmd, sizeof cmd, prefix);
    }
    strncat(cmd, " 2>&1", sizeof cmd - strlen(cmd) - 1);
    fflush(stdout);
    double t0 = sl_now_ms();
    FILE *p = popen(cmd, "r");
    if (!p) {
        set_reason(r, "cannot start xvfb-run");
        goto done;
    }
    char line[8192], json[8192] = "", last[512] = "";
    while (fgets(line, sizeof line, p)) {
        line[strcspn(line, "\r\n")] = 0;
        if (line[0] == '{')
            snprintf(json, sizeof json, "%s", line);
        else if (line[0])
            snprintf(last, sizeof last, "%.500s", line);
    }
    int status = pclose(p);
    r->seconds = (sl_now_ms() - t0) / 1000.0;
    cJSON *root = json[0] ? cJSON_Parse(json) : NULL;
    if (!root) {
        snprintf(reason, sizeof reason, "xvfb-run exited with status %d%s%.400s",
                 status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1, last[0] ? ": " : "", last);
        set_reason(r, reason);
        goto done;
    }
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "views");
    const cJSON *error = cJSON_GetObjectItemCaseSensitive(root, "error");
    if (!cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(root, "ok")) || !cJSON_IsObject(views)) {
        set_reason(r, cJSON_IsString(error) ? error->valuestring : "bench/vtk_tubes.py failed");
    } else {
        r->ok = 1;
        r->filter_ms = json_number(root, "filter_ms");
        r->first_frame_ms = json_number(root, "first_frame_ms");
        r->triangles = json_number(root, "triangles");
        const cJSON *gl = cJSON_GetObjectItemCaseSensitive(root, "gl_renderer");
        const cJSON *version = cJSON_GetObjectItemCaseSensitive(root, "vtk");
        snprintf(r->gl, sizeof r->gl, "%s", cJSON_IsString(gl) ? gl->valuestring : "unknown");
        snprintf(r->version, sizeof r->version, "%s", cJSON_IsString(version) ? version->valuestring : "?");
        for (int v = 0; v < VTK_VIEWS; v++)
            r->ms[v] = json_number(cJSON_GetObjectItemCaseSensitive(views, names[v]), "median_ms");
    }
    cJSON_Delete(root);
done:
    remove(lines);
    remove(cams);
    rmdir(dir);
}

static sl_status bench_speed(sl_gpu *gpu, const options *o, sl_err *err)
{
    const sl_technique *tubes = sl_technique_find("tubes"), *mesh = sl_technique_find("tubes_mesh");
    if (!tubes || !mesh)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "tubes or tubes_mesh is not registered");
    printf("\n## Speed (%dx%d, median of %d orbit frames, ms)\n\n", o->width, o->height, o->frames);
    printf("| dataset | segments | view | tubes | silhouette only | tubes_mesh | mesh / tubes | tubes triangles | mesh triangles | tubes MB | mesh MB |\n");
    printf("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    /* Kept for the VTK table, printed after this one. */
    struct { int done; run_result tubes[VTK_VIEWS], mesh[VTK_VIEWS]; vtk_result vtk; } rows[DATASET_COUNT];
    memset(rows, 0, sizeof rows);
    char vtk_unavailable[240] = "";
    const char *names[VTK_VIEWS] = {"far", "close"};
    for (int d = 0; d < DATASET_COUNT; d++) {
        if (o->only && !strstr(o->only, datasets[d].name))
            continue;
        sl_dataset *ds = NULL;
        sl_status st = sl_generate_json(datasets[d].json, &ds, err);
        if (st != SL_OK)
            return st;
        size_t segs = segment_count(ds);
        sl_pipeline *p = NULL;
        if ((st = sl_pipeline_create(gpu, &p, err)) != SL_OK) {
            sl_dataset_destroy(ds);
            return st;
        }
        sl_pipeline_set_dataset(p, ds);
        const double far = 1.0 / sin(22.5 * SL_PI / 180.0); /* bounding sphere fits the 45 degree view */
        const double dists[VTK_VIEWS] = {far, far / 3.0};
        for (int v = 0; v < VTK_VIEWS && st == SL_OK; v++) {
            sl_params tp, sp, mp;
            sl_params_init(&tp, tubes->params, tubes->param_count);
            sl_params_init(&sp, tubes->params, tubes->param_count);
            sl_params_init(&mp, mesh->params, mesh->param_count);
            double one = 1.0;
            sl_params_set_numbers(&sp, "silhouette_only", &one, 1, err);
            run_result rt = {0}, rs = {0}, rm = {0};
            if ((st = run_orbit(p, tubes, &tp, dists[v], o, &rt, err)) != SL_OK ||
                (st = run_orbit(p, tubes, &sp, dists[v], o, &rs, err)) != SL_OK ||
                (st = run_orbit(p, mesh, &mp, dists[v], o, &rm, err)) != SL_OK)
                break;
            printf("| %s | %zu | %s | %.1f | %.1f | %.1f | %.2f | %.0f | %.0f | %.1f | %.1f |\n", datasets[d].name, segs,
                   names[v], rt.ms, rs.ms, rm.ms, rt.ms > 0 ? rm.ms / rt.ms : 0.0, rt.primitives, rm.primitives,
                   rt.bytes / 1048576.0, rm.bytes / 1048576.0);
            fflush(stdout);
            rows[d].tubes[v] = rt;
            rows[d].mesh[v] = rm;
        }
        if (st == SL_OK && !o->skip_vtk && !vtk_unavailable[0]) {
            run_vtk(ds, datasets[d].name, dists, names, o, &rows[d].vtk);
            /* Missing tools stay missing: do not try again for every dataset. */
            if (!rows[d].vtk.ok && strncmp(rows[d].vtk.reason, "no ", 3) == 0)
                snprintf(vtk_unavailable, sizeof vtk_unavailable, "%s", rows[d].vtk.reason);
        }
        rows[d].done = st == SL_OK;
        sl_pipeline_destroy(p);
        if (st != SL_OK)
            return st;
    }
    printf("\n(tubes triangles: box faces emitted by the geometry shader, 2 per face, after culling.)\n");
    if (o->skip_vtk) {
        printf("\nVTK tube filter comparison: skipped (--skip-vtk).\n");
        return SL_OK;
    }

    const vtk_result *any = NULL;
    double vtk_seconds = 0.0;
    for (int d = 0; d < DATASET_COUNT; d++) {
        vtk_seconds += rows[d].vtk.seconds;
        if (rows[d].vtk.ok && !any)
            any = &rows[d].vtk;
    }
    const sl_technique *mesh_t = sl_technique_find("tubes_mesh");
    sl_params mp;
    sl_params_init(&mp, mesh_t->params, mesh_t->param_count);
    printf("\n## Against VTK's tube filter (%dx%d, median of %d orbit frames, ms)\n\n", o->width, o->height, o->frames);
    printf("The same lines, radius, image size, cameras and orbit through VTK %s: vtkTubeFilter (%d sides, %s, as "
           "tubes_mesh's defaults) and vtkPolyDataMapper, no multisampling, under xvfb-run (GL: %s). Frame ms here are "
           "wall time of a frame until glFinish for all three (VTK: Render + glFinish + 1-pixel readback; ours: "
           "render + resolve + glFinish), so they exceed the GPU-timer ms of the table above. Ratio = our ms / VTK "
           "ms (below 1: ours is faster). Preprocessing: VTK's tube filter, and its first frame (which uploads the "
           "mesh), against tubes_mesh's prepare (CPU mesh build + upload).\n\n",
           any ? any->version : "(not run)", sl_params_int(&mp, "sides"), sl_params_bool(&mp, "caps") ? "capped" : "open",
           any ? any->gl : "-");
    printf("| dataset | view | VTK | tubes | tubes_mesh | tubes / VTK | tubes_mesh / VTK | VTK tube filter | "
           "VTK first frame | tubes_mesh prepare | VTK triangles |\n");
    printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int d = 0; d < DATASET_COUNT; d++) {
        if (!rows[d].done)
            continue;
        const vtk_result *r = &rows[d].vtk;
        for (int v = 0; v < VTK_VIEWS; v++) {
            const run_result *rt = &rows[d].tubes[v], *rm = &rows[d].mesh[v];
            if (!r->ok) {
                printf("| %s | %s | VTK: not available (%s) | %.1f | %.1f | | | | | %.0f | |\n", datasets[d].name,
                       names[v], r->reason[0] ? r->reason : vtk_unavailable, rt->wall_ms, rm->wall_ms, rm->prepare_ms);
                continue;
            }
            printf("| %s | %s | %.1f | %.1f | %.1f | %.2f | %.2f | %.0f | %.0f | %.0f | %.0f |\n", datasets[d].name,
                   names[v], r->ms[v], rt->wall_ms, rm->wall_ms, r->ms[v] > 0 ? rt->wall_ms / r->ms[v] : 0.0,
                   r->ms[v] > 0 ? rm->wall_ms / r->ms[v] : 0.0, r->filter_ms, r->first_frame_ms, rm->prepare_ms,
                   r->triangles);
        }
    }
    if (vtk_seconds > 0.0)
        printf("\n(The VTK runs took %.0f s in all, start-up of Xvfb and Python included.)\n", vtk_seconds);
    fflush(stdout);
    return SL_OK;
}

/* Depth error of a GPU distance map against the reference, x the local radius. */
typedef struct error_stats { double max_all, max_inner, mean; long mismatch, both, away; } error_stats;

static error_stats compare(const float *gpu, const float *ref, const float *rad, int w, int h)
{
    error_stats e = {0};
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            size_t k = (size_t)j * (size_t)w + (size_t)i;
            int a = gpu[k] > 0.0f, b = ref[k] > 0.0f;
            if (a != b || !isfinite(gpu[k])) {
                e.mismatch++;
                continue;
            }
            if (!a)
                continue;
            double rel = fabs((double)gpu[k] - ref[k]) / fmax(rad[k], 1e-30);
            e.max_all = fmax(e.max_all, rel);
            if (!tubes_ref_silhouette(ref, rad, w, h, i, j)) {
                e.max_inner = fmax(e.max_inner, rel);
                e.away++;
            }
            e.mean += rel;
            e.both++;
        }
    if (e.both)
        e.mean /= (double)e.both;
    return e;
}

static sl_status reference_of(const sl_dataset *ds, const sl_view *view, const sl_params *params, int cubic,
                              float *ref, float *rad, int *seg, sl_err *err)
{
    sl_tubes_nodes nodes;
    sl_status st = sl_tubes_nodes_build(&ds->lines, (sl_tubes_tangents)sl_params_choice(params, "tangents"), -1,
                                        &nodes, err);
    if (st != SL_OK)
        return st;
    sl_line_style style;
    sl_line_style_read(params, ds, &style);
    sl_tubes_nodes_set_radii(&ds->lines, style.radius_attribute, &nodes);
    tubes_ref_desc rd = {.view = view, .origin = ds->origin, .nodes = &nodes, .radius = style.radius,
                         .radius_scale = style.radius_scale, .cubic = cubic};
    tubes_ref_render(&rd, ref, rad, seg);
    sl_tubes_nodes_deinit(&nodes);
    return SL_OK;
}

static sl_status bench_error(sl_gpu *gpu, const options *o, sl_err *err)
{
    const char *json = "{\"generator\":\"bundle\",\"lines\":100,\"points\":50,\"seed\":2}";
    (void)o;
    const int w = 128, h = 128;
    sl_dataset *ds = NULL;
    sl_status st = sl_generate_json(json, &ds, err);
    if (st != SL_OK)
        return st;
    const sl_technique *tubes = sl_technique_find("tubes");
    sl_params params;
    sl_params_init(&params, tubes->params, tubes->param_count);
    double radius = sl_dataset_radius(ds) / 60.0; /* tubes several pixels wide, so most pixels are not at a rim */
    sl_params_set_numbers(&params, "radius", &radius, 1, err);
    sl_view view;
    size_t np = (size_t)w * h;
    float *ref = calloc(np, sizeof *ref), *rad = calloc(np, sizeof *rad), *gpu_d = calloc(np, sizeof *gpu_d);
    int *seg = calloc(np, sizeof *seg);
    sl_pipeline *p = NULL;
    if (!ref || !rad || !gpu_d || !seg) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((st = make_view(ds, 30.0, 1.2, w, h, &view, err)) != SL_OK ||
        (st = reference_of(ds, &view, &params, 0, ref, rad, seg, err)) != SL_OK ||
        (st = sl_pipeline_create(gpu, &p, err)) != SL_OK)
        goto done;
    size_t segs = segment_count(ds);
    sl_pipeline_set_dataset(p, ds);
    ds = NULL;
    printf("\n## Depth error against the reference, by root method and iterations\n\n");
    printf("bundle, %zu segments, radius 1/60 of the bounding radius, %dx%d, close view; error in units of the local "
           "tube radius; \"away\" excludes reference silhouettes (3x3 coverage change or depth jump > radius; "
           "tests/render/tubes/tubes_reference.c tubes_ref_silhouette).\n\n", segs, w, h);
    printf("| method | iterations | max error (away) | max error (all) | mean error | pixels (away / both hit) | "
           "coverage mismatch | frame ms |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
    /* Every count up to 12: a coarse grid would hide the real fewest count. */
    static const int iters[] = {2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 16, 20, 24, 32};
    const int ni = (int)(sizeof iters / sizeof iters[0]);
    const char *const *methods = NULL;
    int nm = 0;
    int pm = sl_params_find(&params, "root_method");
    if (pm >= 0) {
        methods = params.schema[pm].choices;
        while (methods[nm])
            nm++;
    }
    /* Fewest iterations per method at several error levels (max away from
     * silhouettes <= level, mean <= level / 10): the bound 1e-3 r,
     * then tighter, down to near float resolution (~3.5e-5 r here). */
    static const double levels[] = {1e-3, 1e-4, 5e-5};
    enum { NL = 3 };
    int need[8][NL];
    for (int m = 0; m < nm && m < 8; m++) {
        for (int l = 0; l < NL; l++)
            need[m][l] = -1;
        for (int k = 0; k < ni; k++) {
            double it = iters[k];
            sl_params_set_numbers(&params, "iterations", &it, 1, err);
            sl_params_set_choice(&params, "root_method", methods[m], err);
            if ((st = sl_pipeline_set_technique(p, tubes, &params, err)) != SL_OK)
                goto done;
            double ms[3];
            sl_frame_stats stats;
            for (int f = 0; f < 3; f++) {
                if ((st = sl_pipeline_render(p, &view, 1, &stats, err)) != SL_OK)
                    goto done;
                ms[f] = stats.gpu_ms > 0.0 ? stats.gpu_ms : stats.wall_ms;
            }
            sl_pipeline_read_distance(p, &view, gpu_d);
            error_stats e = compare(gpu_d, ref, rad, w, h);
            for (int l = 0; l < NL; l++)
                if (need[m][l] < 0 && e.max_inner <= levels[l] && e.mean <= 0.1 * levels[l])
                    need[m][l] = iters[k];
            printf("| %s | %d | %.3g | %.3g | %.3g | %ld / %ld | %ld | %.1f |\n", methods[m], iters[k], e.max_inner,
                   e.max_all, e.mean, e.away, e.both, e.mismatch, median(ms, 3));
            fflush(stdout);
        }
    }
    printf("\nFewest iterations (of those tried) for max error away from silhouettes <= E and mean error <= E/10 "
           "(x radius); in brackets, how many times fewer than %s (-1: not reached):\n\n| E |", nm > 0 ? methods[0] : "");
    for (int m = 0; m < nm && m < 8; m++)
        printf(" %s |", methods[m]);
    printf("\n|---:|");
    for (int m = 0; m < nm && m < 8; m++)
        printf("---:|");
    printf("\n");
    for (int l = 0; l < NL; l++) {
        printf("| %g |", levels[l]);
        for (int m = 0; m < nm && m < 8; m++) {
            printf(" %d", need[m][l]);
            if (m > 0 && need[0][l] > 0 && need[m][l] > 0)
                printf(" (%.2fx)", (double)need[0][l] / need[m][l]);
            printf(" |");
        }
        printf("\n");
    }
done:
    sl_pipeline_destroy(p);
    sl_dataset_destroy(ds);
    free(ref);
    free(rad);
    free(gpu_d);
    free(seg);
    return st;
}

/* Max and mean over segments of max_t |quadratic pair(t) - cubic Hermite(t)| / radius. */
static void curve_deviation(const sl_dataset *ds, const sl_params *params, double *dmax, double *dmean)
{
    *dmax = *dmean = 0.0;
    sl_tubes_nodes n;
    sl_err err;
    if (sl_tubes_nodes_build(&ds->lines, (sl_tubes_tangents)sl_params_choice(params, "tangents"), -1, &n, &err) != SL_OK)
        return;
    sl_line_style style;
    sl_line_style_read(params, ds, &style);
    for (size_t s = 0; s < n.segment_count; s++) {
        const float *a = n.geometry + (size_t)n.segments[2 * s] * SL_TUBES_NODE_FLOATS;
        const float *b = n.geometry + (size_t)n.segments[2 * s + 1] * SL_TUBES_NODE_FLOATS;
        double r = n.has_radii ? 0.5 * (a[3] + b[3]) * style.radius_scale : style.radius;
        double worst = 0.0;
        for (int k = 0; k <= 64; k++) {
            double t = k / 64.0, d2 = 0.0;
            for (int c = 0; c < 3; c++) {
                double p0 = a[c], t0 = a[4 + c], p1 = b[c], t1 = b[4 + c];
                double t2 = t * t, t3 = t2 * t;
                double cub = (2 * t3 - 3 * t2 + 1) * p0 + (t3 - 2 * t2 + t) * t0 + (-2 * t3 + 3 * t2) * p1 + (t3 - t2) * t1;
                double a2 = p0 + t0 / 3, b2 = p1 - t1 / 3, m = 0.5 * (a2 + b2), quad;
                if (t <= 0.5) {
                    double u = 2 * t, v = 1 - u;
                    quad = v * v * p0 + 2 * u * v * a2 + u * u * m;
                } else {
                    double u = 2 * t - 1, v = 1 - u;
                    quad = v * v * m + 2 * u * v * b2 + u * u * p1;
                }
                d2 += (quad - cub) * (quad - cub);
            }
            worst = fmax(worst, sqrt(d2));
        }
        worst /= fmax(r, 1e-30);
        *dmax = fmax(*dmax, worst);
        *dmean += worst;
    }
    if (n.segment_count)
        *dmean /= (double)n.segment_count;
    sl_tubes_nodes_deinit(&n);
}

static sl_status bench_cubic(const options *o, sl_err *err)
{
    /* Tubes several pixels wide (radius 1/60 of the bounding radius where the
     * data gives none, close view as in the error table), so that most pixels
     * hit are away from a silhouette; at the default radius in a far view
     * tubes are below a pixel and "away" would be an empty set. */
    const int w = 128, h = 128;
    printf("\n## Quadratic pair against the true cubic Hermite sweep (reference, both)\n\n");
    printf("Smaller versions of the generated datasets, %dx%d, close view (distance 1.2), radius 1/60 of the bounding "
           "radius (hotroom: its data radii). Curve deviation: max and mean over segments of |quadratic pair(t) - "
           "cubic(t)| at equal parameter (an upper bound of the distance between the curves); depth difference on "
           "pixels both hit away from silhouettes (3x3 coverage change or depth jump > radius of the cubic "
           "reference), and over all pixels both hit (there a rim may switch to another tube); pixel counts of both "
           "sets. All in units of the tube radius.\n\n", w, h);
    printf("| dataset | segments | curve dev. max | curve dev. mean | depth max (away) | depth mean (away) | "
           "pixels away | depth max (all) | pixels both hit | coverage mismatch |\n"
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    const sl_technique *tubes = sl_technique_find("tubes");
    for (int d = 0; d < DATASET_COUNT; d++) {
        if (o->only && !strstr(o->only, datasets[d].name))
            continue;
        sl_dataset *ds = NULL;
        sl_status st = sl_generate_json(datasets[d].json_small, &ds, err);
        if (st != SL_OK)
            return st;
        sl_params params;
        sl_params_init(&params, tubes->params, tubes->param_count);
        double radius = sl_dataset_radius(ds) / 60.0;
        sl_params_set_numbers(&params, "radius", &radius, 1, err);
        size_t np = (size_t)w * h;
        float *q = calloc(np, sizeof *q), *qr = calloc(np, sizeof *qr), *c = calloc(np, sizeof *c),
              *cr = calloc(np, sizeof *cr);
        int *seg = calloc(np, sizeof *seg);
        sl_view view;
        if (!q || !qr || !c || !cr || !seg)
            st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
        if (st == SL_OK && (st = make_view(ds, 30.0, 1.2, w, h, &view, err)) == SL_OK &&
            (st = reference_of(ds, &view, &params, 0, q, qr, seg, err)) == SL_OK &&
            (st = reference_of(ds, &view, &params, 1, c, cr, seg, err)) == SL_OK) {
            double mx = 0.0, mean = 0.0, mx_all = 0.0;
            long both = 0, away = 0, mism = 0;
            for (int j = 0; j < h; j++)
                for (int i = 0; i < w; i++) {
                    size_t k = (size_t)j * w + i;
                    int a = q[k] > 0.0f, b = c[k] > 0.0f;
                    mism += a != b;
                    if (!(a && b))
                        continue;
                    double e = fabs((double)q[k] - c[k]) / fmax(cr[k], 1e-30);
                    mx_all = fmax(mx_all, e);
                    both++;
                    if (tubes_ref_silhouette(c, cr, w, h, i, j))
                        continue;
                    mx = fmax(mx, e);
                    mean += e;
                    away++;
                }
            double dev_max, dev_mean;
            curve_deviation(ds, &params, &dev_max, &dev_mean);
            printf("| %s | %zu | %.3g | %.3g | %.3g | %.3g | %ld | %.3g | %ld | %ld |\n", datasets[d].name,
                   segment_count(ds), dev_max, dev_mean, mx, away ? mean / away : 0.0, away, mx_all, both, mism);
            fflush(stdout);
        }
        free(q); free(qr); free(c); free(cr); free(seg);
        sl_dataset_destroy(ds);
        if (st != SL_OK)
            return st;
    }
    return SL_OK;
}

int main(int argc, char **argv)
{
    options o = {.width = 160, .height = 90, .frames = 3};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--skip-perf") == 0) o.skip_perf = 1;
        else if (strcmp(a, "--skip-error") == 0) o.skip_error = 1;
        else if (strcmp(a, "--skip-cubic") == 0) o.skip_cubic = 1;
        else if (strcmp(a, "--skip-vtk") == 0) o.skip_vtk = 1;
        else if (strcmp(a, "--vtk-png") == 0 && i + 1 < argc) o.vtk_png = argv[++i];
        else if (strcmp(a, "--size") == 0 && i + 1 < argc) {
            if (sscanf(argv[++i], "%dx%d", &o.width, &o.height) != 2 || o.width < 1 || o.height < 1 ||
                o.width > 8192 || o.height > 8192) {
                fprintf(stderr, "bench-tubes: --size WxH, 1..8192\n");
                return 1;
            }
        } else if (strcmp(a, "--frames") == 0 && i + 1 < argc) {
            o.frames = atoi(argv[++i]);
            if (o.frames < 1 || o.frames > 100000) {
                fprintf(stderr, "bench-tubes: --frames in [1, 100000]\n");
                return 1;
            }
        } else if (strcmp(a, "--datasets") == 0 && i + 1 < argc) {
            o.only = argv[++i];
        } else {
            fprintf(stderr, "usage: bench-tubes [--size WxH] [--frames N] [--datasets fibers,hotroom,bundle,brain,furball]\n"
                            "                   [--skip-perf] [--skip-error] [--skip-cubic] [--skip-vtk]\n"
                            "                   [--vtk-png PREFIX]\n");
            return 1;
        }
    }
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "bench-tubes: GPU: %s\n", err.message);
        return 3;
    }
    printf("# bench-tubes — %s\n", sl_gpu_renderer(gpu));
    sl_status st = SL_OK;
    if (!o.skip_perf)
        st = bench_speed(gpu, &o, &err);
    if (st == SL_OK && !o.skip_error)
        st = bench_error(gpu, &o, &err);
    if (st == SL_OK && !o.skip_cubic)
        st = bench_cubic(&o, &err);
    sl_gpu_destroy(gpu);
    if (st != SL_OK) {
        fprintf(stderr, "bench-tubes: %s\n", err.message);
        return 2;
    }
    return 0;
}
