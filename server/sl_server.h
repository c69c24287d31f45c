/* sl_server.h — the internal contract between sightline-server's parts.
 *
 *   main.c     arguments, the `catalog` subcommand, start and stop
 *   ws.c       lws context, WebSocket protocol, static files (service thread);
 *              hands the layers below it sl_transport_hooks (a play timer, the
 *              end of a connection's wait for hello) so they never call it
 *   client_write.c  the write loop: one message per writable callback (service thread)
 *   client_queue.c  a client's reply ring and close request (service thread)
 *   session.c  sessions, hello, joining, the message table and its scene/camera/set/control
 *              handlers (service thread); session_internal.h is what its files share
 *   session_state.c  the state object, patches to every client, control (service thread)
 *   session_paths.c  the path and recording messages (service thread)
 *   session_wake.c  what the render thread left: frames, snapshots, reverts,
 *              checkpoints, dataset descriptions (service thread)
 *   session_drain.c  grace sweep, draining, teardown (service thread)
 *   random_hex.c  random hex for ids, tokens, keys (any thread)
 *   render.c   the render thread: owns sl_gpu, the encoder, the prepared scenes;
 *              render_record.c renders a recording job's frames, render_internal.h
 *              is what the two share
 *   prepared_cache.c  sl_pipelines shared by sessions on one scene (render thread)
 *   progress.c the `progress` rounds of long work, posted to sessions (render thread)
 *   interactive_scale.c  the adaptive scale of interactive frames (render thread)
 *   dataset_cache.c  datasets by source: cached, shared, loaded on its own
 *              loader threads (any caller; its own lock)
 *   encoder.c  frame buffers (refcounted) and JPEG/PNG encoding (render thread)
 *   playback.c live playback of a camera path in a session, seen by all its
 *              clients, and path_seek (service thread)
 *   record.c   recording jobs: a camera path rendered into a video in the
 *              background of a session, its status texts and its one-time
 *              download (service thread; the frames render in render.c)
 *   checkpoint.c  session checkpoints in the catalog: the state a node writes
 *              at each new still frame and another node restores a session
 *              from after the first one died; SHA-256 of join tokens (service thread)
 *   agent.c    the HAProxy agent-check listener (--agent-port; its own thread)
 *   catalog.c  the catalog: datasets, views, paths, checkpoints (sl_catalog.h;
 *              service thread and the CLI), its schema in catalog_schema.c,
 *              over the data-access layer db.c + db_sqlite.c / db_pg.c (sl_db.h)
 *   http.c     /healthz and /metrics bodies (service thread)
 *   http_host.c  the Host / Origin rules, pure (sl_http_host.h; any thread)
 *   client_address.c  --trusted-proxy prefixes and the X-Forwarded-For walk, pure
 *              (sl_client_address.h; any thread); ws_client_address.c reads the
 *              header of an upgrade (service thread)
 * Every *_ms timestamp is sl_clock_ms (core/sl_clock.h), so all of them compare.
 *
 * Threads: the lws service thread owns sockets, clients, the catalog; the
 * render thread owns every GL object; the dataset cache's loader threads
 * only read files and run generators, behind the cache's own lock. The
 * service and render threads share only the fields marked "[lock]" below,
 * guarded by sl_server.lock; the render thread waits on sl_server.wake
 * (a finished load broadcasts it too) and wakes the service thread with
 * lws_cancel_service. Lock order: sl_server.lock, then the cache's lock.
 * Fields marked "[service]" or "[render]" belong to that thread alone.
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
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#include "core/sl_clock.h"
#include "core/sl_params.h"
#include "core/sl_status.h"
#include "sl_catalog.h"
#include "sl_client_address.h"
#include "sl_protocol.h"

struct lws;
struct lws_context;
typedef struct sl_pipeline sl_pipeline;
typedef struct sl_dataset sl_dataset;
typedef struct sl_technique sl_technique;
typedef struct sl_gpu sl_gpu;
typedef struct sl_dataset_load sl_dataset_load;  /* dataset_cache.c */

