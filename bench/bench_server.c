/* bench_server.c — end-to-end numbers of sightline-server on loopback.
 *
 *   bench-server [--dataset NAME (default tiny: 40 lines)] [--seconds S] [--size WxH | --small]
 *                [--drag-seconds S] [--only overhead|drag]
 *
 * Starts a private server (tests/server/sl_server_harness.h). Table 1, the
 * server's own overhead on a small dataset at 256x256: latency from a
 * `camera` message to the first frame echoing its seq (closed loop), fps to
 * 1, 4 and 16 clients of one session, JPEG encode ms per megapixel, bytes
 * per frame. Table 2, drags on real datasets (the tornado built-in and a
 * dipy tract bundle from data/samples, "not available" when absent) with
 * tubes_mesh, tubes and voxel_lines at --size (1280x720; --small 256x144),
 * each with the adaptive interactive scale and with the fixed half scale of
 * before: an open-loop drag (camera moves at 30 Hz for --drag-seconds, as a
 * mouse sends them), fps and camera->frame latency (arrival minus the send
 * time of the frame's camera seq, as the page shows it) while dragging, the
 * scale the server settled on, and the time from the drag's `end` to the
 * full-size still. Prints Markdown; asserts nothing (tests do).
 */
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>

#include "harness/sl_bench.h"
#include "sl_server_harness.h"

typedef struct viewer {
    int port;
    const char *session, *token;
    atomic_int *stop;
    int frames;
    double first_ms, last_ms;
    int ok;
} viewer;

static void *run_viewer(void *arg)
{
    viewer *v = arg;
    tclient c;
    if (tclient_connect(&c, v->port, NULL) != 0 || tclient_hello(&c, v->session, v->token, 64, 64) != 0)
        return NULL;
    c.auto_ack = 1;
    v->ok = 1;
    tclient_wait_frame(&c, 0, 0, 30000);
    int base = c.frames;
    v->first_ms = sl_clock_ms();
    while (!atomic_load(v->stop))
        if (tclient_next(&c, 50, NULL) == 0)
            break;
    v->last_ms = sl_clock_ms();
    v->frames = c.frames - base;
    tclient_close(&c);
    return NULL;
}

static int send_camera(tclient *c, uint32_t seq, const char *phase, double az)
{
    if (phase)
        return tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"phase\":\"%s\",\"camera\":{\"orbit\":"
                               "{\"azimuth\":%.4f,\"elevation\":20,\"distance\":2.5}}}", seq, phase, az);
    return tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"camera\":{\"orbit\":"
                           "{\"azimuth\":%.4f,\"elevation\":20,\"distance\":2.5}}}", seq, az);
}

