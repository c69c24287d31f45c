/* session_internal.h — what the files of the session layer share and nobody else calls:
 * session.c (sessions, hello, the message table), session_state.c, session_paths.c,
 * session_views.c, session_wake.c, client_queue.c. Service thread, as the functions they came from.
 */
#ifndef SL_SESSION_INTERNAL_H
#define SL_SESSION_INTERNAL_H

#include "sl_sessions.h"

/* client_queue.c */
/* An `error` to c, counted in the metrics (merged as sl_client_queue_error). */
void sl_client_send_error(sl_server *srv, sl_client *c, const char *code, const char *message, const char *field);
/* An error in or before hello: the link ends after it, with 1008 and the code as reason. */
void sl_client_refuse(sl_server *srv, sl_client *c, const char *code, const char *message, const char *field);

/* session_state.c */
/* Merges patch (consumed) into every client's pending patch: newest value of each key wins. */
void sl_session_broadcast_patch(sl_session *s, cJSON *patch);
/* Bumps the version, wakes the render thread; caller holds srv->lock. */
void sl_session_state_changed_locked(sl_server *srv, sl_session *s);
/* The session's client with that id, or NULL. */
sl_client *sl_session_find_client(sl_session *s, int id);
/* Control to client id (0: nobody), told to every client. */
void sl_session_set_controller(sl_session *s, int id);
/* Control passes to the longest-connected other client (the list's tail), or nobody. */
void sl_session_pass_control(sl_session *s, int leaving);

/* session.c */
/* Switches dataset and/or technique (and optionally params and camera; NULL: kept): the
 * `scene` and `load_view` messages. Errors go to c. */
void sl_session_apply_scene(sl_server *srv, sl_client *c, const char *dataset, const char *technique,
                            const cJSON *params, const cJSON *camera);

/* session_views.c: message handlers (control already checked where needed). */
void sl_on_list_datasets(sl_server *srv, sl_client *c, const sl_msg *m);
void sl_on_list_views(sl_server *srv, sl_client *c, const sl_msg *m);
void sl_on_list_paths(sl_server *srv, sl_client *c, const sl_msg *m);
void sl_on_save_view(sl_server *srv, sl_client *c, const sl_msg *m);
void sl_on_load_view(sl_server *srv, sl_client *c, const sl_msg *m);

/* session_paths.c: message handlers (control already checked where needed). */
void sl_on_record(sl_server *srv, sl_client *c, const sl_msg *m);
void sl_on_record_cancel(sl_server *srv, sl_client *c, const sl_msg *m);
void sl_on_play(sl_server *srv, sl_client *c, const sl_msg *m);
void sl_on_save_path(sl_server *srv, sl_client *c, const sl_msg *m);
void sl_on_load_path(sl_server *srv, sl_client *c, const sl_msg *m);

#endif