#define SL_SERVER_MAX_ORIGINS 8
#define SL_SERVER_MAX_DATA_DIRS 8
#define SL_CLIENT_MAX_TEXT 32          /* the reply budget: queued replies to the client's own requests;
                                          one more ends the link (1008 "reply budget") */
#define SL_CLOSE_REASON_MAX 124        /* a close frame's reason with its NUL (RFC 6455: 123 bytes) */
#define SL_CLOSE_GRACE_S 5             /* a link told to close that cannot take its close frame is dropped */
#define SL_CLOSE_POLICY_VIOLATION 1008 /* RFC 6455 close codes the sessions use */
#define SL_CLOSE_UNEXPECTED_CONDITION 1011
#define SL_SESSION_MAX_SNAPSHOTS 8     /* pending snapshot requests per session */
#define SL_SOURCE_MAX 2048
#define SL_PROGRESS_RING 8             /* newest progress texts kept per session: two full rounds */

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

/* ---- frames (encoder.c) ---- */

/* A reference-counted encoded message: LWS_PRE bytes of headroom, the
 * 40-byte frame header, the payload. Immutable once published. */
typedef struct sl_frame_buf {
    atomic_int refs;
    sl_frame_header header;
    size_t size;          /* header + payload bytes, starting at data */
    uint8_t *data;        /* = mem + LWS_PRE */
    size_t capacity;      /* bytes available at data */
    uint8_t mem[];
} sl_frame_buf;

sl_frame_buf *sl_frame_buf_create(size_t capacity);
void sl_frame_buf_ref(sl_frame_buf *f);
void sl_frame_buf_unref(sl_frame_buf *f);   /* NULL is fine */

typedef struct sl_encoder sl_encoder;
sl_status sl_encoder_create(sl_encoder **out, sl_err *err);
void sl_encoder_destroy(sl_encoder *e);
/* Encodes bottom-up RGBA rows (GL's order, no flip copy) into a new frame
 * buffer whose header fields other than payload_bytes/quality/subsampling/
 * width/height/kind/encode_ms are filled by the caller afterwards. */
sl_status sl_encoder_jpeg(sl_encoder *e, const uint8_t *rgba_bottom_up, int width, int height, int quality,
                          int subsampling_420, sl_frame_buf **out, double *encode_ms, sl_err *err);
sl_status sl_encoder_png(const uint8_t *rgba_top_down, int width, int height, sl_frame_buf **out,
                         double *encode_ms, sl_err *err);

/* ---- sessions (session.c) ---- */

/* What a session should show: copied whole by the render thread. */
typedef struct sl_session_state {
    uint32_t version;
    char dataset[SL_PROTO_NAME_MAX];
    char dataset_source[SL_SOURCE_MAX];  /* generator JSON or absolute file path */
    int dataset_is_file;
    int dataset_kind;
    char dataset_checksum[SL_CATALOG_CHECKSUM_SIZE]; /* files: the catalog's checksum ("" none) */
    char technique[SL_PROTO_NAME_MAX];
    sl_params params;
    sl_camera_spec camera;               /* checked on arrival (sl_msg_camera_check) */
    uint32_t camera_seq;
    sl_camera_phase phase;
    double camera_ms;                    /* time of the last camera message */
    int width, height;
    float background[4];
    sl_stream_settings stream;
} sl_session_state;

/* interactive_scale.c (render thread only): per session, the cost of
 * interactive frames at each step of the ladder top x {1, 1/2, 1/4, 1/8}. */
