/* http.c — the bodies of GET /healthz (JSON) and GET /metrics (Prometheus text 0.0.4).
 *
 * /healthz names the node and says "ok" (200), "draining" (503: SIGTERM,
 * no new sessions) or "unavailable" (503: no renderer, stopping); a
 * balancer must not use it as its health check for a draining node still
 * serves its sessions (the agent-check, agent.c, says drain instead).
 *
 * Metrics are counters and gauges read under srv->lock in one pass, so a
 * scrape sees one consistent snapshot; the two histograms (render ms and
 * encode ms per frame) use the fixed millisecond buckets of
 * server_metrics.c. Does not send anything (ws.c does). Service thread.
 */
#include "sl_net.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *sl_http_healthz(sl_server *srv, int *status)
{
    pthread_mutex_lock(&srv->lock);
    int up = srv->render_ready > 0 && !srv->stop, ok = up && !srv->draining;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "node", srv->cfg.node_id);
    cJSON_AddStringToObject(o, "status", ok ? "ok" : up ? "draining" : "unavailable");
    cJSON_AddNumberToObject(o, "uptime_s", (sl_clock_ms() - srv->start_ms) / 1000.0);
    cJSON_AddNumberToObject(o, "sessions", srv->session_count);
    cJSON_AddNumberToObject(o, "clients", srv->client_count);
    cJSON_AddNumberToObject(o, "pending", srv->pending_count);
    cJSON_AddNumberToObject(o, "render_queue", sl_sessions_render_queue_locked(srv));
    cJSON_AddNumberToObject(o, "last_frame_ms", srv->last_frame_ms);
    cJSON_AddStringToObject(o, "renderer", srv->gpu_renderer);
    cJSON_AddNumberToObject(o, "protocol", SL_PROTO_VERSION);
    pthread_mutex_unlock(&srv->lock);
    *status = ok ? 200 : 503;
    char *text = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    return text;
}

/* Appends to a growing buffer; on allocation failure the buffer is freed and set NULL. */
static void append(char **buf, size_t *len, size_t *cap, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void append(char **buf, size_t *len, size_t *cap, const char *fmt, ...)
{
    if (!*buf)
        return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(*buf + *len, *cap - *len, fmt, ap);
        va_end(ap);
        if (n < 0)
            return;
        if ((size_t)n < *cap - *len) {
            *len += (size_t)n;
            return;
        }
        char *p = realloc(*buf, *cap * 2 + (size_t)n);
        if (!p) {
            free(*buf);
            *buf = NULL;
            return;
        }
        *buf = p;
        *cap = *cap * 2 + (size_t)n;
    }
}

static void histogram(char **b, size_t *len, size_t *cap, const char *name, const char *help, const sl_histogram *h)
{
    append(b, len, cap, "# HELP %s %s\n# TYPE %s histogram\n", name, help, name);
    for (int i = 0; i < SL_HIST_BUCKETS - 1; i++)
        append(b, len, cap, "%s_bucket{le=\"%g\"} %llu\n", name, sl_histogram_bucket_ms[i], (unsigned long long)h->counts[i]);
    append(b, len, cap, "%s_bucket{le=\"+Inf\"} %llu\n", name, (unsigned long long)h->counts[SL_HIST_BUCKETS - 1]);
    append(b, len, cap, "%s_sum %.3f\n%s_count %llu\n", name, h->sum, name, (unsigned long long)h->total);
}

