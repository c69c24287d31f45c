/* sl_server_harness.h — start a private sightline-server for a test or benchmark,
 * and talk to it as a protocol client.
 *
 * harness_start makes a temporary directory (catalog, empty data dir),
 * registers a small generated dataset "tiny" (so sessions load in
 * milliseconds even under ASan), starts $SIGHTLINE_BINARY_DIR/bin/sightline-server
 * on 127.0.0.1 with --port 0 and reads the chosen port from its stdout.
 * harness_stop sends SIGINT (an immediate stop; SIGTERM would drain) and
 * returns the exit status, so a leak (ASan) or a crash at shutdown fails
 * the test. harness_start_shared starts another server (another node) on
 * the catalog file of a running harness; harness_signal and harness_wait
 * let a test kill a node or watch it drain. tclient wraps sl_wsclient: it
 * parses text messages into cJSON, records every binary frame (header +
 * payload copy), keeps the close frame's code and reason (tclient_wait_close)
 * and acks frames when auto_ack is set. harness_cli_render
 * renders a reference with sightline-render. tclient_connect_page connects
 * as the page does (/ws?session=ID, which a balancer routes by); a cluster
 * of nodes behind HAProxy is sl_cluster.h. Loopback only.
 * One thread per tclient; header-only (static functions) for tests and bench.
 */
#ifndef SL_SERVER_HARNESS_H
#define SL_SERVER_HARNESS_H

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "core/sl_clock.h"
#include "image/sl_image.h"
#include "sl_protocol.h"
#include "sl_wsclient.h"

#define HARNESS_TINY "{\"generator\":\"tornado\",\"lines\":40,\"points\":40,\"seed\":3}"

typedef struct harness {
    pid_t pid;
    int port;
    int out_fd;
    char dir[256];
    char db[300];
    char exe[1024];
} harness;

/* A benchmark run by hand has no ctest environment: SIGHTLINE_BINARY_DIR
 * defaults to the build folder of the running program (its bin/'s parent). */
static __attribute__((unused)) void harness_default_binary_dir(void)
{
    if (getenv("SIGHTLINE_BINARY_DIR"))
        return;
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = 0;
        char *bin = dirname(exe); /* build/bin */
        setenv("SIGHTLINE_BINARY_DIR", dirname(bin), 1);
    }
}

