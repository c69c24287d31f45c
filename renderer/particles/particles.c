/* particles.c — technique `particles`: illustrative isosurface particles
 * (van Pelt, Vilanova, van de Wetering, "Illustrative Volume Visualization
 * Using GPU-Based Particle Systems", IEEE TVCG 2010; README.md).
 *
 * prepare uploads the volume (exact values) and builds one particle set per
 * isovalue (particles_system.h: placement, redistribution, curvature), or
 * takes a finished one from particles_cache.h —
 * only the PREPARED parameters (isovalues, lattice spacing, repulsion
 * radius, the stopping rule, sort, look-up, the particle cap) change the
 * particles, so a camera move or a style change never recomputes them.
 * render draws per set: hidden-surface removal by cone splatting into an id
 * target (Algorithm 3), then each style the set has on (splats, stipples,
 * hatches, contours; each in its own file), then the focus region's volume
 * (particles_focus.h). export writes every
 * alive particle as CSV (set,x,y,z,nx,ny,nz,k1,k2,reliability, world units).
 * Render thread only.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../volume/sl_volume.h"
#include "particles_cache.h"
#include "particles_focus.h"
#include "particles_frame.h"
#include "particles_contours.h"
#include "particles_hatch.h"
#include "particles_hsr.h"
#include "particles_splat.h"
#include "particles_stipple.h"
#include "particles_system.h"
#include "particles_tf2d.h"

#define PT_MAX_SETS SL_PARAM_VALUES_MAX

static const char *const sort_names[] = {"radix", "bitonic", NULL};
static const char *const lookup_names[] = {"prefix_sum", "binary_search", NULL};
static const char *const hatch_mode_names[] = {"curvature", "fixed", NULL};

static const sl_param_def particles_params[] = {
    {"isovalues", SL_PARAM_VALUES, -1e30, 1e30, {0}, NULL, "data",
     "one particle set per isovalue (up to 4; empty: one set at the end of the histogram's background peak, the "
     "skin of a CT or MRI); each strictly inside the volume's value range", SL_INVALIDATE_PREPARED},
    {"spacing", SL_PARAM_FLOAT, 0.25, 16.0, {1.25}, NULL, "voxel",
     "lattice step of the feature location: a particle where the surface crosses a lattice edge (fewer particles "
     "at a larger step, about 1.5 area / step^2)", SL_INVALIDATE_PREPARED},
    {"repulsion_radius", SL_PARAM_FLOAT, 0.5, 8.0, {1.6}, NULL, "spacing",
     "radius of the particles' repulsion, in lattice steps", SL_INVALIDATE_PREPARED},
    {"energy_tol", SL_PARAM_FLOAT, 0.0, 1.0, {0.001}, NULL, "",
     "stop the redistribution when the total energy changes by at most this share in a step (0: run max_steps)",
     SL_INVALIDATE_PREPARED},
    {"max_steps", SL_PARAM_INT, 0, 1000, {25}, NULL, "", "redistribution steps at most (the paper's 25)",
     SL_INVALIDATE_PREPARED},
    {"sort", SL_PARAM_ENUM, 0, 0, {0}, sort_names, "",
     "GPU sort of the particles by bin: radix (stable, LSD) or bitonic (the paper's class)", SL_INVALIDATE_PREPARED},
    {"lookup", SL_PARAM_ENUM, 0, 0, {1}, lookup_names, "",
     "bin table: prefix sum of a histogram or a binary search per bin (the paper's, the default: faster on llvmpipe, "
     "bench-particles); the same table",
     SL_INVALIDATE_PREPARED},
    {"max_particles", SL_PARAM_INT, 1000, 4000000, {1000000}, NULL, "",
     "particles per set at most: a denser lattice is refused with the numbers", SL_INVALIDATE_PREPARED},
    {"flat_curvature", SL_PARAM_FLOAT, 0.0, 1.0, {0.01}, NULL, "1/voxel",
     "curvatures below this count as flat (reliability 0 in the export)", SL_INVALIDATE_FRAME},
    {"hidden_surface_removal", SL_PARAM_INT, 0, 15, {15}, NULL, "sets",
     "per set: draw only the particles whose cone wins their pixel (Algorithm 3), each set on its own",
     SL_INVALIDATE_FRAME},
    {"cone_radius", SL_PARAM_FLOAT, 0.3, 4.0, {1.0}, NULL, "nn",
     "hidden-surface cones: radius in mean nearest-neighbour distances", SL_INVALIDATE_FRAME},
    {"stipple", SL_PARAM_INT, 0, 15, {15}, NULL, "sets", "per set: draw stipples", SL_INVALIDATE_FRAME},
    {"stipple_size", SL_PARAM_FLOAT, 0.0, 4.0, {0.6}, NULL, "nn",
     "diameter of a full-tone stipple, in mean nearest-neighbour distances", SL_INVALIDATE_FRAME},
    {"stipple_brightness", SL_PARAM_FLOAT, -1.0, 1.0, {0.0}, NULL, "", "shifts the tone: more is a brighter picture",
     SL_INVALIDATE_FRAME},
    {"stipple_contrast", SL_PARAM_FLOAT, 0.0, 8.0, {1.0}, NULL, "", "stretches the tone about its middle",
     SL_INVALIDATE_FRAME},
    {"splat", SL_PARAM_INT, 0, 15, {0}, NULL, "sets",
     "per set: draw the hidden-surface cones as opaque disks, Lambert-shaded in the set's ink (Fig. 10a)",
     SL_INVALIDATE_FRAME},
    {"contours", SL_PARAM_INT, 0, 15, {0}, NULL, "sets", "per set: draw contours (sec. 4.2.4)", SL_INVALIDATE_FRAME},
    {"contour_distance", SL_PARAM_FLOAT, 0.0, 4.0, {1.0}, NULL, "nn",
     "particles that project within this many mean nearest-neighbour distances of a contour draw a piece of it",
     SL_INVALIDATE_FRAME},
    {"contour_length", SL_PARAM_FLOAT, 0.2, 4.0, {1.2}, NULL, "nn",
     "length of each particle's contour segment, in mean nearest-neighbour distances", SL_INVALIDATE_FRAME},
    {"contour_width", SL_PARAM_FLOAT, 0.5, 16.0, {2.0}, NULL, "px", "width of the contour lines on screen",
     SL_INVALIDATE_FRAME},
    {"focus_center", SL_PARAM_VEC3, -1e30, 1e30, {0.0, 0.0, 0.0}, NULL, "world",
     "centre of the focus sphere, where the volume is ray marched instead of drawn as particles",
     SL_INVALIDATE_FRAME},
    {"focus_radius", SL_PARAM_FLOAT, 0.0, 1e30, {0.0}, NULL, "world",
     "radius of the focus sphere: inside it the volume (volume_dvr's marcher), outside the particles (0: off)",
     SL_INVALIDATE_FRAME},
    {"focus_transfer_function", SL_PARAM_TRANSFER, 0, 0, {0, SL_TF_AUTO_OPACITY, 0}, NULL, "data",
     "colour and opacity per data value inside the focus sphere (as volume_dvr's transfer_function; default "
     "viridis with an opacity ramp from the histogram)", SL_INVALIDATE_FRAME},
    {"focus_step", SL_PARAM_FLOAT, 0.01, 16.0, {0.5}, NULL, "voxel",
     "sampling distance of the focus ray marcher in smallest voxel spacings (doubled on interactive frames)",
     SL_INVALIDATE_FRAME},
    {"hatch", SL_PARAM_INT, 0, 15, {0}, NULL, "sets", "per set: draw hatch strokes (brightest no stroke, middle one, "
     "darkest cross-hatched where cross_hatching is on)", SL_INVALIDATE_FRAME},
    {"hatch_mode", SL_PARAM_ENUM, 0, 0, {0}, hatch_mode_names, "",
     "stroke direction: the reliability-weighted smoothed main principal direction of the neighbours (hatch_direction "
     "where unreliable) or hatch_direction projected into the tangent plane", SL_INVALIDATE_FRAME},
    {"hatch_direction", SL_PARAM_VEC3, -1.0, 1.0, {0.0, 0.0, 1.0}, NULL, "world",
     "fixed stroke direction, projected into each particle's tangent plane", SL_INVALIDATE_FRAME},
    {"hatch_length", SL_PARAM_FLOAT, 0.2, 8.0, {2.0}, NULL, "nn",
     "stroke length, in mean nearest-neighbour distances", SL_INVALIDATE_FRAME},
    {"hatch_segments", SL_PARAM_INT, 1, 16, {6}, NULL, "",
     "segments per stroke, each vertex moved back onto the surface (the paper's six)", SL_INVALIDATE_FRAME},
    {"hatch_width", SL_PARAM_FLOAT, 0.5, 8.0, {1.0}, NULL, "px", "stroke width on screen", SL_INVALIDATE_FRAME},
    {"cross_hatching", SL_PARAM_INT, 0, 15, {0}, NULL, "sets",
     "per set: a second stroke at cross_angle where the tone is darkest", SL_INVALIDATE_FRAME},
    {"cross_angle", SL_PARAM_FLOAT, 0.0, 180.0, {90.0}, NULL, "deg", "angle of the cross stroke to the main one",
     SL_INVALIDATE_FRAME},
    {"hatch_threshold", SL_PARAM_FLOAT, 0.0, 1.0, {0.7}, NULL, "",
     "no stroke where the brightness (the diffuse term; 1 - it for light ink) is at least this", SL_INVALIDATE_FRAME},
    {"cross_threshold", SL_PARAM_FLOAT, 0.0, 1.0, {0.35}, NULL, "",
     "cross strokes where the brightness is below this", SL_INVALIDATE_FRAME},
    {"curvature_coloring", SL_PARAM_INT, 0, 15, {0}, NULL, "sets",
     "per set: colour the marks by the 2D curvature transfer function curvature_tf", SL_INVALIDATE_FRAME},
    {"curvature_tf", SL_PARAM_TRANSFER_2D, 0, 0, {SL_TF2D_PRESET_RIDGES_VALLEYS}, NULL, "1/voxel",
     "colour over the principal curvatures (k1, k2) per voxel, round widgets composited in order over the set's ink",
     SL_INVALIDATE_FRAME},
    {"set0_color", SL_PARAM_VEC3, 0.0, 1.0, {0.95, 0.95, 0.9}, NULL, "rgb", "ink of set 0", SL_INVALIDATE_FRAME},
    {"set1_color", SL_PARAM_VEC3, 0.0, 1.0, {0.95, 0.7, 0.45}, NULL, "rgb", "ink of set 1", SL_INVALIDATE_FRAME},
    {"set2_color", SL_PARAM_VEC3, 0.0, 1.0, {0.55, 0.8, 1.0}, NULL, "rgb", "ink of set 2", SL_INVALIDATE_FRAME},
    {"set3_color", SL_PARAM_VEC3, 0.0, 1.0, {0.7, 1.0, 0.6}, NULL, "rgb", "ink of set 3", SL_INVALIDATE_FRAME},
    {"light_direction", SL_PARAM_VEC3, -1.0, 1.0, {0.3, 0.5, 1.0}, NULL, "eye space",
     "direction towards the light: x right, y up, z towards the viewer", SL_INVALIDATE_FRAME},
};

typedef struct particles_state {
    const sl_dataset *dataset;      /* borrowed */
    sl_volume_geometry geom;
    sl_volume_texture volume;
    sl_volume_bricks bricks;           /* min-max bricks: placement skips the tiles no isovalue crosses */
    double bricks_ms;
    pt_system *system;
    int set_count;
    double iso[PT_MAX_SETS];
    pt_set sets[PT_MAX_SETS];
    pt_hsr hsr;
    pt_stipple stipple;
    pt_splat splat;
    pt_contours contours;
    pt_focus focus;
    pt_hatch hatch;
    pt_tf2d tf2d;
    GLuint vao, camera_ubo;
    float max_point;                   /* GL_POINT_SIZE_RANGE max */
    size_t gpu_bytes;
    sl_prepare_stats prep;
} particles_state;

