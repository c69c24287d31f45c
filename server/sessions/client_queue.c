/* client_queue.c — what a client is sent in reply to its own requests (the reply ring: its
 * budget, errors merged by code and field) and the request to end its link with a close
 * frame; the error replies count in the metrics. Service thread. */
#include "sl_sessions.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>


#include "session_internal.h"

void sl_client_close(sl_client *c, int code, const char *reason, int after_replies)
{
    if (c->close_code)
        return;
    c->close_code = code;
    c->close_after_replies = after_replies;
    snprintf(c->close_reason, sizeof c->close_reason, "%s", reason);
    if (c->transport && c->transport->closing)
        c->transport->closing(c);
}

/* The next free slot of c's reply ring, or NULL when the reply budget is
 * used up (the link is then told to close) or c is closing anyway. */
static sl_reply *reply_slot(sl_client *c)
{
    if (c->close_code)
        return NULL;
    if (c->reply_count >= SL_CLIENT_MAX_TEXT) {
        char reason[80];
        snprintf(reason, sizeof reason, "reply budget: %d replies not read", SL_CLIENT_MAX_TEXT);
        sl_client_close(c, SL_CLOSE_POLICY_VIOLATION, reason, 0);
        return NULL;
    }
    sl_reply *r = &c->replies[(c->reply_head + c->reply_count) % SL_CLIENT_MAX_TEXT];
    memset(r, 0, sizeof *r);
    c->reply_count++;
    sl_client_wake(c);
    return r;
}

int sl_client_queue_text(sl_client *c, char *text)
{
    if (!text) {
        sl_client_close(c, SL_CLOSE_UNEXPECTED_CONDITION, "out of memory", 0);
        return -1;
    }
    sl_reply *r = reply_slot(c);
    if (!r) {
        free(text);
        return -1;
    }
    r->text = text;
    return 0;
}

int sl_client_queue_error(sl_client *c, const char *code, const char *message, const char *field)
{
    if (!field)
        field = "";
    char *text = strdup(message ? message : "");
    if (!text) {
        sl_client_close(c, SL_CLOSE_UNEXPECTED_CONDITION, "out of memory", 0);
        return -1;
    }
    for (int i = 0; i < c->reply_count; i++) {
        sl_reply *q = &c->replies[(c->reply_head + i) % SL_CLIENT_MAX_TEXT];
        if (q->code[0] && strcmp(q->code, code) == 0 && strncmp(q->field, field, sizeof q->field - 1) == 0) {
            free(q->text);
            q->text = text;
            q->repeated++;
            return 0;
        }
    }
    sl_reply *r = reply_slot(c);
    if (!r) {
        free(text);
        return -1;
    }
    r->text = text;
    snprintf(r->code, sizeof r->code, "%s", code);
    snprintf(r->field, sizeof r->field, "%s", field);
    return 0;
}

void sl_client_send_error(sl_server *srv, sl_client *c, const char *code, const char *message, const char *field)
{
    pthread_mutex_lock(&srv->lock);
    srv->metrics.errors_sent++;
    pthread_mutex_unlock(&srv->lock);
    sl_client_queue_error(c, code, message, field);
}

/* An error in or before hello: the link ends after it, with 1008 and the code as reason. */
void sl_client_refuse(sl_server *srv, sl_client *c, const char *code, const char *message, const char *field)
{
    sl_client_send_error(srv, c, code, message, field);
    sl_client_close(c, SL_CLOSE_POLICY_VIOLATION, code, 1);
}

void sl_client_wake(sl_client *c)
{
    if (c->transport && c->transport->want_write)
        c->transport->want_write(c);
}