static __attribute__((unused)) int harness_run_wait(char *const argv[])
{
    pid_t pid = fork();
    if (pid == 0) {
        int devnull = open("/dev/null", O_WRONLY);
        if (devnull >= 0)
            dup2(devnull, 1);
        execv(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) < 0)
        return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* extra: NULL-terminated extra server arguments (may be NULL). shared: NULL
 * for a catalog of its own, or a started harness whose catalog file and
 * data dir this server uses too (stop this one first). Returns 0 on success. */
static __attribute__((unused)) int harness_start_shared(harness *h, const harness *shared, const char *const *extra)
{
    memset(h, 0, sizeof *h);
    h->pid = -1;
    const char *bin = getenv("SIGHTLINE_BINARY_DIR");
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    snprintf(h->exe, sizeof h->exe, "%s/bin/sightline-server", bin ? bin : "build");
    snprintf(h->dir, sizeof h->dir, "/tmp/sl-server-test-XXXXXX");
    if (!mkdtemp(h->dir)) {
        fprintf(stderr, "harness: mkdtemp failed: %s\n", strerror(errno));
        return -1;
    }
    char data[300], web[1024];
    snprintf(data, sizeof data, "%s/data", h->dir);
    mkdir(data, 0755);
    snprintf(h->db, sizeof h->db, "%s/catalog.db", h->dir);
    if (shared) {
        snprintf(h->db, sizeof h->db, "%s", shared->db);
        snprintf(data, sizeof data, "%s/data", shared->dir);
    }
    snprintf(web, sizeof web, "%s/web", src ? src : ".");
    char *reg[] = {h->exe, "catalog", "add-generator", "tiny", HARNESS_TINY, "--db", h->db, "--data-dir", data, NULL};
    int rc = shared ? 0 : harness_run_wait(reg);
    if (rc != 0) {
        fprintf(stderr, "harness: catalog add-generator exited %d\n", rc);
        return -1;
    }
    int pipefd[2];
    if (pipe(pipefd) != 0)
        return -1;
    const char *argv[40] = {h->exe, "--port", "0", "--bind", "127.0.0.1", "--db", h->db, "--data-dir", data,
                            "--web-dir", web, "--default-dataset", "tiny"};
    int argc = 13;
    for (int i = 0; extra && extra[i] && argc < 38; i++)
        argv[argc++] = extra[i];
    argv[argc] = NULL;
    char log[400];
    snprintf(log, sizeof log, "%s/server.log", h->dir);
    /* LeakSanitizer's dynamic-TLS scan sometimes reads a stale block after
     * Mesa's driver is dlclose()d at eglTerminate and crashes ("Tracer caught
     * signal 11", "DTLS ... at 0x...15e"), so the server runs with use_tls=0.
     * Without the TLS root set LSan can only report more, never less; what it
     * then reports in addition are the dynamic loader's own TLS blocks, so the
     * server gets tests/lsan.supp plus one line for ld-linux. */
    char supp[400], line[512];
    snprintf(supp, sizeof supp, "%s/lsan.supp", h->dir);
    char lead_supp[1024];
    snprintf(lead_supp, sizeof lead_supp, "%s/tests/lsan.supp", src ? src : ".");
    FILE *in = fopen(lead_supp, "r"), *out = fopen(supp, "w");
    while (in && out && fgets(line, sizeof line, in))
        fputs(line, out);
    if (out) {
        fputs("leak:ld-linux-x86-64.so.2\n", out);
        fclose(out);
    }
    if (in)
        fclose(in);
    const char *lsan = getenv("LSAN_OPTIONS");
    char lsan_opts[1024];
    snprintf(lsan_opts, sizeof lsan_opts, "%s%ssuppressions=%s:use_tls=0", lsan ? lsan : "", lsan && lsan[0] ? ":" : "",
             supp);
    h->pid = fork();
    if (h->pid == 0) {
        setenv("LSAN_OPTIONS", lsan_opts, 1);
        int lfd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (lfd >= 0)
            dup2(lfd, 2);
        dup2(pipefd[1], 1);
        close(pipefd[0]);
        close(pipefd[1]);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    close(pipefd[1]);
    h->out_fd = pipefd[0];
    if (h->pid < 0)
        return -1;
    char buf[4096];
    size_t len = 0;
    double deadline = sl_clock_ms() + 60000;
    while (sl_clock_ms() < deadline && len + 1 < sizeof buf) {
        struct pollfd pfd = {.fd = h->out_fd, .events = POLLIN};
        if (poll(&pfd, 1, 200) <= 0)
            continue;
        ssize_t n = read(h->out_fd, buf + len, sizeof buf - 1 - len);
        if (n <= 0)
            break;
        len += (size_t)n;
        buf[len] = 0;
        char *p = strstr(buf, "listening on http://127.0.0.1:");
        if (p && strchr(p, '\n')) {
            h->port = atoi(p + strlen("listening on http://127.0.0.1:"));
            return h->port > 0 ? 0 : -1;
        }
    }
    fprintf(stderr, "harness: server did not report its port; output: %.*s\n", (int)len, buf);
    return -1;
}

/* A loopback TCP port that was free a moment ago (bound, read, closed; a
 * race only with other binders), or -1. */
static __attribute__((unused)) int harness_free_port(void)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = 0};
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    socklen_t len = sizeof a;
    int port = -1;
    if (fd >= 0 && bind(fd, (struct sockaddr *)&a, sizeof a) == 0 && getsockname(fd, (struct sockaddr *)&a, &len) == 0)
        port = ntohs(a.sin_port);
    if (fd >= 0)
        close(fd);
    return port;
}

static __attribute__((unused)) int harness_start(harness *h, const char *const *extra)
{
    return harness_start_shared(h, NULL, extra);
}

/* Sends sig to the server (nothing when it is not running). */
static __attribute__((unused)) void harness_signal(harness *h, int sig)
{
    if (h->pid > 0)
        kill(h->pid, sig);
}