static void particles_release(void *opaque)
{
    particles_state *s = opaque;
    if (!s)
        return;
    for (int k = 0; k < s->set_count; k++)
        pt_set_release(&s->sets[k]);
    pt_system_destroy(s->system);
    sl_volume_texture_destroy(&s->volume);
    sl_volume_bricks_destroy(&s->bricks);
    pt_hsr_deinit(&s->hsr);
    pt_stipple_deinit(&s->stipple);
    pt_splat_deinit(&s->splat);
    pt_contours_deinit(&s->contours);
    pt_focus_deinit(&s->focus);
    pt_hatch_deinit(&s->hatch);
    pt_tf2d_deinit(&s->tf2d);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->camera_ubo) glDeleteBuffers(1, &s->camera_ubo);
    free(s);
}

/* The isovalues of the sets: as given, or one at the end of the histogram's
 * background peak (the start of the automatic opacity ramp), mid-range
 * without one. Each must lie strictly inside the value range. */
static sl_status resolve_isovalues(const sl_volume *vol, const sl_params *params, double iso[PT_MAX_SETS],
                                   int *count, sl_err *err)
{
    int n = sl_params_values(params, "isovalues", iso);
    double lo = vol->value_min, hi = vol->value_max;
    if (n == 0) {
        iso[0] = sl_volume_auto_isovalue(vol);
        n = 1;
    }
    for (int k = 0; k < n; k++)
        if (!(iso[k] > lo && iso[k] < hi))
            return sl_err_set(err, SL_ERR_INVALID,
                              "isovalue %g of set %d is at or beyond the volume's value range (%g, %g): no surface",
                              iso[k], k, lo, hi);
    *count = n;
    return SL_OK;
}

