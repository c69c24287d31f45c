/* client_write.c — sl_client_write_next (sl_server.h): one message to a client whose socket
 * is writable, in order of precedence: its replies, the close frame, the coalesced state patch,
 * control requests (to the controller), the session's progress texts, its newest error,
 * recording and playback texts, a snapshot, the newest frame within the ack window.
 * Service thread. */
#include "sl_net.h"

#include <stdlib.h>
#include <string.h>

#include <libwebsockets.h>

/* text (consumed) copied behind the LWS_PRE bytes lws_write needs; NULL when
 * out of memory. */
static uint8_t *lws_text_buffer(char *text, size_t *len)
{
    *len = strlen(text);
    uint8_t *buf = malloc(LWS_PRE + *len);
    if (buf)
        memcpy(buf + LWS_PRE, text, *len);
    free(text);
    return buf;
}

static int write_buf(struct lws *wsi, uint8_t *data, size_t len, enum lws_write_protocol proto)
{
    int n = lws_write(wsi, data, len, proto);
    return n < (int)len ? -1 : 0;
}

/* Writes text (consumed) at once and asks for the next writable callback. */
static int write_text_now(sl_client *c, char *text)
{
    if (!text)
        return -1;
    size_t len;
    uint8_t *buf = lws_text_buffer(text, &len);
    if (!buf)
        return -1;
    int rc = write_buf((struct lws *)c->link, buf + LWS_PRE, len, LWS_WRITE_TEXT);
    free(buf);
    lws_callback_on_writable((struct lws *)c->link);
    return rc;
}

int sl_client_write_next(sl_server *srv, sl_client *c)
{
    if (c->close_code && (!c->close_after_replies || c->reply_count == 0)) {
        lws_close_reason((struct lws *)c->link, (enum lws_close_status)c->close_code, (unsigned char *)c->close_reason,
                         strlen(c->close_reason));
        return -1;
    }
    if (c->reply_count > 0) {
        sl_reply r = c->replies[c->reply_head];
        memset(&c->replies[c->reply_head], 0, sizeof r);
        c->reply_head = (c->reply_head + 1) % SL_CLIENT_MAX_TEXT;
        c->reply_count--;
        char *text = r.text;
        if (r.code[0]) {
            text = sl_msg_error_repeat_text(r.code, r.text, r.field, r.repeated);
            free(r.text);
        }
        if (!text) {
            sl_client_close(c, LWS_CLOSE_STATUS_UNEXPECTED_CONDITION, "out of memory", 0);
            return 0;
        }
        return write_text_now(c, text);
    }
    sl_session *s = c->session;
    if (!s)
        return 0;
    if (c->patch) {
        cJSON *patch = c->patch;
        c->patch = NULL;
        return write_text_now(c, sl_msg_state_text(c->patch_version, patch));
    }
    if (s->controller == c->id) {
        for (sl_client *r = s->clients; r; r = r->next) {
            if (!r->wants_control || r == c)
                continue;
            r->wants_control = 0;
            return write_text_now(c, sl_msg_control_request_text(r->id));
        }
    }
    /* The session's progress texts, each once and in order (a client more
     * than the ring behind skips the oldest); before errors, so a failed
     * load's `done` precedes its load_failed. */
    char *progress = NULL;
    pthread_mutex_lock(&srv->lock);
    if (c->progress_seq != s->slot.progress_seq) {
        uint32_t next = c->progress_seq + 1, oldest = s->slot.progress_seq - (SL_PROGRESS_RING - 1);
        if (s->slot.progress_seq >= SL_PROGRESS_RING && next < oldest)
            next = oldest;
        c->progress_seq = next;
        progress = strdup(s->slot.progress_text[next % SL_PROGRESS_RING]);
    }
    pthread_mutex_unlock(&srv->lock);
    if (progress)
        return write_text_now(c, progress);
    char *error = NULL;
    pthread_mutex_lock(&srv->lock);
    if (c->error_seq != s->slot.error_seq) {
        c->error_seq = s->slot.error_seq;
        srv->metrics.errors_sent++;
        int load = strcmp(s->slot.error_code, "load_failed") == 0;
        error = sl_msg_error_text(load ? "load_failed" : "render_failed", s->slot.error_text, load ? "dataset" : "");
    }
    pthread_mutex_unlock(&srv->lock);
    if (error)
        return write_text_now(c, error);
    char *recording = NULL;
    pthread_mutex_lock(&srv->lock);
    if (c->record_seq != s->slot.record_seq) {
        c->record_seq = s->slot.record_seq;
        recording = s->slot.record_text ? strdup(s->slot.record_text) : NULL;
    }
    pthread_mutex_unlock(&srv->lock);
    if (recording)
        return write_text_now(c, recording);
    if (c->play_seq != s->play_seq) {
        c->play_seq = s->play_seq;
        if (s->play_text)
            return write_text_now(c, strdup(s->play_text));
    }
    if (c->snapshot) {
        sl_frame_buf *f = c->snapshot;
        c->snapshot = NULL;
        int rc = write_buf((struct lws *)c->link, f->data, f->size, LWS_WRITE_BINARY);
        sl_frame_buf_unref(f);
        lws_callback_on_writable((struct lws *)c->link);
        return rc;
    }
    sl_frame_buf *f = NULL;
    pthread_mutex_lock(&srv->lock);
    if (s->slot.latest && s->slot.latest->header.frame_id > c->sent_frame_id && c->inflight_count < SL_PROTO_ACK_WINDOW) {
        f = s->slot.latest;
        sl_frame_buf_ref(f);
        if (c->sent_frame_id)
            srv->metrics.frames_dropped += f->header.frame_id - c->sent_frame_id - 1;
        srv->metrics.frames_sent++;
        srv->metrics.bytes_sent += f->size;
    }
    pthread_mutex_unlock(&srv->lock);
    if (!f)
        return 0;
    c->sent_frame_id = f->header.frame_id;
    c->inflight[c->inflight_count++] = f->header.frame_id;
    int rc = write_buf((struct lws *)c->link, f->data, f->size, LWS_WRITE_BINARY);
    sl_frame_buf_unref(f);
    return rc;
}