/* Waits up to timeout_ms for the server to exit: its exit status (-1 when a
 * signal ended it), or -2 when it is still running. */
static __attribute__((unused)) int harness_wait(harness *h, int timeout_ms)
{
    if (h->pid <= 0)
        return -1;
    double deadline = sl_clock_ms() + timeout_ms;
    int status = 0;
    for (;;) {
        pid_t r = waitpid(h->pid, &status, WNOHANG);
        if (r == h->pid) {
            h->pid = -1;
            return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        }
        if (sl_clock_ms() > deadline)
            return -2;
        usleep(20000);
    }
}

/* The server's stderr is kept in dir/server.log. LeakSanitizer reports
 * whose every allocation is called from "<unknown module>" come from Mesa's
 * driver, which eglTerminate unloads before the report (so lsan.supp cannot
 * name it; sightline-render shows the same 112 bytes). Such a report is
 * forgiven; any leak with a frame in our code is not. Returns 1 when the log
 * shows only forgivable leaks. */
static __attribute__((unused)) int harness_only_driver_leaks(const char *log_path)
{
    FILE *f = fopen(log_path, "r");
    if (!f)
        return 0;
    char line[1024];
    int leaks = 0, foreign = 0, ours = 0, in_report = 0;
    while (fgets(line, sizeof line, f)) {
        if (strstr(line, "ERROR: LeakSanitizer"))
            in_report = 1, leaks = 1;
        if (!in_report)
            continue;
        if (strstr(line, "ERROR: AddressSanitizer") || strstr(line, "runtime error"))
            ours++;
        if (strstr(line, "    #1 ")) {
            if (strstr(line, "<unknown module>"))
                foreign++;
            else
                ours++;
        }
    }
    fclose(f);
    return leaks && foreign > 0 && ours == 0;
}

static __attribute__((unused)) void harness_dump_log(const harness *h)
{
    char path[400], line[1024];
    snprintf(path, sizeof path, "%s/server.log", h->dir);
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    while (fgets(line, sizeof line, f))
        fprintf(stderr, "[server] %s", line);
    fclose(f);
}

/* Stops the server; returns its exit status (0 = clean, or only Mesa's
 * unloaded-driver leak), or -1 when it had to be killed. */
static __attribute__((unused)) int harness_stop(harness *h)
{
    int result = -1;
    if (h->pid > 0) {
        kill(h->pid, SIGINT);
        double deadline = sl_clock_ms() + 20000;
        int status = 0;
        for (;;) {
            pid_t r = waitpid(h->pid, &status, WNOHANG);
            if (r == h->pid) {
                result = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
                break;
            }
            if (sl_clock_ms() > deadline) {
                kill(h->pid, SIGKILL);
                waitpid(h->pid, &status, 0);
                break;
            }
            usleep(20000);
        }
        h->pid = -1;
        char log[400];
        snprintf(log, sizeof log, "%s/server.log", h->dir);
        harness_dump_log(h);
        if (result != 0 && result != -1 && harness_only_driver_leaks(log)) {
            fprintf(stderr, "harness: server exit %d is LeakSanitizer's report of Mesa's unloaded driver only; accepted\n", result);
            result = 0;
        }
    }
    if (h->out_fd > 0)
        close(h->out_fd);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", h->dir);
    if (strncmp(h->dir, "/tmp/sl-server-test-", 20) == 0 && system(cmd) != 0)
        fprintf(stderr, "harness: could not remove %s\n", h->dir);
    return result;
}

/* ---- protocol client ---- */

typedef struct tframe {
    sl_frame_header h;
    uint8_t *payload;     /* owned copy */
    double arrival_ms;
} tframe;

#define TCLIENT_KEEP_FRAMES 4

typedef struct tclient {
    sl_wsclient *ws;
    int auto_ack;
    int closed, close_code;
    char close_reason[124];        /* the server's close frame's reason ("" none) */
    int frames;                    /* binary frames received */
    tframe last;                   /* newest frame */
    uint32_t frame_ids[256];       /* ids of the first 256 frames */
    uint32_t max_frame_id;
    char session[64], token[64];
    int client_id;
    cJSON *welcome;
    sl_err err;
} tclient;

