/* sl_server.h — the ground every layer of sightline-server stands on: its
 * configuration, its metrics, the server object with the thread that owns each
 * field, and the hooks through which a lower layer reaches up.
 *
 * The layers, each a folder with one header, arrows one way (README.md):
 *   net/       the transport: lws context, WebSocket callbacks, HTTP routes, the
 *              write loop, the agent-check listener (net/sl_net.h)
 *   sessions/  sessions, clients as the sessions see them, the message table,
 *              control, playback, recordings, checkpoints; no socket type
 *              (sessions/sl_sessions.h)
 *   render/    the render thread, prepared scenes, the dataset cache, adaptive
 *              scale, the encoder, progress (render/sl_render.h)
 *   catalog/   the catalog over SQLite or PostgreSQL, called from above
 *              (catalog/sl_catalog.h)
 * net -> sessions -> render; catalog beside; main.c wires them. Here too:
 * client_address.c (sl_client_address.h: --trusted-proxy prefixes, part of
 * the configuration, and the X-Forwarded-For walk; pure, any thread) and
 * server_metrics.c (the histograms). Every *_ms timestamp is sl_clock_ms
 * (core/sl_clock.h), so all of them compare.
 *
 * Threads: the lws service thread owns sockets, clients, the catalog; the
 * render thread owns every GL object; the dataset cache's loader threads
 * only read files and run generators, behind the cache's own lock. The
 * service and render threads share only the fields marked "[lock]", here and
 * in the layer headers, guarded by sl_server.lock; the render thread waits on
 * sl_server.wake (a finished load broadcasts it too) and wakes the service
 * thread through sl_server.transport.wake_service. Lock order: sl_server.lock,
 * then the cache's lock. Fields marked "[service]" or "[render]" belong to that
 * thread alone.
 * Nothing is queued without a bound: state is "newest wins", a session keeps
 * one latest frame and its newest SL_PROGRESS_RING progress texts, a client
 * keeps at most SL_CLIENT_MAX_TEXT replies, and a session waits for at most
 * one dataset load (so the loaders' queue is bounded by the sessions).
 * Only a client's own requests go into its reply ring (so only it can fill
 * it and get closed for it, with 1008 "reply budget"; its queued errors
 * merge by code and field, so repeating a bad request never fills it);
 * whatever other clients or the render thread cause reaches it as coalesced
 * state on the client or session — the state patch, pending control
 * requests (one flag per requester), the session's latest render error and
 * latest frame — written when its socket is writable.
 */
#ifndef SL_SERVER_H
#define SL_SERVER_H

#include <pthread.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#include "core/sl_clock.h"
#include "core/sl_status.h"
#include "sl_client_address.h"
#include "sl_protocol.h"

struct lws_context;
struct sl_agent;
typedef struct sl_db sl_db;
typedef struct sl_client sl_client;
typedef struct sl_render_slot sl_render_slot;

#define SL_SERVER_MAX_ORIGINS 8
#define SL_SERVER_MAX_DATA_DIRS 8

typedef struct sl_server_config {
    char node_id[SL_NODE_ID_MAX + 1]; /* --node-id: names this node in session ids, welcome, /healthz */
    int agent_port;                /* --agent-port: HAProxy agent-check listener, 0 = off */
    int port;                      /* 0: any free port (printed on stdout) */
    const char *bind;              /* default 127.0.0.1 */
    const char *db_path;
    const char *web_dir;           /* default <source>/web or ./web */
    const char *data_dirs[SL_SERVER_MAX_DATA_DIRS];
    int data_dir_count;
    const char *origins[SL_SERVER_MAX_ORIGINS];  /* extra allowed Origin values */
    int origin_count;
    int max_clients;               /* default 64: clients past hello */
    int max_pending;               /* default 16: upgraded connections that have not sent hello */
    int max_pending_per_address;   /* default 4: of those, from one client address */
    sl_net_prefix trusted_proxies[SL_TRUSTED_PROXY_MAX]; /* --trusted-proxy: peers whose X-Forwarded-For
                                                            names the client (none by default) */
    int trusted_proxy_count;
    int max_sessions;              /* default 32 */
    int grace_s;                   /* default 300 */
    int idle_release_s;            /* default 30: a session without clients this long lets go of its
                                      prepared state (re-prepared when it renders again) */
    int hello_timeout_s;           /* default 10: seconds from upgrade to hello */
    const char *egl_device;        /* NULL: auto */
    const char *default_dataset;   /* NULL: the first catalog dataset the first technique accepts */
    double test_frame_delay_ms;    /* tests only: sleep this x (frame pixels / session pixels) per frame */
    double test_frame_fixed_ms;    /* tests only: and this, whatever the size (a vertex-bound render) */
    double test_frame_time_ms;     /* tests only, > 0: the adaptive scale sees this x (frame pixels / session
                                      pixels) as a frame's time instead of the measured one (no sleep) */
    double test_frame_time_fixed_ms; /* tests only, > 0: and this more, whatever the size (injected as above) */
    double test_load_delay_ms;     /* tests only: every dataset load sleeps this long first (loader thread) */
} sl_server_config;


