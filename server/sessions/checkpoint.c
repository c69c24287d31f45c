/* checkpoint.c — session checkpoints: what a node writes to the shared
 * catalog so that another node can bring a session back after it died.
 *
 * A checkpoint is the session's state object (sl_session_state_json: dataset
 * name, technique, parameters, camera, size, background, stream settings,
 * bounds) plus a "checkpoint" object {node, saved_s, empty_since_s} (wall
 * clock seconds; empty_since_s 0 while the session has clients). It is
 * written when the session is made, when a still frame of a new state
 * version is published (render.c flags it, session.c writes it: the
 * catalog belongs to the service thread) and when a draining node hands
 * its sessions over. The join token is never stored: only its SHA-256 in
 * lowercase hex (libcrypto EVP), compared in constant time
 * (CRYPTO_memcmp). A restore looks the dataset up again by name in the
 * shared catalog and checks parameters and camera with the rules a
 * client's messages go through, so a checkpoint is never trusted further
 * than a client would be. Not here: frames, recordings, playback, control
 * (a restored session starts with a fresh render and no controller until
 * its first client). Service thread only.
 */
#include "sl_sessions.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <openssl/crypto.h>
#include <openssl/evp.h>

#include "core/sl_technique.h"
#include "sl_params_json.h"

sl_status sl_checkpoint_token_hash(const char *token, char hex[65], sl_err *err)
{
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    hex[0] = '\0';
    if (EVP_Digest(token, strlen(token), md, &n, EVP_sha256(), NULL) != 1 || n != 32)
        return sl_err_set(err, SL_ERR_NOMEM, "SHA-256 of the session token failed (libcrypto)");
    for (unsigned i = 0; i < n; i++)
        snprintf(hex + 2 * i, 3, "%02x", md[i]);
    return SL_OK;
}

void sl_checkpoint_crypto_cleanup(void)
{
    OPENSSL_cleanup();
}

int sl_checkpoint_token_matches(const char *token, const char *want_hex)
{
    char hex[65];
    sl_err err = {0};
    if (strlen(want_hex) != 64 || sl_checkpoint_token_hash(token, hex, &err) != SL_OK)
        return 0;
    return CRYPTO_memcmp(hex, want_hex, 64) == 0;
}

void sl_checkpoint_write(sl_server *srv, sl_session *s)
{
    sl_err err = {0};
    char hash[65];
    cJSON *o = sl_session_state_json(s);
    cJSON *meta = o ? cJSON_AddObjectToObject(o, "checkpoint") : NULL;
    double now_s = (double)time(NULL);
    double empty_s = s->client_count > 0 ? 0 : now_s - (sl_clock_ms() - s->empty_since_ms) / 1000.0;
    if (meta) {
        cJSON_AddStringToObject(meta, "node", srv->cfg.node_id);
        cJSON_AddNumberToObject(meta, "saved_s", now_s);
        cJSON_AddNumberToObject(meta, "empty_since_s", empty_s > 0 ? empty_s : 0);
    }
    char *text = meta ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    if (!text)
        sl_err_set(&err, SL_ERR_NOMEM, "out of memory writing the checkpoint of session %s", s->id);
    if (text && sl_checkpoint_token_hash(s->token, hash, &err) == SL_OK)
        sl_catalog_session_put(srv->db, s->id, srv->cfg.node_id, hash, text, &err);
    if (err.message[0])
        fprintf(stderr, "sightline-server: checkpoint of %s not written: %s\n", s->id, err.message);
    free(text);
}

static const cJSON *member(const cJSON *o, const char *key)
{
    return cJSON_GetObjectItemCaseSensitive(o, key);
}

/* Bounds [[x,y,z],[x,y,z]] of a checkpoint into b; 0 when absent or malformed. */
static int read_bounds(const cJSON *j, double b[2][3])
{
    if (cJSON_GetArraySize(j) != 2)
        return 0;
    for (int i = 0; i < 2; i++) {
        const cJSON *row = cJSON_GetArrayItem(j, i);
        if (cJSON_GetArraySize(row) != 3)
            return 0;
        for (int k = 0; k < 3; k++) {
            const cJSON *v = cJSON_GetArrayItem(row, k);
            if (!cJSON_IsNumber(v))
                return 0;
            b[i][k] = v->valuedouble;
        }
    }
    return 1;
}