static void add_extra(sl_prepare_stats *p, const char *name, double value)
{
    sl_prepare_stats_add(p, name, value);
}

static void fill_prepare_stats(particles_state *s)
{
    double placement = s->bricks_ms, sort = 0, lookup = 0, energy = 0, final = 0, preprocess = 0;
    char name[32];
    for (int k = 0; k < s->set_count; k++) {
        const pt_set_stats *st = &s->sets[k].stats;
        snprintf(name, sizeof name, "set%d.isovalue", k), add_extra(&s->prep, name, s->iso[k]);
        snprintf(name, sizeof name, "set%d.particles", k), add_extra(&s->prep, name, st->alive);
        snprintf(name, sizeof name, "set%d.seeded", k), add_extra(&s->prep, name, st->seeded);
        snprintf(name, sizeof name, "set%d.dropped", k), add_extra(&s->prep, name, st->dropped);
        snprintf(name, sizeof name, "set%d.steps", k), add_extra(&s->prep, name, st->steps);
        snprintf(name, sizeof name, "set%d.final_energy", k), add_extra(&s->prep, name, st->final_energy);
        snprintf(name, sizeof name, "set%d.ms_per_step", k), add_extra(&s->prep, name, st->ms_per_step);
        snprintf(name, sizeof name, "set%d.mean_nn", k), add_extra(&s->prep, name, st->mean_nn);
        snprintf(name, sizeof name, "set%d.nn_cv", k), add_extra(&s->prep, name, st->nn_cv);
        placement += st->placement_ms;
        sort += st->sort_ms + st->id_sort_ms + st->gather_ms;
        lookup += st->lookup_ms;
        energy += st->energy_ms;
        final += st->final_ms + st->settle_ms;
    }
    preprocess = placement + sort + lookup + energy + final;
    add_extra(&s->prep, "placement_ms", placement);
    add_extra(&s->prep, "sort_ms", sort);
    add_extra(&s->prep, "lookup_ms", lookup);
    add_extra(&s->prep, "energy_ms", energy);
    add_extra(&s->prep, "curvature_ms", final);
    s->prep.preprocess_ms = preprocess;
}

