/* transfer_2d.c — the 2D (curvature) transfer function as a value: presets,
 * validation and equality (see sl_transfer_function_2d in sl_params.h).
 *
 * Does not evaluate the function (how widgets combine is the technique's)
 * nor parse JSON (proto/params_json.c). Any thread; no GL. Invariant kept by
 * sl_params_set_transfer_2d: a stored function passed the check here and
 * its unused widgets are zero.
 */
#include "sl_params.h"

#include <math.h>
#include <string.h>

void sl_transfer_function_2d_preset(int preset, sl_transfer_function_2d *out)
{
    memset(out, 0, sizeof *out);
    switch (preset) {
    case SL_TF2D_PRESET_RIDGES_VALLEYS:
    default: {
        /* Kindlmann's ridge (k1 > 0 = k2) light and valley (k1 = 0 > k2) dark. */
        static const double ridges_valleys[2][7] = {
            {0.25, 0.0, 0.3, 0.95, 0.95, 0.9, 1.0},
            {0.0, -0.25, 0.3, 0.1, 0.1, 0.1, 1.0},
        };
        out->count = 2;
        out->range = 0.5;
        memcpy(out->widget, ridges_valleys, sizeof ridges_valleys);
        break;
    }
    }
}

sl_status sl_transfer_function_2d_check(const char *name, const sl_transfer_function_2d *tf, sl_err *err)
{
    if (tf->count < 1 || tf->count > SL_TF2D_MAX_WIDGETS)
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s' takes 1 to %d widgets, got %d", name,
                          SL_TF2D_MAX_WIDGETS, tf->count);
    if (!isfinite(tf->range) || !(tf->range > 0.0))
        return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': range %g must be finite and > 0", name, tf->range);
    static const char *const field[7] = {"k1", "k2", "radius", "red", "green", "blue", "alpha"};
    for (int k = 0; k < tf->count; k++) {
        const double *w = tf->widget[k];
        for (int c = 0; c < 7; c++) {
            if (!isfinite(w[c]))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': widget %d: %s is %g, must be finite", name,
                                  k, field[c], w[c]);
            if (c == 2 && !(w[c] > 0.0))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': widget %d: radius %g must be > 0", name, k,
                                  w[c]);
            if (c >= 3 && (w[c] < 0.0 || w[c] > 1.0))
                return sl_err_set(err, SL_ERR_INVALID, "parameter '%s': widget %d: %s %g is outside [0, 1]", name, k,
                                  field[c], w[c]);
        }
    }
    return SL_OK;
}

int sl_transfer_function_2d_equal(const sl_transfer_function_2d *a, const sl_transfer_function_2d *b)
{
    if (a->count != b->count || a->range != b->range)
        return 0;
    int n = a->count < 0 ? 0 : a->count > SL_TF2D_MAX_WIDGETS ? SL_TF2D_MAX_WIDGETS : a->count;
    return memcmp(a->widget, b->widget, (size_t)n * sizeof a->widget[0]) == 0;
}
