/* embree_tubes.c — the Embree 3 peer of bench-tubes: vtk_tubes.py's contract, CPU ray casting.
 *
 *   peer-embree-tubes --lines LINES.vtk --cameras CAMERAS.txt --size WxH --radius R [--threads N (2)]
 *                     [--png PREFIX] [--packet 1|4|8|16 (1)] [--quality low|medium|high (high)]
 *
 * LINES.vtk goes through Sightline's loader (sl_load_vtk); a vertex's radius is |point array
 * "radius"| (what bench-tubes writes), else |the data's radii|, else R. Polylines become
 * RTC_GEOMETRY_TYPE_ROUND_HERMITE_CURVE segments with the Catmull-Rom tangents of `tubes`
 * (tubes_nodes.c): (x[i+1] - x[i-1]) / 2, one-sided at line ends, for position and radius.
 * CAMERAS.txt: "VIEW INDEX eye target up fov_y_deg" (INDEX < 0: untimed). A frame: one ray per
 * pixel centre (rtcIntersect1, or 2x2/4x2/4x4 packets), Lambert + ambient under vtk_tubes.py's
 * headlight, RGB8 in host memory; its time is wall time until all N threads (16x16 tiles from
 * an atomic counter) joined. build_ms: rtcNewScene .. rtcCommitScene, buffer filling included.
 * One JSON line out; {"ok": false, "error"} and exit 1 on any bad input. No end caps (Embree's cubic
 * round curves are a bare sweep surface), no specular, no antialiasing; never linked into the product.
 * Threads: main parses, builds, times and writes; workers only trace tiles into disjoint pixels.
 */
#include <cjson/cJSON.h>
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_clock.h"
#include "data/sl_load.h"
#include "image/sl_image.h"

#define TILE 16
#define MAX_VIEWS 64
#define MAX_FRAMES 1000000
#define MAX_THREADS 256
#define MAX_SIDE 16384
#define VIEW_NAME_MAX 64

typedef struct options {
    const char *lines, *cameras, *png;
    int width, height, threads, packet;
    double radius;
    enum RTCBuildQuality quality;
    const char *quality_name;
} options;

typedef struct frame_spec {
    int view;    /* index into the view table */
    int index;   /* < 0: untimed warm-up */
    double c[10]; /* eye, target, up, fov_y_deg (file coordinates) */
} frame_spec;

typedef struct view_stats {
    char name[VIEW_NAME_MAX];
    double *ms;  /* owned, timed frames */
    int count, capacity;
    int saved;   /* its first timed frame went to PNG */
} view_stats;

/* Embree's errors, from any thread Embree calls back on; the first message is kept. */
typedef struct device_errors {
    pthread_mutex_t lock;
    atomic_int count;
    char first[512]; /* guarded by lock */
} device_errors;

/* What every worker of one frame reads (written by main before the threads start). */
typedef struct frame_job {
    RTCScene scene;
    int width, height, packet, tiles_x, tile_count;
    float eye[3], forward[3], right[3], up[3], light[3]; /* right/up scaled by the image-plane extent */
    uint8_t *rgb;             /* width * height * 3, rows top-down; each tile written by one worker */
    atomic_int next_tile;
} frame_job;

