/* sl_render.h — the render layer of sightline-server: the render thread and what it
 * is made of. Below the sessions (which fill a session's render slot and read what
 * the thread leaves there) and above nothing of the server but the catalog.
 *
 *   render.c         the render thread: owns sl_gpu, the encoder, the prepared scenes;
 *                    picks work from the slots, publishes frames, reaps doomed slots
 *   render_scene.c   a slot's scene made ready (dataset load, prepare) and its view
 *                    rendered: the steps of a frame that render.c and render_record.c share
 *   render_record.c  a recording job's frames
 *   prepared_cache.c sl_pipelines shared by sessions on one scene (render thread)
 *   progress.c       the `progress` rounds of long work, posted to slots (render thread)
 *   record_status.c  a recording job's status text in its slot (lock held; any thread)
 *   interactive_scale.c  the adaptive scale of interactive frames (render thread)
 *   dataset_cache.c  datasets by source: cached, shared, loaded on its own
 *                    loader threads (any caller; its own lock)
 *   encoder.c        frame buffers (refcounted) and JPEG/PNG encoding (render thread)
 * They share render_internal.h. Never touches a socket or a session.
 */
#ifndef SL_RENDER_H
#define SL_RENDER_H

#include <stdatomic.h>
#include <stdint.h>

#include "catalog/sl_catalog.h"
#include "core/sl_params.h"
#include "sl_server.h"

typedef struct sl_pipeline sl_pipeline;
typedef struct sl_dataset sl_dataset;
typedef struct sl_technique sl_technique;
typedef struct sl_gpu sl_gpu;
typedef struct sl_dataset_load sl_dataset_load;  /* dataset_cache.c */

#define SL_SESSION_MAX_SNAPSHOTS 8     /* pending snapshot requests per session */
#define SL_SOURCE_MAX 2048
#define SL_PROGRESS_RING 8             /* newest progress texts kept per session: two full rounds */

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

/* ---- what to render ---- */

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

/* ---- recordings (made by sessions/record.c, their frames rendered by render_record.c) ---- */
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

/* ---- the render slot ---- */

/* A session as the render thread sees it: what it shows, the frames and texts the
 * render thread leaves for it, and the render thread's own state of it. The session
 * layer embeds one in every sl_session (sl_session.slot) and links it into
 * sl_server.slots, the list the render thread walks; the render layer never sees
 * the session around it. */
typedef struct sl_render_slot sl_render_slot;
struct sl_render_slot {
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
    sl_render_slot *next;                    /* [lock] in sl_server.slots */
    /* Immutable: frees the session holding this slot (render thread, once the slot is
     * doomed, unlinked and its scene and load are released; or at shutdown). */
    void (*destroy)(sl_render_slot *slot);
    /* [render] */
    sl_prepared *prepared;                   /* the scene it renders through (a reference), or NULL */
    sl_dataset_load *load;                   /* the dataset load it waits for, or NULL */
    int load_is_new;                         /* that load was queued for it (a load, not a cache hit) */
    sl_progress_round round;
    sl_session_state good;                   /* the last state that rendered a frame */
    int has_good;
    sl_iscale iscale;                        /* interactive scale estimates */
};

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
void sl_progress_begin(sl_server *srv, sl_render_slot *s, const sl_session_state *st);
/* Posts stage (loading, preparing, first_frame) once per round, in order; a
 * stage at or before the last one posted, or no active round, does nothing. */
void sl_progress_stage_post(sl_server *srv, sl_render_slot *s, sl_progress_stage stage);
/* Ends the active round with done: ok 1 and the frame that showed the work
 * (its id and render ms), or ok 0 when it ended without one. */
void sl_progress_end(sl_server *srv, sl_render_slot *s, int ok, double render_ms, uint32_t frame);

/* record_status.c */
/* Sets the slot's newest `recording` text (lock held): the job's id and
 * state ("queued", "running", "done", "cancelled", "failed") plus the
 * fields of `extra` (consumed; may be NULL). */
void sl_record_status_locked(sl_render_slot *s, const sl_record_job *j, const char *state, cJSON *extra);

/* render.c */
sl_status sl_render_start(sl_server *srv, sl_err *err);
void sl_render_stop(sl_server *srv);

#endif
