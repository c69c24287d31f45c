/* tubes_reference.h — CPU double-precision reference intersector for the `tubes` technique.
 *
 * The surface is, by definition, the union of spheres swept along the two
 * quadratic Bezier sub-segments of every Hermite segment (Russig et al. 3.2);
 * with `cubic` set it is the sweep along the true cubic Hermite curve instead
 * (to measure the quadratic approximation). Brute force: dense sampling of
 * the sweep parameter, then golden-section refinement of every local minimum
 * of the entry distance. Shares no code with the shader path (no ray space,
 * no root bracketing, de Casteljau in world coordinates). Single thread.
 */
#ifndef TUBES_REFERENCE_H
#define TUBES_REFERENCE_H

#include "core/sl_camera.h"
#include "tubes/tubes_nodes.h"

typedef struct tubes_ref_desc {
    const sl_view *view;          /* initialised view; eye and rays in world units */
    sl_vec3 origin;               /* dataset origin (node positions are relative to it) */
    const sl_tubes_nodes *nodes;
    double radius;                /* radius where the data gives none */
    double radius_scale;          /* factor on data radii */
    int cubic;                    /* 0: two quadratics per segment (the rendered surface); 1: cubic Hermite */
    int samples;                  /* samples of t per sub-segment (0: 512) */
} tubes_ref_desc;

/* Per pixel (rows top-down): Euclidean distance from the eye to the nearest
 * sphere entry beyond the near plane (0 = miss), the sweep radius there and
 * the segment index (-1 = miss). radius and segment may be NULL. */
void tubes_ref_render(const tubes_ref_desc *desc, float *distance, float *radius, int *segment);

#endif