/* ---- metrics (server_metrics.c; written under the lock, read by net/http.c) ---- */

#define SL_HIST_BUCKETS 12
typedef struct sl_histogram {
    uint64_t counts[SL_HIST_BUCKETS];       /* cumulative at render time */
    double sum;
    uint64_t total;
} sl_histogram;

/* Executions a frame can come from (core/sl_backend.h): "gl", "embree", "cpu", and
 * "single" for techniques with one. */
#define SL_METRIC_BACKENDS 4
extern const char *const sl_metric_backend_names[SL_METRIC_BACKENDS];
int sl_metric_backend_index(const char *backend); /* NULL or unknown: the "single" slot */

typedef struct sl_metrics {                  /* [lock] */
    uint64_t frames_rendered, frames_sent, frames_dropped, frames_failed;
    uint64_t snapshots, bytes_sent, messages_in, errors_sent;
    uint64_t dataset_loads, dataset_cache_hits, dataset_load_failures;
    uint64_t refused_full, refused_address, pending_evicted;  /* WebSocket admission */
    uint64_t forwarded_clients, forwarded_ignored, forwarded_malformed; /* X-Forwarded-For of upgrades */
    sl_histogram render_ms, encode_ms;
    sl_histogram load_ms, prepare_ms;        /* dataset loads (loader thread), technique prepares */
    uint64_t frames_by_backend[SL_METRIC_BACKENDS]; /* frames rendered, by sl_metric_backend_names */
} sl_metrics;

/* The upper bounds of the first SL_HIST_BUCKETS - 1 buckets; the last is +Inf. */
extern const double sl_histogram_bucket_ms[SL_HIST_BUCKETS - 1];
/* Counts ms into h (lock held). */
void sl_histogram_add(sl_histogram *h, double ms);

/* ---- the server ---- */

/* What the transport (net/ws.c) hands the layers below it when it starts (sl_ws_create), so that
 * they reach up only through these and never call the transport's files. */
typedef struct sl_server sl_server;
typedef struct sl_transport_hooks {
    void (*schedule_play)(sl_server *srv, double ms); /* run sl_play_tick in ms from now (replacing an
                                                         earlier schedule) */
    void (*hello_done)(sl_server *srv, sl_client *c); /* c said hello: it no longer waits for it (its
                                                         hello timeout ends) */
    void (*want_write)(sl_client *c);                /* c has something to send: call sl_client_write_next
                                                         for it soon */
    void (*closing)(sl_client *c);                   /* c was told to close (sl_client_close): drop the link
                                                         if it cannot take the close frame within
                                                         SL_CLOSE_GRACE_S */
    void (*wake_service)(sl_server *srv);            /* any thread (the render thread): the service thread
                                                         runs sl_sessions_on_wake soon */
} sl_transport_hooks;

struct sl_server {
    sl_server_config cfg;
    struct lws_context *lws;
    int port;                                /* listening port (after sl_ws_create) */
    sl_db *db;                             /* [service] */
    pthread_mutex_t lock;
    pthread_cond_t wake;                     /* render thread waits here */
    sl_render_slot *slots;                   /* [lock] every session's render slot (sessions/ links them in,
                                                render/ unlinks and destroys the doomed ones) */
    int session_count;                       /* [lock] live (not doomed) */
    int client_count;                        /* [service] past hello: counted against --max-clients */
    int pending_count;                       /* [service] upgraded, no hello yet: --max-pending */
    sl_client *pending;                      /* [service] those connections, newest first */
    int next_client_id;                      /* [service] */
    sl_metrics metrics;                      /* [lock] */
    int prepared_scenes;                     /* [lock] live prepared scenes (written by the render thread) */
    int stop;                                /* [lock] */
    int draining;                            /* [lock] SIGTERM: no new sessions; exits when drained */
    double drain_start_ms;                   /* [service] when draining began */
    double last_frame_ms;                    /* [lock] render + encode ms of the newest frame (render thread) */
    struct sl_agent *agent;                  /* [service] the agent-check listener, or NULL */
    int render_ready;                        /* [lock] 1 up, -1 failed */
    char gpu_renderer[128];                  /* [lock] */
    char render_fail[256];                   /* [lock] */
    pthread_t render_thread;
    int render_started;
    double start_ms;
    cJSON *techniques_json;                  /* [service] cached list with schemas */
    char record_dir[64];                     /* recording files, made at start and removed at exit ("" none) */
    uint32_t next_record_id;                 /* [service] */
    sl_transport_hooks transport;            /* [service] set by sl_ws_create */
};


#endif
