/* gen_marschner_lobb.c — the Marschner–Lobb test signal sampled on a size^3 f32 grid.
 *
 * rho(x,y,z) = (1 - sin(pi z / 2) + alpha (1 + rho_r(sqrt(x^2 + y^2)))) / (2 (1 + alpha)),
 * rho_r(r) = cos(2 pi fM cos(pi r / 2)), on [-1, 1]^3 (Marschner & Lobb,
 * "An evaluation of reconstruction filters for volume rendering", 1994),
 * with fM = 6, alpha = 0.25 by default: values in [0, 1], a signal whose
 * iso-surface 0.5 exposes the aliasing of a reconstruction filter. Voxel
 * (i,j,k) sits at -1 + 2 i / (size - 1) etc.: origin (-1,-1,-1), spacing
 * 2 / (size - 1). Optional seeded uniform noise of amplitude `noise`. Any thread.
 */
#include "gen_family.h"
#include "gen_random.h"

#include <math.h>
#include <stdlib.h>

#define SL_ML_PI 3.141592653589793

enum { K_SIZE, K_SEED, K_FM, K_ALPHA, K_NOISE };

static sl_status ml_generate(const double *values, sl_dataset **out, sl_err *err)
{
    int size = (int)values[K_SIZE];
    uint64_t seed = (uint64_t)values[K_SEED];
    double fm = values[K_FM], alpha = values[K_ALPHA], noise = values[K_NOISE];
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VOLUME, "marschner_lobb");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "marschner_lobb: out of memory");
    sl_volume *vol = &ds->volume;
    const int dims[3] = {size, size, size};
    if (sl_volume_alloc(vol, dims, 1, SL_VOXEL_F32, err) != SL_OK)
        goto fail;
    double step = 2.0 / (double)(size - 1);
    for (int c = 0; c < 3; c++)
        vol->spacing[c] = step;
    ds->origin = sl_v3(-1.0, -1.0, -1.0);
    /* rho is separable into a z term and an (x, y) term: tabulate both. */
    size_t n = (size_t)size;
    double *plane = malloc(n * n * sizeof *plane), *height = malloc(n * sizeof *height);
    if (!plane || !height) {
        free(plane);
        free(height);
        sl_err_set(err, SL_ERR_NOMEM, "out of memory for a %d^2 table", size);
        goto fail;
    }
    for (size_t j = 0; j < n; j++)
        for (size_t i = 0; i < n; i++) {
            double x = -1.0 + step * (double)i, y = -1.0 + step * (double)j;
            double r = sqrt(x * x + y * y);
            plane[j * n + i] = alpha * (1.0 + cos(2.0 * SL_ML_PI * fm * cos(SL_ML_PI * r / 2.0)));
        }
    for (size_t k = 0; k < n; k++)
        height[k] = 1.0 - sin(SL_ML_PI * (-1.0 + step * (double)k) / 2.0);
    double norm = 1.0 / (2.0 * (1.0 + alpha));
    float *data = vol->data;
    sl_rng rng;
    sl_rng_seed(&rng, seed, 0);
    size_t i = 0;
    for (size_t k = 0; k < n; k++)
        for (size_t j = 0; j < n * n; j++, i++) {
            double v = (height[k] + plane[j]) * norm;
            if (noise > 0.0)
                v += noise * sl_rng_range(&rng, -1.0, 1.0);
            data[i] = (float)v;
        }
    free(plane);
    free(height);
    if (sl_dataset_finish_volume(ds, err) != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "marschner_lobb");
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_marschner_lobb = {
    .name = "marschner_lobb",
    .kind = SL_DATASET_VOLUME,
    .description = "Marschner-Lobb test signal on [-1,1]^3, f32, values in [0,1]",
    .keys_help = "size voxels per axis (8..512, default 41), seed (for noise), fm (0..32, default 6), "
                 "alpha (0..10, default 0.25), noise amplitude (0..1, default 0)",
    .key_count = 5,
    .keys = {
        {.name = "size", .type = SL_GEN_INT, .min = 8, .max = 512, .def = 41},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
        {.name = "fm", .type = SL_GEN_NUMBER, .min = 0, .max = 32, .def = 6},
        {.name = "alpha", .type = SL_GEN_NUMBER, .min = 0, .max = 10, .def = 0.25},
        {.name = "noise", .type = SL_GEN_NUMBER, .min = 0, .max = 1, .def = 0},
    },
    .generate = ml_generate,
};
