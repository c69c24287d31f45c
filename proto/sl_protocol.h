/* sl_protocol.h — the sightline.v1 wire protocol (proto/PROTOCOL.md): client
 * message parsing, server message serializers and the binary frame header.
 *
 * Parsing checks every field of a client message (type, ranges, unknown
 * keys) and reports the first bad one by name, so the server can answer with
 * an `error` naming the field and keep the connection. It does not check
 * what needs server state (session ids, tokens, technique parameters,
 * camera geometry): the server does that. Shared by sightline-server, the
 * server tests and the server benchmark. Any thread; no GL, no sockets.
 * Invariant: a parsed sl_msg owns its cJSON tree; every cJSON pointer in it
 * is borrowed from that tree and dies with sl_msg_deinit.
 */
#ifndef SL_PROTOCOL_H
#define SL_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#include "core/sl_camera.h"
#include "core/sl_params.h"
#include "core/sl_status.h"

#define SL_PROTO_VERSION 1
#define SL_PROTO_SUBPROTOCOL "sightline.v1"
#define SL_PROTO_MAX_MESSAGE (64 * 1024)        /* bytes of one client message after hello */
#define SL_PROTO_MAX_HELLO 4096                 /* bytes of a message before hello */
#define SL_PROTO_ID_MAX 64                      /* session id / token / view name buffers */
#define SL_PROTO_NAME_MAX 128                   /* dataset and technique names */
#define SL_PROTO_MAX_SIZE 4096                  /* largest width or height a client may ask */
#define SL_PROTO_ACK_WINDOW 2                   /* unacknowledged frames a client may have */
#define SL_NODE_ID_MAX 32                       /* characters of a node id ([A-Za-z0-9_-]) */
#define SL_SESSION_HEX 16                       /* hex digits after the node id in a session id */
#define SL_SESSION_ID_SIZE (SL_NODE_ID_MAX + 1 + SL_SESSION_HEX + 1) /* "NODE.<hex>" and its NUL */

typedef enum sl_msg_type {
    SL_MSG_INVALID = 0,
    SL_MSG_HELLO,
    SL_MSG_CAMERA,
    SL_MSG_SET,
    SL_MSG_SCENE,
    SL_MSG_LIST_DATASETS,
    SL_MSG_LIST_VIEWS,
    SL_MSG_SAVE_VIEW,
    SL_MSG_LOAD_VIEW,
    SL_MSG_RESIZE,
    SL_MSG_ACK,
    SL_MSG_SNAPSHOT,
    SL_MSG_CONTROL,
    SL_MSG_PING,
    SL_MSG_RECORD,
    SL_MSG_RECORD_CANCEL,
    SL_MSG_PLAY_PATH,
    SL_MSG_PLAY_STOP,
    SL_MSG_PATH_SEEK,
    SL_MSG_SAVE_PATH,
    SL_MSG_LIST_PATHS,
    SL_MSG_LOAD_PATH,
} sl_msg_type;

typedef enum sl_camera_phase {
    SL_PHASE_NONE = 0,  /* a one-off change: render a still frame now */
    SL_PHASE_START,
    SL_PHASE_MOVE,
    SL_PHASE_END,
} sl_camera_phase;

typedef enum sl_control_action {
    SL_CONTROL_REQUEST = 1, /* a viewer asks for control */
    SL_CONTROL_GRANT,       /* the controller hands control to `client` */
    SL_CONTROL_RELEASE,     /* the controller gives control up */
} sl_control_action;

/* One parsed client message. Fields not used by `type` are zero. */
typedef struct sl_msg {
    sl_msg_type type;
    cJSON *root;                      /* owned */
    int version;                      /* hello */
    char session[SL_PROTO_ID_MAX];    /* hello: "" = new session */
    char token[SL_PROTO_ID_MAX];      /* hello */
    int width, height;                /* hello, resize: 0 = not given */
    long long seq;                    /* camera, ping */
    sl_camera_phase phase;            /* camera */
    const cJSON *camera;              /* camera, scene (optional), borrowed */
    const cJSON *params;              /* set, scene (optional): object, borrowed */
    const cJSON *stream;              /* set (optional): object, borrowed */
    const cJSON *background;          /* set (optional): [r,g,b,a], borrowed */
    char dataset[SL_PROTO_NAME_MAX];  /* scene: "" = keep */
    char technique[SL_PROTO_NAME_MAX];/* scene: "" = keep */
    char name[SL_PROTO_ID_MAX];       /* save_view, load_view, save_path, load_path */
    uint32_t frame_id;                /* ack */
    sl_control_action action;         /* control */
    int client;                       /* control grant: target client id */
    const cJSON *path;                /* record, play_path, path_seek, save_path: the path object (scene.md "Paths"), borrowed */
    int loop;                         /* play_path: 1 = start again at t = 0 after the last key */
    double t;                         /* path_seek: seconds, finite, >= 0 */
    char format[8];                   /* record: "mp4" or "webm" */
    int crf;                          /* record: -1 = the codec's default */
} sl_msg;