static int fail(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Prints {"ok": false, "error": ...}; returns the exit status 1. */
static int fail(const char *fmt, ...)
{
    char msg[1200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    cJSON *o = cJSON_CreateObject();
    cJSON_AddFalseToObject(o, "ok");
    cJSON_AddStringToObject(o, "error", msg);
    char *s = cJSON_PrintUnformatted(o);
    printf("%s\n", s ? s : "{\"ok\": false, \"error\": \"out of memory\"}");
    fflush(stdout);
    free(s);
    cJSON_Delete(o);
    return 1;
}

static void on_device_error(void *user, enum RTCError code, const char *str)
{
    device_errors *e = user;
    pthread_mutex_lock(&e->lock);
    if (atomic_fetch_add(&e->count, 1) == 0)
        snprintf(e->first, sizeof e->first, "Embree error %d: %s", (int)code, str ? str : "(no message)");
    pthread_mutex_unlock(&e->lock);
}

/* Whole-string integer / finite double; 0 on success. */
static int parse_int(const char *s, long lo, long hi, int *out)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (end == s || *end || v < lo || v > hi)
        return -1;
    *out = (int)v;
    return 0;
}

static int parse_double(const char *s, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

/* Fills o from argv; on a bad argument writes why into msg and returns -1. */
static int parse_options(int argc, char **argv, options *o, char *msg, size_t size)
{
    *o = (options){.threads = 2, .packet = 1, .quality = RTC_BUILD_QUALITY_HIGH, .quality_name = "high"};
    const char *sz = NULL, *radius = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (i + 1 >= argc) {
            snprintf(msg, size, "%s: missing value (usage: --lines F --cameras F --size WxH --radius R "
                     "[--threads N] [--png PREFIX] [--packet 1|4|8|16] [--quality low|medium|high])", a);
            return -1;
        }
        const char *v = argv[++i];
        if (!strcmp(a, "--lines"))
            o->lines = v;
        else if (!strcmp(a, "--cameras"))
            o->cameras = v;
        else if (!strcmp(a, "--size"))
            sz = v;
        else if (!strcmp(a, "--radius"))
            radius = v;
        else if (!strcmp(a, "--png"))
            o->png = v;
        else if (!strcmp(a, "--threads")) {
            if (parse_int(v, 1, MAX_THREADS, &o->threads)) {
                snprintf(msg, size, "--threads %.100s: want an integer in 1..%d", v, MAX_THREADS);
                return -1;
            }
        } else if (!strcmp(a, "--packet")) {
            if (parse_int(v, 1, 16, &o->packet) || (o->packet != 1 && o->packet != 4 && o->packet != 8 &&
                                                    o->packet != 16)) {
                snprintf(msg, size, "--packet %.100s: want 1, 4, 8 or 16", v);
                return -1;
            }
        } else if (!strcmp(a, "--quality")) {
            if (!strcmp(v, "low"))
                o->quality = RTC_BUILD_QUALITY_LOW;
            else if (!strcmp(v, "medium"))
                o->quality = RTC_BUILD_QUALITY_MEDIUM;
            else if (!strcmp(v, "high"))
                o->quality = RTC_BUILD_QUALITY_HIGH;
            else {
                snprintf(msg, size, "--quality %.100s: want low, medium or high", v);
                return -1;
            }
            o->quality_name = v;
        } else {
            snprintf(msg, size, "unknown option %.100s", a);
            return -1;
        }
    }
    if (!o->lines || !o->cameras || !sz || !radius) {
        snprintf(msg, size, "--lines, --cameras, --size and --radius are required");
        return -1;
    }
    char w[32], h[32];
    const char *x = strpbrk(sz, "xX");
    if (!x || x == sz || (size_t)(x - sz) >= sizeof w || strlen(x + 1) >= sizeof h) {
        snprintf(msg, size, "--size %.100s: want WxH", sz);
        return -1;
    }
    snprintf(w, sizeof w, "%.*s", (int)(x - sz), sz);
    snprintf(h, sizeof h, "%s", x + 1);
    if (parse_int(w, 1, MAX_SIDE, &o->width) || parse_int(h, 1, MAX_SIDE, &o->height)) {
        snprintf(msg, size, "--size %.100s: want WxH, each 1..%d", sz, MAX_SIDE);
        return -1;
    }
    if (parse_double(radius, &o->radius) || o->radius <= 0.0) {
        snprintf(msg, size, "--radius %.100s: want a finite number > 0", radius);
        return -1;
    }
    return 0;
}

static int view_name_ok(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n >= VIEW_NAME_MAX)
        return 0;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') || *s == '_' ||
              *s == '-' || *s == '.'))
            return 0;
    return 1;
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross3(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Reads CAMERAS.txt into *frames (malloc'd) and the view table; msg on failure. */
static int read_cameras(const char *path, frame_spec **frames, int *frame_count, view_stats *views,
                        int *view_count, char *msg, size_t size)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(msg, size, "cannot open cameras file %.400s", path);
        return -1;
    }
    char *line = NULL;
    size_t cap = 0;
    int number = 0, rc = -1, capacity = 0;
    *frames = NULL;
    *frame_count = 0;
    while (getline(&line, &cap, f) != -1) {
        number++;
        char *fields[13], *save = NULL;
        int n = 0;
        for (char *t = strtok_r(line, " \t\r\n", &save); t && n < 13; t = strtok_r(NULL, " \t\r\n", &save))
            fields[n++] = t;
        if (n == 0 || fields[0][0] == '#')
            continue;
        if (n != 12) {
            snprintf(msg, size, "%.400s:%d: want VIEW INDEX and 10 numbers", path, number);
            goto done;
        }
        frame_spec fr;
        if (!view_name_ok(fields[0])) {
            snprintf(msg, size, "%.400s:%d: VIEW '%.80s' must be 1..%d of [A-Za-z0-9_.-]", path, number, fields[0],
                     VIEW_NAME_MAX - 1);
            goto done;
        }
        if (parse_int(fields[1], -1000000000L, 1000000000L, &fr.index)) {
            snprintf(msg, size, "%.400s:%d: INDEX '%.80s' is not an integer", path, number, fields[1]);
            goto done;
        }
        for (int k = 0; k < 10; k++)
            if (parse_double(fields[2 + k], &fr.c[k])) {
                snprintf(msg, size, "%.400s:%d: field %d '%.80s' is not a finite number", path, number, 3 + k,
                         fields[2 + k]);
                goto done;
            }
        double fwd[3] = {fr.c[3] - fr.c[0], fr.c[4] - fr.c[1], fr.c[5] - fr.c[2]}, side[3];
        cross3(fwd, fr.c + 6, side);
        if (!(fr.c[9] > 0.0 && fr.c[9] < 180.0) || dot3(fwd, fwd) == 0.0 ||
            dot3(side, side) <= 1e-12 * dot3(fwd, fwd) * dot3(fr.c + 6, fr.c + 6)) {
            snprintf(msg, size, "%.400s:%d: want eye != target, up not along the view direction, 0 < fov < 180",
                     path, number);
            goto done;
        }
        fr.view = -1;
        for (int v = 0; v < *view_count; v++)
            if (!strcmp(views[v].name, fields[0]))
                fr.view = v;
        if (fr.view < 0) {
            if (*view_count == MAX_VIEWS) {
                snprintf(msg, size, "%.400s:%d: more than %d views", path, number, MAX_VIEWS);
                goto done;
            }
            fr.view = (*view_count)++;
            snprintf(views[fr.view].name, VIEW_NAME_MAX, "%s", fields[0]);
        }
        if (*frame_count == MAX_FRAMES) {
            snprintf(msg, size, "%.400s: more than %d frames", path, MAX_FRAMES);
            goto done;
        }
        if (*frame_count == capacity) {
            capacity = capacity ? 2 * capacity : 64;
            frame_spec *grown = realloc(*frames, (size_t)capacity * sizeof **frames);
            if (!grown) {
                snprintf(msg, size, "out of memory for %d frames", capacity);
                goto done;
            }
            *frames = grown;
        }
        (*frames)[(*frame_count)++] = fr;
    }
    if (ferror(f))
        snprintf(msg, size, "cannot read %.400s", path);
    else if (*frame_count == 0)
        snprintf(msg, size, "%.400s has no frames", path);
    else
        rc = 0;
done:
    free(line);
    fclose(f);
    return rc;
}

