/* render_internal.h — what render.c, render_scene.c and render_record.c share: the render
 * thread's context and the steps of a frame (render_scene.c). Render thread only. */
#ifndef SL_RENDER_INTERNAL_H
#define SL_RENDER_INTERNAL_H

#include "sl_render.h"

enum job_kind { JOB_NONE, JOB_FRAME, JOB_STILL, JOB_SNAPSHOT, JOB_RECORD };

typedef struct render_ctx {
    sl_server *srv;
    sl_gpu *gpu;
    sl_encoder *enc;
    uint8_t *rgba;
    size_t rgba_cap;
    unsigned rr;          /* round-robin start */
    sl_dataset_cache *datasets;
    sl_prepared_cache prepared;
} render_ctx;

/* render_scene.c */
/* Gets s ready to render st (render_scene.c says how): 1 when ready; 0 when waiting for a load or
 * failed, with the failure reported. */
int sl_render_ready_scene(render_ctx *ctx, sl_render_slot *s, const sl_session_state *st);
/* Renders st's view at scale of the session's size into the context's target, interactive or
 * still quality; *render_ms the render call's wall time, *backend the execution that drew it. */
sl_status sl_render_view(render_ctx *ctx, sl_render_slot *s, const sl_session_state *st, int interactive,
                         double scale, int *w_out, int *h_out, double *render_ms, const char **backend,
                         sl_err *err);
/* Tests only: the configured frame delay for a w x h frame. */
void sl_render_test_delay(const sl_server *srv, const sl_session_state *st, int w, int h);
/* A render failure: the slot's error (render_failed), st counted as rendered. Takes the lock. */
void sl_render_report_error(sl_server *srv, sl_render_slot *s, const sl_session_state *st, const sl_err *err);

/* render_record.c */
/* The next step of a recording job (cancel: stop it). */
void sl_render_record(render_ctx *ctx, sl_render_slot *s, sl_record_job *j, int cancel);

#endif
