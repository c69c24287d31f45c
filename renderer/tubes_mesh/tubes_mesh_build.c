/* tubes_mesh_build.c — swept-circle tessellation of polylines (see tubes_mesh_build.h).
 *
 * Frames are propagated by parallel transport (the normal is projected off
 * each new tangent), so tubes do not twist. Tangents at inner vertices are
 * the normalized sum of the unit directions of both adjacent segments, which
 * stays defined for sharp turns short of a full reversal (then the incoming
 * direction is used). Counts are checked before anything is allocated:
 * indices must fit in 32 bits.
 */
#include "tubes_mesh_build.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct v3f { float x, y, z; } v3f;

static v3f vsub(v3f a, v3f b) { return (v3f){a.x - b.x, a.y - b.y, a.z - b.z}; }
static v3f vadd(v3f a, v3f b) { return (v3f){a.x + b.x, a.y + b.y, a.z + b.z}; }
static v3f vscale(v3f a, float s) { return (v3f){a.x * s, a.y * s, a.z * s}; }
static float vdot(v3f a, v3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static v3f vcross(v3f a, v3f b) { return (v3f){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static float vlen(v3f a) { return sqrtf(vdot(a, a)); }
static v3f vnorm(v3f a) { float l = vlen(a); return l > 0.0f ? vscale(a, 1.0f / l) : (v3f){0, 0, 0}; }
static v3f load(const float *p) { return (v3f){p[0], p[1], p[2]}; }
static void store(float *o, v3f a) { o[0] = a.x; o[1] = a.y; o[2] = a.z; }

/* Any unit vector orthogonal to the unit vector t. */
static v3f any_orthogonal(v3f t)
{
    v3f axis = fabsf(t.x) < 0.6f ? (v3f){1, 0, 0} : (fabsf(t.y) < 0.6f ? (v3f){0, 1, 0} : (v3f){0, 0, 1});
    return vnorm(vcross(t, axis));
}

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
    m->vertices = malloc((max_vertices ? max_vertices : 1) * sizeof *m->vertices);
    m->indices = malloc((max_indices ? max_indices : 1) * sizeof *m->indices);
    size_t *kept = malloc((lines->vertex_count ? lines->vertex_count : 1) * sizeof *kept);
    if (!m->vertices || !m->indices || !kept) {
        free(kept);
        sl_tube_mesh_deinit(m);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for a tube mesh of %zu vertices", max_vertices);
    }
    const float cos_step = cosf(2.0f * (float)SL_PI / (float)sides), sin_step = sinf(2.0f * (float)SL_PI / (float)sides);

    for (size_t li = 0; li < lines->line_count; li++) {
        size_t first = lines->line_offsets[li], end = lines->line_offsets[li + 1];
        size_t n = 0;
        for (size_t v = first; v < end; v++) {
            if (n > 0 && vlen(vsub(load(&lines->positions[3 * v]), load(&lines->positions[3 * kept[n - 1]]))) == 0.0f)
                continue; /* zero-length segment */
            kept[n++] = v;
        }
        if (n < 2)
            continue;
        m->tube_count++;
        v3f normal = {0, 0, 0};
        size_t ring0 = m->vertex_count;
        for (size_t k = 0; k < n; k++) {
            v3f p = load(&lines->positions[3 * kept[k]]);
            v3f d_in = k > 0 ? vnorm(vsub(p, load(&lines->positions[3 * kept[k - 1]]))) : (v3f){0, 0, 0};
            v3f d_out = k + 1 < n ? vnorm(vsub(load(&lines->positions[3 * kept[k + 1]]), p)) : (v3f){0, 0, 0};
            v3f t = vnorm(vadd(d_in, d_out));
            if (vlen(t) < 1e-6f)
                t = k > 0 ? d_in : d_out;
            normal = k == 0 ? any_orthogonal(t) : vnorm(vsub(normal, vscale(t, vdot(normal, t))));
            if (vlen(normal) < 0.5f)
                normal = any_orthogonal(t);
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
    return SL_OK;
}
