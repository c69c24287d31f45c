/* bench_peers.c — the peers of a benchmark: what a user would otherwise pick, on our file and cameras.
 *
 * sl_bench_peer_files_write puts the lines (legacy VTK, binary big-endian, the
 * data's radii as the point scalar `radius`) and every view's cameras (the
 * very cameras sl_bench_time_frames renders) in a temporary folder; each peer
 * program reads both and prints one JSON line ({"ok": true, "views": {VIEW:
 * {"median_ms", "min_ms", "max_ms"}}, ...} or {"ok": false, "error"}):
 * bench/vtk_tubes.py and bench/vtk_ribbons.py under xvfb-run (Debian's VTK
 * is X11-only; the lines file then also carries the ribbons' NORMALS) and
 * peer-embree-tubes (bench/peers/, next to the running program). A peer that
 * is missing or fails gives ok = 0 and a reason for the table, never a crash.
 * Main thread; runs child processes through popen.
 */
#include "sl_bench.h"

#include <cjson/cJSON.h>
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/sl_clock.h"

#ifndef SIGHTLINE_SOURCE_DIR
#define SIGHTLINE_SOURCE_DIR "."
#endif

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

sl_status sl_bench_write_lines_vtk(const sl_dataset *ds, float radius_scale, const float *normals, const char *path,
                                   sl_err *err)
{
    if (ds->kind != SL_DATASET_LINES)
        return sl_err_set(err, SL_ERR_INVALID, "%s is not a line set", ds->name);
    FILE *f = fopen(path, "wb");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "cannot write %s", path);
    const sl_lines *l = &ds->lines;
    char title[sizeof ds->name];
    snprintf(title, sizeof title, "%s", ds->name);
    for (char *c = title; *c; c++)
        if (*c == '\n' || *c == '\r')
            *c = ' '; /* the title is one line of the format */
    fprintf(f, "# vtk DataFile Version 3.0\nsightline benchmark %s\nBINARY\nDATASET POLYDATA\nPOINTS %zu float\n",
            title, l->vertex_count);
    for (size_t k = 0; k < 3 * l->vertex_count; k++)
        put_be_float(l->positions[k], f);
    fprintf(f, "\nLINES %zu %zu\n", l->line_count, l->line_count + l->vertex_count);
    for (size_t k = 0; k < l->line_count; k++) {
        put_be32(l->line_offsets[k + 1] - l->line_offsets[k], f);
        for (uint32_t i = l->line_offsets[k]; i < l->line_offsets[k + 1]; i++)
            put_be32(i, f);
    }
    if (l->radii || normals)
        fprintf(f, "\nPOINT_DATA %zu\n", l->vertex_count);
    if (l->radii) {
        fprintf(f, "SCALARS radius float 1\nLOOKUP_TABLE default\n");
        for (size_t k = 0; k < l->vertex_count; k++)
            put_be_float(l->radii[k] * radius_scale, f);
        if (normals)
            fputc('\n', f);
    }
    if (normals) {
        fprintf(f, "NORMALS normals float\n");
        for (size_t k = 0; k < 3 * l->vertex_count; k++)
            put_be_float(normals[k], f);
    }
    fputc('\n', f);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return sl_err_set(err, SL_ERR_IO, "cannot write %s", path);
    return SL_OK;
}

