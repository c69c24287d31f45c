/* volume_dvr.c — technique `volume_dvr`: GPU ray-marched direct volume rendering.
 *
 * Emission–absorption compositing, maximum intensity projection and a
 * shaded first-hit isosurface of one scalar volume (vector fields: their
 * magnitude): the shared preparation and ray marcher of renderer/volume/
 * (3D texture, min-max bricks, sl_volume_marcher: baked transfer function,
 * one full-screen pass of volume/volume_march.frag.glsl). prepare uploads
 * the volume and builds the brick grid once; every parameter is FRAME
 * level and only becomes a sl_volume_march_desc: the marcher re-bakes the
 * TF texture and rebuilds the brick mask when they change (a mode or
 * isovalue change only the mask), a camera move uploads nothing (counted in
 * sl_volume_counters). The model the frames follow is stated in README.md
 * (checked against tests/support/volume_reference.h). Render thread only.
 */
#include <stdlib.h>

#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../volume/sl_volume.h"

static const char *const mode_names[] = {"composite", "mip", "iso", NULL};
static const char *const interpolation_names[] = {"linear", "nearest", NULL};
static const char *const gradient_names[] = {"on_the_fly", "texture", NULL};

static const sl_param_def volume_dvr_params[] = {
    {"transfer_function", SL_PARAM_TRANSFER, 0, 0, {0, SL_TF_AUTO_OPACITY, 0}, NULL, "data",
     "colour and opacity per data value: points [[value, r, g, b, a], ...] or {colormap, opacity ramp, range}; "
     "default viridis over the value range with an opacity ramp chosen from the histogram", SL_INVALIDATE_FRAME},
    {"mode", SL_PARAM_ENUM, 0, 0, {0}, mode_names, "",
     "composite (emission-absorption), mip (maximum intensity), iso (first crossing of isovalue, shaded)",
     SL_INVALIDATE_FRAME},
    {"isovalue", SL_PARAM_FLOAT, -1e30, 1e30, {SL_PARAM_AUTO}, NULL, "data",
     "iso mode: the surface's value; auto: where the histogram's background peak ends (the object's boundary), "
     "mid-range without one", SL_INVALIDATE_FRAME},
    {"step", SL_PARAM_FLOAT, 0.01, 16.0, {0.5}, NULL, "voxel",
     "sampling distance in units of the smallest voxel spacing (opacity is corrected for it)", SL_INVALIDATE_FRAME},
    {"jitter", SL_PARAM_BOOL, 0, 1, {1}, NULL, "", "per-pixel random start within a step (against wood-grain)",
     SL_INVALIDATE_FRAME},
    {"alpha_threshold", SL_PARAM_FLOAT, 0.01, 1.0, {0.99}, NULL, "", "composite: stop a ray at this opacity",
     SL_INVALIDATE_FRAME},
    {"interpolation", SL_PARAM_ENUM, 0, 0, {0}, interpolation_names, "", "trilinear or nearest voxel",
     SL_INVALIDATE_FRAME},
    {"shading", SL_PARAM_BOOL, 0, 1, {0}, NULL, "",
     "composite: Blinn-Phong with the gradient (central differences) as normal", SL_INVALIDATE_FRAME},
    {"gradient", SL_PARAM_ENUM, 0, 0, {0}, gradient_names, "",
     "shading normals: central differences per sample (6 fetches) or a precomputed gradient texture (1 fetch, "
     "4 bytes per voxel, built once when first used)", SL_INVALIDATE_FRAME},
    {"empty_space_skipping", SL_PARAM_BOOL, 0, 1, {1}, NULL, "",
     "jump over 8^3 bricks that cannot contribute (same image)", SL_INVALIDATE_FRAME},
    {"clip_min", SL_PARAM_VEC3, 0.0, 1.0, {0, 0, 0}, NULL, "normalized", "clip box corner, 0..1 of the volume box",
     SL_INVALIDATE_FRAME},
    {"clip_max", SL_PARAM_VEC3, 0.0, 1.0, {1, 1, 1}, NULL, "normalized", "clip box corner, 0..1 of the volume box",
     SL_INVALIDATE_FRAME},
    {"light_direction", SL_PARAM_VEC3, -1.0, 1.0, {0.3, 0.5, 1.0}, NULL, "eye space",
     "direction towards the light: x right, y up, z towards the viewer", SL_INVALIDATE_FRAME},
    {"ambient", SL_PARAM_FLOAT, 0.0, 1.0, {0.25}, NULL, "", "ambient light", SL_INVALIDATE_FRAME},
    {"diffuse", SL_PARAM_FLOAT, 0.0, 1.0, {0.75}, NULL, "", "Lambert diffuse weight", SL_INVALIDATE_FRAME},
    {"specular", SL_PARAM_FLOAT, 0.0, 1.0, {0.3}, NULL, "", "Blinn-Phong specular weight", SL_INVALIDATE_FRAME},
    {"shininess", SL_PARAM_FLOAT, 1.0, 512.0, {32}, NULL, "", "Blinn-Phong exponent", SL_INVALIDATE_FRAME},
};