/* Per-vertex radius: |"radius" array|, else |data radii|, else R. NULL (msg set) on a bad value. */
static const float *vertex_radii(const sl_lines *l, double fallback, float *storage, char *msg, size_t size)
{
    int a = sl_lines_find_attribute(l, "radius");
    const float *src = a >= 0 ? l->attributes[a].values : l->radii;
    for (size_t v = 0; v < l->vertex_count; v++) {
        float r = src ? fabsf(src[v]) : (float)fallback;
        if (!isfinite(r)) {
            snprintf(msg, size, "radius of point %zu is not finite", v);
            return NULL;
        }
        storage[v] = r;
    }
    return storage;
}

/* Fills Embree's vertex (x, y, z, r) and tangent (dx, dy, dz, dr) buffers and
 * the index buffer of segment starts; Catmull-Rom as in tubes_nodes.c. */
static void fill_curves(const sl_lines *l, const float *radii, float *vert, float *tangent, uint32_t *index)
{
    size_t s = 0;
    for (size_t k = 0; k < l->line_count; k++) {
        size_t lo = l->line_offsets[k], hi = l->line_offsets[k + 1];
        for (size_t v = lo; v < hi; v++) {
            size_t a = v, b = v;
            float half = 1.0f;
            if (hi - lo >= 2) {
                a = v > lo ? v - 1 : v;
                b = v + 1 < hi ? v + 1 : v;
                half = (v > lo && v + 1 < hi) ? 0.5f : 1.0f;
            }
            for (int c = 0; c < 3; c++) {
                vert[4 * v + c] = l->positions[3 * v + c];
                tangent[4 * v + c] = half * (l->positions[3 * b + c] - l->positions[3 * a + c]);
            }
            vert[4 * v + 3] = radii[v];
            tangent[4 * v + 3] = half * (radii[b] - radii[a]);
            if (v + 1 < hi)
                index[s++] = (uint32_t)v;
        }
    }
}