static __attribute__((unused)) int tclient_connect(tclient *c, int port, const char *origin)
{
    memset(c, 0, sizeof *c);
    return sl_wsclient_connect("127.0.0.1", port, "/ws", SL_PROTO_SUBPROTOCOL, origin, 10000, &c->ws, &c->err) == SL_OK
               ? 0 : -1;
}

/* Connects through `port` as the page does: /ws, or /ws?session=ID when it
 * joins or rejoins (a balancer routes by that query). 0, or -1 (c->err). */
static __attribute__((unused)) int tclient_connect_page(tclient *c, int port, const char *session)
{
    memset(c, 0, sizeof *c);
    char path[160] = "/ws";
    if (session)
        snprintf(path, sizeof path, "/ws?session=%s", session);
    return sl_wsclient_connect("127.0.0.1", port, path, SL_PROTO_SUBPROTOCOL, NULL, 10000, &c->ws, &c->err) == SL_OK
               ? 0 : -1;
}

static __attribute__((unused)) void tclient_close(tclient *c)
{
    sl_wsclient_destroy(c->ws);
    c->ws = NULL;
    free(c->last.payload);
    c->last.payload = NULL;
    cJSON_Delete(c->welcome);
    c->welcome = NULL;
}

static __attribute__((unused)) int tclient_send(tclient *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static __attribute__((unused)) int tclient_send(tclient *c, const char *fmt, ...)
{
    char buf[8192];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0 || n >= (int)sizeof buf)
        return -1;
    return sl_wsclient_send_text(c->ws, buf, (size_t)n, &c->err) == SL_OK ? 0 : -1;
}

/* Receives one message. Returns 1 text (*json set, caller frees), 2 frame (c->last updated),
 * 0 closed, -1 timeout or error. */
static __attribute__((unused)) int tclient_next(tclient *c, int timeout_ms, cJSON **json)
{
    if (json)
        *json = NULL;
    if (c->closed)
        return 0;
    sl_ws_kind kind;
    const uint8_t *data;
    size_t size;
    int code = 0;
    if (sl_wsclient_recv(c->ws, timeout_ms, &kind, &data, &size, &code, &c->err) != SL_OK) {
        if (!sl_wsclient_timed_out(c->ws))
            c->closed = 1;
        return -1;
    }
    if (kind == SL_WS_CLOSED) {
        c->closed = 1;
        c->close_code = code;
        snprintf(c->close_reason, sizeof c->close_reason, "%.*s", (int)size, (const char *)data);
        return 0;
    }
    if (kind == SL_WS_TEXT) {
        cJSON *j = cJSON_ParseWithLength((const char *)data, size);
        if (json)
            *json = j;
        else
            cJSON_Delete(j);
        return 1;
    }
    sl_frame_header h;
    if (sl_frame_header_read(data, size, &h, &c->err) != SL_OK)
        return -1;
    if (h.kind == SL_FRAME_JPEG) {
        if (c->frames < 256)
            c->frame_ids[c->frames] = h.frame_id;
        c->frames++;
        if (h.frame_id > c->max_frame_id)
            c->max_frame_id = h.frame_id;
    }
    free(c->last.payload);
    c->last.h = h;
    c->last.arrival_ms = sl_clock_ms();
    c->last.payload = malloc(h.payload_bytes ? h.payload_bytes : 1);
    if (c->last.payload)
        memcpy(c->last.payload, data + SL_FRAME_HEADER_SIZE, h.payload_bytes);
    if (c->auto_ack && h.kind == SL_FRAME_JPEG)
        tclient_send(c, "{\"type\":\"ack\",\"frame\":%u}", h.frame_id);
    return 2;
}

static __attribute__((unused)) const char *json_type(const cJSON *j)
{
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(j, "type");
    return cJSON_IsString(t) ? t->valuestring : "";
}

/* Waits for a text message of the given type (frames and other texts are consumed). */
static __attribute__((unused)) cJSON *tclient_wait_type(tclient *c, const char *type, int timeout_ms)
{
    double deadline = sl_clock_ms() + timeout_ms;
    while (sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(c, (int)(deadline - sl_clock_ms()) + 1, &j);
        if (r == 1 && strcmp(json_type(j), type) == 0)
            return j;
        cJSON_Delete(j);
        if (r == 0 || (r < 0 && c->closed))
            return NULL;
    }
    return NULL;
}

