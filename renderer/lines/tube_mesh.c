/* tube_mesh.c — swept-circle tessellation of polylines (see sl_tube_mesh.h).
 *
 * Tangents and frames come from sl_lines_prep.h (bisector tangents,
 * projection transport: tubes do not twist); this file places the rings,
 * their triangles and the caps. Counts are checked before anything is
 * allocated: indices must fit in 32 bits. Any thread; no GL.
 */
#include "sl_tube_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lines_v3f.h"
#include "sl_lines_prep.h"

void sl_tube_mesh_deinit(sl_tube_mesh *m)
{
    free(m->vertices);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

sl_status sl_tube_mesh_build(const sl_lines *lines, int sides, int caps,
                             sl_tube_mesh *m, sl_err *err)
{
    memset(m, 0, sizeof *m);
    if (sides < 3 || sides > 64)
        return sl_err_set(err, SL_ERR_INVALID, "tube sides must be in [3, 64], got %d", sides);
    /* Upper bounds from the raw counts (duplicates only lower them). */
    size_t rings = lines->vertex_count;
    size_t max_vertices = rings * (size_t)sides + lines->line_count * (size_t)(caps ? 2 * (sides + 1) : 0);
    size_t max_indices = (rings ? rings : 1) * (size_t)sides * 6 + lines->line_count * (size_t)(caps ? 6 * sides : 0);
    if (max_vertices >= UINT32_MAX || max_indices >= (size_t)1 << 31)
        return sl_err_set(err, SL_ERR_LIMIT, "tube mesh of %zu vertices and %zu indices is too large; lower 'sides'",
                          max_vertices, max_indices);
    size_t nv = lines->vertex_count ? lines->vertex_count : 1;
    m->vertices = malloc((max_vertices ? max_vertices : 1) * sizeof *m->vertices);
    m->indices = malloc((max_indices ? max_indices : 1) * sizeof *m->indices);
    size_t *kept = malloc(nv * sizeof *kept);
    float *t3 = malloc(nv * 3 * sizeof *t3), *n3 = malloc(nv * 3 * sizeof *n3);
    if (!m->vertices || !m->indices || !kept || !t3 || !n3) {
        free(kept);
        free(t3);
        free(n3);
        sl_tube_mesh_deinit(m);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for a tube mesh of %zu vertices", max_vertices);
    }
    sl_lines_tangents(lines, SL_LINES_TANGENT_BISECTOR, t3);
    sl_lines_transport_normals(lines, t3, NULL, n3);
    const float cos_step = cosf(2.0f * (float)SL_PI / (float)sides), sin_step = sinf(2.0f * (float)SL_PI / (float)sides);

    for (size_t li = 0; li < lines->line_count; li++) {
        size_t n = sl_lines_kept(lines, li, kept);
        if (n < 2)
            continue;
        m->tube_count++;
        size_t ring0 = m->vertex_count;
        for (size_t k = 0; k < n; k++) {
            v3f p = load(&lines->positions[3 * kept[k]]);
            v3f t = load(&t3[3 * kept[k]]), normal = load(&n3[3 * kept[k]]);
            v3f binormal = vcross(t, normal);
            float radius = lines->radii ? lines->radii[kept[k]] : -1.0f;
            float c = 1.0f, s = 0.0f;
            for (int j = 0; j < sides; j++) {
                v3f dir = vadd(vscale(normal, c), vscale(binormal, s));
                sl_tube_vertex *out = &m->vertices[m->vertex_count++];
                store(out->centre, p);
                store(out->offset, dir);
                store(out->normal, dir);
                out->radius = radius;
                out->source = (uint32_t)kept[k];
                float c2 = c * cos_step - s * sin_step;
                s = c * sin_step + s * cos_step;
                c = c2;
            }
            if (k > 0) {
                uint32_t a = (uint32_t)(ring0 + (k - 1) * (size_t)sides), b = (uint32_t)(ring0 + k * (size_t)sides);
                for (int j = 0; j < sides; j++) {
                    uint32_t j1 = (uint32_t)((j + 1) % sides);
                    uint32_t *ix = &m->indices[m->index_count];
                    ix[0] = a + (uint32_t)j; ix[1] = a + j1; ix[2] = b + (uint32_t)j;
                    ix[3] = b + (uint32_t)j; ix[4] = a + j1; ix[5] = b + j1;
                    m->index_count += 6;
                }
            }
        }
        if (!caps)
            continue;
        for (int end_cap = 0; end_cap < 2; end_cap++) {
            size_t k = end_cap ? n - 1 : 0;
            size_t ring = ring0 + k * (size_t)sides;
            v3f p = load(&lines->positions[3 * kept[k]]);
            v3f t = end_cap ? vnorm(vsub(p, load(&lines->positions[3 * kept[n - 2]])))
                            : vnorm(vsub(p, load(&lines->positions[3 * kept[1]])));
            uint32_t centre = (uint32_t)m->vertex_count;
            sl_tube_vertex cv = m->vertices[ring];
            store(cv.offset, (v3f){0, 0, 0});
            store(cv.normal, t);
            m->vertices[m->vertex_count++] = cv;
            for (int j = 0; j < sides; j++) {
                sl_tube_vertex rv = m->vertices[ring + (size_t)j];
                store(rv.normal, t);
                m->vertices[m->vertex_count++] = rv;
            }
            for (int j = 0; j < sides; j++) {
                uint32_t *ix = &m->indices[m->index_count];
                ix[0] = centre;
                ix[1] = centre + 1 + (uint32_t)j;
                ix[2] = centre + 1 + (uint32_t)((j + 1) % sides);
                m->index_count += 3;
            }
        }
    }
    free(kept);
    free(t3);
    free(n3);
    return SL_OK;
}