/* Table 1: server overhead on a small dataset (closed-loop latency, fan-out fps, encode cost). */
static int overhead_table(const char *dataset, int w, int h, double seconds)
{
    harness hs;
    /* Up to 15 viewers connect at once from 127.0.0.1 (default pending cap per address: 4). */
    const char *extra[] = {"--default-dataset", dataset, "--max-pending", "32", "--max-pending-per-address", "32",
                           NULL};
    if (harness_start(&hs, extra) != 0) {
        fprintf(stderr, "bench-server: could not start the server\n");
        harness_stop(&hs);
        return 1;
    }
    tclient ctl;
    if (tclient_connect(&ctl, hs.port, NULL) != 0 || tclient_hello(&ctl, NULL, NULL, w, h) != 0) {
        fprintf(stderr, "bench-server: hello failed: %s\n", ctl.err.message);
        harness_stop(&hs);
        return 1;
    }
    ctl.auto_ack = 1;
    tclient_wait_frame(&ctl, 0, 1, 120000); /* dataset load + prepare */

    sl_bench_stat lat_move = {0}, lat_still = {0}, enc_i = {0}, enc_s = {0}, bytes_i = {0}, bytes_s = {0};
    sl_bench_stat render_i = {0}, render_s = {0};
    int iw = 0, ih = 0;
    uint32_t seq = 0;
    /* Interactive latency: one move at a time, next after its frame is shown. */
    for (int i = 0; i < 40; i++) {
        double t0 = sl_clock_ms();
        send_camera(&ctl, ++seq, "move", i * 3.0);
        if (tclient_wait_frame(&ctl, seq, 0, 30000) != 0)
            break;
        sl_bench_stat_add(&lat_move, ctl.last.arrival_ms - t0);
    }
    send_camera(&ctl, ++seq, "end", 120.0);
    tclient_wait_frame(&ctl, seq, 1, 30000);
    /* Still latency: one-off changes. */
    for (int i = 0; i < 20; i++) {
        double t0 = sl_clock_ms();
        send_camera(&ctl, ++seq, NULL, 130.0 + i * 5.0);
        if (tclient_wait_frame(&ctl, seq, 1, 30000) != 0)
            break;
        sl_bench_stat_add(&lat_still, ctl.last.arrival_ms - t0);
    }

    /* FPS to 1, 4, 16 clients of one session (the controller counts as one). */
    int counts[3] = {1, 4, 16};
    double fps_mean[3], fps_min[3];
    for (int k = 0; k < 3; k++) {
        int nv = counts[k] - 1;
        atomic_int stop = 0;
        viewer vs[16];
        pthread_t th[16];
        for (int i = 0; i < nv; i++) {
            vs[i] = (viewer){.port = hs.port, .session = ctl.session, .token = ctl.token, .stop = &stop};
            pthread_create(&th[i], NULL, run_viewer, &vs[i]);
        }
        usleep(500000);
        int base = ctl.frames;
        double t0 = sl_clock_ms(), az = 0;
        while (sl_clock_ms() - t0 < seconds * 1000.0) {
            send_camera(&ctl, ++seq, "move", az += 2.0);
            if (tclient_wait_frame(&ctl, seq, 0, 30000) != 0)
                break;
            double mpx = ctl.last.h.width * ctl.last.h.height / 1e6;
            if (ctl.last.h.flags & SL_FRAME_FLAG_INTERACTIVE) {
                sl_bench_stat_add(&enc_i, ctl.last.h.encode_ms / mpx);
                sl_bench_stat_add(&bytes_i, ctl.last.h.payload_bytes);
                sl_bench_stat_add(&render_i, ctl.last.h.render_ms);
                iw = ctl.last.h.width;
                ih = ctl.last.h.height;
            }
        }
        double ctl_fps = (ctl.frames - base) / ((sl_clock_ms() - t0) / 1000.0);
        atomic_store(&stop, 1);
        double sum = ctl_fps, mn = ctl_fps;
        for (int i = 0; i < nv; i++) {
            pthread_join(th[i], NULL);
            double f = vs[i].ok && vs[i].last_ms > vs[i].first_ms
                           ? vs[i].frames / ((vs[i].last_ms - vs[i].first_ms) / 1000.0) : 0;
            sum += f;
            mn = fmin(mn, f);
        }
        fps_mean[k] = sum / counts[k];
        fps_min[k] = mn;
        send_camera(&ctl, ++seq, "end", az);
        tclient_wait_frame(&ctl, seq, 1, 30000);
    }
    /* Still frames for encode cost and size. */
    for (int i = 0; i < 10; i++) {
        send_camera(&ctl, ++seq, NULL, 200.0 + i * 7.0);
        if (tclient_wait_frame(&ctl, seq, 1, 30000) != 0)
            break;
        double mpx = ctl.last.h.width * ctl.last.h.height / 1e6;
        sl_bench_stat_add(&enc_s, ctl.last.h.encode_ms / mpx);
        sl_bench_stat_add(&bytes_s, ctl.last.h.payload_bytes);
        sl_bench_stat_add(&render_s, ctl.last.h.render_ms);
    }
    tclient_close(&ctl);
    harness_stop(&hs);

    printf("sightline-server benchmark: dataset %s, %dx%d (interactive frames %dx%d, adaptive scale), loopback\n",
           dataset, w, h, iw, ih);
    printf("| metric | value |\n| --- | --- |\n");
    printf("| latency camera->frame, interactive (median / p95) | %.1f / %.1f ms (n=%d) |\n",
           sl_bench_stat_pct(&lat_move, 50), sl_bench_stat_pct(&lat_move, 95), lat_move.n);
    printf("| latency camera->frame, still (median / p95) | %.1f / %.1f ms (n=%d) |\n",
           sl_bench_stat_pct(&lat_still, 50), sl_bench_stat_pct(&lat_still, 95), lat_still.n);
    for (int k = 0; k < 3; k++)
        printf("| fps per client, %2d client(s) in one session (mean / min) | %.1f / %.1f |\n", counts[k],
               fps_mean[k], fps_min[k]);
    printf("| render+readback ms per frame, interactive / still (mean) | %.2f / %.2f |\n", sl_bench_stat_mean(&render_i),
           sl_bench_stat_mean(&render_s));
    printf("| JPEG encode ms per megapixel, interactive q60 4:2:0 (mean) | %.2f |\n", sl_bench_stat_mean(&enc_i));
    printf("| JPEG encode ms per megapixel, still q92 4:4:4 (mean) | %.2f |\n", sl_bench_stat_mean(&enc_s));
    printf("| bytes per frame, interactive / still (mean) | %.0f / %.0f |\n", sl_bench_stat_mean(&bytes_i), sl_bench_stat_mean(&bytes_s));
    return 0;
}

