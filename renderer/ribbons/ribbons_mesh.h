/* ribbons_mesh.h — the ring topology of every ribbons pipeline and the static CPU mesh of `pipeline = mesh`.
 *
 * Topology (shared by the u16 chunk patterns of pulling/geometry/flat and
 * the mesh): the quads between two rings of N vertices, in the order of
 * tubes_mesh_build (a+j, a+j1, c+j, c+j, a+j1, c+j1; CCW from outside since
 * n x b = t), and the flat elliptic cap fans (start cap faces -t).
 *
 * The mesh (plan §3.3, the paper's memory-hungry comparison): N vertices per
 * dataset point (index point * N + j), each a copy of the point's three
 * packed vec4 (ribbons_prep.h) plus the point and ring slot, so the vertex
 * shader still applies width_ratio, min_thickness, min_pixels, radius and
 * the helicity rotation as uniforms. u32 indices in chunk order: per chunk
 * its mantle, then its start cap, then its end cap, so a chunk is one
 * contiguous index range (culling draws ranges). Counts are checked before
 * anything is allocated (vertices and indices below 2^32 - 1). CPU, any
 * thread, no GL.
 */
#ifndef SL_RIBBONS_MESH_H
#define SL_RIBBONS_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "ribbons_prep.h"
#include "../lines/sl_lines_prep.h"

/* Chunk cap bits: the chunk starts / ends its line. */
#define SL_RIBBONS_CAP_START 1u
#define SL_RIBBONS_CAP_END 2u
unsigned sl_ribbons_chunk_caps(const sl_lines *l, const sl_line_chunk *ch);

/* Writes the 6 * columns indices of the quads between the rings starting at
 * vertex a and c (ring slots j and j + 1 mod N for j < columns; columns = N
 * closes the ring, N - 1 leaves an open strip). Returns the count written. */
size_t sl_ribbons_quad_indices(uint32_t a, uint32_t c, int N, int columns, uint32_t *out);
/* Writes the 3 (N - 2) indices of the cap fan of the ring at vertex ring;
 * end = 0: the start cap (faces -t), 1: the end cap. Returns the count. */
size_t sl_ribbons_cap_indices(uint32_t ring, int N, int end, uint32_t *out);

typedef struct sl_ribbons_mesh_vertex {
    float pos_radius[4], normal_twist[4], tangent_slope[4]; /* the point's (ribbons_prep.h) */
    uint32_t point, slot;                                    /* dataset vertex, ring slot j */
} sl_ribbons_mesh_vertex;                                    /* 56 bytes */

typedef struct sl_ribbons_mesh {
    sl_ribbons_mesh_vertex *vertices; /* owned; points * N */
    size_t vertex_count;
    uint32_t *indices;                /* owned */
    size_t index_count;
    size_t *chunk_first;              /* owned; per chunk the first index of its mantle (caps follow) */
} sl_ribbons_mesh;

/* Builds the mesh of pts over chunks (sl_lines_chunks_build of l) for
 * 3 <= sides <= 32. SL_ERR_LIMIT (naming the counts) when the vertices or
 * indices do not fit 32 bits, SL_ERR_INVALID for bad sides, SL_ERR_NOMEM;
 * *out is zeroed on failure. */
sl_status sl_ribbons_mesh_build(const sl_ribbons_points *pts, const sl_lines *l, const sl_line_chunk *chunks,
                                size_t chunk_count, int sides, sl_ribbons_mesh *out, sl_err *err);

void sl_ribbons_mesh_deinit(sl_ribbons_mesh *m); /* zeroed or half-built is fine */

#endif