sl_status sl_bench_peer_files_write(const sl_dataset *ds, float radius_scale, const float *normals,
                                    const sl_bench_view_spec *views, int view_count, const sl_bench_options *o,
                                    sl_bench_peer_files *files, sl_err *err)
{
    memset(files, 0, sizeof *files);
    snprintf(files->dir, sizeof files->dir, "/tmp/sightline-bench-XXXXXX");
    if (!mkdtemp(files->dir)) {
        files->dir[0] = 0;
        return sl_err_set(err, SL_ERR_IO, "cannot create a temporary folder");
    }
    snprintf(files->lines, sizeof files->lines, "%s/lines.vtk", files->dir);
    snprintf(files->cameras, sizeof files->cameras, "%s/cameras.txt", files->dir);
    sl_status st = sl_bench_write_lines_vtk(ds, radius_scale, normals, files->lines, err);
    FILE *f = st == SL_OK ? fopen(files->cameras, "w") : NULL;
    if (st == SL_OK && !f)
        st = sl_err_set(err, SL_ERR_IO, "cannot write %s", files->cameras);
    for (int v = 0; v < view_count && st == SL_OK; v++)
        for (int fr = -1; fr < o->frames && st == SL_OK; fr++) {
            sl_camera c;
            if ((st = views[v].camera(ds, fr, o->frames, views[v].ctx, &c, err)) != SL_OK)
                break;
            /* File coordinates are the dataset's float coordinates: world - origin. */
            fprintf(f, "%s %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", views[v].name, fr,
                    c.eye.x - ds->origin.x, c.eye.y - ds->origin.y, c.eye.z - ds->origin.z, c.target.x - ds->origin.x,
                    c.target.y - ds->origin.y, c.target.z - ds->origin.z, c.up.x, c.up.y, c.up.z, c.fov_y_deg);
        }
    if (f && fclose(f) != 0 && st == SL_OK)
        st = sl_err_set(err, SL_ERR_IO, "cannot write %s", files->cameras);
    if (st != SL_OK)
        sl_bench_peer_files_remove(files);
    return st;
}

void sl_bench_peer_files_remove(sl_bench_peer_files *files)
{
    if (!files->dir[0])
        return;
    remove(files->lines);
    remove(files->cameras);
    rmdir(files->dir);
    files->dir[0] = 0;
}

static void set_reason(sl_bench_peer_result *r, const char *what)
{
    r->ok = 0;
    size_t n = 0;
    for (const char *c = what; *c && n + 1 < sizeof r->reason; c++)
        r->reason[n++] = (*c == '|' || *c == '\n' || *c == '\r') ? ' ' : *c; /* table-safe */
    r->reason[n] = 0;
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

/* Appends " --lines FILE --cameras FILE", quoted, to the shell command. */
static void append_files(char *cmd, size_t size, const sl_bench_peer_files *files)
{
    strncat(cmd, " --lines ", size - strlen(cmd) - 1);
    append_quoted(cmd, size, files->lines);
    strncat(cmd, " --cameras ", size - strlen(cmd) - 1);
    append_quoted(cmd, size, files->cameras);
}

static double json_number(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : 0.0;
}

static void json_string(const cJSON *o, const char *key, char *out, size_t size)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    snprintf(out, size, "%s", cJSON_IsString(v) ? v->valuestring : "");
}

/* Runs cmd (stderr merged), keeps its last JSON line and fills r from it. */
static void run_peer(const char *cmd, const sl_bench_tube_peer_desc *d, const char *label, sl_bench_peer_result *r)
{
    fflush(stdout);
    double t0 = sl_clock_ms();
    FILE *p = popen(cmd, "r");
    if (!p) {
        set_reason(r, "cannot start the peer");
        return;
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
    r->seconds = (sl_clock_ms() - t0) / 1000.0;
    cJSON *root = json[0] ? cJSON_Parse(json) : NULL;
    if (!root) {
        char reason[700];
        snprintf(reason, sizeof reason, "%s exited with status %d%s%.400s", label,
                 status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1, last[0] ? ": " : "", last);
        set_reason(r, reason);
        return;
    }
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "views");
    const cJSON *error = cJSON_GetObjectItemCaseSensitive(root, "error");
    if (!cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(root, "ok")) || !cJSON_IsObject(views)) {
        set_reason(r, cJSON_IsString(error) ? error->valuestring : "the peer failed");
    } else {
        r->ok = 1;
        r->build_ms = json_number(root, cJSON_GetObjectItemCaseSensitive(root, "filter_ms") ? "filter_ms" : "build_ms");
        r->first_frame_ms = json_number(root, "first_frame_ms");
        r->triangles = json_number(root, "triangles");
        r->mesh_bytes = json_number(root, "mesh_bytes");
        json_string(root, "gl_renderer", r->renderer, sizeof r->renderer);
        json_string(root, cJSON_GetObjectItemCaseSensitive(root, "vtk") ? "vtk" : "embree", r->version,
                    sizeof r->version);
        for (int v = 0; v < d->view_count && v < SL_BENCH_MAX_VIEWS; v++) {
            const cJSON *view = cJSON_GetObjectItemCaseSensitive(views, d->views[v].name);
            r->median_ms[v] = json_number(view, "median_ms");
            r->min_ms[v] = json_number(view, "min_ms");
            r->max_ms[v] = json_number(view, "max_ms");
            if (!(r->median_ms[v] > 0.0)) {
                char reason[160];
                snprintf(reason, sizeof reason, "%s reported no frames for view %s", label, d->views[v].name);
                set_reason(r, reason);
            }
        }
    }
    cJSON_Delete(root);
}

