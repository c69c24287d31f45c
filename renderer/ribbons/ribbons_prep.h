/* ribbons_prep.h — CPU preparation of the `ribbons` technique: frame choice and per-point packing.
 *
 * Resolves the `frame` parameter against what a dataset carries (auto: data
 * normals, else a per-vertex SL_ATTR_HELICITY attribute, else parallel
 * transport) and packs one entry per dataset vertex (1:1, plan §0) into the
 * three std430 vec4 arrays of the pulling pipeline (plan §1.3): position +
 * radius, normal + accumulated twist R = Σ ½(h_{i-1}+h_i) l_i (without the
 * twist_scale f, applied in the shader), tangent + dR/ds. Everything is built
 * on the shared line preparation (lines/sl_lines_prep.h). No GL; any thread.
 * Paper: Neuhauser et al., Sec. 3.1 (frames), Sec. 4 (Eqs. 6-7, the twist sum).
 */
#ifndef SL_RIBBONS_PREP_H
#define SL_RIBBONS_PREP_H

#include <stddef.h>

#include "../core/sl_status.h"
#include "../data/sl_dataset.h"

/* The order of the `frame` enum of the schema. */
typedef enum sl_ribbons_frame {
    SL_RIBBONS_FRAME_AUTO,
    SL_RIBBONS_FRAME_TRANSPORT,
    SL_RIBBONS_FRAME_HELICITY,
    SL_RIBBONS_FRAME_DATA,
} sl_ribbons_frame;

/* |R| never exceeds this (float phase error about 1e-1 rad at the bound; README). */
#define SL_RIBBONS_TWIST_LIMIT 1e6

/* The frame used for `choice` on ds (never AUTO). SL_ERR_INVALID naming the
 * dataset when `data` is asked without per-vertex normals or `helicity`
 * without a helicity attribute; *out is then TRANSPORT. */
sl_status sl_ribbons_frame_resolve(const sl_dataset *ds, sl_ribbons_frame choice, sl_ribbons_frame *out,
                                   sl_err *err);

/* The three arrays (owned; 4 floats per dataset vertex each). */
typedef struct sl_ribbons_points {
    size_t count;            /* dataset vertices */
    float *pos_radius;       /* xyz relative to the origin; w: radius, or -1 (use the `radius` uniform) */
    float *normal_twist;     /* xyz: unit face normal n ⊥ t; w: R (0 without helicity) */
    float *tangent_slope;    /* xyz: unit tangent (0 on a collapsed line); w: dR/ds */
    sl_ribbons_frame frame;  /* as resolved */
    size_t normal_fallbacks; /* data frame: vertices whose normal was unusable (transport instead) */
} sl_ribbons_points;

/* Fills *out for frame (resolved, not AUTO). radius_attribute >= 0: radii are
 * |attribute| (sl_lines_attribute_radii); else the data's radii, else -1.
 * Helicity, when the dataset has it, gives R under every frame (twist lines
 * work on transport too); non-finite h counts 0 and |R| is clamped to
 * SL_RIBBONS_TWIST_LIMIT. SL_ERR_NOMEM with *out zeroed. */
sl_status sl_ribbons_points_init(sl_ribbons_points *out, const sl_lines *l, sl_ribbons_frame frame,
                                 int radius_attribute, sl_err *err);

void sl_ribbons_points_deinit(sl_ribbons_points *p); /* zeroed or half-built is fine */

#endif
