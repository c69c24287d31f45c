/* ribbons_depth_error.h — a renderer's depth image of one straight elliptic ribbon against the analytic profile.
 *
 * Per pixel, the ray of proto/scene.md (ref_camera, double) against
 * ribbons_ref_ray_ellipse: |error| / r over the pixels both hit (max, mean,
 * max over near-head-on mantle pixels), and on every pixel where the ray
 * enters the mantle with a finite N-gon bound (ribbons_ref_polygon_bound)
 * the prism's depth must lie in [t_ref - eps, t_ref + bound + eps] (the
 * inscribed prism is never in front); a ray through the inner cap (inside
 * the inscribed polygon) must meet the cap's depth within eps. Coverage: a
 * ray entering the profile shrunk to the polygon's incircle ellipse (radii x
 * cos(pi/N)) must hit, one missing the profile must miss, both with a margin
 * of margin_px pixels (rasterization of edges through pixel centres).
 * Shared by bench-ribbons (run time against error) and ribbons-depth-check
 * (the render test). Limits: one segment, camera outside it. Any thread.
 */
#ifndef RIBBONS_DEPTH_ERROR_H
#define RIBBONS_DEPTH_ERROR_H

#include <stddef.h>

#include "ref_camera.h"
#include "ribbons_reference.h"

typedef struct ribbons_depth_limits {
    int sides;            /* N of the rendered ring (the bound) */
    double head_on_cos;   /* circle-space incidence cosine of "near head-on", e.g. 0.9 */
    double eps;           /* world distance allowed for float depth, e.g. 1e-4 */
    double margin_px;     /* coverage margin in pixels, e.g. 1/64 */
} ribbons_depth_limits;

typedef struct ribbons_depth_error {
    size_t ref_hits, gpu_hits, both;
    double max_err, mean_err;   /* |t_gpu - t_ref| / r over `both` */
    double max_head_on;         /* the same over mantle pixels with cos_in >= head_on_cos */
    size_t checked;             /* pixels held to the bound (mantle with a finite bound, inner cap) */
    double max_bound;           /* largest bound / r met on those */
    double max_over_bound;      /* max (t_gpu - t_ref) / bound over the mantle pixels checked */
    size_t outside_bound;       /* checked pixels outside [t_ref - eps, t_ref + bound + eps] */
    size_t missed;              /* inside the incircle profile, nothing drawn */
    size_t spurious;            /* drawn where the ray misses the profile */
    size_t mismatch;            /* any pixel where exactly one of the two hits */
    int bad_i, bad_j;           /* the first pixel outside the bound or the coverage rules; -1 none */
    double bad_gpu, bad_ref, bad_bound; /* its distances and bound (world) */
} ribbons_depth_error;

/* distance: width x height eye distances, row 0 at the top, 0 = nothing
 * (sl_pipeline_read_distance, sightline-render --depth). Returns 0, or -1 on
 * bad input (seg or limits). */
int ribbons_depth_error_measure(const float *distance, const ref_camera *cam, const ribbons_ref_segment *seg,
                                const ribbons_depth_limits *limits, ribbons_depth_error *out);

#endif