#define SL_ISCALE_STEPS 4
typedef struct sl_iscale {
    int valid;
    uint64_t scene_key;               /* what the estimates were measured on */
    double top;                       /* interactive_scale: step 0 */
    double ema_ms[SL_ISCALE_STEPS];   /* moving average of a step's frame cost, 0 = unknown */
    double still_ms;                  /* cost of the last full-size still, 0 = unknown */
    int step;                         /* the step in use */
    int frames_at_step;               /* interactive frames measured since it was chosen */
} sl_iscale;
/* Starts afresh when scene_key (dataset, technique, params, size) or top changed. */
void sl_iscale_sync(sl_iscale *a, uint64_t scene_key, double top);
/* The scale of the next interactive frame (top when st is not adaptive); *step its ladder index. */
double sl_iscale_choose(sl_iscale *a, const sl_stream_settings *st, int *step);
/* A frame's cost (render + readback + encode ms, no load or prepare): an
 * interactive frame at ladder step `step`, or a full-size still. */
void sl_iscale_record(sl_iscale *a, int interactive, int step, double cost_ms);

/* prepared_cache.c (render thread only): one sl_pipeline per (dataset
 * source, technique, parameters equal up to the frame level), shared by the
 * sessions that show it; the last release destroys it. */
typedef struct sl_prepared {
    int refs;                        /* sessions holding it */
    char source[SL_SOURCE_MAX];
    const sl_technique *technique;
    sl_params key;                   /* the parameters it was made for */
    sl_dataset *dataset;             /* borrowed: the pipeline owns it */
    sl_pipeline *pipeline;           /* owned */
    struct sl_prepared *next;
} sl_prepared;
typedef struct sl_prepared_cache {
    sl_gpu *gpu;                     /* borrowed */
    sl_prepared *list;
    int count;
} sl_prepared_cache;
/* A prepared scene of (source, t, params) holding dataset ds, with a new
 * reference; NULL when there is none. */
sl_prepared *sl_prepared_find(sl_prepared_cache *c, const char *source, const sl_technique *t,
                              const sl_params *params, const sl_dataset *ds);
/* A new reference to the dataset some prepared scene of source holds, or NULL. */
sl_dataset *sl_prepared_dataset_of(sl_prepared_cache *c, const char *source);
/* A new prepared scene (refs 1) of ds (consumed, also on failure); nothing
 * is prepared until its first render. SL_ERR_NOMEM, SL_ERR_LIMIT (source
 * too long), SL_ERR_INVALID (t cannot draw ds). */
sl_status sl_prepared_create(sl_prepared_cache *c, const char *source, sl_dataset *ds, const sl_technique *t,
                             const sl_params *params, sl_prepared **out, sl_err *err);
void sl_prepared_release(sl_prepared_cache *c, sl_prepared *p); /* NULL is fine */

/* progress.c (render thread): the session's current round of long work. */
typedef struct sl_progress_round {
    int active;
    uint32_t id;                     /* = the session's progress_round while active */
    uint32_t version;                /* state version worked on */
    char dataset[SL_PROTO_NAME_MAX], technique[SL_PROTO_NAME_MAX];
    double t0_ms, load_ms, prepare_ms;
    int stage;                       /* the last stage posted, -1 none */
    char backend[16];                /* the execution of the newest frame ("" = one only) */
} sl_progress_round;

typedef struct sl_client sl_client;
typedef struct sl_session sl_session;

/* ---- recordings (record.c; frames rendered by render.c) ---- */
#define SL_RECORD_MAX_FRAMES 3600                     /* frames of one job */
#define SL_RECORD_MAX_PIXELS (3600.0 * 1920.0 * 1080.0) /* frames x width x height of one job */
typedef struct sl_scene_path sl_scene_path;
typedef struct sl_video_writer sl_video_writer;
typedef struct sl_record_job {
    /* immutable once created */
    uint32_t id;                     /* per server, from 1 */
    sl_scene_path *path;             /* owned */
    sl_session_state base;           /* the session's state when the job was asked for: size, scene, params */
    int frames;
    int crf;                         /* -1: the codec's default */
    char format[8];                  /* "mp4" or "webm" */
    char file[320];                  /* where the video is written */
    char key[33];                    /* the download key (random hex) in the job's URL */
    /* [lock] */
    int cancel;                      /* a client asked to cancel */
    int finished;                    /* nothing more renders: done, cancelled or failed */
    int ok;                          /* finished with a complete file, not yet downloaded */
    /* [render] */
    sl_video_writer *writer;
    int next_frame;
    double t0_ms;
} sl_record_job;