sl_status sl_checkpoint_restore_state(sl_server *srv, const char *state_json, sl_session_state *st,
                                      cJSON **bounds, double *empty_since_s, sl_err *err)
{
    *bounds = NULL;
    *empty_since_s = 0;
    cJSON *o = cJSON_Parse(state_json);
    sl_status rc = SL_OK;
    const cJSON *ds = member(o, "dataset"), *tq = member(o, "technique"), *pa = member(o, "params");
    const cJSON *ca = member(o, "camera"), *w = member(o, "width"), *h = member(o, "height");
    const cJSON *bg = member(o, "background"), *stream = member(o, "stream"), *meta = member(o, "checkpoint");
    const sl_technique *t = cJSON_IsString(tq) ? sl_technique_find(tq->valuestring) : NULL;
    double b[2][3];
    int have_bounds = read_bounds(member(o, "bounds"), b);
    char field[SL_PROTO_ID_MAX];
    if (!cJSON_IsObject(o) || !cJSON_IsString(ds) || !cJSON_IsNumber(w) || !cJSON_IsNumber(h) ||
        w->valuedouble < 1 || w->valuedouble > SL_PROTO_MAX_SIZE || h->valuedouble < 1 ||
        h->valuedouble > SL_PROTO_MAX_SIZE || cJSON_GetArraySize(bg) != 4) {
        rc = sl_err_set(err, SL_ERR_INVALID, "the session's checkpoint is malformed (dataset, size or background)");
        goto done;
    }
    if (!t) {
        rc = sl_err_set(err, SL_ERR_INVALID, "the session's technique is not in this node's build");
        goto done;
    }
    if ((rc = sl_catalog_lookup(srv->db, ds->valuestring, st->dataset_source, sizeof st->dataset_source,
                                &st->dataset_is_file, &st->dataset_kind, st->dataset_checksum, err)) != SL_OK)
        goto done;
    if (!(t->dataset_kinds & (unsigned)st->dataset_kind)) {
        rc = sl_err_set(err, SL_ERR_INVALID, "technique %s cannot render the session's dataset", t->name);
        goto done;
    }
    snprintf(st->dataset, sizeof st->dataset, "%s", ds->valuestring);
    snprintf(st->technique, sizeof st->technique, "%s", t->name);
    sl_params_init(&st->params, t->params, t->param_count);
    if (cJSON_IsObject(pa) && (rc = sl_params_apply_json(&st->params, pa, err)) != SL_OK)
        goto done;
    if ((rc = sl_msg_camera_check(ca, have_bounds ? (const double (*)[3])b : NULL, &st->camera, err)) != SL_OK)
        goto done;
    st->stream = SL_STREAM_DEFAULTS;
    if (cJSON_IsObject(stream) && (rc = sl_msg_stream_apply(&st->stream, stream, field, err)) != SL_OK)
        goto done;
    for (int i = 0; i < 4; i++) {
        const cJSON *v = cJSON_GetArrayItem(bg, i);
        st->background[i] = cJSON_IsNumber(v) ? (float)v->valuedouble : 0.0f;
    }
    const cJSON *ver = member(o, "version"), *seq = member(o, "camera_seq");
    st->version = (cJSON_IsNumber(ver) && ver->valuedouble >= 0 && ver->valuedouble < 4e9 ? (uint32_t)ver->valuedouble
                                                                                          : 0) + 1;
    st->camera_seq = cJSON_IsNumber(seq) && seq->valuedouble >= 0 && seq->valuedouble < 4294967296.0
                         ? (uint32_t)seq->valuedouble : 0;
    st->width = (int)w->valuedouble;
    st->height = (int)h->valuedouble;
    st->phase = SL_PHASE_NONE;
    if (have_bounds)
        *bounds = cJSON_Duplicate(member(o, "bounds"), 1);
    const cJSON *empty = member(meta, "empty_since_s");
    if (cJSON_IsNumber(empty) && empty->valuedouble > 0)
        *empty_since_s = empty->valuedouble;
done:
    cJSON_Delete(o);
    return rc;
}