/* ---- Table 2: drags on real datasets ---- */

#define DRAG_HZ 30.0
#define DRAG_MAX_SEQ 4096

typedef struct drag_row {
    int ok;
    char why[160];              /* when !ok */
    int frames;                 /* interactive frames that arrived during the drag */
    double fps;
    sl_bench_stat latency;      /* per frame: arrival - send time of its camera seq */
    int last_w, last_h;         /* the newest interactive frame: the scale settled on */
    int widths[8], nwidths;     /* distinct interactive widths seen, in order */
    double still_after_ms;      /* `end` sent -> full-size still arrived */
    double still_cost_ms;       /* render + encode of a full-size still (frame header) */
} drag_row;

/* Waits for a `state` message, then for a still frame showing at least its version. */
static int wait_state_still(tclient *c, int timeout_ms)
{
    double deadline = sl_clock_ms() + timeout_ms;
    cJSON *st = tclient_wait_type(c, "state", timeout_ms);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(st, "version");
    uint32_t version = cJSON_IsNumber(v) ? (uint32_t)v->valuedouble : 0;
    cJSON_Delete(st);
    if (!version)
        return -1;
    while (sl_clock_ms() < deadline) {
        int r = tclient_next(c, (int)(deadline - sl_clock_ms()) + 1, NULL);
        if (r == 2 && c->last.h.kind == SL_FRAME_JPEG && !(c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE) &&
            c->last.h.state_version >= version)
            return 0;
        if (r == 0 || (r < 0 && c->closed))
            return -1;
    }
    return -1;
}

/* Switches the session to dataset/technique at the start camera with the
 * given stream settings, renders two stills (the first may prepare), then
 * drags for drag_s seconds and waits for the still. */
static void drag_once(tclient *c, uint32_t *seq, const char *dataset, const char *technique, const char *stream,
                      double drag_s, drag_row *r)
{
    memset(r, 0, sizeof *r);
    int timeout = 600000; /* prepares of big scenes on llvmpipe */
    if (tclient_send(c, "{\"type\":\"scene\",\"dataset\":\"%s\",\"technique\":\"%s\",\"camera\":{\"orbit\":"
                        "{\"azimuth\":0,\"elevation\":20,\"distance\":2.5},\"fov_y\":45}}", dataset, technique) != 0 ||
        wait_state_still(c, timeout) != 0) {
        snprintf(r->why, sizeof r->why, "scene %s/%s gave no still frame", dataset, technique);
        return;
    }
    if (tclient_send(c, "{\"type\":\"set\",\"stream\":%s}", stream) != 0 || wait_state_still(c, timeout) != 0) {
        snprintf(r->why, sizeof r->why, "stream settings gave no still frame");
        return;
    }
    r->still_cost_ms = c->last.h.render_ms + c->last.h.encode_ms;
    static double sent[DRAG_MAX_SEQ];
    uint32_t first = *seq + 1;
    double t0 = sl_clock_ms(), next = t0, az = 0, t_end = t0 + drag_s * 1000.0;
    while (sl_clock_ms() < t_end) {
        double now = sl_clock_ms();
        if (now >= next) {
            send_camera(c, ++*seq, "move", az += 1.5);
            if (*seq - first < DRAG_MAX_SEQ)
                sent[*seq - first] = now;
            next += 1000.0 / DRAG_HZ;
        }
        int wait = (int)(fmin(next, t_end) - sl_clock_ms());
        if (tclient_next(c, wait < 1 ? 1 : wait, NULL) != 2 || c->last.h.kind != SL_FRAME_JPEG ||
            !(c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE) || c->last.h.camera_seq < first)
            continue;
        uint32_t k = c->last.h.camera_seq - first;
        if (k < DRAG_MAX_SEQ)
            sl_bench_stat_add(&r->latency, c->last.arrival_ms - sent[k]);
        r->frames++;
        r->last_w = c->last.h.width;
        r->last_h = c->last.h.height;
        int seen = 0;
        for (int i = 0; i < r->nwidths; i++)
            seen |= r->widths[i] == r->last_w;
        if (!seen && r->nwidths < 8)
            r->widths[r->nwidths++] = r->last_w;
    }
    r->fps = r->frames / drag_s;
    double t_sent_end = sl_clock_ms();
    send_camera(c, ++*seq, "end", az);
    if (tclient_wait_frame(c, *seq, 1, timeout) != 0) {
        snprintf(r->why, sizeof r->why, "no still frame after the drag");
        return;
    }
    r->still_after_ms = c->last.arrival_ms - t_sent_end;
    r->ok = 1;
}