/* One queued reply to a client's own request. An error is kept as its
 * parts, so later errors of the same code and field merge into it (one
 * message with `repeated`) while it waits: a burst of bad requests costs
 * one slot per kind of mistake, not one per request. */
typedef struct sl_reply {
    char *text;                     /* owned: the whole message, or an error's sentence */
    char code[24];                  /* an error's code; "" for any other reply */
    char field[SL_PROTO_ID_MAX];    /* an error's field */
    uint32_t repeated;              /* errors merged into this one after the first */
} sl_reply;

struct sl_client {                  /* [service] */
    void *link;                     /* the transport's handle of the connection (ws.c: its struct lws) */
    const struct sl_transport_hooks *transport; /* how the layers below the transport reach it for c */
    int id;
    char addr[SL_CLIENT_ADDRESS_MAX]; /* client address, numeric (sl_ws_client_address) */
    sl_session *session;            /* NULL before hello */
    int hello_done;
    int pending;                    /* in server->pending: upgraded, no hello yet */
    sl_client *pending_next;        /* in server->pending (newest first) */
    char *rx;                       /* message being reassembled */
    size_t rx_len, rx_cap;
    sl_reply replies[SL_CLIENT_MAX_TEXT]; /* ring: the reply budget */
    int reply_head, reply_count;
    cJSON *patch;                   /* coalesced state patch not yet sent */
    uint32_t patch_version;
    uint32_t sent_frame_id;         /* newest frame id sent */
    uint32_t inflight[SL_PROTO_ACK_WINDOW]; /* sent, unacknowledged frame ids */
    int inflight_count;
    sl_frame_buf *snapshot;         /* PNG waiting to be sent */
    uint32_t error_seq;             /* session error_seq already reported (set at attach) */
    int wants_control;              /* asked for control; the controller has not been told yet */
    uint32_t progress_seq;          /* newest session progress text sent (set at attach) */
    uint32_t record_seq;            /* session record_seq whose text was sent (set at attach) */
    uint32_t play_seq;              /* session play_seq whose text was sent (set at attach) */
    int close_code;                 /* the link ends with this close code (0: open) and close_reason */
    char close_reason[SL_CLOSE_REASON_MAX];
    int close_after_replies;        /* the queued replies are written before the close frame */
    sl_client *next;                /* in session->clients */
};