/* 1 when s is a node id: 1..SL_NODE_ID_MAX characters of [A-Za-z0-9_-]. */
int sl_node_id_valid(const char *s);
/* 1 when s is a session id: a node id, '.', and SL_SESSION_HEX lowercase hex
 * digits (sessions are named by the node that made them, PROTOCOL.md). */
int sl_session_id_valid(const char *s);

/* Parses one client text message of `len` bytes (need not be NUL-terminated).
 * On failure returns SL_ERR_INVALID, fills err, writes a stable error code
 * ("bad_json", "unknown_type", "bad_field") to code and the offending field
 * name ("" when the whole message is at fault) to field, and leaves *msg
 * zeroed. code and field are caller buffers of at least 32 and
 * SL_PROTO_ID_MAX bytes. */
sl_status sl_msg_parse(const char *text, size_t len, sl_msg *msg,
                       char *code, char *field, sl_err *err);
void sl_msg_deinit(sl_msg *msg);   /* safe on a zeroed or deinitialized msg */

/* Camera limits of the protocol (PROTOCOL.md) on top of scene.md's rules,
 * so that every accepted camera renders (no overflow to inf on the way). */
#define SL_PROTO_CAMERA_MAX_DISTANCE 1e6   /* orbit distance, bounding-sphere radii */
#define SL_PROTO_CAMERA_MAX_AZIMUTH 1e6    /* |orbit azimuth|, degrees */
#define SL_PROTO_CAMERA_MAX_COORD 1e12     /* |eye|, |target| components, world units */

/* Parses and checks a `camera` object as the render thread will use it: the
 * scene rules (sl_camera_json_parse: finite numbers, distance > 0, elevation
 * within SL_ORBIT_MAX_ELEVATION, fov in (0, 180)), the limits above, then
 * the resolved view (sl_camera_spec_resolve, sl_view_init) against
 * bounds = {lo, hi} of the session's dataset, or the cube [-1, 1]^3 when
 * bounds is NULL (not loaded yet). On success *out (when not NULL) receives
 * the parsed camera; on failure SL_ERR_INVALID with a message naming the
 * field path (camera.orbit.distance ...) and its limit, *out unchanged. */
sl_status sl_msg_camera_check(const cJSON *camera, const double (*bounds)[3], sl_camera_spec *out, sl_err *err);

const char *sl_msg_type_name(sl_msg_type type);
const char *sl_camera_phase_name(sl_camera_phase phase);

/* ---- server -> client messages ----
 * Every *_text function returns a malloc'd compact JSON string (NULL on
 * allocation failure); a cJSON argument named "consumed" is owned by the
 * function from then on, even on failure. */

/* {"type":"error","code":code,"message":message,"field":field}; field may be NULL or "". */
char *sl_msg_error_text(const char *code, const char *message, const char *field);
/* The same with "repeated":repeated when repeated > 0: that many more errors
 * of this code and field were merged into this one (message: the newest's). */
char *sl_msg_error_repeat_text(const char *code, const char *message, const char *field, uint32_t repeated);

/* A session's stream settings (the `stream` object of `set` and state).
 * While dragging, the server picks the scale: with interactive_adaptive the
 * largest step of interactive_scale x {1, 1/2, 1/4, 1/8} whose predicted
 * frame time (render + readback + encode) fits interactive_budget_ms;
 * without it always interactive_scale. Still frames are full size. */
typedef struct sl_stream_settings {
    double interactive_scale;      /* 1: the largest scale while dragging, 0.1..1 */
    int interactive_adaptive;      /* 1: pick a smaller step when frames are slow; 0: fixed scale */
    int interactive_budget_ms;     /* 100 (10 fps), 10..2000: frame time the adaptive scale aims under */
    int interactive_quality;       /* 60, 1..100 */
    int interactive_420;           /* 1 */
    int still_quality;             /* 92, 1..100 */
    int still_420;                 /* 0 */
    int still_delay_ms;            /* 200, 0..10000 */
} sl_stream_settings;

#define SL_STREAM_DEFAULTS ((sl_stream_settings){.interactive_scale = 1.0, .interactive_adaptive = 1, \
                                                 .interactive_budget_ms = 100, .interactive_quality = 60, \
                                                 .interactive_420 = 1, .still_quality = 92, .still_420 = 0, \
                                                 .still_delay_ms = 200})

cJSON *sl_msg_stream_json(const sl_stream_settings *s);
/* Applies a `stream` patch to *s, all or nothing. On failure returns
 * SL_ERR_INVALID, fills err and writes the field ("stream.<key>") to field
 * (SL_PROTO_ID_MAX bytes); *s is unchanged. */
sl_status sl_msg_stream_apply(sl_stream_settings *s, const cJSON *patch, char *field, sl_err *err);

/* The state object of welcome and of a full state patch (PROTOCOL.md). */
typedef struct sl_msg_state {
    uint32_t version;
    const char *dataset, *technique;
    const sl_params *params;
    const sl_camera_spec *camera;  /* a checked camera (sl_msg_camera_check) */
    uint32_t camera_seq;
    int width, height;
    const float *background;       /* 4 floats */
    const sl_stream_settings *stream;
    int controller;                /* client id, 0 = nobody */
    const cJSON *bounds;           /* [[x,y,z],[x,y,z]] or NULL (copied) */
} sl_msg_state;

