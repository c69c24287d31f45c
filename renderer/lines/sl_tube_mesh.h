/* sl_tube_mesh.h — CPU construction of swept-circle tube meshes (tubes_mesh, lines_oit).
 *
 * Rings around the BISECTOR tangents and transported normals of
 * sl_lines_prep.h; vertices carry unit offsets so the radius stays a uniform.
 * Does not upload anything. Any thread; no GL. */
#ifndef SL_TUBE_MESH_H
#define SL_TUBE_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "../data/sl_dataset.h"

/* One vertex: centre on the polyline, unit offset to the surface, unit
 * normal, data radius (< 0: none given), and the index of the source
 * vertex in the line set (to fetch attribute values at render time). */
typedef struct sl_tube_vertex {
    float centre[3], offset[3], normal[3];
    float radius;
    uint32_t source;
} sl_tube_vertex;

typedef struct sl_tube_mesh {
    sl_tube_vertex *vertices;
    uint32_t *indices;       /* triangles */
    size_t vertex_count, index_count;
    size_t tube_count;       /* polylines that produced geometry */
} sl_tube_mesh;

/* Sweeps a circle of `sides` vertices (3..64) along every polyline with a
 * rotation-minimizing frame, with flat caps when `caps`. Zero-length
 * segments are dropped (sl_lines_kept); polylines that collapse to a point
 * produce nothing. SL_ERR_INVALID (sides), SL_ERR_LIMIT (32-bit indices),
 * SL_ERR_NOMEM; *mesh is then zeroed. */
sl_status sl_tube_mesh_build(const sl_lines *lines, int sides, int caps,
                             sl_tube_mesh *mesh, sl_err *err);
void sl_tube_mesh_deinit(sl_tube_mesh *mesh);

#endif