struct sl_session {
    char id[SL_SESSION_ID_SIZE], token[33];  /* immutable: "NODE.<hex>", 32 hex digits */
    sl_session_state state;                  /* [lock] desired state */
    uint32_t rendered_version;               /* [lock] written by render thread */
    int rendered_interactive;                /* [lock] */
    int rendering;                           /* [lock] render thread works on it */
    sl_frame_buf *latest;                    /* [lock] newest frame, owned ref */
    uint32_t next_frame_id;                  /* [lock] */
    int snap_req[SL_SESSION_MAX_SNAPSHOTS];  /* [lock] client ids waiting for a PNG */
    int snap_req_count;
    sl_frame_buf *snap_ready;                /* [lock] rendered PNG */
    int snap_ready_ids[SL_SESSION_MAX_SNAPSHOTS];
    int snap_ready_count;
    char error_code[24];                     /* [lock] code of the last error: render_failed, load_failed */
    char error_text[512];                    /* [lock] last render or load error */
    uint32_t error_seq;                      /* [lock] */
    /* A dataset load failed: put the scene (dataset, technique, params) back
     * to revert_to unless the desired state moved on from the failed source.
     * Written by the render thread, applied by the service thread, which
     * stays the only writer of `state`. */
    int revert_pending;                      /* [lock] */
    char revert_failed_source[SL_SOURCE_MAX];/* [lock] */
    sl_session_state revert_to;              /* [lock] */
    int doomed;                              /* [lock] expired; render thread frees */
    int checkpoint_due;                      /* [lock] set by the render thread when it published a
                                                still frame of a version not yet checkpointed */
    uint32_t checkpoint_version;             /* [lock] newest state version flagged for a checkpoint */
    char *info_bounds, *info_counts, *info_attrs; /* [lock] set by the render thread after a load */
    char info_dataset[SL_PROTO_NAME_MAX];    /* [lock] which dataset the info describes */
    int info_pending;                        /* [lock] not yet taken by the service thread */
    double idle_since_ms;                    /* [lock] written by the service thread: 0 while
                                                clients are attached, else when the last left */
    uint32_t progress_round;                 /* [lock] current round of long work (progress.c) */
    uint32_t progress_seq;                   /* [lock] number of the newest progress text (0: none) */
    uint32_t progress_round_start;           /* [lock] progress_seq before the current round's first */
    int progress_closed;                     /* [lock] the current round's `done` was posted */
    char *progress_text[SL_PROGRESS_RING];   /* [lock] owned texts, text n at n % SL_PROGRESS_RING */
    sl_record_job *record;                   /* [lock] the newest recording job (running or finished), or NULL */
    char *record_text;                       /* [lock] its newest `recording` message (coalesced: newest wins) */
    uint32_t record_seq;                     /* [lock] bumped with every new record_text */
    sl_session *next;                        /* [lock] in server->sessions */
    /* [service] */
    sl_client *clients;
    int client_count;
    int controller;                          /* client id, 0 = nobody */
    double empty_since_ms;
    uint32_t dispatched_frame;               /* newest frame id dispatched to clients */
    sl_scene_path *play;                     /* the path playing live (playback.c), owned, or NULL */
    double play_t0_ms;                       /* when t = 0 of the path was (moves on at each loop) */
    int play_loop;                           /* 1: start again after the last key */
    int play_frame;                          /* the path frame shown last, -1 none */
    sl_params play_base;                     /* the parameters a keyed parameter is applied over */
    char *play_text;                         /* newest `playback` message (newest wins), owned */
    uint32_t play_seq;                       /* bumped with every new play_text */
    cJSON *bounds;                           /* [[x,y,z],[x,y,z]] of the loaded dataset, or NULL */
    /* [render] */
    sl_prepared *prepared;                   /* the scene it renders through (a reference), or NULL */
    sl_dataset_load *load;                   /* the dataset load it waits for, or NULL */
    int load_is_new;                         /* that load was queued for it (a load, not a cache hit) */
    sl_progress_round round;
    sl_session_state good;                   /* the last state that rendered a frame */
    int has_good;
    sl_iscale iscale;                        /* interactive scale estimates */
};

/* ---- metrics (http.c) ---- */

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



void sl_histogram_add(sl_histogram *h, double ms);

/* ---- the server ---- */

/* What the transport (ws.c) hands the layers below it when it starts (sl_ws_create), so that
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
    sl_session *sessions;                    /* [lock] */
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

/* session.c and its files (session_*.c, client_*.c, random_hex.c; service thread unless noted) */
void sl_sessions_on_text(sl_server *srv, sl_client *c, const char *text, size_t len);
void sl_sessions_on_close(sl_server *srv, sl_client *c);
void sl_sessions_on_wake(sl_server *srv);     /* dispatch frames, snapshots, errors */
void sl_sessions_sweep(sl_server *srv);       /* expire sessions past the grace period */
void sl_sessions_destroy_all(sl_server *srv); /* at shutdown, after the render thread ended */
void sl_session_free(sl_session *s);          /* render thread or shutdown; after its scene and load were released */
/* 2 x bytes lowercase hex digits of getrandom (bytes <= 32) and a NUL into
 * out: session ids, tokens, recording keys. Any thread. */