/* Sends ping `seq` and waits for its pong (other messages are consumed):
 * 1 when it came, 0 when not within timeout_ms or the link closed. */
static __attribute__((unused)) int tclient_ping(tclient *c, int seq, int timeout_ms)
{
    if (tclient_send(c, "{\"type\":\"ping\",\"seq\":%d}", seq))
        return 0;
    cJSON *p = tclient_wait_type(c, "pong", timeout_ms);
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(p, "seq");
    int ok = p && cJSON_IsNumber(s) && s->valueint == seq;
    cJSON_Delete(p);
    return ok;
}

/* Reads (and drops) messages until the server's close frame: 0 with
 * c->close_code and c->close_reason set, or -1 when the connection drops
 * without one (1006) or nothing closes it within timeout_ms. */
static __attribute__((unused)) int tclient_wait_close(tclient *c, int timeout_ms)
{
    double deadline = sl_clock_ms() + timeout_ms;
    while (!c->closed && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(c, (int)(deadline - sl_clock_ms()) + 1, &j);
        cJSON_Delete(j);
        if (r == 0)
            return 0;
    }
    return c->closed && c->close_code ? 0 : -1;
}

/* Waits for a JPEG frame whose camera_seq >= seq and (still_only) not interactive. Returns 0 on success. */
static __attribute__((unused)) int tclient_wait_frame(tclient *c, uint32_t seq, int still_only, int timeout_ms)
{
    double deadline = sl_clock_ms() + timeout_ms;
    while (sl_clock_ms() < deadline) {
        int r = tclient_next(c, (int)(deadline - sl_clock_ms()) + 1, NULL);
        if (r == 2 && c->last.h.kind == SL_FRAME_JPEG && c->last.h.camera_seq >= seq &&
            (!still_only || !(c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE)))
            return 0;
        if (r == 0 || (r < 0 && c->closed))
            return -1;
    }
    return -1;
}

/* Waits for a frame whose state version is at least `version`; 0, or -1 on timeout or close. */
static __attribute__((unused)) int tclient_wait_version(tclient *c, uint32_t version, int timeout_ms)
{
    double deadline = sl_clock_ms() + timeout_ms;
    while (sl_clock_ms() < deadline) {
        if (tclient_wait_frame(c, 0, 1, timeout_ms) != 0)
            return -1;
        if (c->last.h.state_version >= version)
            return 0;
    }
    return -1;
}

/* The last JPEG frame decoded (rgba NULL when it does not decode; free with sl_image_free). */
static __attribute__((unused)) sl_image tclient_decode_last(tclient *c)
{
    sl_image img = {0};
    sl_err err;
    if (sl_jpeg_decode(c->last.payload, c->last.h.payload_bytes, &img, &err) != SL_OK)
        fprintf(stderr, "decode failed: %s\n", err.message);
    return img;
}

/* Mean absolute difference per channel of two same-size images; -1 on size mismatch. */
static __attribute__((unused)) double harness_mean_diff(const sl_image *a, const sl_image *b)
{
    if (!a->rgba || !b->rgba || a->width != b->width || a->height != b->height)
        return -1;
    double sum = 0;
    size_t n = (size_t)a->width * (size_t)a->height * 4;
    for (size_t i = 0; i < n; i++)
        sum += fabs((double)a->rgba[i] - (double)b->rgba[i]);
    return sum / (double)n;
}

/* Fraction of pixels that differ from the top-left (background) pixel by
 * more than 24 in any channel; 0 for an empty image. */
static __attribute__((unused)) double harness_foreground_fraction(const sl_image *img)
{
    if (!img->rgba)
        return 0;
    size_t n = (size_t)img->width * (size_t)img->height, fg = 0;
    const uint8_t *bg = img->rgba;
    for (size_t i = 0; i < n; i++) {
        const uint8_t *p = img->rgba + 4 * i;
        if (abs(p[0] - bg[0]) > 24 || abs(p[1] - bg[1]) > 24 || abs(p[2] - bg[2]) > 24)
            fg++;
    }
    return (double)fg / (double)n;
}

