/* volume_brick_runs.c — how far each brick is from the nearest one of the other kind (see sl_volume.h).
 *
 * Chebyshev (L∞) distance transforms of the visible-brick mask, in bricks:
 * for an invisible brick, d > 0 when every brick within d - 1 of it (a cube
 * of 2d - 1 bricks per side) is invisible too; for a visible one the same
 * towards the nearest invisible brick. Capped at SL_VOLUME_RUN_MAX. L∞ separates into one pass per axis: the distance along x to the nearest
 * visible brick of the row, then per y and z the smallest max(|Δ|, previous)
 * over the column — exact, O(n · (dims[1] + dims[2])). Any thread; no GL.
 */
#include "sl_volume.h"

#include <stdlib.h>

static size_t at(const int dims[3], int x, int y, int z)
{
    return ((size_t)z * (size_t)dims[1] + (size_t)y) * (size_t)dims[0] + (size_t)x;
}

/* One column pass: out(i) = min_j max(|i - j|, in(j)) along an axis of
 * `len` entries `stride` apart; `col` is scratch of len entries. */
static void column_pass(uint8_t *d, size_t base, size_t stride, int len, uint8_t *col)
{
    for (int i = 0; i < len; i++)
        col[i] = d[base + (size_t)i * stride];
    for (int i = 0; i < len; i++) {
        int best = SL_VOLUME_RUN_MAX;
        for (int j = 0; j < len && best > 0; j++) {
            int gap = abs(i - j);
            if (gap >= best)
                continue;
            int v = col[j] > gap ? col[j] : gap;
            if (v < best)
                best = v;
        }
        d[base + (size_t)i * stride] = (uint8_t)best;
    }
}

/* Distance of every brick to the nearest brick whose visibility is `to`
 * (0 on those), capped at SL_VOLUME_RUN_MAX. */
static void distance_to(const uint8_t *visible, const int dims[3], int to, uint8_t *out, uint8_t *col)
{
    /* x: two sweeps along each row. */
    for (int z = 0; z < dims[2]; z++)
        for (int y = 0; y < dims[1]; y++) {
            int run = SL_VOLUME_RUN_MAX;
            for (int x = 0; x < dims[0]; x++) {
                size_t i = at(dims, x, y, z);
                run = (visible[i] != 0) == to ? 0 : (run < SL_VOLUME_RUN_MAX ? run + 1 : run);
                out[i] = (uint8_t)run;
            }
            run = SL_VOLUME_RUN_MAX;
            for (int x = dims[0] - 1; x >= 0; x--) {
                size_t i = at(dims, x, y, z);
                run = (visible[i] != 0) == to ? 0 : (run < SL_VOLUME_RUN_MAX ? run + 1 : run);
                if (run < out[i])
                    out[i] = (uint8_t)run;
            }
        }
    for (int z = 0; z < dims[2]; z++)
        for (int x = 0; x < dims[0]; x++)
            column_pass(out, at(dims, x, 0, z), (size_t)dims[0], dims[1], col);
    for (int y = 0; y < dims[1]; y++)
        for (int x = 0; x < dims[0]; x++)
            column_pass(out, at(dims, x, y, 0), (size_t)dims[0] * (size_t)dims[1], dims[2], col);
}

int sl_volume_brick_runs(const uint8_t *visible, const int dims[3], uint8_t *out)
{
    size_t n = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    uint8_t *col = malloc((size_t)(dims[1] > dims[2] ? dims[1] : dims[2]) + 1);
    uint8_t *other = malloc(n);
    if (!col || !other) {
        free(col);
        free(other);
        return -1;
    }
    distance_to(visible, dims, 1, out, col);   /* invisible bricks: to the nearest visible */
    distance_to(visible, dims, 0, other, col); /* visible bricks: to the nearest invisible */
    for (size_t i = 0; i < n; i++)
        out[i] = visible[i] ? (uint8_t)(SL_VOLUME_RUN_VISIBLE + other[i]) : out[i];
    free(col);
    free(other);
    return 0;
}