static uint8_t shade(const frame_job *job, float ngx, float ngy, float ngz, float dx, float dy, float dz)
{
    float len = sqrtf(ngx * ngx + ngy * ngy + ngz * ngz);
    if (!(len > 0.0f))
        return 0;
    if (ngx * dx + ngy * dy + ngz * dz > 0.0f)
        len = -len; /* face the viewer */
    float d = (ngx * job->light[0] + ngy * job->light[1] + ngz * job->light[2]) / len;
    float c = 0.8f * (0.25f + 0.75f * (d > 0.0f ? d : 0.0f));
    return (uint8_t)(255.0f * c + 0.5f);
}

static void pixel_dir(const frame_job *job, int x, int y, float *d)
{
    float sx = 2.0f * ((float)x + 0.5f) / (float)job->width - 1.0f;
    float sy = 1.0f - 2.0f * ((float)y + 0.5f) / (float)job->height;
    for (int c = 0; c < 3; c++)
        d[c] = job->forward[c] + sx * job->right[c] + sy * job->up[c];
}

static void put_pixel(const frame_job *job, int x, int y, uint8_t g)
{
    uint8_t *p = job->rgb + 3 * ((size_t)y * (size_t)job->width + (size_t)x);
    p[0] = p[1] = p[2] = g;
}

static void trace_tile_single(const frame_job *job, int x0, int y0, int x1, int y1)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            float d[3];
            pixel_dir(job, x, y, d);
            struct RTCRayHit rh = {
                .ray = {.org_x = job->eye[0], .org_y = job->eye[1], .org_z = job->eye[2], .tnear = 0.0f,
                        .dir_x = d[0], .dir_y = d[1], .dir_z = d[2], .tfar = INFINITY, .mask = 0xffffffffu},
                .hit = {.geomID = RTC_INVALID_GEOMETRY_ID, .instID = {RTC_INVALID_GEOMETRY_ID}}};
            rtcIntersect1(job->scene, &ctx, &rh);
            put_pixel(job, x, y, rh.hit.geomID == RTC_INVALID_GEOMETRY_ID
                                     ? 0 : shade(job, rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z, d[0], d[1], d[2]));
        }
}

/* One packet of N = 4, 8 or 16 rays in Embree's SoA layout (field k of ray i at k*N + i). */
typedef union packet {
    struct RTCRayHit4 p4;
    struct RTCRayHit8 p8;
    struct RTCRayHit16 p16;
    float f[(12 + 7 + RTC_MAX_INSTANCE_LEVEL_COUNT) * 16];
    uint32_t u[(12 + 7 + RTC_MAX_INSTANCE_LEVEL_COUNT) * 16];
} packet;

enum { RAY_ORG = 0, RAY_TNEAR = 3, RAY_DIR = 4, RAY_TIME = 7, RAY_TFAR = 8, RAY_MASK = 9, RAY_ID = 10,
       RAY_FLAGS = 11, HIT_NG = 12, HIT_GEOM = 18, HIT_INST = 19 };

