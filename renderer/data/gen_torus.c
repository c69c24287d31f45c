/* gen_torus.c — an implicit field: signed distance to a torus united with a sphere.
 *
 * On [-1, 1]^3 (origin (-1,-1,-1), spacing 2 / (size - 1)), f32 values
 * f = min(d_torus, d_sphere): a torus of major radius 0.55 and minor radius
 * `minor` around the z axis, and a sphere of radius `sphere` centred on the
 * torus ring at (0.55, 0, 0). Exact Euclidean distance outside and inside
 * each solid; the union (min) is exact outside and a bound inside. The zero
 * iso-surface is the shape; negative inside. Optional seeded uniform noise
 * of amplitude `noise`. Any thread.
 */
#include "gen_family.h"
#include "gen_random.h"

#include <math.h>

#define SL_TORUS_MAJOR 0.55

enum { K_SIZE, K_SEED, K_MINOR, K_SPHERE, K_NOISE };

static sl_status torus_generate(const double *values, sl_dataset **out, sl_err *err)
{
    int size = (int)values[K_SIZE];
    uint64_t seed = (uint64_t)values[K_SEED];
    double minor = values[K_MINOR], sphere = values[K_SPHERE], noise = values[K_NOISE];
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VOLUME, "torus");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "torus: out of memory");
    sl_volume *vol = &ds->volume;
    const int dims[3] = {size, size, size};
    if (sl_volume_alloc(vol, dims, 1, SL_VOXEL_F32, err) != SL_OK)
        goto fail;
    double step = 2.0 / (double)(size - 1);
    for (int c = 0; c < 3; c++)
        vol->spacing[c] = step;
    ds->origin = sl_v3(-1.0, -1.0, -1.0);
    float *data = vol->data;
    sl_rng rng;
    sl_rng_seed(&rng, seed, 0);
    size_t i = 0;
    for (int k = 0; k < size; k++) {
        double z = -1.0 + step * k;
        for (int j = 0; j < size; j++) {
            double y = -1.0 + step * j;
            for (int x_i = 0; x_i < size; x_i++, i++) {
                double x = -1.0 + step * x_i;
                double ring = sqrt(x * x + y * y) - SL_TORUS_MAJOR;
                double d_torus = sqrt(ring * ring + z * z) - minor;
                double sx = x - SL_TORUS_MAJOR;
                double d_sphere = sqrt(sx * sx + y * y + z * z) - sphere;
                double v = fmin(d_torus, d_sphere);
                if (noise > 0.0)
                    v += noise * sl_rng_range(&rng, -1.0, 1.0);
                data[i] = (float)v;
            }
        }
    }
    if (sl_dataset_finish_volume(ds, err) != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "torus");
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_torus = {
    .name = "torus",
    .kind = SL_DATASET_VOLUME,
    .description = "signed distance to a torus united with a sphere on [-1,1]^3, f32, negative inside",
    .keys_help = "size voxels per axis (8..512, default 64), seed (for noise), minor torus radius (0.01..0.4, default 0.2), "
                 "sphere radius (0.01..0.45, default 0.3), noise amplitude (0..1, default 0)",
    .key_count = 5,
    .keys = {
        {.name = "size", .type = SL_GEN_INT, .min = 8, .max = 512, .def = 64},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
        {.name = "minor", .type = SL_GEN_NUMBER, .min = 0.01, .max = 0.4, .def = 0.2},
        {.name = "sphere", .type = SL_GEN_NUMBER, .min = 0.01, .max = 0.45, .def = 0.3},
        {.name = "noise", .type = SL_GEN_NUMBER, .min = 0, .max = 1, .def = 0},
    },
    .generate = torus_generate,
};
