/* lines_reference.h — CPU double-precision reference for transparent tubes
 * around polylines: the exact tube crossings of every ray, sorted and
 * composited front to back.
 *
 * The tube of a polyline is, by definition, the union of the capsules
 * (cylinder + end spheres, radius r) of its segments — what the line
 * techniques draw, up to their own approximations (tubes_mesh's polygon
 * rings and open ends, voxel_lines' quantized endpoints). Along a ray every
 * maximal interval inside one polyline's tube is one crossing and is blended
 * once, at its entry on the tube's surface: colour = two-sided Blinn-Phong (ambient + diffuse ×
 * N·L, specular (N·H)^shininess) of the curve's colour at the exact entry
 * normal, opacity `opacity`. The crossings of all polylines are sorted by
 * eye distance along the view direction and blended front to back
 * (premultiplied) over the background until alpha reaches `alpha_stop`.
 *
 * A curved polyline that crosses one ray twice is two crossings; two
 * segments of one polyline overlapping at a joint are one. Brute force over
 * every segment (a per-polyline bounding box skips rays that miss it), in
 * double; shares no code with the renderers besides the camera's pixel-ray
 * formula (sl_view_ray_dir). Limits: O(pixels × segments of the polylines a
 * ray's box test passes) — meant for test-sized frames (≤ 320×240, ≤ 10^4
 * segments). The eye must be outside every tube. Single thread.
 */
#ifndef LINES_REFERENCE_H
#define LINES_REFERENCE_H

#include <stddef.h>
#include <stdint.h>

#include "core/sl_camera.h"
#include "data/sl_dataset.h"

typedef struct lines_ref_desc {
    const sl_view *view;        /* initialised view (rays, near plane, background) */
    const sl_dataset *lines;    /* SL_DATASET_LINES; world = origin + position */
    double radius;              /* tube radius, world units, > 0 */
    const float *curve_rgb;     /* 3 per polyline, 0..1 (linear, as the techniques blend) */
    double opacity;             /* per crossing, 0..1 */
    double alpha_stop;          /* stop once alpha >= this (1: blend everything) */
    double light_eye[3];        /* unit light direction: x R + y U - z F (line_style's convention) */
    double ambient, diffuse, specular, shininess;
    int open_ends;              /* 1: no sphere at a polyline's first and last vertex (an open tube,
                                   as mesh tubes without caps): a ray entering through the end disk
                                   blends nothing there */
} lines_ref_desc;

typedef struct lines_ref_stats {
    size_t pixels_hit;          /* pixels with at least one crossing */
    size_t crossings;           /* over all pixels */
    size_t max_crossings;       /* of one pixel */
    size_t repeat_crossings;    /* crossings of a polyline that already crossed that pixel's ray */
} lines_ref_stats;

/* Renders desc into rgba (width × height × 4, rows top-down, RGBA8, alpha
 * = 255). stats may be NULL. Returns 0, or -1 on bad input or no memory. */
int lines_ref_render(const lines_ref_desc *desc, uint8_t *rgba, lines_ref_stats *stats);

#endif
