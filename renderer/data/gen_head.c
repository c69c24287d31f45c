/* gen_head.c — a nested-shells "head" phantom, CT-like, on a size^3 grid.
 *
 * Ellipsoids painted inside-out over air: scalp (soft tissue), skull (bone
 * shell about 6 mm thick), a thin CSF gap, brain, and two lateral plus one
 * third ventricle (CSF). Values are Hounsfield-like (air -1000, CSF +8,
 * brain +35, scalp +40, bone +1000); u16 stores HU + 1024 like a CT, u8
 * stores a windowed display value (air 0, CSF 60, brain 110, scalp 130, bone
 * 250). Boundaries are anti-aliased over one voxel (partial volume), so iso-
 * surfaces are smooth at any size. World units are millimetres: the grid
 * spans 220 mm, centred on the origin. Optional seeded Gaussian noise
 * (`noise` = 1 gives sigma 100 HU, or 25 u8 steps). Not anatomy. Any thread.
 */
#include "gen_family.h"
#include "gen_random.h"

#include <math.h>
#include <stdint.h>

#define SL_HEAD_EXTENT_MM 220.0
#define SL_HEAD_SCALE_MM 100.0 /* ellipsoid axes below are in units of 100 mm */

enum { K_SIZE, K_SEED, K_TYPE, K_NOISE };
enum { T_AIR, T_SCALP, T_BONE, T_CSF, T_BRAIN };

/* HU and u8 value per tissue. */
static const double tissue_hu[] = {-1000.0, 40.0, 1000.0, 8.0, 35.0};
static const double tissue_u8[] = {0.0, 130.0, 250.0, 60.0, 110.0};

typedef struct ellipsoid { double c[3], a[3]; int tissue; } ellipsoid;

/* Painted in order: each covers what came before. Every shape after the
 * first lies inside the first (the scalp), so a voxel outside it is air. */
static const ellipsoid shapes[] = {
    {{0.0, 0.0, 0.05}, {0.72, 0.90, 0.88}, T_SCALP},
    {{0.0, 0.0, 0.05}, {0.67, 0.85, 0.83}, T_BONE},
    {{0.0, 0.0, 0.05}, {0.61, 0.79, 0.77}, T_CSF},
    {{0.0, 0.0, 0.05}, {0.59, 0.77, 0.745}, T_BRAIN},
    {{-0.09, 0.02, 0.12}, {0.06, 0.28, 0.12}, T_CSF},
    {{0.09, 0.02, 0.12}, {0.06, 0.28, 0.12}, T_CSF},
    {{0.0, -0.05, 0.0}, {0.02, 0.10, 0.08}, T_CSF},
};

/* Fraction of a voxel of width w (mm) at p (mm) inside the ellipsoid. */
static double coverage(const ellipsoid *e, const double p[3], double w)
{
    double s = 0.0, amin = e->a[0];
    for (int c = 0; c < 3; c++) {
        double q = (p[c] / SL_HEAD_SCALE_MM - e->c[c]) / e->a[c];
        s += q * q;
        if (e->a[c] < amin)
            amin = e->a[c];
    }
    double d = (sqrt(s) - 1.0) * amin * SL_HEAD_SCALE_MM; /* approximate signed distance, mm */
    double f = 0.5 - d / w;
    return f < 0.0 ? 0.0 : f > 1.0 ? 1.0 : f;
}

static sl_status head_generate(const double *values, sl_dataset **out, sl_err *err)
{
    int size = (int)values[K_SIZE];
    uint64_t seed = (uint64_t)values[K_SEED];
    int u8 = values[K_TYPE] == 1.0;
    double noise = values[K_NOISE];
    const double *table = u8 ? tissue_u8 : tissue_hu;
    double sigma = noise * (u8 ? 25.0 : 100.0);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VOLUME, "head");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "head: out of memory");
    sl_volume *vol = &ds->volume;
    const int dims[3] = {size, size, size};
    if (sl_volume_alloc(vol, dims, 1, u8 ? SL_VOXEL_U8 : SL_VOXEL_U16, err) != SL_OK)
        goto fail;
    double step = SL_HEAD_EXTENT_MM / (double)(size - 1);
    for (int c = 0; c < 3; c++)
        vol->spacing[c] = step;
    ds->origin = sl_v3(-0.5 * SL_HEAD_EXTENT_MM, -0.5 * SL_HEAD_EXTENT_MM, -0.5 * SL_HEAD_EXTENT_MM);
    sl_rng rng;
    sl_rng_seed(&rng, seed, 0);
    size_t i = 0;
    for (int k = 0; k < size; k++)
        for (int j = 0; j < size; j++)
            for (int x = 0; x < size; x++, i++) {
                double p[3] = {-0.5 * SL_HEAD_EXTENT_MM + step * x, -0.5 * SL_HEAD_EXTENT_MM + step * j,
                               -0.5 * SL_HEAD_EXTENT_MM + step * k};
                double v = table[T_AIR];
                for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; s++) {
                    double f = coverage(&shapes[s], p, step);
                    if (f <= 0.0 && s == 0)
                        break;
                    if (f > 0.0)
                        v += f * (table[shapes[s].tissue] - v);
                }
                if (sigma > 0.0)
                    v += sigma * sl_rng_normal(&rng);
                if (u8) {
                    v = v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : v;
                    ((uint8_t *)vol->data)[i] = (uint8_t)lround(v);
                } else {
                    v += 1024.0;
                    v = v < 0.0 ? 0.0 : v > 4095.0 ? 4095.0 : v;
                    ((uint16_t *)vol->data)[i] = (uint16_t)lround(v);
                }
            }
    if (sl_dataset_finish_volume(ds, err) != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "head");
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_head = {
    .name = "head",
    .kind = SL_DATASET_VOLUME,
    .description = "CT-like nested-shells head phantom (scalp, skull, CSF, brain, ventricles), 220 mm cube, u16 = HU + 1024 or windowed u8",
    .keys_help = "size voxels per axis (8..512, default 128), seed (for noise), voxel_type (\"u16\" default or \"u8\"), "
                 "noise (0..1, default 0; 1 = sigma 100 HU)",
    .key_count = 4,
    .keys = {
        {.name = "size", .type = SL_GEN_INT, .min = 8, .max = 512, .def = 128},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
        {.name = "voxel_type", .type = SL_GEN_CHOICE, .def = 0, .choices = {"u16", "u8"}},
        {.name = "noise", .type = SL_GEN_NUMBER, .min = 0, .max = 1, .def = 0},
    },
    .generate = head_generate,
};