static void trace_tile_packets(const frame_job *job, int x0, int y0, int x1, int y1)
{
    const int n = job->packet, bw = n == 4 ? 2 : 4, bh = n / bw;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (int by = y0; by < y1; by += bh)
        for (int bx = x0; bx < x1; bx += bw) {
            RTC_ALIGN(64) packet pk;
            RTC_ALIGN(64) int valid[16];
            for (int i = 0; i < n; i++) {
                int x = bx + i % bw, y = by + i / bw;
                float d[3];
                valid[i] = x < x1 && y < y1 ? -1 : 0;
                pixel_dir(job, x, y, d);
                for (int c = 0; c < 3; c++) {
                    pk.f[(RAY_ORG + c) * n + i] = job->eye[c];
                    pk.f[(RAY_DIR + c) * n + i] = d[c];
                }
                pk.f[RAY_TNEAR * n + i] = 0.0f;
                pk.f[RAY_TIME * n + i] = 0.0f;
                pk.f[RAY_TFAR * n + i] = INFINITY;
                pk.u[RAY_MASK * n + i] = 0xffffffffu;
                pk.u[RAY_ID * n + i] = (uint32_t)i;
                pk.u[RAY_FLAGS * n + i] = 0;
                pk.u[HIT_GEOM * n + i] = RTC_INVALID_GEOMETRY_ID;
                pk.u[HIT_INST * n + i] = RTC_INVALID_GEOMETRY_ID;
            }
            if (n == 4)
                rtcIntersect4(valid, job->scene, &ctx, &pk.p4);
            else if (n == 8)
                rtcIntersect8(valid, job->scene, &ctx, &pk.p8);
            else
                rtcIntersect16(valid, job->scene, &ctx, &pk.p16);
            for (int i = 0; i < n; i++) {
                if (!valid[i])
                    continue;
                uint8_t g = 0;
                if (pk.u[HIT_GEOM * n + i] != RTC_INVALID_GEOMETRY_ID)
                    g = shade(job, pk.f[HIT_NG * n + i], pk.f[(HIT_NG + 1) * n + i], pk.f[(HIT_NG + 2) * n + i],
                              pk.f[RAY_DIR * n + i], pk.f[(RAY_DIR + 1) * n + i], pk.f[(RAY_DIR + 2) * n + i]);
                put_pixel(job, bx + i % bw, by + i / bw, g);
            }
        }
}

/* Worker (and main, as one of the N): traces tiles until none is left. */
static void *trace_tiles(void *arg)
{
    frame_job *job = arg;
    for (;;) {
        int t = atomic_fetch_add(&job->next_tile, 1);
        if (t >= job->tile_count)
            return NULL;
        int x0 = (t % job->tiles_x) * TILE, y0 = (t / job->tiles_x) * TILE;
        int x1 = x0 + TILE < job->width ? x0 + TILE : job->width;
        int y1 = y0 + TILE < job->height ? y0 + TILE : job->height;
        if (job->packet == 1)
            trace_tile_single(job, x0, y0, x1, y1);
        else
            trace_tile_packets(job, x0, y0, x1, y1);
    }
}

/* Camera of fr relative to the dataset origin into job. */
static void set_camera(frame_job *job, const frame_spec *fr, const sl_vec3 *origin)
{
    const double o[3] = {origin->x, origin->y, origin->z};
    double f[3], r[3], u[3];
    for (int c = 0; c < 3; c++)
        f[c] = fr->c[3 + c] - fr->c[c];
    double fl = sqrt(dot3(f, f));
    for (int c = 0; c < 3; c++)
        f[c] /= fl;
    cross3(f, fr->c + 6, r);
    double rl = sqrt(dot3(r, r));
    for (int c = 0; c < 3; c++)
        r[c] /= rl;
    cross3(r, f, u);
    double th = tan(0.5 * fr->c[9] * M_PI / 180.0), aspect = (double)job->width / job->height;
    double l[3];
    for (int c = 0; c < 3; c++)
        l[c] = 0.3 * r[c] + 0.5 * u[c] - 1.0 * f[c]; /* the headlight of vtk_tubes.py, (0.3, 0.5, 1) in eye space */
    double ll = sqrt(dot3(l, l));
    for (int c = 0; c < 3; c++) {
        job->eye[c] = (float)(fr->c[c] - o[c]);
        job->forward[c] = (float)f[c];
        job->right[c] = (float)(r[c] * th * aspect);
        job->up[c] = (float)(u[c] * th);
        job->light[c] = (float)(l[c] / ll);
    }
}

/* Renders one frame with `threads` threads (main included); returns its wall ms, or -1 (msg set). */
static double render_frame(frame_job *job, int threads, char *msg, size_t size)
{
    pthread_t tid[MAX_THREADS];
    int started = 0;
    double t0 = sl_clock_ms();
    atomic_store(&job->next_tile, 0);
    for (; started < threads - 1; started++)
        if (pthread_create(&tid[started], NULL, trace_tiles, job) != 0)
            break;
    trace_tiles(job);
    for (int i = 0; i < started; i++)
        pthread_join(tid[i], NULL);
    double ms = sl_clock_ms() - t0;
    if (started < threads - 1) {
        snprintf(msg, size, "could start only %d of %d worker threads", started, threads - 1);
        return -1.0;
    }
    return ms;
}