static const char *scale_name(int w, int full, char *buf, size_t size)
{
    double s = (double)w / full;
    const char *names[] = {"1", "1/2", "1/4", "1/8", "1/16"};
    for (int k = 0; k < 5; k++)
        if (fabs(s - 1.0 / (1 << k)) < 0.02 / (1 << k))
            return names[k];
    snprintf(buf, size, "%.3f", s);
    return buf;
}

static void print_row(const char *dataset, const char *technique, const char *mode, int w, drag_row *r)
{
    if (!r->ok) {
        printf("| %s | %s | %s | not available: %s | | | | |\n", dataset, technique, mode, r->why);
        return;
    }
    if (r->frames == 0) {
        printf("| %s | %s | %s | none: no interactive frame arrived during the drag | 0.0 | - | %.0f | %.0f |\n",
               dataset, technique, mode, r->still_after_ms, r->still_cost_ms);
        return;
    }
    char b1[16], used[96] = "";
    size_t n = 0;
    for (int i = 0; i < r->nwidths && n < sizeof used; i++) {
        char b[16];
        n += (size_t)snprintf(used + n, sizeof used - n, "%s%s", i ? ", " : "", scale_name(r->widths[i], w, b, sizeof b));
    }
    printf("| %s | %s | %s | %s (%dx%d; used %s) | %.1f | %.0f / %.0f | %.0f | %.0f |\n", dataset, technique, mode,
           scale_name(r->last_w, w, b1, sizeof b1), r->last_w, r->last_h, used,
           r->fps, sl_bench_stat_pct(&r->latency, 50), sl_bench_stat_pct(&r->latency, 95), r->still_after_ms, r->still_cost_ms);
}

