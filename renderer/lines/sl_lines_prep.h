/* sl_lines_prep.h — the CPU line preparation every line technique shares.
 *
 * Tangents, rotation-minimizing normals, given normals made orthogonal to the
 * tangent, radii from an attribute, trapezoid sums along lines, chunks of
 * consecutive segments with bounding boxes, a frustum test for such boxes and
 * the positions' bounds. All work on a dataset's sl_lines, read positions
 * relative to the dataset origin and write caller-owned arrays of
 * vertex_count entries (3 floats per vertex for vectors), one entry per
 * dataset vertex. A segment is "zero-length" when its float length is 0 (the
 * tubes_mesh rule, sl_lines_kept). Any thread; no GL; does not allocate
 * except sl_lines_chunks_build.
 */
#ifndef SL_LINES_PREP_H
#define SL_LINES_PREP_H

#include <stddef.h>
#include <stdint.h>

#include "../core/sl_camera.h"
#include "../data/sl_dataset.h"

typedef enum sl_lines_tangent_rule {
    SL_LINES_TANGENT_BISECTOR,    /* unit normalize(d_in + d_out) over kept vertices; a reversal takes d_in */
    SL_LINES_TANGENT_CATMULL_ROM, /* (x[i+1] - x[i-1]) / 2 over all vertices, one-sided at ends (not unit) */
} sl_lines_tangent_rule;

/* The vertices of line `line` that start no zero-length segment: a vertex is
 * kept when it is the line's first or its distance to the last kept vertex
 * is not 0. Writes their indices to kept (room for the line's vertex count)
 * and returns how many; a line of n kept vertices has n - 1 drawable
 * segments. */
size_t sl_lines_kept(const sl_lines *l, size_t line, size_t *kept);

/* Tangents, 3 floats per vertex. BISECTOR: at kept vertices as the rule says
 * (end vertices: their one segment's direction); a vertex dropped by
 * sl_lines_kept copies the tangent of the kept vertex it coincides with; a
 * line that collapses to one point gets (0,0,0). CATMULL_ROM: the
 * finite-difference derivative per segment parameter at every vertex
 * (tubes' Hermite nodes), (0,0,0) on one-vertex lines. Returns the number of
 * drawable (non-zero-length) segments. */
size_t sl_lines_tangents(const sl_lines *l, sl_lines_tangent_rule rule, float *t3);

/* Rotation-minimizing normals by projection transport along BISECTOR
 * tangents t3: n0 = normalize(seed3[first] projected off t0) (seed3 NULL,
 * non-finite, or parallel to t0: any vector orthogonal to t0), then n_k =
 * normalize(n_{k-1} - t_k (n_{k-1}.t_k)), re-seeded the same way when that
 * projection vanishes. Dropped vertices copy the normal of their kept
 * vertex; lines without a segment get (1,0,0). Unit and orthogonal to t3
 * wherever t3 is non-zero. */
void sl_lines_transport_normals(const sl_lines *l, const float *t3, const float *seed3, float *n3);

/* Given normals (3 per vertex) projected off t3, normalized and
 * sign-aligned to the previous point of the line (a negative dot product
 * flips). Where the given normal is non-finite or its projection is shorter
 * than 1e-3 of its length (parallel to the tangent), the transported
 * previous normal continues instead (any orthogonal vector at a line's
 * start). Returns how many vertices fell back. */
size_t sl_lines_project_normals(const sl_lines *l, const float *t3, const float *given3, float *n3);

/* out[i * stride] = |value of per-vertex attribute `attribute` at vertex i|,
 * non-finite -> 0 (the radius rule of tubes_mesh and tubes). attribute must
 * be a valid per-vertex index; stride >= 1. */
void sl_lines_attribute_radii(const sl_lines *l, int attribute, float *out, size_t stride);

/* Trapezoid sums along each line, in double: out[first] = 0, out[i] =
 * out[i-1] + (v[i-1] + v[i]) / 2 * |x[i] - x[i-1]| (values NULL: v = 1, the
 * arc length), non-finite v counted as 0, every partial sum clamped to
 * [-limit, limit] (limit > 0; INFINITY: no clamp). d_ds (NULL: not wanted)
 * gets d(out)/ds by central differences over arc length s (one-sided at the
 * ends, 0 where the arc length does not change). */
void sl_lines_accumulate(const sl_lines *l, const float *values, double limit, float *out, float *d_ds);

/* max_segments consecutive segments of one line (never across lines); the
 * chunk's points are first_point .. first_point + segments. lo/hi: their
 * bounding box relative to the dataset origin. */
typedef struct sl_line_chunk {
    uint32_t first_point, segments, line;
    float lo[3], hi[3];
} sl_line_chunk;

/* Chunks of at most max_segments (>= 1) segments over every line with at
 * least two vertices, in line order; zero-length segments are kept (one
 * chunk point per dataset vertex). *out is owned by the caller (free; NULL
 * with *count 0 when there is no segment). SL_ERR_INVALID for max_segments
 * 0, SL_ERR_NOMEM; *out and *count are then NULL and 0. */
sl_status sl_lines_chunks_build(const sl_lines *l, uint32_t max_segments, sl_line_chunk **out, size_t *count,
                                sl_err *err);

/* Whether the box origin + [lo - grow, hi + grow] (world) may be seen by
 * view: 0 when all its corners lie outside one of the four side planes or
 * in front of the near plane, else 1 (conservative: boxes near a frustum
 * corner may be reported visible). In double. */
int sl_lines_box_visible(const sl_view *view, sl_vec3 origin, const float lo[3], const float hi[3], double grow);

/* Bounding box of the positions (relative to the origin, without radii), in
 * double; (0,0,0) for both when there are no vertices. */
void sl_lines_position_bounds(const sl_lines *l, double lo[3], double hi[3]);

#endif
