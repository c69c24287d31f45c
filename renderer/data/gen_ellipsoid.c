/* gen_ellipsoid.c — an analytic ellipsoid field (bright inside) for the particle tests.
 *
 * Grid: x, y on [-1, 1] (origin -1, spacing h = 2 / (size - 1)); z spacing
 * h_z = anisotropy·h, dims_z = round((size - 1) / anisotropy) + 1, or exactly
 * `slices` when that key is not 0; the z slices are centred on z = 0 (origin_z
 * = -(dims_z - 1)·h_z / 2), so the z extent is about [-1, 1] (exactly when
 * anisotropy divides size - 1) and an odd dims_z has a slice at z = 0.
 * Profiles, with q = sqrt((x/a)² + (y/b)² + (z/c)²) and a, b, c the keys in
 * world units (fractions of the half-extent 1):
 *   linear:  f = 1 - q; the level f = iso is the ellipsoid of semi-axes (1 - iso)(a, b, c);
 *   plateau: f = max(1 - q, 0.5): flat at 0.5 wherever q >= 0.5;
 *   sheet:   f = 1 on the one slice k = floor((dims_z - 1) / 2) (z = 0 when dims_z is odd,
 *            else half a slice below) where (x/a)² + (y/b)² <= 1, else 0.
 * Data values: f32 stores f. u16 / u8 store the integers
 *   v = round((clamp(f, -1.5, 1) + 1.5) / 2.5 · M),  M = 65535 (u16) or 255 (u8),
 * and the dataset's values are these integers (no scale), so an isovalue iso_f of f is
 * iso_data = (iso_f + 1.5) / 2.5 · M in data units (iso 0.5 → 52428 u16, 204 u8).
 * No randomness, hence no seed key (8 keys, the SL_GEN_MAX_KEYS limit). Any thread.
 */
#include "gen_family.h"

#include <math.h>
#include <stdint.h>

#define SL_ELLIPSOID_CLAMP_LOW -1.5
#define SL_ELLIPSOID_CLAMP_HIGH 1.0

enum { K_SIZE, K_A, K_B, K_C, K_ANISOTROPY, K_SLICES, K_TYPE, K_PROFILE };
enum { T_F32, T_U16, T_U8 };
enum { P_LINEAR, P_PLATEAU, P_SHEET };

static double profile_value(int profile, const double p[3], const double axes[3], int on_sheet_slice)
{
    double qx = p[0] / axes[0], qy = p[1] / axes[1], qz = p[2] / axes[2];
    if (profile == P_SHEET)
        return on_sheet_slice && qx * qx + qy * qy <= 1.0 ? 1.0 : 0.0;
    double f = 1.0 - sqrt(qx * qx + qy * qy + qz * qz);
    return profile == P_PLATEAU ? fmax(f, 0.5) : f;
}

static double quantized(double f, double levels)
{
    double c = f < SL_ELLIPSOID_CLAMP_LOW ? SL_ELLIPSOID_CLAMP_LOW : f > SL_ELLIPSOID_CLAMP_HIGH ? SL_ELLIPSOID_CLAMP_HIGH : f;
    return round((c - SL_ELLIPSOID_CLAMP_LOW) / (SL_ELLIPSOID_CLAMP_HIGH - SL_ELLIPSOID_CLAMP_LOW) * levels);
}

static sl_status ellipsoid_generate(const double *values, sl_dataset **out, sl_err *err)
{
    int size = (int)values[K_SIZE];
    const double axes[3] = {values[K_A], values[K_B], values[K_C]};
    double anisotropy = values[K_ANISOTROPY];
    int slices = (int)values[K_SLICES], type = (int)values[K_TYPE], profile = (int)values[K_PROFILE];
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VOLUME, "ellipsoid");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "ellipsoid: out of memory");
    sl_volume *vol = &ds->volume;
    int dims_z = slices > 0 ? slices : (int)lround((double)(size - 1) / anisotropy) + 1;
    const int dims[3] = {size, size, dims_z};
    static const sl_voxel_type voxel_types[] = {SL_VOXEL_F32, SL_VOXEL_U16, SL_VOXEL_U8};
    if (sl_volume_alloc(vol, dims, 1, voxel_types[type], err) != SL_OK)
        goto fail;
    double step = 2.0 / (double)(size - 1), step_z = anisotropy * step;
    vol->spacing[0] = vol->spacing[1] = step;
    vol->spacing[2] = step_z;
    double origin_z = -0.5 * (double)(dims_z - 1) * step_z;
    ds->origin = sl_v3(-1.0, -1.0, origin_z);
    int sheet_slice = (dims_z - 1) / 2;
    size_t i = 0;
    for (int k = 0; k < dims_z; k++)
        for (int j = 0; j < size; j++)
            for (int x = 0; x < size; x++, i++) {
                const double p[3] = {-1.0 + step * x, -1.0 + step * j, origin_z + step_z * k};
                double f = profile_value(profile, p, axes, k == sheet_slice);
                if (type == T_F32)
                    ((float *)vol->data)[i] = (float)f;
                else if (type == T_U16)
                    ((uint16_t *)vol->data)[i] = (uint16_t)quantized(f, 65535.0);
                else
                    ((uint8_t *)vol->data)[i] = (uint8_t)quantized(f, 255.0);
            }
    if (sl_dataset_finish_volume(ds, err) != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "ellipsoid");
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_ellipsoid = {
    .name = "ellipsoid",
    .kind = SL_DATASET_VOLUME,
    .description = "analytic ellipsoid field, bright inside (f = 1 - q, plateau or one-slice sheet), "
                   "f32 or u16/u8 = (f + 1.5) / 2.5 of the integer range, anisotropic z",
    .keys_help = "size voxels along x and y (8..512, default 64), a, b, c semi-axes as fractions of the half-extent "
                 "(0.05..0.95, default 0.6), anisotropy z spacing over x spacing (0.25..4, default 1), "
                 "slices z slices (0..2048, default 0 = from anisotropy), voxel_type (\"f32\" default, \"u16\", \"u8\"), "
                 "profile (\"linear\" default, \"plateau\", \"sheet\")",
    .key_count = 8,
    .keys = {
        {.name = "size", .type = SL_GEN_INT, .min = 8, .max = 512, .def = 64},
        {.name = "a", .type = SL_GEN_NUMBER, .min = 0.05, .max = 0.95, .def = 0.6},
        {.name = "b", .type = SL_GEN_NUMBER, .min = 0.05, .max = 0.95, .def = 0.6},
        {.name = "c", .type = SL_GEN_NUMBER, .min = 0.05, .max = 0.95, .def = 0.6},
        {.name = "anisotropy", .type = SL_GEN_NUMBER, .min = 0.25, .max = 4, .def = 1},
        {.name = "slices", .type = SL_GEN_INT, .min = 0, .max = 2048, .def = 0},
        {.name = "voxel_type", .type = SL_GEN_CHOICE, .def = 0, .choices = {"f32", "u16", "u8"}},
        {.name = "profile", .type = SL_GEN_CHOICE, .def = 0, .choices = {"linear", "plateau", "sheet"}},
    },
    .generate = ellipsoid_generate,
};
