/* session_views.c — the messages that read or write the catalog for a client: the lists
 * of datasets, saved views and saved paths, save_view and load_view (load_view switches
 * the scene as a `scene` message would). Handlers of session.c's message table (control
 * already checked where needed). Service thread.
 */
#include "sl_sessions.h"

#include <stdlib.h>

#include "session_internal.h"
#include "sl_camera_json.h"
#include "sl_params_json.h"

static char *print_and_free(cJSON *o)
{
    char *t = o ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    return t;
}

void sl_on_list_datasets(sl_server *srv, sl_client *c, const sl_msg *m)
{
    (void)m;
    sl_client_queue_text(c, sl_msg_list_text("datasets", "datasets", sl_catalog_list_json(srv->db, 0)));
}

void sl_on_list_views(sl_server *srv, sl_client *c, const sl_msg *m)
{
    (void)m;
    sl_client_queue_text(c, sl_msg_list_text("views", "views", sl_catalog_list_views_json(srv->db)));
}

void sl_on_list_paths(sl_server *srv, sl_client *c, const sl_msg *m)
{
    (void)m;
    sl_client_queue_text(c, sl_msg_list_text("paths", "paths", sl_catalog_list_paths_json(srv->db)));
}

/* Views are one catalog-wide namespace that save_view may overwrite, so only a controller
 * (who can change what the session shows anyway) may write it. */
void sl_on_save_view(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_err err = {0};
    char *params = print_and_free(sl_params_to_json(&s->slot.state.params));
    char *camera = print_and_free(sl_camera_to_json(&s->slot.state.camera));
    sl_status st = camera ? sl_catalog_save_view(srv->db, m->name, s->slot.state.dataset, s->slot.state.technique,
                                                 params ? params : "{}", camera, &err)
                          : sl_err_set(&err, SL_ERR_NOMEM, "out of memory writing the view's camera");
    free(params);
    free(camera);
    if (st)
        sl_client_send_error(srv, c, st == SL_ERR_LIMIT ? "limit" : "internal", err.message, "name");
    else
        sl_client_queue_text(c, sl_msg_view_saved_text(m->name));
}

void sl_on_load_view(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_play_stop(srv, c->session, "scene");
    sl_err err = {0};
    cJSON *v = NULL;
    if (sl_catalog_load_view(srv->db, m->name, &v, &err) != SL_OK || !v) {
        sl_client_send_error(srv, c, "not_found", v ? err.message : "no saved view with that name", "name");
        cJSON_Delete(v);
        return;
    }
    const cJSON *ds = cJSON_GetObjectItemCaseSensitive(v, "dataset");
    const cJSON *tq = cJSON_GetObjectItemCaseSensitive(v, "technique");
    const cJSON *pa = cJSON_GetObjectItemCaseSensitive(v, "params");
    const cJSON *ca = cJSON_GetObjectItemCaseSensitive(v, "camera");
    sl_session_apply_scene(srv, c, cJSON_IsString(ds) ? ds->valuestring : NULL, cJSON_IsString(tq) ? tq->valuestring : NULL,
                cJSON_IsObject(pa) ? pa : NULL, cJSON_IsObject(ca) ? ca : NULL);
    cJSON_Delete(v);
}
