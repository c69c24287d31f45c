/* test_ribbons_mesh.c — ring topology and the static mesh of `ribbons` pipeline mesh (renderer/ribbons/ribbons_mesh.h).
 *
 * The quad order (tubes_mesh's: diagonal a_j+1 - c_j) and the cap fans'
 * orientation; on a generated tornado (12 lines, 3 and more chunks per line
 * at K = 16) the mesh holds N copies of every point with its point and slot,
 * every chunk's indices form one contiguous range [mantle | start cap | end
 * cap] whose vertices are the chunk's own points, and the ranges tile the
 * index buffer; the 32-bit limit and bad sides are refused before anything
 * is allocated.
 */
#include <stdlib.h>
#include <string.h>

#include "sl_test.h"
#include "data/sl_generate.h"
#include "ribbons/ribbons_mesh.h"

static void test_topology(void)
{
    uint32_t idx[6 * 4];
    SL_CHECK(sl_ribbons_quad_indices(10, 14, 4, 4, idx) == 24);
    const uint32_t first[6] = {10, 11, 14, 14, 11, 15};
    SL_CHECK(memcmp(idx, first, sizeof first) == 0);
    SL_CHECK(idx[18] == 13 && idx[19] == 10 && idx[23] == 14); /* the last quad closes the ring */
    SL_CHECK(sl_ribbons_quad_indices(0, 2, 2, 1, idx) == 6);   /* flat: one open quad */
    const uint32_t flat[6] = {0, 1, 2, 2, 1, 3};
    SL_CHECK(memcmp(idx, flat, sizeof flat) == 0);
    SL_CHECK(sl_ribbons_cap_indices(8, 5, 0, idx) == 9);
    SL_CHECK(idx[0] == 8 && idx[1] == 10 && idx[2] == 9);    /* start cap faces -t */
    SL_CHECK(sl_ribbons_cap_indices(8, 5, 1, idx) == 9);
    SL_CHECK(idx[0] == 8 && idx[1] == 9 && idx[2] == 10);
}

static void test_mesh(void)
{
    sl_err err;
    sl_dataset *ds = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"tornado\",\"lines\":12,\"points\":40,\"seed\":3}", &ds, &err) == SL_OK);
    if (!ds)
        return;
    const sl_lines *l = &ds->lines;
    sl_ribbons_points pts;
    sl_line_chunk *chunks = NULL;
    size_t chunk_count = 0;
    SL_CHECK(sl_ribbons_points_init(&pts, l, SL_RIBBONS_FRAME_TRANSPORT, -1, &err) == SL_OK);
    SL_CHECK(sl_lines_chunks_build(l, 16, &chunks, &chunk_count, &err) == SL_OK);
    SL_CHECK(chunk_count >= 3 * l->line_count);
    const int N = 5;
    sl_ribbons_mesh m;
    SL_CHECK(sl_ribbons_mesh_build(&pts, l, chunks, chunk_count, N, &m, &err) == SL_OK);
    SL_CHECK(m.vertex_count == pts.count * N);
    int fields_ok = 1;
    for (size_t i = 0; i < pts.count && m.vertices; i++)
        for (int j = 0; j < N; j++) {
            const sl_ribbons_mesh_vertex *v = &m.vertices[i * N + (size_t)j];
            fields_ok &= v->point == i && v->slot == (uint32_t)j &&
                         memcmp(v->pos_radius, &pts.pos_radius[4 * i], 16) == 0 &&
                         memcmp(v->normal_twist, &pts.normal_twist[4 * i], 16) == 0 &&
                         memcmp(v->tangent_slope, &pts.tangent_slope[4 * i], 16) == 0;
        }
    SL_CHECK(fields_ok);
    size_t next = 0, caps = 0;
    int ranges_ok = 1, own_points = 1;
    for (size_t c = 0; c < chunk_count && m.chunk_first; c++) {
        const sl_line_chunk *ch = &chunks[c];
        unsigned cb = sl_ribbons_chunk_caps(l, ch);
        size_t count = 6u * N * ch->segments + 3u * (N - 2) * ((cb & 1u) + (cb >> 1));
        caps += (cb & 1u) + (cb >> 1);
        ranges_ok &= m.chunk_first[c] == next;
        for (size_t k = next; k < next + count && k < m.index_count; k++) {
            uint32_t point = m.indices[k] / (uint32_t)N;
            own_points &= point >= ch->first_point && point <= ch->first_point + ch->segments;
        }
        next += count;
    }
    SL_CHECK(ranges_ok);
    SL_CHECK(own_points);
    SL_CHECK(next == m.index_count);
    SL_CHECK(caps == 2 * l->line_count);
    sl_ribbons_mesh_deinit(&m);

    SL_CHECK(sl_ribbons_mesh_build(&pts, l, chunks, chunk_count, 2, &m, &err) == SL_ERR_INVALID);
    SL_CHECK(m.vertices == NULL && m.indices == NULL);
    /* 2^28 points x 32 slots do not fit u32 indices: refused from the counts alone. */
    sl_ribbons_points huge = pts;
    huge.count = (size_t)1 << 28;
    SL_CHECK(sl_ribbons_mesh_build(&huge, l, chunks, chunk_count, 32, &m, &err) == SL_ERR_LIMIT);
    SL_CHECK(strstr(err.message, "does not fit 32-bit indices") != NULL);
    SL_CHECK(m.vertices == NULL && m.indices == NULL && m.chunk_first == NULL);
    free(chunks);
    sl_ribbons_points_deinit(&pts);
    sl_dataset_destroy(ds);
}

int main(void)
{
    test_topology();
    test_mesh();
    SL_TEST_END();
}