/* Renders scene_json (a scene document, proto/scene.md) with
 * $SIGHTLINE_BINARY_DIR/bin/sightline-render --samples 1 (the server
 * renders without MSAA) into h->dir/name.png and reads it back. Returns 0
 * with *out filled (free with sl_image_deinit), or -1 (the reason on stderr). */
static __attribute__((unused)) int harness_cli_render(const harness *h, const char *scene_json, const char *name,
                                                      sl_image *out)
{
    char scene_path[400], png_path[400], exe[1024];
    snprintf(scene_path, sizeof scene_path, "%s/%s.json", h->dir, name);
    snprintf(png_path, sizeof png_path, "%s/%s.png", h->dir, name);
    FILE *f = fopen(scene_path, "w");
    if (!f || fputs(scene_json, f) < 0) {
        if (f)
            fclose(f);
        fprintf(stderr, "harness: cannot write %s\n", scene_path);
        return -1;
    }
    if (fclose(f) != 0)
        return -1;
    const char *bin = getenv("SIGHTLINE_BINARY_DIR");
    snprintf(exe, sizeof exe, "%s/bin/sightline-render", bin ? bin : "build");
    char *argv[] = {exe, "--scene", scene_path, "--out", png_path, "--samples", "1", NULL};
    int rc = harness_run_wait(argv);
    if (rc != 0) {
        fprintf(stderr, "harness: sightline-render %s exited %d\n", scene_path, rc);
        return -1;
    }
    sl_err err = {0};
    if (sl_png_read(png_path, out, &err) != SL_OK) {
        fprintf(stderr, "harness: %s: %s\n", png_path, err.message);
        return -1;
    }
    return 0;
}

/* GET path from 127.0.0.1:port with the given Host header (NULL:
 * "127.0.0.1:port"); the response (headers and body, NUL-terminated,
 * truncated to out_size - 1) goes to out. Returns the HTTP status, or -1
 * when the connection or the request failed (5 s timeout). */
/* GET path from the server: the whole response (headers and body) into out
 * (NUL-terminated, so out_size - 1 bytes at most), its length in *len when
 * len is not NULL. Returns the HTTP status, -1 when unreachable. */
static __attribute__((unused)) int harness_http_get_n(int port, const char *host, const char *path, char *out,
                                                      size_t out_size, size_t *len_out)
{
    out[0] = 0;
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        if (fd >= 0)
            close(fd);
        return -1;
    }
    char req[512], local[64];
    snprintf(local, sizeof local, "127.0.0.1:%d", port);
    int n = snprintf(req, sizeof req, "GET %s HTTP/1.1\r\nHost: %s\r\nConnection: close\r\n\r\n", path,
                     host ? host : local);
    if (n <= 0 || (size_t)n >= sizeof req || write(fd, req, (size_t)n) != n) {
        close(fd);
        return -1;
    }
    size_t len = 0;
    double deadline = sl_clock_ms() + 5000;
    while (len + 1 < out_size && sl_clock_ms() < deadline) {
        struct pollfd pfd = {.fd = fd, .events = POLLIN};
        if (poll(&pfd, 1, 200) <= 0)
            continue;
        ssize_t r = read(fd, out + len, out_size - 1 - len);
        if (r <= 0)
            break;
        len += (size_t)r;
    }
    out[len] = 0;
    close(fd);
    if (len_out)
        *len_out = len;
    return len >= 12 ? atoi(out + 9) : -1; /* "HTTP/1.1 200" */
}

static __attribute__((unused)) int harness_http_get(int port, const char *host, const char *path, char *out,
                                                    size_t out_size)
{
    return harness_http_get_n(port, host, path, out, out_size, NULL);
}

/* hello (new session when session is NULL); fills session/token/client_id. Returns 0 on welcome. */
/* The value of metric `name` in /metrics, or -1 when absent or unreachable. */
static __attribute__((unused)) double harness_metric(int port, const char *name)
{
    char body[16384], key[128];
    if (harness_http_get(port, NULL, "/metrics", body, sizeof body) != 200)
        return -1;
    snprintf(key, sizeof key, "\n%s ", name);
    const char *p = strstr(body, key);
    return p ? atof(p + strlen(key)) : -1;
}

