/* ribbons_mesh.c — ring topology and the static mesh of `pipeline = mesh` (see ribbons_mesh.h).
 *
 * Limits are checked from the raw counts before anything is allocated.
 * CPU, any thread, no GL.
 */
#include "ribbons_mesh.h"

#include <stdlib.h>
#include <string.h>

unsigned sl_ribbons_chunk_caps(const sl_lines *l, const sl_line_chunk *ch)
{
    unsigned caps = 0;
    if (ch->first_point == l->line_offsets[ch->line])
        caps |= SL_RIBBONS_CAP_START;
    if (ch->first_point + ch->segments + 1 == l->line_offsets[ch->line + 1])
        caps |= SL_RIBBONS_CAP_END;
    return caps;
}

size_t sl_ribbons_quad_indices(uint32_t a, uint32_t c, int N, int columns, uint32_t *out)
{
    size_t k = 0;
    for (int j = 0; j < columns; j++) {
        uint32_t j0 = (uint32_t)j, j1 = (uint32_t)(j + 1) % (uint32_t)N;
        const uint32_t quad[6] = {a + j0, a + j1, c + j0, c + j0, a + j1, c + j1};
        for (int q = 0; q < 6; q++)
            out[k++] = quad[q];
    }
    return k;
}

size_t sl_ribbons_cap_indices(uint32_t ring, int N, int end, uint32_t *out)
{
    size_t k = 0;
    for (uint32_t j = 1; j + 1 < (uint32_t)N; j++) {
        out[k++] = ring;
        out[k++] = ring + (end ? j : j + 1);
        out[k++] = ring + (end ? j + 1 : j);
    }
    return k;
}

void sl_ribbons_mesh_deinit(sl_ribbons_mesh *m)
{
    free(m->vertices);
    free(m->indices);
    free(m->chunk_first);
    memset(m, 0, sizeof *m);
}

sl_status sl_ribbons_mesh_build(const sl_ribbons_points *pts, const sl_lines *l, const sl_line_chunk *chunks,
                                size_t chunk_count, int sides, sl_ribbons_mesh *out, sl_err *err)
{
    memset(out, 0, sizeof *out);
    if (sides < 3 || sides > 32)
        return sl_err_set(err, SL_ERR_INVALID, "ribbons mesh: sides must be in [3, 32], got %d", sides);
    const size_t N = (size_t)sides, cap = 3 * (N - 2);
    size_t vertices = pts->count * N, indices = 0;
    for (size_t c = 0; c < chunk_count; c++) {
        unsigned caps = sl_ribbons_chunk_caps(l, &chunks[c]);
        indices += 6 * N * chunks[c].segments + cap * ((caps & 1u) + (caps >> 1));
    }
    if (vertices >= UINT32_MAX || indices >= UINT32_MAX)
        return sl_err_set(err, SL_ERR_LIMIT,
                          "ribbons mesh of %zu vertices and %zu indices does not fit 32-bit indices; lower 'sides' "
                          "or use pipeline pulling", vertices, indices);
    out->vertices = malloc((vertices ? vertices : 1) * sizeof *out->vertices);
    out->indices = malloc((indices ? indices : 1) * sizeof *out->indices);
    out->chunk_first = malloc((chunk_count ? chunk_count : 1) * sizeof *out->chunk_first);
    if (!out->vertices || !out->indices || !out->chunk_first) {
        sl_ribbons_mesh_deinit(out);
        return sl_err_set(err, SL_ERR_NOMEM, "ribbons mesh: out of memory for %zu vertices and %zu indices",
                          vertices, indices);
    }
    for (size_t i = 0; i < pts->count; i++)
        for (size_t j = 0; j < N; j++) {
            sl_ribbons_mesh_vertex *v = &out->vertices[i * N + j];
            memcpy(v->pos_radius, &pts->pos_radius[4 * i], sizeof v->pos_radius);
            memcpy(v->normal_twist, &pts->normal_twist[4 * i], sizeof v->normal_twist);
            memcpy(v->tangent_slope, &pts->tangent_slope[4 * i], sizeof v->tangent_slope);
            v->point = (uint32_t)i;
            v->slot = (uint32_t)j;
        }
    out->vertex_count = vertices;
    size_t k = 0;
    for (size_t c = 0; c < chunk_count; c++) {
        const sl_line_chunk *ch = &chunks[c];
        out->chunk_first[c] = k;
        for (uint32_t s = 0; s < ch->segments; s++) {
            uint32_t a = (ch->first_point + s) * (uint32_t)N;
            k += sl_ribbons_quad_indices(a, a + (uint32_t)N, sides, sides, out->indices + k);
        }
        unsigned caps = sl_ribbons_chunk_caps(l, ch);
        if (caps & SL_RIBBONS_CAP_START)
            k += sl_ribbons_cap_indices(ch->first_point * (uint32_t)N, sides, 0, out->indices + k);
        if (caps & SL_RIBBONS_CAP_END)
            k += sl_ribbons_cap_indices((ch->first_point + ch->segments) * (uint32_t)N, sides, 1, out->indices + k);
    }
    out->index_count = k;
    return SL_OK;
}
