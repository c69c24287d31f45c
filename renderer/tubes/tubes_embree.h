/* tubes_embree.h — the CPU execution of `tubes`: the same Hermite nodes ray-traced with Embree 3.
 *
 * The model is the GL path's exactly: every Hermite segment split into the two quadratic
 * Bézier sub-segments of tubes.geom.glsl (positions, radii and colour scalars, computed
 * in float the same way), each the sweep of a sphere (the union of its spheres, end
 * spheres included). A sub-segment whose sweep has a smooth envelope (tubes_sweep.h) goes
 * to Embree as a RTC_GEOMETRY_TYPE_ROUND_BEZIER_CURVE (the quadratic degree-elevated),
 * with sphere points where an envelope ends (line ends, corners, bifurcations); any other
 * sub-segment, and any beside one, is a user primitive intersected exactly in double
 * (tubes_sweep.c). Embree sees curves and caps 2 % fatter, and every candidate it returns
 * is decided on the true sweep in double (Newton, else the exact search, hopping across
 * joints), candidates taken in turn until the next lies beyond the best entry: Embree's
 * float intersector drops grazing rays and cuts curves at their end planes (README.md).
 * A ray that starts inside the sweep sees the next entry beyond the near plane, as in the
 * GL path.
 *
 * One Embree device and scene per prepared dataset; the BVH is rebuilt only when the
 * radii change (a camera, colour or light change only traces). Frames are traced in
 * 16x16 tiles by sl_parallel_run (all cores, SIGHTLINE_THREADS overrides), 16-, 8- or
 * 4-ray packets of coherent primary rays (single rays for the candidates after the first),
 * shaded with sl_line_shade.h into an sl_host_frame. Built only with Embree (SL_HAVE_EMBREE); without it
 * sl_tubes_embree_available() is 0 and create fails. Render thread, except that the
 * tracing runs on the worker threads it starts.
 */
#ifndef SL_TUBES_EMBREE_H
#define SL_TUBES_EMBREE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/sl_camera.h"
#include "../core/sl_status.h"
#include "../gpu/sl_host_frame.h"
#include "../line_style/sl_line_shade.h"
#include "tubes_nodes.h"

typedef struct sl_tubes_embree sl_tubes_embree;

typedef struct sl_tubes_embree_stats {
    int builds;             /* BVH builds since create */
    double build_ms;        /* the last build: buffers + rtcCommitScene */
    double bvh_bytes;       /* bytes Embree holds (memory monitor) */
    size_t curves, spheres, exact; /* primitives of the last build by kind */
    int threads;            /* workers that traced tiles in the last frame */
    int packet;             /* rays per packet */
    double rays, refined, retraced; /* last frame: primary rays, hits refined in double, rays traced again */
    double trace_ms;        /* last frame: tracing and shading, all threads joined */
} sl_tubes_embree_stats;

/* 1 when this build has Embree. */
int sl_tubes_embree_available(void);

/* A device; the nodes are copied (geometry, segments, colour pointers need not outlive
 * the call except nodes->color, read at every render). SL_ERR_UNSUPPORTED without Embree,
 * naming the package. */
sl_status sl_tubes_embree_create(const sl_tubes_nodes *nodes, sl_tubes_embree **out, sl_err *err);
void sl_tubes_embree_destroy(sl_tubes_embree *e); /* NULL is fine */

/* Builds the BVH for these radii unless it holds them already (radius_scale applies to
 * data radii, radius where the data has none); *rebuilt_ms = the build's time, or 0. */
sl_status sl_tubes_embree_ensure(sl_tubes_embree *e, float radius, float radius_scale, double *rebuilt_ms,
                                 sl_err *err);

/* Traces view into frame (resized to the view) with node radii r * radius_scale (data
 * radii) or `radius` (has_radii 0); rebuilds the BVH first when those changed. colors:
 * 2 floats per node (scalar, its derivative), as nodes->color. *rebuilt_ms is the
 * build's time when this frame rebuilt, else 0. */
sl_status sl_tubes_embree_render(sl_tubes_embree *e, const sl_view *view, const sl_line_shader *shader,
                                 const float *colors, float radius, float radius_scale, sl_host_frame *frame,
                                 double *rebuilt_ms, sl_err *err);

void sl_tubes_embree_stats_get(const sl_tubes_embree *e, sl_tubes_embree_stats *out);

#endif
