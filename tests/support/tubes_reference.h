/* tubes_reference.h — CPU double-precision reference intersector for the `tubes` technique.
 *
 * The surface is, by definition, the union of spheres swept along the two
 * quadratic Bezier sub-segments of every Hermite segment (Russig et al. 3.2);
 * with `cubic` set it is the sweep along the true cubic Hermite curve instead
 * (to measure the quadratic approximation). Brute force: dense sampling of
 * the sweep parameter, then golden-section refinement of every local minimum
 * of the entry distance. Shares no code with the shader path (no ray space,
 * no root bracketing, de Casteljau in world coordinates). Its input is its
 * own list of Hermite segments in double (tubes_reference_input.h builds it
 * from the scene's JSON or the loaded polylines, not through the renderer's
 * node builder). Single thread.
 */
#ifndef TUBES_REFERENCE_H
#define TUBES_REFERENCE_H

#include <stddef.h>

#include "core/sl_camera.h"

/* One Hermite segment: positions and their derivatives along the segment
 * parameter t in [0, 1], relative to tubes_ref_desc.origin; the radius and
 * its derivative (final: any radius scale already applied). */
typedef struct tubes_ref_segment {
    sl_vec3 p0, t0, p1, t1;
    double r0, dr0, r1, dr1;
} tubes_ref_segment;

typedef struct tubes_ref_desc {
    const sl_view *view;          /* initialised view; eye and rays in world units */
    sl_vec3 origin;               /* world position the segment coordinates are relative to */
    const tubes_ref_segment *segments;
    size_t segment_count;
    int cubic;                    /* 0: two quadratics per segment (the rendered surface); 1: cubic Hermite */
    int samples;                  /* cap on samples of t per piece (0: 8192); a piece takes 16 + 16 x its
                                     control-polygon length / its smallest radius (see piece_samples) */
} tubes_ref_desc;

/* Per pixel (rows top-down): Euclidean distance from the eye to the nearest
 * sphere entry beyond the near plane (0 = miss), the sweep radius there and
 * the segment index (-1 = miss). radius and segment may be NULL. */
void tubes_ref_render(const tubes_ref_desc *desc, float *distance, float *radius, int *segment);

/* 1 when pixel (i, j) of a reference distance map (w x h, rows top-down,
 * 0 = miss) is at a silhouette: within its 3x3 neighbourhood the coverage
 * changes, or the distance jumps by more than the local radius rad[] (one tube
 * in front of another, even of the same segment). A joint between two
 * segments of one tube is not a silhouette (the distance is continuous). */
int tubes_ref_silhouette(const float *distance, const float *rad, int w, int h, int i, int j);

#endif