void sl_random_hex(char *out, int bytes);
/* The session's state object (sl_msg_state_json): welcome, patches, checkpoints. Service thread. */
cJSON *sl_session_state_json(const sl_session *s);
/* Queues a text message for c (takes ownership of text). Returns -1 when the
 * reply budget is used up (the link then ends with 1008 "reply budget"), or
 * on a NULL text (out of memory: 1011); the text is freed either way. */
int sl_client_queue_text(sl_client *c, char *text);
/* c has something to send: the transport calls sl_client_write_next for it soon. */
void sl_client_wake(sl_client *c);
/* Queues an `error`, merged into a queued one of the same code and field
 * when there is one (its `repeated` counts the others; the newest message
 * wins). Returns -1 as sl_client_queue_text. */
int sl_client_queue_error(sl_client *c, const char *code, const char *message, const char *field);
/* Ends c's link with a close frame: code (an RFC 6455 status) and reason
 * (cut to SL_CLOSE_REASON_MAX - 1 bytes), at c's next writable callback,
 * after its queued replies when after_replies is set; a peer that cannot
 * take the frame is dropped SL_CLOSE_GRACE_S later. The first call wins;
 * c's further messages are ignored. */
void sl_client_close(sl_client *c, int code, const char *reason, int after_replies);
/* Called from ws.c on writable: sends one message. Returns -1 to close. */
int sl_client_write_next(sl_server *srv, sl_client *c);

/* The session's camera (and parameters, when params is not NULL) set by
 * the server itself (path playback and seek): the state changes as for a
 * camera message with `phase` (camera_seq kept), and every client gets the
 * patch. */
void sl_session_set_view(sl_server *srv, sl_session *s, const sl_camera_spec *camera, const sl_params *params,
                         sl_camera_phase phase);

/* playback.c (service thread) */
/* Starts playing path (scene.md "Paths", checked against the session's
 * technique; replaces a path playing) from t = 0: the session's camera and
 * keyed parameters follow it in real time, one state change per path
 * frame (k / fps) that is due, so the render thread's newest-wins state
 * drops frames when rendering is slower. SL_ERR_INVALID naming the field. */
sl_status sl_play_start(sl_server *srv, sl_session *s, const cJSON *path, int loop, sl_err *err);
/* Stops a playing path (nothing when none) and tells every client why
 * (reason: "play_stop", "camera", "scene", "seek"). The camera stays where it was. */
void sl_play_stop(sl_server *srv, sl_session *s, const char *reason);
/* Sets the session's camera and keyed parameters to path's at time t (a
 * still frame), stopping playback first. SL_ERR_INVALID naming the field. */
sl_status sl_play_seek(sl_server *srv, sl_session *s, const cJSON *path, double t, sl_err *err);
/* Steps every playing session; returns ms until the next step is due, -1 when nothing plays. */
double sl_play_tick(sl_server *srv);

/* dataset_cache.c (any thread; its own lock): datasets by source, loaded on
 * SL_DATASET_LOADERS loader threads, the last SL_DATASET_CACHE_SLOTS kept. */
#define SL_DATASET_CACHE_SLOTS 4
#define SL_DATASET_LOADERS 2
typedef struct sl_dataset_cache sl_dataset_cache;  /* a sl_dataset_load is one load, shared by its waiters */
typedef struct sl_dataset_cache_desc {
    int loaders;                 /* loader threads, 0 = SL_DATASET_LOADERS */
    /* A load finished: its status and time (loader thread, no cache lock held). */
    void (*on_done)(void *arg, sl_status status, double load_ms);
    void *arg;
    double test_delay_ms;        /* tests only: every load sleeps this long first */
    const char *const *data_dirs; /* borrowed: a file must lie inside one (sl_dataset_open's confinement) */
    int data_dir_count;
} sl_dataset_cache_desc;
typedef enum sl_dataset_origin {
    SL_DATASET_CACHED,      /* *out is set: no load */
    SL_DATASET_SHARED_LOAD, /* *load: joined a load of the same source already in flight */
    SL_DATASET_NEW_LOAD,    /* *load: queued a new load */
} sl_dataset_origin;
/* Starts the loader threads. SL_ERR_NOMEM when memory or a thread is missing. */
sl_status sl_dataset_cache_create(const sl_dataset_cache_desc *desc, sl_dataset_cache **out, sl_err *err);
/* Stops the loaders (a running load finishes first) and drops the cache's
 * references. Every load must have been released. NULL is fine. */
