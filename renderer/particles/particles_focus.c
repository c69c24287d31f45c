/* particles_focus.c — focus + context of `particles` (particles_focus.h).
 *
 * The depth model: the marks are drawn first with depth GREATER (reversed-Z)
 * and writes on; their depth is copied into a texture (gpu/sl_depth_copy.h:
 * the marcher must not read the attachment it writes; with MSAA the nearest
 * mark among each pixel's samples). The marcher's ray interval inside the
 * sphere and the box ends at the mark's eye distance, its premultiplied
 * colour is blended (ONE, ONE_MINUS_SRC_ALPHA) over the target, and it
 * writes max(mark, its own A > 0.5 depth): a mark in front of the sphere
 * keeps its pixel byte for byte, one behind it is covered as much as the
 * volume's opacity says. With MSAA the marcher still shades once per pixel
 * for all its samples: a pixel holding any mark in front of the sphere stays
 * byte-equal to the marks alone, at the price of no volume in the uncovered
 * samples of such a rim pixel.
 */
#include "particles_focus.h"

#include <string.h>

void pt_focus_init(pt_focus *f, const sl_volume *data, const sl_volume_texture *volume,
                   const sl_volume_geometry *geom)
{
    memset(f, 0, sizeof *f);
    f->data = data;
    f->volume = volume;
    f->geom = geom;
}

void pt_focus_deinit(pt_focus *f)
{
    if (!f)
        return;
    sl_depth_copy_deinit(&f->depth);
    if (f->ready) {
        sl_volume_marcher_deinit(&f->marcher);
        sl_volume_bricks_destroy(&f->bricks);
    }
    f->ready = 0;
}

size_t pt_focus_bytes(const pt_focus *f)
{
    if (!f->ready)
        return 0;
    return f->bricks.bytes + f->marcher.bytes + sl_depth_copy_bytes(&f->depth);
}

/* The bricks and the marcher, once (the marcher compiles its plain program
 * at init and the focus variant at its first draw). */
static sl_status ensure_ready(pt_focus *f, sl_err *err)
{
    if (f->ready)
        return SL_OK;
    sl_status st = sl_volume_bricks_create(f->data, &f->bricks, err);
    if (st != SL_OK)
        return st;
    if ((st = sl_volume_marcher_init(&f->marcher, f->data, err)) != SL_OK) {
        sl_volume_bricks_destroy(&f->bricks);
        return st;
    }
    f->ready = 1;
    return SL_OK;
}

sl_status pt_focus_draw(pt_focus *f, const sl_view *view, const sl_params *params, const sl_target *target,
                        sl_render_stats *stats, sl_err *err)
{
    double radius = sl_params_float(params, "focus_radius");
    if (!(radius > 0.0))
        return SL_OK;
    sl_status st = ensure_ready(f, err);
    if (st == SL_OK)
        st = sl_depth_copy_update(&f->depth, target, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "particles: focus");
        return st;
    }
    glViewport(0, 0, view->width, view->height);
    float centre[3], light[3];
    sl_params_vec3(params, "focus_center", centre);
    sl_params_vec3(params, "light_direction", light);
    /* volume_dvr's defaults for what the focus has no parameter of. */
    sl_volume_march_desc d = {
        .mode = SL_VOLUME_MARCH_COMPOSITE,
        .tf = sl_params_transfer(params, "focus_transfer_function"),
        .step = sl_params_float(params, "focus_step"),
        .jitter = 1,
        .clip = 0,
        .light_dir = {light[0], light[1], light[2]},
        .focus = {.centre = {centre[0], centre[1], centre[2]}, .radius = radius, .opaque_depth_tex = f->depth.texture},
    };
    sl_render_stats ms = {0};
    if ((st = sl_volume_marcher_draw(&f->marcher, f->volume, &f->bricks, f->geom, view, &d, &ms, err)) != SL_OK) {
        sl_err_prefix(err, "particles: focus");
        return st;
    }
    glBindTextureUnit(6, 0);
    stats->samples += ms.samples;
    stats->samples_skipped += ms.samples_skipped;
    return SL_OK;
}
