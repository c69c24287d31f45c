/* sl_sessions.h — the session layer of sightline-server: sessions, clients as the
 * sessions see them, control and its hand-off, grace, playback, recording jobs,
 * checkpoints. Pure state and decisions: no socket type anywhere; the transport
 * above calls in (sl_sessions_on_text, on_close, on_wake, sweep, drain) and is
 * reached back only through sl_server.transport. Below it the render layer
 * (each session's render slot) and the catalog. Service thread unless noted.
 *
 *   session.c        sessions, hello and joining, the message table and its
 *                    scene/camera/set/control handlers
 *   session_state.c  the state object, patches to every client, control
 *   session_paths.c  the path and recording messages
 *   session_views.c  the catalog lists, save_view and load_view
 *   session_wake.c   what the render thread left: frames, snapshots, reverts,
 *                    checkpoints, dataset descriptions
 *   session_drain.c  grace sweep, draining, teardown
 *   client_queue.c   a client's reply ring and close request
 *   playback.c       live playback of a camera path, seen by all its clients, and path_seek
 *   record.c         recording jobs: made, checked, freed, their one-time download
 *   checkpoint.c     session checkpoints in the catalog; SHA-256 of join tokens
 *   random_hex.c     random hex for ids, tokens, keys (any thread)
 * They share session_internal.h.
 */
#ifndef SL_SESSIONS_H
#define SL_SESSIONS_H

#include <stddef.h>

#include "render/sl_render.h"
#include "sl_server.h"

typedef struct sl_session sl_session;

#define SL_CLIENT_MAX_TEXT 32          /* the reply budget: queued replies to the client's own requests;
                                          one more ends the link (1008 "reply budget") */
#define SL_CLOSE_REASON_MAX 124        /* a close frame's reason with its NUL (RFC 6455: 123 bytes) */
#define SL_CLOSE_GRACE_S 5             /* a link told to close that cannot take its close frame is dropped */
#define SL_CLOSE_POLICY_VIOLATION 1008 /* RFC 6455 close codes the sessions use */
#define SL_CLOSE_UNEXPECTED_CONDITION 1011

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
    sl_render_slot slot;                     /* what the render thread shares ([lock]) and owns ([render]) */
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
};
/* The session holding slot. */
static inline sl_session *sl_session_of(sl_render_slot *slot)
{
    return (sl_session *)((char *)slot - offsetof(sl_session, slot));
}
/* The first session of srv->slots and the one after s, NULL at the end (lock held, or the
 * service thread, the only one that links sessions in; the render thread unlinks doomed ones). */
static inline sl_session *sl_sessions_first(const sl_server *srv)
{
    return srv->slots ? sl_session_of(srv->slots) : NULL;
}
static inline sl_session *sl_session_next(const sl_session *s)
{
    return s->slot.next ? sl_session_of(s->slot.next) : NULL;
}

/* session.c and its files (session_*.c, client_*.c, random_hex.c; service thread unless noted) */
void sl_sessions_on_text(sl_server *srv, sl_client *c, const char *text, size_t len);
void sl_sessions_on_close(sl_server *srv, sl_client *c);
void sl_sessions_on_wake(sl_server *srv);     /* dispatch frames, snapshots, errors */
void sl_sessions_sweep(sl_server *srv);       /* expire sessions past the grace period */
void sl_sessions_destroy_all(sl_server *srv); /* at shutdown, after the render thread ended */
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

/* record.c */
/* A new job for session s (service thread, s->state as its base): path
 * checked against the session's technique (sl_scene_path_parse), at most
 * SL_RECORD_MAX_FRAMES frames and SL_RECORD_MAX_PIXELS, the video size
 * checked (sl_video_check). SL_ERR_INVALID naming what is wrong. */
sl_status sl_record_create(sl_server *srv, sl_session *s, const cJSON *path, const char *format, int crf,
                           sl_record_job **out, sl_err *err);
/* Frees a job: its writer (render thread, or a finished job) and its file. NULL is fine. */
void sl_record_free(sl_record_job *j);
/* For GET /recording/KEY?token=T (service thread): 200 with the file path
 * to serve (the job then gives it up: a second GET is 410), 403 for a
 * wrong token, 404 for no such finished recording, 410 when it was
 * downloaded already. */
int sl_record_take_download(sl_server *srv, const char *key, const char *token, char *file, size_t size,
                            const char **mime);

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

#endif