static sl_status particles_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **out,
                                   sl_err *err)
{
    (void)gpu;
    *out = NULL;
    particles_state *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "particles: out of memory");
    s->dataset = ds;
    sl_volume_geometry_init(ds, &s->geom);
    pt_focus_init(&s->focus, &ds->volume, &s->volume, &s->geom);
    sl_status st = resolve_isovalues(&ds->volume, params, s->iso, &s->set_count, err);
    int built = 0;
    if (st != SL_OK)
        goto fail;
    double t_upload = sl_clock_ms();
    if ((st = sl_volume_texture_create(&ds->volume, &s->volume, err)) != SL_OK)
        goto fail;
    glFinish();
    s->prep.upload_ms = sl_clock_ms() - t_upload;
    double t_bricks = sl_clock_ms();
    if ((st = sl_volume_bricks_create(&ds->volume, &s->bricks, err)) != SL_OK)
        goto fail;
    s->bricks_ms = sl_clock_ms() - t_bricks;
    if ((st = pt_system_create(&s->system, err)) != SL_OK || (st = pt_hsr_init(&s->hsr, err)) != SL_OK ||
        (st = pt_stipple_init(&s->stipple, err)) != SL_OK || (st = pt_splat_init(&s->splat, err)) != SL_OK ||
        (st = pt_contours_init(&s->contours, err)) != SL_OK ||
        (st = pt_tf2d_init(&s->tf2d, err)) != SL_OK)
        goto fail;
    pt_field field = {.texture = s->volume.tex,
                      .value_scale = s->volume.value_scale,
                      .value_offset = s->volume.value_offset,
                      .min_spacing = s->geom.min_spacing,
                      .value_min = ds->volume.value_min,
                      .value_max = ds->volume.value_max,
                      .bricks = &s->bricks};
    for (int a = 0; a < 3; a++) {
        field.dims[a] = ds->volume.dims[a];
        field.spacing[a] = ds->volume.spacing[a];
    }
    pt_hatch_init(&s->hatch, &field);
    double step = sl_params_float(params, "spacing");
    pt_system_desc desc = {.lattice_step = step,
                           .sigma = sl_params_float(params, "repulsion_radius") * step * s->geom.min_spacing,
                           .energy_tol = sl_params_float(params, "energy_tol"),
                           .max_steps = sl_params_int(params, "max_steps"),
                           .sort = (pt_sort_method)sl_params_choice(params, "sort"),
                           .lookup = (pt_lookup_method)sl_params_choice(params, "lookup"),
                           .max_particles = (uint32_t)sl_params_int(params, "max_particles")};
    uint64_t volume_hash = pt_cache_volume_hash(&ds->volume);
    int cached = 0;
    for (built = 0; built < s->set_count; built++) {
        desc.iso = s->iso[built];
        int hit = pt_cache_lookup(volume_hash, &desc, &s->sets[built], err);
        if (hit < 0) {
            st = SL_ERR_GPU;
            goto fail;
        }
        if (hit) {
            cached++;
        } else if ((st = pt_set_build(s->system, &field, &desc, &s->sets[built], err)) != SL_OK) {
            sl_err_prefix(err, "set %d (isovalue %g)", built, s->iso[built]);
            goto fail;
        } else {
            pt_cache_store(volume_hash, &desc, &s->sets[built]);
        }
        s->gpu_bytes += s->sets[built].bytes;
    }
    sl_prepare_stats_add(&s->prep, "sets_cached", cached);
    glCreateVertexArrays(1, &s->vao);
    GLfloat range[2] = {1, 64};
    glGetFloatv(GL_POINT_SIZE_RANGE, range);
    s->max_point = range[1];
    if ((st = sl_gl_check_errors("particles: preparing", err)) != SL_OK)
        goto fail;
    s->gpu_bytes += s->volume.bytes + s->bricks.bytes;
    fill_prepare_stats(s);
    *out = s;
    return SL_OK;