void sl_dataset_cache_destroy(sl_dataset_cache *c);
/* Never waits for a load. The dataset of source (a file path when is_file,
 * else generator JSON): cached (*out: the caller's own reference, for
 * sl_pipeline_set_dataset or sl_dataset_destroy), or *load: a reference to
 * its load (release it with sl_dataset_load_release). *origin says which.
 * A cached file whose inode, size or mtime changed is loaded again. A file
 * with a checksum (the catalog's, sl_catalog_file_checksum; NULL or ""
 * for none) is read only when its bytes still have it: else the load fails
 * naming both checksums (a node whose data directory holds another file
 * than the one registered refuses it). Fails here only when out of memory
 * or for a source of SL_SOURCE_MAX bytes or more. */
sl_status sl_dataset_cache_request(sl_dataset_cache *c, const char *source, int is_file, const char *checksum,
                                   sl_dataset **out,
                                   sl_dataset_load **load, sl_dataset_origin *origin, sl_err *err);
/* 0 while the load is queued or running. 1 when it finished; then, when out
 * is not NULL: *status SL_OK and *out the caller's own reference, or the
 * loader's failure (*out NULL, err filled); *load_ms its time on the loader. */
int sl_dataset_load_poll(sl_dataset_cache *c, sl_dataset_load *l, sl_dataset **out, double *load_ms,
                         sl_status *status, sl_err *err);
const char *sl_dataset_load_source(const sl_dataset_load *l); /* immutable */
/* Drops the caller's reference; a queued load nobody waits for is dropped. NULL is fine. */
void sl_dataset_load_release(sl_dataset_cache *c, sl_dataset_load *l);

/* progress.c (render thread) */
/* Starts a round for st (ending an unfinished one with done, ok 0). */
void sl_progress_begin(sl_server *srv, sl_session *s, const sl_session_state *st);
/* Posts stage (loading, preparing, first_frame) once per round, in order; a
 * stage at or before the last one posted, or no active round, does nothing. */
void sl_progress_stage_post(sl_server *srv, sl_session *s, sl_progress_stage stage);
/* Ends the active round with done: ok 1 and the frame that showed the work
 * (its id and render ms), or ok 0 when it ended without one. */
void sl_progress_end(sl_server *srv, sl_session *s, int ok, double render_ms, uint32_t frame);

/* record.c */
/* A new job for session s (service thread, s->state as its base): path
 * checked against the session's technique (sl_scene_path_parse), at most
 * SL_RECORD_MAX_FRAMES frames and SL_RECORD_MAX_PIXELS, the video size
 * checked (sl_video_check). SL_ERR_INVALID naming what is wrong. */
sl_status sl_record_create(sl_server *srv, sl_session *s, const cJSON *path, const char *format, int crf,
                           sl_record_job **out, sl_err *err);
/* Frees a job: its writer (render thread, or a finished job) and its file. NULL is fine. */
void sl_record_free(sl_record_job *j);
/* Sets the session's newest `recording` text (lock held): the job's id and
 * state ("queued", "running", "done", "cancelled", "failed") plus the
 * fields of `extra` (consumed; may be NULL). */
void sl_record_status_locked(sl_session *s, const sl_record_job *j, const char *state, cJSON *extra);
/* For GET /recording/KEY?token=T (service thread): 200 with the file path
 * to serve (the job then gives it up: a second GET is 410), 403 for a
 * wrong token, 404 for no such finished recording, 410 when it was
 * downloaded already. */