char *sl_http_metrics(sl_server *srv)
{
    size_t len = 0, cap = 4096;
    char *b = malloc(cap);
    pthread_mutex_lock(&srv->lock);
    sl_metrics m = srv->metrics;
    int sessions = srv->session_count, clients = srv->client_count, pending = srv->pending_count;
    int prepared = srv->prepared_scenes, draining = srv->draining;
    int queue = sl_sessions_render_queue_locked(srv);
    pthread_mutex_unlock(&srv->lock);
    struct { const char *name, *help; uint64_t v; } counters[] = {
        {"sightline_frames_rendered_total", "Frames rendered and encoded.", m.frames_rendered},
        {"sightline_frames_sent_total", "Frame messages sent to clients.", m.frames_sent},
        {"sightline_frames_dropped_total", "Frames a client never received because a newer one replaced them.",
         m.frames_dropped},
        {"sightline_frames_failed_total", "Renders that failed (error sent to the session).", m.frames_failed},
        {"sightline_snapshots_total", "PNG snapshots rendered.", m.snapshots},
        {"sightline_frame_bytes_sent_total", "Bytes of frame messages sent.", m.bytes_sent},
        {"sightline_messages_received_total", "Client text messages received.", m.messages_in},
        {"sightline_errors_sent_total", "error messages sent to clients.", m.errors_sent},
        {"sightline_dataset_loads_total", "Datasets loaded or generated (cache misses).", m.dataset_loads},
        {"sightline_dataset_cache_hits_total", "Sessions given an already loaded dataset.", m.dataset_cache_hits},
        {"sightline_dataset_load_failures_total", "Dataset loads that failed (the session kept its last good scene).",
         m.dataset_load_failures},
        {"sightline_refused_full_total", "WebSocket upgrades or hellos refused: --max-clients past hello.",
         m.refused_full},
        {"sightline_refused_address_total", "WebSocket upgrades refused: --max-pending-per-address.",
         m.refused_address},
        {"sightline_pending_evicted_total", "Connections without hello closed to make room (--max-pending).",
         m.pending_evicted},
        {"sightline_forwarded_clients_total", "WebSocket upgrades whose client address came from a "
         "--trusted-proxy's X-Forwarded-For.", m.forwarded_clients},
        {"sightline_forwarded_ignored_total", "WebSocket upgrades with an X-Forwarded-For from a peer that is not "
         "a --trusted-proxy (ignored).", m.forwarded_ignored},
        {"sightline_forwarded_malformed_total", "WebSocket upgrades from a --trusted-proxy whose X-Forwarded-For "
         "did not parse (the last trusted hop was used).", m.forwarded_malformed},
    };
    for (size_t i = 0; i < sizeof counters / sizeof counters[0]; i++)
        append(&b, &len, &cap, "# HELP %s %s\n# TYPE %s counter\n%s %llu\n", counters[i].name, counters[i].help,
               counters[i].name, counters[i].name, (unsigned long long)counters[i].v);
    append(&b, &len, &cap, "# HELP sightline_frames_by_backend_total Frames rendered, by the execution that drew "
           "them (gl, embree, cpu; single: techniques with one).\n# TYPE sightline_frames_by_backend_total counter\n");
    for (int i = 0; i < SL_METRIC_BACKENDS; i++)
        append(&b, &len, &cap, "sightline_frames_by_backend_total{backend=\"%s\"} %llu\n", sl_metric_backend_names[i],
               (unsigned long long)m.frames_by_backend[i]);
    append(&b, &len, &cap, "# HELP sightline_node_info This node's id (--node-id), in the label.\n"
           "# TYPE sightline_node_info gauge\nsightline_node_info{node=\"%s\"} 1\n", srv->cfg.node_id);
    append(&b, &len, &cap, "# HELP sightline_draining 1 while the node drains (SIGTERM): no new sessions.\n"
           "# TYPE sightline_draining gauge\nsightline_draining %d\n", draining);
    append(&b, &len, &cap, "# HELP sightline_render_queue Sessions waiting for a render.\n"
           "# TYPE sightline_render_queue gauge\nsightline_render_queue %d\n", queue);
    append(&b, &len, &cap, "# HELP sightline_clients WebSocket clients past hello.\n# TYPE sightline_clients gauge\n"
           "sightline_clients %d\n", clients);
    append(&b, &len, &cap, "# HELP sightline_pending_connections WebSocket connections that have not sent hello.\n"
           "# TYPE sightline_pending_connections gauge\nsightline_pending_connections %d\n", pending);
    append(&b, &len, &cap, "# HELP sightline_sessions Live sessions.\n# TYPE sightline_sessions gauge\n"
           "sightline_sessions %d\n", sessions);
    append(&b, &len, &cap, "# HELP sightline_prepared_scenes Prepared technique states held (shared by the sessions "
           "showing the same scene).\n# TYPE sightline_prepared_scenes gauge\nsightline_prepared_scenes %d\n",
           prepared);
    histogram(&b, &len, &cap, "sightline_render_ms", "Render plus readback wall time per frame (no prepare), ms.",
              &m.render_ms);
    histogram(&b, &len, &cap, "sightline_dataset_load_ms", "Dataset load or generation time on a loader thread, ms.",
              &m.load_ms);
    histogram(&b, &len, &cap, "sightline_prepare_ms", "Technique prepare time on the render thread, ms.",
              &m.prepare_ms);
    histogram(&b, &len, &cap, "sightline_encode_ms", "JPEG encode wall time per frame, ms.", &m.encode_ms);
    return b;
}