/* Table 2. The tract sample is registered with `catalog add` while the server runs (SQLite WAL). */
static int drag_table(const char *src_dir, int w, int h, double drag_s)
{
    char tract_dir[PATH_MAX], tract[PATH_MAX + 16];
    snprintf(tract_dir, sizeof tract_dir, "%s/data/samples/minimal_bundles/sub_1", src_dir);
    snprintf(tract, sizeof tract, "%s/AF_L.trk", tract_dir);
    harness hs;
    const char *extra[] = {"--data-dir", tract_dir, NULL};
    struct stat sb;
    int have_tract = stat(tract, &sb) == 0;
    if (harness_start(&hs, have_tract ? extra : NULL) != 0) {
        fprintf(stderr, "bench-server: could not start the server\n");
        harness_stop(&hs);
        return 1;
    }
    char why_tract[200] = "";
    if (!have_tract) {
        snprintf(why_tract, sizeof why_tract, "%s",
                 "data/samples/minimal_bundles/sub_1/AF_L.trk is absent (run scripts/fetch-sample-data)");
    } else {
        char *add[] = {hs.exe, "--db", hs.db, "--data-dir", tract_dir, "catalog", "add", tract, NULL};
        int rc = harness_run_wait(add);
        if (rc != 0)
            snprintf(why_tract, sizeof why_tract, "`catalog add .../AF_L.trk` exited %d", rc);
    }
    tclient c;
    if (tclient_connect(&c, hs.port, NULL) != 0 || tclient_hello(&c, NULL, NULL, w, h) != 0) {
        fprintf(stderr, "bench-server: hello failed: %s\n", c.err.message);
        harness_stop(&hs);
        return 1;
    }
    c.auto_ack = 1;
    tclient_wait_frame(&c, 0, 1, 120000);
    const char *datasets[2] = {"tornado", "AF_L.trk"};
    const char *labels[2] = {"tornado (1000 lines x 200 points)", "AF_L.trk (dipy sub_1, 50 lines x 20 points)"};
    const char *techniques[3] = {"tubes_mesh", "tubes", "voxel_lines"};
    const char *modes[2] = {"fixed 1/2 (before)", "adaptive (<= 1, 100 ms)"};
    const char *streams[2] = {"{\"interactive_adaptive\":false,\"interactive_scale\":0.5}",
                              "{\"interactive_adaptive\":true,\"interactive_scale\":1,\"interactive_budget_ms\":100}"};
    printf("\nDrags on real datasets at %dx%d: camera moves at %.0f Hz for %.1f s (open loop), loopback. "
           "fps = interactive frames per second of drag; latency = frame arrival - send time of its camera seq; "
           "still after = `end` sent -> full-size still arrived (still_delay_ms 200 + render); "
           "still cost = render + encode of one full-size still.\n\n",
           w, h, DRAG_HZ, drag_s);
    printf("| dataset | technique | interactive scale | settled scale (size; scales used) | fps dragging | "
           "latency median / p95 ms | still after ms | still cost ms |\n");
    printf("| --- | --- | --- | --- | ---: | ---: | ---: | ---: |\n");
    fflush(stdout);
    uint32_t seq = 0;
    for (int d = 0; d < 2; d++) {
        for (int t = 0; t < 3; t++) {
            for (int m = 0; m < 2; m++) {
                drag_row r;
                if (d == 1 && why_tract[0]) {
                    memset(&r, 0, sizeof r);
                    snprintf(r.why, sizeof r.why, "%.150s", why_tract);
                } else {
                    drag_once(&c, &seq, datasets[d], techniques[t], streams[m], drag_s, &r);
                }
                print_row(labels[d], techniques[t], modes[m], w, &r);
                fflush(stdout);
            }
        }
    }
    tclient_close(&c);
    harness_stop(&hs);
    return 0;
}

int main(int argc, char **argv)
{
    const char *dataset = "tiny"; /* server overhead; heavy datasets measure the technique instead */
    int w = 1280, h = 720;
    double seconds = 3.0, drag_s = 4.0;
    const char *only = NULL;
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(argv[i], "--small") == 0)
            w = 256, h = 144;
        else if (strcmp(argv[i], "--dataset") == 0 && v)
            dataset = v, i++;
        else if (strcmp(argv[i], "--size") == 0 && v && sscanf(v, "%dx%d", &w, &h) == 2 && w > 0 && h > 0)
            i++;
        else if (strcmp(argv[i], "--seconds") == 0 && v)
            seconds = atof(v), i++;
        else if (strcmp(argv[i], "--drag-seconds") == 0 && v && atof(v) > 0)
            drag_s = atof(v), i++;
        else if (strcmp(argv[i], "--only") == 0 && v && (strcmp(v, "overhead") == 0 || strcmp(v, "drag") == 0))
            only = v, i++;
        else {
            fprintf(stderr, "usage: bench-server [--dataset NAME] [--seconds S] [--size WxH | --small]\n"
                            "                    [--drag-seconds S] [--only overhead|drag]\n");
            return 2;
        }
    }
    harness_default_binary_dir();
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    if (!src) {
        setenv("SIGHTLINE_SOURCE_DIR", SIGHTLINE_SOURCE_DIR, 1);
        src = SIGHTLINE_SOURCE_DIR;
    }
    int rc = 0;
    if (!only || strcmp(only, "overhead") == 0)
        rc |= overhead_table(dataset, 256, 256, seconds);
    if (!only || strcmp(only, "drag") == 0)
        rc |= drag_table(src, w, h, drag_s);
    return rc;
}