int sl_record_take_download(sl_server *srv, const char *key, const char *token, char *file, size_t size,
                            const char **mime);

/* render.c */
sl_status sl_render_start(sl_server *srv, sl_err *err);
void sl_render_stop(sl_server *srv);

/* checkpoint.c (service thread) */
/* Lowercase hex SHA-256 of token into hex (65 bytes). SL_ERR_NOMEM when libcrypto fails. */
sl_status sl_checkpoint_token_hash(const char *token, char hex[65], sl_err *err);
/* Frees libcrypto's state (its per-thread error queue included) at the end of
 * main, once no thread uses it: the exit-time leak check (sl_leak_check.h) can
 * run before libcrypto's own atexit cleanup and would report it. */
void sl_checkpoint_crypto_cleanup(void);
/* 1 when SHA-256(token) equals want_hex, compared in constant time. */
int sl_checkpoint_token_matches(const char *token, const char *want_hex);
/* Writes the session's checkpoint (its state, this node as owner, the
 * token's hash); a failure is logged, the session goes on. */
void sl_checkpoint_write(sl_server *srv, sl_session *s);
/* Fills st (zeroed by the caller) from a checkpoint's state_json: the
 * dataset looked up in the catalog by name, the technique's parameters over
 * its defaults, the camera checked as a client's would be, size,
 * background, stream; *bounds the dataset bounds it held (owned, or NULL). *empty_since_s is the wall-clock second at which
 * the session had no clients any more when that was written (0: it had
 * clients). SL_ERR_INVALID naming what does not restore. */
sl_status sl_checkpoint_restore_state(sl_server *srv, const char *state_json, sl_session_state *st,
                                      cJSON **bounds, double *empty_since_s, sl_err *err);

/* agent.c: the HAProxy agent-check listener on cfg.agent_port (its own thread). */
/* The one line the agent answers now (lock not held by the caller): "drain\n"
 * while draining, else "up ready W%\n" (see agent.c for W). out gets 32 bytes. */
void sl_agent_reply(sl_server *srv, char out[32]);
sl_status sl_agent_start(sl_server *srv, sl_err *err);
void sl_agent_stop(sl_server *srv);                 /* NULL agent is fine */

/* session_drain.c: draining (main.c / ws.c, service thread) */
/* Starts draining: new sessions are refused with `draining`. */
void sl_sessions_drain_begin(sl_server *srv);
/* 1 once draining may end: no session has clients, or --grace seconds have
 * passed since it began. Then every live session's checkpoint is written
 * (so another node restores it when its clients come back). */
int sl_sessions_drain_done(sl_server *srv);
/* Sessions waiting for a render (a snapshot, a state version not rendered,
 * a still frame owed), the render thread's notion of pending work. Lock held. */
int sl_sessions_render_queue_locked(const sl_server *srv);

/* http.c */
char *sl_http_healthz(sl_server *srv, int *status);
char *sl_http_metrics(sl_server *srv);

/* ws.c */
sl_status sl_ws_create(sl_server *srv, int *port, sl_err *err);
/* ws_client_address.c: the client address of upgrade wsi (the peer, or behind a
 * --trusted-proxy the address it forwards), canonical text in out (size >=
 * SL_CLIENT_ADDRESS_MAX). count: 1 at the first look of an upgrade, which
 * counts and logs a forwarded, ignored or malformed header. Service thread. */
void sl_ws_client_address(sl_server *srv, struct lws *wsi, int count, char *out, size_t size);
/* Serves until *interrupted; *drain (the first SIGTERM) starts draining, and
 * the loop ends once sl_sessions_drain_done says so. */
void sl_ws_run(sl_server *srv, volatile sig_atomic_t *interrupted, volatile sig_atomic_t *drain);
void sl_ws_destroy(sl_server *srv);

#endif