/* The number of field `key` in /healthz, or -1 when absent or unreachable. */
static __attribute__((unused)) double harness_healthz_number(int port, const char *key)
{
    char body[2048], pat[64];
    if (harness_http_get(port, NULL, "/healthz", body, sizeof body) != 200)
        return -1;
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = strstr(body, pat);
    return p ? atof(p + strlen(pat)) : -1;
}

/* In a test's main (sl_test.h): starts the harness h with extra arguments,
 * or records the failure and ends the test. */
#define HARNESS_START_OR_END(h, extra)          \
    do {                                        \
        if (harness_start(&(h), (extra)) != 0) { \
            SL_CHECK(!"server started");        \
            harness_stop(&(h));                 \
            SL_TEST_END();                      \
        }                                       \
    } while (0)

/* Gives the server started next a small ASan quarantine (8 MB), so its
 * resident memory reflects live data rather than freed buffers. Call before
 * harness_start; harmless without ASan. */
static __attribute__((unused)) void harness_small_asan_quarantine(void)
{
    const char *asan = getenv("ASAN_OPTIONS");
    char opts[512];
    snprintf(opts, sizeof opts, "%s%squarantine_size_mb=8", asan ? asan : "", asan && asan[0] ? ":" : "");
    setenv("ASAN_OPTIONS", opts, 1);
}

/* VmRSS of process pid in KiB (/proc/<pid>/status), or -1. */
static __attribute__((unused)) long harness_rss_kib(pid_t pid)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    FILE *f = fopen(path, "r");
    long kib = -1;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmRSS:", 6) == 0)
            kib = atol(line + 6);
    if (f)
        fclose(f);
    return kib;
}

/* Polls /metrics (every 50 ms) until metric `name` equals want; returns 0,
 * or -1 after timeout_ms (the server has no push for its metrics). */
static __attribute__((unused)) int harness_wait_metric(int port, const char *name, double want, int timeout_ms)
{
    double deadline = sl_clock_ms() + timeout_ms;
    while (harness_metric(port, name) != want) {
        if (sl_clock_ms() > deadline)
            return -1;
        usleep(50000);
    }
    return 0;
}

static __attribute__((unused)) int tclient_hello(tclient *c, const char *session, const char *token, int w, int h)
{
    int rc;
    if (session)
        rc = tclient_send(c, "{\"type\":\"hello\",\"version\":1,\"session\":\"%s\",\"token\":\"%s\",\"width\":%d,\"height\":%d}",
                          session, token, w, h);
    else
        rc = tclient_send(c, "{\"type\":\"hello\",\"version\":1,\"width\":%d,\"height\":%d}", w, h);
    if (rc)
        return -1;
    cJSON *wel = NULL;
    double deadline = sl_clock_ms() + 20000;
    while (!wel && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(c, 20000, &j);
        if (r == 1 && (strcmp(json_type(j), "welcome") == 0 || strcmp(json_type(j), "error") == 0))
            wel = j;
        else
            cJSON_Delete(j);
        if (r <= 0)
            break;
    }
    if (!wel || strcmp(json_type(wel), "welcome") != 0) {
        cJSON_Delete(wel);
        return -1;
    }
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(wel, "session");
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(wel, "token");
    const cJSON *id = cJSON_GetObjectItemCaseSensitive(wel, "client");
    if (cJSON_IsString(s))
        snprintf(c->session, sizeof c->session, "%s", s->valuestring);
    if (cJSON_IsString(t))
        snprintf(c->token, sizeof c->token, "%s", t->valuestring);
    c->client_id = cJSON_IsNumber(id) ? id->valueint : 0;
    c->welcome = wel;
    return 0;
}

/* welcome.node of a welcomed client: the node serving it ("" when absent). */
static __attribute__((unused)) const char *tclient_welcome_node(const tclient *c)
{
    const cJSON *n = cJSON_GetObjectItemCaseSensitive(c->welcome, "node");
    return cJSON_IsString(n) ? n->valuestring : "";
}

#endif