cJSON *sl_msg_state_json(const sl_msg_state *st);
/* {"type":"state","version":v,"patch":patch (consumed)} */
char *sl_msg_state_text(uint32_t version, cJSON *patch);

/* welcome: what a client needs after hello. It also carries the default
 * camera (camera_default) and limits.max_elevation from core/sl_camera.h,
 * so the page holds no camera numbers of its own. */
typedef struct sl_msg_welcome {
    const char *session, *token;
    const char *node;              /* the node serving the session (--node-id) */
    int client;
    int is_controller;
    cJSON *state;                  /* consumed: sl_msg_state_json */
    cJSON *techniques;             /* consumed: array of technique schemas */
    cJSON *datasets;               /* consumed: catalog list */
    int max_clients, grace_s;      /* limits that are server options */
} sl_msg_welcome;

char *sl_msg_welcome_text(const sl_msg_welcome *w);
/* {"type":type,key:list (consumed)}: "datasets"/"datasets", "views"/"views". */
char *sl_msg_list_text(const char *type, const char *key, cJSON *list);
char *sl_msg_view_saved_text(const char *name);
/* {"type":type,"name":name} plus "path": path (consumed, may be NULL): path_saved, path. */
char *sl_msg_named_text(const char *type, const char *name, cJSON *path);
char *sl_msg_control_request_text(int client);
char *sl_msg_pong_text(long long seq);
/* {"type":"playback","state":"playing"|"stopped","t","duration","frame","frames","loop"} plus
 * "reason" (stopped only; NULL leaves it out): the session's live path playback. */
char *sl_msg_playback_text(const char *state, double t, double duration, int frame, int frames, int loop,
                           const char *reason);

/* Long work on a session's scene, in the order it happens (PROTOCOL.md,
 * "Progress"): loading the dataset, preparing the technique, rendering the
 * first frame, done. One round of work sends each stage at most once. */
typedef enum sl_progress_stage {
    SL_PROGRESS_LOADING = 0,
    SL_PROGRESS_PREPARING,
    SL_PROGRESS_FIRST_FRAME,
    SL_PROGRESS_DONE,
} sl_progress_stage;

typedef struct sl_msg_progress {
    sl_progress_stage stage;
    uint32_t round;                /* per session, increasing: one dataset switch, prepare... */
    uint32_t version;              /* the state version the work is for */
    const char *dataset, *technique;
    double fraction;               /* 0..1 when known, < 0: unknown (sent as null) */
    double elapsed_ms;             /* since the round began */
    double load_ms, prepare_ms;    /* so far (0 = none), all stages */
    double render_ms;              /* done: the first frame's render + readback */
    uint32_t frame;                /* done: id of that frame, 0 when none */
    int ok;                        /* done: 1 a frame was published; 0 failed or superseded */
    const char *backend;           /* done: the execution that drew it ("gl", "embree"; core/sl_backend.h),
                                      NULL (sent as null) for techniques with one */
} sl_msg_progress;

char *sl_msg_progress_text(const sl_msg_progress *p);
const char *sl_progress_stage_name(sl_progress_stage stage);

/* Binary frames (server -> client): a fixed 40-byte little-endian header
 * followed by `payload_bytes` bytes of JPEG (kind 0) or PNG (kind 1). */
#define SL_FRAME_HEADER_SIZE 40
#define SL_FRAME_MAGIC 0x31464c53u   /* "SLF1" as little-endian u32 */

typedef enum sl_frame_kind { SL_FRAME_JPEG = 0, SL_FRAME_PNG = 1 } sl_frame_kind;
#define SL_FRAME_FLAG_INTERACTIVE 1u

typedef struct sl_frame_header {
    uint8_t kind;            /* sl_frame_kind */
    uint8_t flags;           /* SL_FRAME_FLAG_* */
    uint32_t frame_id;       /* per session, increasing from 1 */
    uint32_t state_version;  /* the session state this frame shows */
    uint16_t width, height;  /* pixels of the encoded image */
    uint8_t quality;         /* JPEG quality 1..100; 100 for PNG */
    uint8_t subsampling;     /* 0 = 4:4:4, 1 = 4:2:0 (JPEG), 0 for PNG */
    float render_ms;         /* wall time of render + readback */
    float encode_ms;         /* wall time of the encode */
    uint32_t camera_seq;     /* newest camera `seq` this frame includes */
    uint32_t payload_bytes;  /* bytes after the header */
} sl_frame_header;

void sl_frame_header_write(const sl_frame_header *h, uint8_t out[SL_FRAME_HEADER_SIZE]);
/* Reads a header from a received binary message of `size` bytes; fails
 * (SL_ERR_FORMAT) on a short buffer, a wrong magic or header size, an unknown
 * kind, or payload_bytes that disagree with size. */
sl_status sl_frame_header_read(const uint8_t *data, size_t size, sl_frame_header *h, sl_err *err);

#endif