/* The start of a VTK peer's command line: xvfb-run, /usr/bin/python3 and
 * bench/<script> with the files and the size; 1, or 0 with r->reason set. */
static int vtk_command(const char *script_name, const sl_bench_tube_peer_desc *d, char *cmd, size_t size,
                       sl_bench_peer_result *r)
{
    memset(r, 0, sizeof *r);
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    char script[4096], reason[600];
    snprintf(script, sizeof script, "%s/bench/%s", src && *src ? src : SIGHTLINE_SOURCE_DIR, script_name);
    if (access(script, R_OK) != 0) {
        snprintf(reason, sizeof reason, "no %.400s; set SIGHTLINE_SOURCE_DIR", script);
        set_reason(r, reason);
        return 0;
    }
    if (access("/usr/bin/python3", X_OK) != 0 || !executable_on_path("xvfb-run")) {
        set_reason(r, "no /usr/bin/python3 or xvfb-run; scripts/bench installs bench/packages.txt");
        return 0;
    }
    const sl_bench_options *o = d->options;
    snprintf(cmd, size, "xvfb-run -a -s '-screen 0 %dx%dx24' /usr/bin/python3 ", o->width > 1280 ? o->width : 1280,
             o->height > 1024 ? o->height : 1024);
    append_quoted(cmd, size, script);
    append_files(cmd, size, d->files);
    size_t n = strlen(cmd);
    snprintf(cmd + n, size - n, " --size %dx%d", o->width, o->height);
    return 1;
}

void sl_bench_peer_vtk_tubes(const sl_bench_tube_peer_desc *d, sl_bench_peer_result *r)
{
    char cmd[16384];
    if (!vtk_command("vtk_tubes.py", d, cmd, sizeof cmd, r))
        return;
    size_t n = strlen(cmd);
    snprintf(cmd + n, sizeof cmd - n, " --radius %.9g --sides %d --caps %d 2>&1", d->radius, d->sides, d->caps);
    run_peer(cmd, d, "vtk_tubes.py", r);
}

void sl_bench_peer_vtk_ribbons(const sl_bench_tube_peer_desc *d, sl_bench_peer_result *r)
{
    char cmd[16384];
    if (!vtk_command("vtk_ribbons.py", d, cmd, sizeof cmd, r))
        return;
    size_t n = strlen(cmd);
    snprintf(cmd + n, sizeof cmd - n, " --width %.9g 2>&1", d->radius);
    run_peer(cmd, d, "vtk_ribbons.py", r);
}

void sl_bench_peer_embree_tubes(const sl_bench_tube_peer_desc *d, sl_bench_peer_result *r)
{
    memset(r, 0, sizeof *r);
    char self[PATH_MAX], exe[PATH_MAX + 32];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) {
        set_reason(r, "cannot find this program's folder");
        return;
    }
    self[n] = 0;
    char *slash = strrchr(self, '/');
    if (slash)
        *slash = 0;
    snprintf(exe, sizeof exe, "%s/peer-embree-tubes", self);
    if (access(exe, X_OK) != 0) {
        set_reason(r, "no peer-embree-tubes: Embree 3 was not found at build time (Debian libembree-dev, "
                      "bench/packages.txt)");
        return;
    }
    const sl_bench_options *o = d->options;
    char cmd[16384] = "";
    append_quoted(cmd, sizeof cmd, exe);
    append_files(cmd, sizeof cmd, d->files);
    size_t len = strlen(cmd);
    snprintf(cmd + len, sizeof cmd - len, " --size %dx%d --radius %.9g --threads %d 2>&1", o->width, o->height,
             d->radius, d->threads > 0 ? d->threads : 1);
    run_peer(cmd, d, "peer-embree-tubes", r);
}