typedef struct volume_dvr_state {
    const sl_dataset *dataset;     /* borrowed */
    sl_volume_geometry geom;
    sl_volume_texture volume;
    sl_volume_bricks bricks;
    sl_volume_marcher marcher;
    GLuint gradient_tex;           /* built at the first frame that shades with it, or 0 */
    size_t gpu_bytes;
    sl_prepare_stats prep;
} volume_dvr_state;

static void volume_dvr_release(void *opaque)
{
    volume_dvr_state *s = opaque;
    if (!s)
        return;
    sl_volume_texture_destroy(&s->volume);
    sl_volume_bricks_destroy(&s->bricks);
    sl_volume_marcher_deinit(&s->marcher);
    if (s->gradient_tex) glDeleteTextures(1, &s->gradient_tex);
    free(s);
}

static sl_status volume_dvr_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **out,
                                    sl_err *err)
{
    (void)gpu;
    (void)params;
    *out = NULL;
    volume_dvr_state *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "volume_dvr: out of memory");
    s->dataset = ds;
    sl_volume_geometry_init(ds, &s->geom);
    sl_status st = sl_volume_marcher_init(&s->marcher, &ds->volume, err); /* compiles the composite program */
    if (st != SL_OK)
        goto fail;
    double t_upload = sl_clock_ms();
    if ((st = sl_volume_texture_create(&ds->volume, &s->volume, err)) != SL_OK)
        goto fail;
    double t_bricks = sl_clock_ms();
    if ((st = sl_volume_bricks_create(&ds->volume, &s->bricks, err)) != SL_OK)
        goto fail;
    s->prep.preprocess_ms = sl_clock_ms() - t_bricks; /* includes the (small) brick uploads */
    glFinish();
    s->prep.upload_ms = sl_clock_ms() - t_upload - s->prep.preprocess_ms;
    if ((st = sl_gl_check_errors("volume_dvr: preparing", err)) != SL_OK)
        goto fail;
    s->gpu_bytes = s->volume.bytes + s->bricks.bytes + s->marcher.bytes;
    *out = s;
    return SL_OK;
fail:
    sl_err_prefix(err, "volume_dvr");
    volume_dvr_release(s);
    return st;
}

static sl_status volume_dvr_render(void *opaque, const sl_view *view, const sl_params *params, sl_target *target,
                                   sl_render_stats *stats, sl_err *err)
{
    (void)target;
    volume_dvr_state *s = opaque;
    sl_volume_march_desc d = {
        .mode = (sl_volume_march_mode)sl_params_choice(params, "mode"),
        .tf = sl_params_transfer(params, "transfer_function"),
        .step = sl_params_float(params, "step"),
        .iso = sl_params_is_auto(params, "isovalue") ? sl_volume_auto_isovalue(&s->dataset->volume)
                                                      : sl_params_float(params, "isovalue"),
        .alpha_stop = sl_params_float(params, "alpha_threshold"),
        .jitter = sl_params_bool(params, "jitter"),
        .no_skipping = !sl_params_bool(params, "empty_space_skipping"),
        .nearest = sl_params_choice(params, "interpolation") == 1,
        .shading = sl_params_bool(params, "shading"),
        .clip = 1,
        .material = {sl_params_float(params, "ambient"), sl_params_float(params, "diffuse"),
                     sl_params_float(params, "specular"), sl_params_float(params, "shininess")},
    };
    float clip_min[3], clip_max[3], light[3];
    sl_params_vec3(params, "clip_min", clip_min);
    sl_params_vec3(params, "clip_max", clip_max);
    sl_params_vec3(params, "light_direction", light);
    for (int a = 0; a < 3; a++) {
        d.clip_min[a] = clip_min[a];
        d.clip_max[a] = clip_max[a];
        d.light_dir[a] = light[a];
    }
    int shades = (d.shading && d.mode == SL_VOLUME_MARCH_COMPOSITE) || d.mode == SL_VOLUME_MARCH_ISO;
    if (shades && sl_params_choice(params, "gradient") == 1) {
        if (!s->gradient_tex) {
            size_t bytes = 0;
            sl_status st = sl_volume_gradient_create(&s->dataset->volume, &s->gradient_tex, &bytes, err);
            if (st != SL_OK)
                return st;
            s->gpu_bytes += bytes;
        }
        d.gradient_tex = s->gradient_tex;
    }
    return sl_volume_marcher_draw(&s->marcher, &s->volume, &s->bricks, &s->geom, view, &d, stats, err);
}

static void volume_dvr_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const volume_dvr_state *s = opaque;
    *out = s ? s->prep : (sl_prepare_stats){0};
}

static size_t volume_dvr_gpu_bytes(const void *opaque)
{
    const volume_dvr_state *s = opaque;
    return s ? s->gpu_bytes : 0;
}

const sl_technique sl_volume_dvr_technique = {
    .name = "volume_dvr",
    .description = "GPU ray-marched direct volume rendering: composite, MIP, shaded isosurface",
    .dataset_kinds = SL_DATASET_VOLUME | SL_DATASET_VECTORS,
    .params = volume_dvr_params,
    .param_count = (int)(sizeof volume_dvr_params / sizeof volume_dvr_params[0]),
    .prepare = volume_dvr_prepare,
    .render = volume_dvr_render,
    .release = volume_dvr_release,
    .gpu_bytes = volume_dvr_gpu_bytes,
    .prepare_stats = volume_dvr_prepare_stats,
};