fail:
    s->set_count = built;
    sl_err_prefix(err, "particles");
    particles_release(s);
    return st;
}

static double luminance(const float c[3])
{
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

/* The per-set style switches (INT "sets" masks): a set draws when any of
 * its bits is on. A new style adds its switch here. */
static const char *const style_masks[] = {"stipple", "splat", "hatch", "contours", NULL};

static int any_style_mask(const sl_params *params)
{
    int mask = 0;
    for (int i = 0; style_masks[i]; i++)
        mask |= sl_params_int(params, style_masks[i]);
    return mask;
}

static sl_status particles_render(void *opaque, const sl_view *view, const sl_params *params, sl_target *target,
                                  sl_render_stats *stats, sl_err *err)
{
    particles_state *s = opaque;
    int hsr_mask = sl_params_int(params, "hidden_surface_removal");
    int stipple_mask = sl_params_int(params, "stipple");
    sl_camera_ubo_update(&s->camera_ubo, view);
    pt_frame frame;
    pt_frame_init(&frame, view, params, s->geom.origin, s->max_point);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glPointParameteri(GL_POINT_SPRITE_COORD_ORIGIN, GL_LOWER_LEFT);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(s->vao);
    double drawn = 0.0;
    for (int k = 0; k < s->set_count; k++) {
        const pt_set *set = &s->sets[k];
        int styles = any_style_mask(params);
        if (set->stats.alive == 0 || !(styles >> k & 1))
            continue;
        pt_set_view sv = {.set = set, .index = k};
        char name[16];
        snprintf(name, sizeof name, "set%d_color", k);
        sl_params_vec3(params, name, sv.ink);
        sv.ink_dark = luminance(sv.ink) < luminance(view->background);
        sv.curvature = pt_tf2d_lookup(&s->tf2d, k, sl_params_int(params, "curvature_coloring") >> k & 1,
                                      sl_params_transfer_2d(params, "curvature_tf"), sv.ink, s->geom.min_spacing);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, set->records);
        double cone_radius = sl_params_float(params, "cone_radius") * set->stats.mean_nn;
        if (hsr_mask >> k & 1 && cone_radius > 0.0) {
            sl_status st = pt_hsr_draw(&s->hsr, &frame, (GLsizei)set->stats.alive, cone_radius, err);
            if (st != SL_OK)
                return st;
            glBindFramebuffer(GL_FRAMEBUFFER, target->fbo);
            glViewport(0, 0, target->width, target->height);
            sv.hsr = 1;
            sv.id_tex = s->hsr.ids;
        }
        if (sl_params_int(params, "splat") >> k & 1)
            drawn += pt_splat_draw(&s->splat, &frame, &sv, cone_radius);
        if (stipple_mask >> k & 1)
            drawn += pt_stipple_draw(&s->stipple, &frame, &sv, params);
        if (sl_params_int(params, "hatch") >> k & 1) {
            sl_status st = pt_hatch_draw(&s->hatch, &frame, &sv, s->iso[k], params, &drawn, err);
            if (st != SL_OK)
                return st;
        }
        if (sl_params_int(params, "contours") >> k & 1) {
            double sigma = sl_params_float(params, "repulsion_radius") * sl_params_float(params, "spacing") *
                           s->geom.min_spacing;
            sl_status st = pt_contours_draw(&s->contours, &frame, &sv, params, sigma, err);
            if (st != SL_OK)
                return st;
        }
    }
    sl_status focus_st = pt_focus_draw(&s->focus, view, params, target, stats, err);
    if (focus_st != SL_OK)
        return focus_st;
    glDisable(GL_BLEND);
    glBindTextureUnit(0, 0);
    glBindVertexArray(0);
    glDisable(GL_PROGRAM_POINT_SIZE);
    stats->primitives = drawn;
    for (int k = 0; k < s->set_count; k++)
        stats->dropped += s->sets[k].stats.dropped;
    return SL_OK;
}

