/* interactive_scale.c — the image scale of a session's interactive frames.
 *
 * Ladder: the stream's interactive_scale (the client's upper bound) times 1,
 * 1/2, 1/4, 1/8. Each step keeps a moving average of its frames' cost
 * (render + readback + encode, no loads or prepares); an unmeasured step is
 * predicted from the nearest measured one, else from the full-size still, by
 * the pixel ratio. The pick is the largest step predicted within
 * interactive_budget_ms. When none fits, the smallest step, unless measured
 * costs show it is not faster (a vertex-bound render): then the largest step
 * that costs no more than SL_ISCALE_GAIN less. Hysteresis: down at once; up
 * to a fitting step one step at a time, after SL_ISCALE_UP_FRAMES frames and
 * with SL_ISCALE_UP_HEADROOM to spare. A still frame rescales every average
 * by its cost change (the view moved). A new scene key starts afresh.
 * Render thread only; does not decide when a frame is interactive.
 */
#include "sl_render.h"

#include <string.h>

#define SL_ISCALE_EMA_ALPHA 0.3     /* weight of the newest frame in a step's average */
#define SL_ISCALE_UP_FRAMES 4       /* frames at a step before a larger one is tried */
#define SL_ISCALE_UP_HEADROOM 0.8   /* a larger step must be predicted under this share of the budget */
#define SL_ISCALE_GAIN 0.75         /* a smaller step must cost at most this share of the larger one */

static double step_scale(const sl_iscale *a, int k)
{
    return a->top / (double)(1 << k);
}

/* Predicted cost (ms) of step k; negative when nothing is known yet. */
static double predict(const sl_iscale *a, int k)
{
    if (a->ema_ms[k] > 0)
        return a->ema_ms[k];
    double s = step_scale(a, k);
    for (int d = 1; d < SL_ISCALE_STEPS; d++) {
        for (int j = k - d; j <= k + d; j += 2 * d) {
            if (j < 0 || j >= SL_ISCALE_STEPS || a->ema_ms[j] <= 0)
                continue;
            double sj = step_scale(a, j);
            return a->ema_ms[j] * (s * s) / (sj * sj);
        }
    }
    if (a->still_ms > 0)
        return a->still_ms * s * s;
    return -1;
}

/* Measured cost of step k, 0 when unknown; step 0 falls back on the still
 * (at still quality, so an upper bound). */
static double measured(const sl_iscale *a, int k)
{
    if (a->ema_ms[k] > 0)
        return a->ema_ms[k];
    return k == 0 && a->still_ms > 0 ? a->still_ms * a->top * a->top : 0;
}

void sl_iscale_sync(sl_iscale *a, uint64_t scene_key, double top)
{
    if (a->valid && a->scene_key == scene_key && a->top == top)
        return;
    memset(a, 0, sizeof *a);
    a->valid = 1;
    a->scene_key = scene_key;
    a->top = top;
}

double sl_iscale_choose(sl_iscale *a, const sl_stream_settings *st, int *step)
{
    *step = 0;
    if (!st->interactive_adaptive)
        return a->top;
    double budget = st->interactive_budget_ms;
    int best = -1;
    for (int k = 0; k < SL_ISCALE_STEPS && best < 0; k++)
        if (predict(a, k) <= budget)
            best = k;
    if (best < 0) {
        /* Nothing fits: the smallest step, or a larger one that measured about as fast. */
        best = SL_ISCALE_STEPS - 1;
        while (best > 0 && measured(a, best) > 0 && measured(a, best - 1) > 0 &&
               measured(a, best) > SL_ISCALE_GAIN * measured(a, best - 1))
            best--;
    } else if (best < a->step) {
        int up = a->step - 1;
        int ready = a->frames_at_step >= SL_ISCALE_UP_FRAMES && predict(a, up) <= budget * SL_ISCALE_UP_HEADROOM;
        best = ready ? up : a->step;
    }
    if (best != a->step) {
        a->step = best;
        a->frames_at_step = 0;
    }
    *step = a->step;
    return step_scale(a, a->step);
}

void sl_iscale_record(sl_iscale *a, int interactive, int step, double cost_ms)
{
    if (cost_ms <= 0)
        return;
    if (!interactive) {
        if (a->still_ms > 0)
            for (int k = 0; k < SL_ISCALE_STEPS; k++)
                a->ema_ms[k] *= cost_ms / a->still_ms;
        a->still_ms = cost_ms;
        a->frames_at_step = 0;
        return;
    }
    if (step < 0 || step >= SL_ISCALE_STEPS)
        return;
    double *e = &a->ema_ms[step];
    *e = *e > 0 ? *e + SL_ISCALE_EMA_ALPHA * (cost_ms - *e) : cost_ms;
    if (step == a->step)
        a->frames_at_step++;
}