static int write_png(const char *prefix, const char *view, const uint8_t *rgb, int w, int h, char *msg,
                     size_t size)
{
    size_t n = (size_t)w * (size_t)h;
    uint8_t *rgba = malloc(4 * n);
    if (!rgba) {
        snprintf(msg, size, "out of memory for the PNG of view %s", view);
        return -1;
    }
    for (size_t i = 0; i < n; i++) {
        memcpy(rgba + 4 * i, rgb + 3 * i, 3);
        rgba[4 * i + 3] = 255;
    }
    char path[4200];
    snprintf(path, sizeof path, "%.4000s-%s.png", prefix, view);
    sl_err err = {0};
    sl_status st = sl_png_write(path, rgba, w, h, &err);
    free(rgba);
    if (st != SL_OK) {
        snprintf(msg, size, "%.1000s", err.message);
        return -1;
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static int print_result(double build_ms, const char *version, const options *o, size_t segments,
                        size_t points, view_stats *views, int view_count)
{
    cJSON *root = cJSON_CreateObject(), *vs = cJSON_CreateObject();
    cJSON_AddTrueToObject(root, "ok");
    cJSON_AddNumberToObject(root, "build_ms", build_ms);
    cJSON_AddStringToObject(root, "embree", version);
    cJSON_AddNumberToObject(root, "threads", o->threads);
    cJSON_AddNumberToObject(root, "segments", (double)segments);
    cJSON_AddNumberToObject(root, "points", (double)points);
    cJSON_AddStringToObject(root, "build_quality", o->quality_name);
    cJSON_AddNumberToObject(root, "packet", o->packet);
    for (int v = 0; v < view_count; v++) {
        view_stats *s = &views[v];
        if (s->count == 0)
            continue;
        qsort(s->ms, (size_t)s->count, sizeof *s->ms, cmp_double);
        int n = s->count;
        double median = n % 2 ? s->ms[n / 2] : 0.5 * (s->ms[n / 2 - 1] + s->ms[n / 2]);
        cJSON *e = cJSON_CreateObject();
        cJSON_AddNumberToObject(e, "median_ms", median);
        cJSON_AddNumberToObject(e, "min_ms", s->ms[0]);
        cJSON_AddNumberToObject(e, "max_ms", s->ms[n - 1]);
        cJSON_AddNumberToObject(e, "frames", n);
        cJSON_AddItemToObject(vs, s->name, e);
    }
    cJSON_AddItemToObject(root, "views", vs);
    char *text = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    if (!text)
        return fail("out of memory for the JSON result");
    printf("%s\n", text);
    fflush(stdout);
    free(text);
    return 0;
}

int main(int argc, char **argv)
{
    static device_errors errors = {.lock = PTHREAD_MUTEX_INITIALIZER};
    static view_stats views[MAX_VIEWS];
    char msg[1100];
    options o;
    frame_spec *frames = NULL;
    int frame_count = 0, view_count = 0, rc = 1;
    sl_dataset *ds = NULL;
    uint8_t *data = NULL, *rgb = NULL;
    float *radii = NULL;
    RTCDevice device = NULL;
    RTCScene scene = NULL;
    sl_err err = {0};
    size_t size = 0, segments = 0;

    if (parse_options(argc, argv, &o, msg, sizeof msg) || read_cameras(o.cameras, &frames, &frame_count, views,
                                                                       &view_count, msg, sizeof msg)) {
        rc = fail("%s", msg);
        goto done;
    }
    if (sl_read_file(o.lines, SL_MAX_FILE_BYTES, &data, &size, &err) != SL_OK ||
        sl_load_vtk(data, size, o.lines, &ds, &err) != SL_OK) {
        rc = fail("%s", err.message);
        goto done;
    }
    if (ds->kind != SL_DATASET_LINES || ds->lines.vertex_count == 0) {
        rc = fail("%.400s: want POLYDATA lines with points", o.lines);
        goto done;
    }
    const sl_lines *l = &ds->lines;
    for (size_t k = 0; k < l->line_count; k++) {
        size_t len = l->line_offsets[k + 1] - l->line_offsets[k];
        segments += len >= 2 ? len - 1 : 0;
    }
    if (segments == 0) {
        rc = fail("%.400s: no line has two points", o.lines);
        goto done;
    }
    radii = malloc(l->vertex_count * sizeof *radii);
    rgb = calloc((size_t)o.width * (size_t)o.height, 3);
    if (!radii || !rgb) {
        rc = fail("out of memory for %zu radii and a %dx%d image", l->vertex_count, o.width, o.height);
        goto done;
    }
    if (!vertex_radii(l, o.radius, radii, msg, sizeof msg)) {
        rc = fail("%.400s: %s", o.lines, msg);
        goto done;
    }

    char config[64];
    snprintf(config, sizeof config, "threads=%d", o.threads);
    device = rtcNewDevice(config);
    if (!device) {
        rc = fail("rtcNewDevice(\"%s\") failed: Embree error %d", config, (int)rtcGetDeviceError(NULL));
        goto done;
    }
    rtcSetDeviceErrorFunction(device, on_device_error, &errors);
    char version[32];
    snprintf(version, sizeof version, "%d.%d.%d", (int)rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MAJOR),
             (int)rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MINOR),
             (int)rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_PATCH));
    if (!rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_CURVE_GEOMETRY_SUPPORTED)) {
        rc = fail("this Embree %s was built without curve geometry", version);
        goto done;
    }
    if (o.packet > 1 && !rtcGetDeviceProperty(device, o.packet == 4   ? RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED
                                                      : o.packet == 8 ? RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED
                                                                      : RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) {
        rc = fail("this Embree %s on this CPU has no native %d-ray packets", version, o.packet);
        goto done;
    }

    double t0 = sl_clock_ms();
    scene = rtcNewScene(device);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_HERMITE_CURVE);
    float *vert = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                          l->vertex_count);
    float *tangent = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_TANGENT, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                         l->vertex_count);
    uint32_t *index = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t),
                                              segments);
    if (scene && geom && vert && tangent && index) {
        fill_curves(l, radii, vert, tangent, index);
        rtcSetGeometryBuildQuality(geom, o.quality);
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene, geom);
        rtcSetSceneBuildQuality(scene, o.quality);
        rtcCommitScene(scene);
    }
    if (geom)
        rtcReleaseGeometry(geom);
    double build_ms = sl_clock_ms() - t0;
    if (atomic_load(&errors.count) || !scene || !geom || !vert || !tangent || !index) {
        rc = fail("building the scene: %s", atomic_load(&errors.count) ? errors.first : "Embree returned NULL");
        goto done;
    }

    frame_job job = {.scene = scene, .width = o.width, .height = o.height, .packet = o.packet, .rgb = rgb,
                     .tiles_x = (o.width + TILE - 1) / TILE};
    job.tile_count = job.tiles_x * ((o.height + TILE - 1) / TILE);
    for (int i = 0; i < frame_count; i++) {
        const frame_spec *fr = &frames[i];
        set_camera(&job, fr, &ds->origin);
        double ms = render_frame(&job, o.threads, msg, sizeof msg);
        if (ms < 0.0) {
            rc = fail("%s", msg);
            goto done;
        }
        if (atomic_load(&errors.count)) {
            rc = fail("frame %d of view %s: %s", fr->index, views[fr->view].name, errors.first);
            goto done;
        }
        if (fr->index < 0)
            continue;
        view_stats *s = &views[fr->view];
        if (s->count == s->capacity) {
            int cap = s->capacity ? 2 * s->capacity : 16;
            double *grown = realloc(s->ms, (size_t)cap * sizeof *grown);
            if (!grown) {
                rc = fail("out of memory for frame times");
                goto done;
            }
            s->ms = grown;
            s->capacity = cap;
        }
        s->ms[s->count++] = ms;
        if (o.png && !s->saved) {
            s->saved = 1;
            if (write_png(o.png, s->name, rgb, o.width, o.height, msg, sizeof msg)) {
                rc = fail("%s", msg);
                goto done;
            }
        }
    }
    rc = print_result(build_ms, version, &o, segments, l->vertex_count, views, view_count);

done:
    if (scene)
        rtcReleaseScene(scene);
    if (device)
        rtcReleaseDevice(device);
    for (int v = 0; v < view_count; v++)
        free(views[v].ms);
    free(frames);
    free(radii);
    free(rgb);
    free(data);
    sl_dataset_destroy(ds);
    return rc;
}