static size_t particles_gpu_bytes(const void *opaque)
{
    const particles_state *s = opaque;
    if (!s)
        return 0;
    return s->gpu_bytes + pt_hsr_bytes(&s->hsr) + pt_contours_bytes(&s->contours) + pt_focus_bytes(&s->focus) +
           pt_hatch_bytes(&s->hatch) + (size_t)PT_TF2D_SETS * PT_TF2D_SIZE * PT_TF2D_SIZE * 4;
}

static void particles_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const particles_state *s = opaque;
    *out = s ? s->prep : (sl_prepare_stats){0};
}

/* The reliability of the principal directions (README.md; sec. 4.2.3). */
static double reliability(double k1, double k2, double eps)
{
    if (fabs(k1) < eps && fabs(k2) < eps)
        return 0.0;
    double si;
    if (k1 == k2)
        si = k1 > 0 ? -1.0 : 1.0;
    else
        si = 2.0 / M_PI * atan((k2 + k1) / (k2 - k1));
    return 1.0 - fabs(2.0 * (fabs(si) - 0.5));
}

static sl_status particles_export(void *opaque, const sl_params *params, const char *path, sl_err *err)
{
    const particles_state *s = opaque;
    FILE *f = fopen(path, "w");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "particles: cannot write %s", path);
    double eps = sl_params_float(params, "flat_curvature") / s->geom.min_spacing;
    fprintf(f, "set,x,y,z,nx,ny,nz,k1,k2,reliability\n");
    sl_status st = SL_OK;
    for (int k = 0; k < s->set_count && st == SL_OK; k++) {
        uint32_t n = s->sets[k].stats.alive;
        if (n == 0)
            continue;
        pt_record *r = malloc((size_t)n * sizeof *r);
        if (!r) {
            st = sl_err_set(err, SL_ERR_NOMEM, "particles: out of memory exporting %u particles", n);
            break;
        }
        glGetNamedBufferSubData(s->sets[k].records, 0, (GLsizeiptr)((size_t)n * sizeof *r), r);
        for (uint32_t i = 0; i < n; i++)
            fprintf(f, "%d,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", k, s->geom.origin.x + r[i].x[0],
                    s->geom.origin.y + r[i].x[1], s->geom.origin.z + r[i].x[2], r[i].n[0], r[i].n[1], r[i].n[2],
                    r[i].k1, r[i].k2, reliability(r[i].k1, r[i].k2, eps));
        free(r);
    }
    if (fclose(f) != 0 && st == SL_OK)
        st = sl_err_set(err, SL_ERR_IO, "particles: writing %s failed", path);
    return st;
}

const sl_technique sl_particles_technique = {
    .name = "particles",
    .description = "illustrative isosurface particles: stipples, splats, curvature hatching, contours, "
                   "focus + context (van Pelt et al., GPU-based particle systems, 2010)",
    .dataset_kinds = SL_DATASET_VOLUME,
    .params = particles_params,
    .param_count = (int)(sizeof particles_params / sizeof particles_params[0]),
    .prepare = particles_prepare,
    .render = particles_render,
    .release = particles_release,
    .gpu_bytes = particles_gpu_bytes,
    .prepare_stats = particles_prepare_stats,
    .export_ext = ".csv",
    .export_geometry = particles_export,
};
