/* tubes_nodes.h — Hermite nodes and segments for the `tubes` technique.
 *
 * A node carries position, radius and colour scalar, each with its derivative
 * with respect to the segment parameter t in [0, 1]; a segment is an index
 * pair (Russig et al., "GPU-based Raycasting of Hermite Spline Tubes", 3.1).
 * Nodes are built from any line set: one node per vertex, one segment per
 * consecutive vertex pair, tangents from the data when it gives them, else
 * Catmull-Rom finite differences (one-sided at line ends). Explicit Hermite
 * data ({"nodes":[...],"segments":[...]}, read by data/load_hermite.c) becomes a line set of two-vertex
 * lines that carries its tangents and derivatives exactly, so it flows
 * through every loader-facing path and the node builder gives the nodes back.
 * Does not touch GL; any thread. Positions stay relative to the dataset origin.
 */
#ifndef SL_TUBES_NODES_H
#define SL_TUBES_NODES_H

#include <stddef.h>
#include <stdint.h>

#include "../data/sl_dataset.h"

/* Floats per node in the geometry array: p.xyz, r, t.xyz, dr. */
#define SL_TUBES_NODE_FLOATS 8

typedef enum sl_tubes_tangents {
    /* Explicit Hermite data (it has SL_ATTR_RADIUS_DERIVATIVE): its tangents
     * exactly. Other data with tangents (e.g. a streamline's velocity, a
     * derivative in time, not along the segment): their direction, with the
     * length of the Catmull-Rom tangent. No tangents: Catmull-Rom. */
    SL_TUBES_TANGENTS_AUTO = 0,
    SL_TUBES_TANGENTS_CATMULL_ROM = 1, /* always finite differences of the positions */
    SL_TUBES_TANGENTS_DATA_EXACT = 2,  /* the data's tangents as they are (Catmull-Rom without) */
} sl_tubes_tangents;

typedef struct sl_tubes_nodes {
    size_t node_count, segment_count;
    float *geometry;     /* owned: SL_TUBES_NODE_FLOATS per node; r, dr = 0 when has_radii == 0 */
    float *color;        /* owned: 2 per node (c, dc); zeros without a colour attribute */
    uint32_t *segments;  /* owned: 2 per segment, node indices */
    int has_radii;       /* the data gave radii (else the `radius` parameter applies) */
    int color_attribute; /* per-vertex attribute in `color`, or -1 */
} sl_tubes_nodes;

/* Builds nodes and segments from a line set (colour from per-vertex
 * attribute `color_attribute`, or -1 for none). Lines with fewer than two
 * vertices give no segment. Fails with SL_ERR_LIMIT past 2^32 nodes, with
 * SL_ERR_NOMEM on allocation failure; *out is then zeroed. */
sl_status sl_tubes_nodes_build(const sl_lines *lines, sl_tubes_tangents tangents, int color_attribute,
                               sl_tubes_nodes *out, sl_err *err);

/* Takes the node radii from per-vertex attribute `radius_attribute` instead
 * of lines->radii: r = |value| (non-finite: 0) and dr from the attribute
 * "<name>_derivative" when the data has it, else Catmull-Rom finite
 * differences along each line (one-sided at the ends); sets has_radii.
 * -1 or an index the lines lack changes nothing. Needs out->geometry (call
 * before the geometry is freed). */
void sl_tubes_nodes_set_radii(const sl_lines *lines, int radius_attribute, sl_tubes_nodes *out);

/* Refills out->color from another attribute (-1: zeros). */
void sl_tubes_nodes_set_color(const sl_lines *lines, int color_attribute, sl_tubes_nodes *out);

void sl_tubes_nodes_deinit(sl_tubes_nodes *nodes); /* zeroed or NULL is fine */

#endif
