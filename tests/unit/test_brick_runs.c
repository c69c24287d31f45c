/* test_brick_runs.c — sl_volume_brick_runs (renderer/volume/) against a
 * brute-force Chebyshev distance: for random masks of several shapes and
 * densities (all visible, none visible, one visible brick, 1-brick-thick
 * axes), every brick's run is its kind (visible: SL_VOLUME_RUN_VISIBLE + d)
 * and d is the smallest Chebyshev distance to a brick of the other kind,
 * capped at SL_VOLUME_RUN_MAX — so the cube within d - 1 is of its kind,
 * which is what lets a ray skip or sample it without lookups.
 */
#include <stdlib.h>
#include <string.h>

#include "volume/sl_volume.h"
#include "sl_test.h"

static int brute_run(const uint8_t *vis, const int d[3], int x, int y, int z)
{
    int self = vis[((size_t)z * d[1] + y) * d[0] + x] != 0, best = SL_VOLUME_RUN_MAX;
    for (int k = 0; k < d[2]; k++)
        for (int j = 0; j < d[1]; j++)
            for (int i = 0; i < d[0]; i++) {
                if ((vis[((size_t)k * d[1] + j) * d[0] + i] != 0) == self)
                    continue;
                int dx = abs(i - x), dy = abs(j - y), dz = abs(k - z);
                int m = dx > dy ? dx : dy;
                m = m > dz ? m : dz;
                if (m < best)
                    best = m;
            }
    return self ? SL_VOLUME_RUN_VISIBLE + best : best;
}

static void check_mask(const int d[3], const uint8_t *vis, const char *what)
{
    size_t n = (size_t)d[0] * d[1] * d[2];
    uint8_t *out = malloc(n);
    SL_CHECK(out && sl_volume_brick_runs(vis, d, out) == 0);
    int bad = 0;
    for (int z = 0; z < d[2] && out; z++)
        for (int y = 0; y < d[1]; y++)
            for (int x = 0; x < d[0]; x++)
                bad += out[((size_t)z * d[1] + y) * d[0] + x] != brute_run(vis, d, x, y, z);
    SL_CHECK_MSG(bad == 0, "%s (%dx%dx%d): %d bricks off the brute-force run", what, d[0], d[1], d[2], bad);
    free(out);
}

int main(void)
{
    const int shapes[][3] = {{7, 5, 6}, {16, 16, 16}, {1, 1, 20}, {20, 1, 1}, {9, 9, 1}, {1, 1, 1}};
    const double densities[] = {0.0, 0.01, 0.2, 0.7, 1.0};
    srand(12345);
    for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; s++)
        for (size_t q = 0; q < sizeof densities / sizeof densities[0]; q++) {
            size_t n = (size_t)shapes[s][0] * shapes[s][1] * shapes[s][2];
            uint8_t *vis = malloc(n);
            for (size_t i = 0; i < n; i++)
                vis[i] = (uint8_t)((double)rand() / RAND_MAX < densities[q] ? 1 + rand() % 3 : 0);
            char what[64];
            snprintf(what, sizeof what, "density %.2f", densities[q]);
            check_mask(shapes[s], vis, what);
            /* One visible brick in the middle of an empty grid. */
            memset(vis, 0, n);
            vis[n / 2] = 1;
            check_mask(shapes[s], vis, "one visible brick");
            free(vis);
        }
    /* A grid wider than the cap: distances stop at SL_VOLUME_RUN_MAX. */
    const int wide[3] = {300, 1, 1};
    uint8_t vis[300] = {0};
    vis[0] = 1;
    check_mask(wide, vis, "beyond the cap");
    SL_TEST_END();
}
