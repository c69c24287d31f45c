/* test_tubes_nodes.c — Hermite nodes from line sets and from explicit JSON (renderer/tubes/tubes_nodes.c).
 *
 * Checks Catmull-Rom tangents (interior and one-sided ends) for positions,
 * radii and the colour scalar against hand-computed values; the three
 * tangent modes with data tangents; segments per line; explicit Hermite JSON
 * round trip (exact tangents and derivatives, bifurcations, sharp corners,
 * 1e5 offsets kept to float precision relative to the origin); and that every
 * malformed document is refused with a message naming the field; radii from
 * a per-vertex attribute (sl_tubes_nodes_set_radii).
 */
#include <stdlib.h>
#include <string.h>

#include "sl_test.h"
#include "data/sl_load.h"
#include "tubes/tubes_nodes.h"

static sl_dataset *three_points(int with_tangents)
{
    sl_err err;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "t");
    SL_CHECK(sl_lines_alloc(&ds->lines, 2, 5, 1, with_tangents, &err) == SL_OK);
    /* line 0: (0,0,0) (1,0,0) (3,1,0); line 1: (0,2,0) (0,2,2) */
    const float p[15] = {0, 0, 0, 1, 0, 0, 3, 1, 0, 0, 2, 0, 0, 2, 2};
    memcpy(ds->lines.positions, p, sizeof p);
    const float r[5] = {1, 2, 4, 1, 1};
    memcpy(ds->lines.radii, r, sizeof r);
    ds->lines.line_offsets[0] = 0;
    ds->lines.line_offsets[1] = 3;
    ds->lines.line_offsets[2] = 5;
    float *c = sl_lines_add_attribute(&ds->lines, "speed", 0, &err);
    const float cv[5] = {0, 10, 30, 5, 7};
    memcpy(c, cv, sizeof cv);
    if (with_tangents)
        for (int v = 0; v < 5; v++)
            ds->lines.tangents[3 * v + 2] = 100.0f; /* velocity along +z, 100 units long */
    return ds;
}

static void test_catmull_rom(void)
{
    sl_err err;
    sl_dataset *ds = three_points(0);
    sl_tubes_nodes n;
    SL_CHECK(sl_tubes_nodes_build(&ds->lines, SL_TUBES_TANGENTS_AUTO, 0, &n, &err) == SL_OK);
    SL_CHECK(n.node_count == 5 && n.segment_count == 3);
    SL_CHECK(n.segments[0] == 0 && n.segments[1] == 1 && n.segments[2] == 1 && n.segments[3] == 2);
    SL_CHECK(n.segments[4] == 3 && n.segments[5] == 4);
    const float *g = n.geometry;
    /* node 0: one-sided p1 - p0 = (1,0,0); dr = 1 */
    SL_CHECK_NEAR(g[4], 1, 0); SL_CHECK_NEAR(g[5], 0, 0); SL_CHECK_NEAR(g[7], 1, 0);
    /* node 1: (p2 - p0) / 2 = (1.5, 0.5, 0); dr = (4 - 1) / 2 */
    g = n.geometry + SL_TUBES_NODE_FLOATS;
    SL_CHECK_NEAR(g[4], 1.5, 0); SL_CHECK_NEAR(g[5], 0.5, 0); SL_CHECK_NEAR(g[7], 1.5, 0);
    SL_CHECK_NEAR(g[3], 2, 0);
    /* node 2: one-sided p2 - p1 = (2, 1, 0) */
    g = n.geometry + 2 * SL_TUBES_NODE_FLOATS;
    SL_CHECK_NEAR(g[4], 2, 0); SL_CHECK_NEAR(g[5], 1, 0);
    /* colour: c and dc, finite differences within each line only */
    SL_CHECK_NEAR(n.color[2], 10, 0); SL_CHECK_NEAR(n.color[3], 15, 0);
    SL_CHECK_NEAR(n.color[6], 5, 0); SL_CHECK_NEAR(n.color[7], 2, 0);
    SL_CHECK(n.has_radii == 1 && n.color_attribute == 0);
    sl_tubes_nodes_set_color(&ds->lines, -1, &n);
    SL_CHECK(n.color[2] == 0.0f && n.color_attribute == -1);
    sl_tubes_nodes_deinit(&n);
    sl_tubes_nodes_deinit(&n); /* twice is fine */
    sl_dataset_destroy(ds);
}

static void test_tangent_modes(void)
{
    sl_err err;
    sl_dataset *ds = three_points(1);
    sl_tubes_nodes n;
    /* auto: the data's direction (+z) with the Catmull-Rom length */
    SL_CHECK(sl_tubes_nodes_build(&ds->lines, SL_TUBES_TANGENTS_AUTO, -1, &n, &err) == SL_OK);
    const float *g = n.geometry + SL_TUBES_NODE_FLOATS;
    SL_CHECK_NEAR(g[4], 0, 0); SL_CHECK_NEAR(g[6], sqrt(1.5 * 1.5 + 0.5 * 0.5), 1e-6);
    sl_tubes_nodes_deinit(&n);
    SL_CHECK(sl_tubes_nodes_build(&ds->lines, SL_TUBES_TANGENTS_DATA_EXACT, -1, &n, &err) == SL_OK);
    SL_CHECK_NEAR(n.geometry[SL_TUBES_NODE_FLOATS + 6], 100, 0);
    sl_tubes_nodes_deinit(&n);
    SL_CHECK(sl_tubes_nodes_build(&ds->lines, SL_TUBES_TANGENTS_CATMULL_ROM, -1, &n, &err) == SL_OK);
    SL_CHECK_NEAR(n.geometry[SL_TUBES_NODE_FLOATS + 4], 1.5, 0);
    SL_CHECK_NEAR(n.geometry[SL_TUBES_NODE_FLOATS + 6], 0, 0);
    sl_tubes_nodes_deinit(&n);
    sl_dataset_destroy(ds);
}

static void test_json(void)
{
    sl_err err;
    sl_dataset *ds = NULL;
    /* a bifurcation at node 1 and a sharp corner (node 3 duplicates node 1's position) */
    const char *doc = "{\"nodes\":["
                      "{\"p\":[100000,0,0],\"t\":[1,0,0],\"r\":0.5,\"dr\":0.25,\"c\":2,\"dc\":-1},"
                      "{\"p\":[100001,0,0],\"t\":[1,0.5,0],\"r\":0.25},"
                      "{\"p\":[100002,1,0],\"t\":[0,1,0],\"r\":0.125},"
                      "{\"p\":[100001,0,0],\"t\":[0,-3,0],\"r\":0.25}],"
                      "\"segments\":[[0,1],[1,2],[3,2],[1,0]]}";
    SL_CHECK(sl_load_hermite_json((const uint8_t *)doc, strlen(doc), "x/h.json", &ds, &err) == SL_OK);
    if (!ds)
        return;
    SL_CHECK(strcmp(ds->name, "h.json") == 0);
    SL_CHECK(ds->lines.line_count == 4 && ds->lines.vertex_count == 8);
    SL_CHECK_NEAR(ds->origin.x + ds->lines.positions[0], 100000.0, 1e-6);
    SL_CHECK_NEAR(ds->origin.x + ds->lines.positions[3], 100001.0, 1e-6);
    SL_CHECK_NEAR(ds->bounds_max.x, 100002.125, 1e-6);
    sl_tubes_nodes n;
    int scalar = sl_lines_find_attribute(&ds->lines, SL_ATTR_SCALAR);
    SL_CHECK(scalar >= 0);
    SL_CHECK(sl_tubes_nodes_build(&ds->lines, SL_TUBES_TANGENTS_AUTO, scalar, &n, &err) == SL_OK);
    SL_CHECK(n.segment_count == 4);
    const float *g0 = n.geometry;
    SL_CHECK_NEAR(g0[3], 0.5, 0); SL_CHECK_NEAR(g0[7], 0.25, 0); SL_CHECK_NEAR(g0[4], 1, 0);
    SL_CHECK_NEAR(n.color[0], 2, 0); SL_CHECK_NEAR(n.color[1], -1, 0);
    /* segment 2 starts at node 3: the corner's own tangent, not node 1's */
    const float *g4 = n.geometry + 4 * SL_TUBES_NODE_FLOATS;
    SL_CHECK_NEAR(g4[5], -3, 0);
    /* node 1 without dr/c/dc: zeros, not finite differences */
    const float *g1 = n.geometry + SL_TUBES_NODE_FLOATS;
    SL_CHECK_NEAR(g1[7], 0, 0); SL_CHECK_NEAR(n.color[3], 0, 0);
    sl_tubes_nodes_deinit(&n);
    sl_dataset_destroy(ds);

    static const char *const bad[][2] = {
        {"[]", "object"},
        {"{\"nodes\":[],\"segments\":[],\"x\":1}", "x is not"},
        {"{\"nodes\":{},\"segments\":[]}", "nodes must"},
        {"{\"nodes\":[],\"segments\":{}}", "segments must"},
        {"{\"nodes\":[{\"t\":[0,0,0],\"r\":1}],\"segments\":[]}", "nodes[0].p"},
        {"{\"nodes\":[{\"p\":[0,0],\"t\":[0,0,0],\"r\":1}],\"segments\":[]}", "nodes[0].p"},
        {"{\"nodes\":[{\"p\":[0,0,0],\"t\":[0,\"a\",0],\"r\":1}],\"segments\":[]}", "nodes[0].t[1]"},
        {"{\"nodes\":[{\"p\":[0,0,0],\"t\":[0,0,0]}],\"segments\":[]}", "nodes[0].r"},
        {"{\"nodes\":[{\"p\":[0,0,0],\"t\":[0,0,0],\"r\":-1}],\"segments\":[]}", "nodes[0].r"},
        {"{\"nodes\":[{\"p\":[0,0,0],\"t\":[0,0,0],\"r\":1,\"q\":1}],\"segments\":[]}", "nodes[0].q"},
        {"{\"nodes\":[{\"p\":[0,0,0],\"t\":[0,0,0],\"r\":1}],\"segments\":[[0,1]]}", "segments[0][1]"},
        {"{\"nodes\":[{\"p\":[0,0,0],\"t\":[0,0,0],\"r\":1}],\"segments\":[[0,0.5]]}", "segments[0][1]"},
        {"{\"nodes\":[{\"p\":[0,0,0],\"t\":[0,0,0],\"r\":1}],\"segments\":[[0]]}", "segments[0]"},
        {"{\"nodes\":[{\"p\":[0,0,0],\"t\":[0,0,0],\"r\":1}],\"segments\":[[-1,0]]}", "segments[0][0]"},
        {"{\"nodes\":[{\"p\":[1e400,0,0],\"t\":[0,0,0],\"r\":1}],\"segments\":[]}", "nodes[0].p"},
        {"{\"nodes\":", "not valid JSON"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        ds = (sl_dataset *)1;
        err.message[0] = 0;
        sl_status st = sl_load_hermite_json((const uint8_t *)bad[k][0], strlen(bad[k][0]), NULL, &ds, &err);
        SL_CHECK_MSG(st != SL_OK && ds == NULL && strstr(err.message, bad[k][1]),
                     "case %zu: status %d message '%s'", k, (int)st, err.message);
    }
    /* an empty but well-formed set is fine: nothing to draw */
    const char *empty = "{\"nodes\":[],\"segments\":[]}";
    SL_CHECK(sl_load_hermite_json((const uint8_t *)empty, strlen(empty), NULL, &ds, &err) == SL_OK);
    SL_CHECK(ds && ds->lines.line_count == 0);
    sl_dataset_destroy(ds);
}

/* Radii from a per-vertex attribute (the shared radius_attribute parameter):
 * r = |value|, dr by finite differences within each line, or from the
 * attribute's "_derivative" companion; -1 and a missing index change nothing. */
static void test_radius_attribute(void)
{
    sl_err err;
    sl_dataset *ds = three_points(0);
    sl_tubes_nodes n;
    SL_CHECK(sl_tubes_nodes_build(&ds->lines, SL_TUBES_TANGENTS_AUTO, -1, &n, &err) == SL_OK);
    sl_tubes_nodes_set_radii(&ds->lines, -1, &n);
    SL_CHECK_NEAR(n.geometry[SL_TUBES_NODE_FLOATS + 3], 2, 0); /* lines->radii kept */
    sl_tubes_nodes_set_radii(&ds->lines, 7, &n);
    SL_CHECK_NEAR(n.geometry[SL_TUBES_NODE_FLOATS + 3], 2, 0);
    ds->lines.attributes[0].values[3] = -5.0f; /* |value| */
    sl_tubes_nodes_set_radii(&ds->lines, 0, &n);
    SL_CHECK(n.has_radii == 1);
    const float *g = n.geometry;
    SL_CHECK_NEAR(g[3], 0, 0); SL_CHECK_NEAR(g[7], 10, 0);                  /* one-sided: 10 - 0 */
    g = n.geometry + SL_TUBES_NODE_FLOATS;
    SL_CHECK_NEAR(g[3], 10, 0); SL_CHECK_NEAR(g[7], 15, 0);                 /* (30 - 0) / 2 */
    g = n.geometry + 3 * SL_TUBES_NODE_FLOATS;
    SL_CHECK_NEAR(g[3], 5, 0); SL_CHECK_NEAR(g[7], 12, 0);                  /* line 1 alone: 7 - (-5) */
    sl_tubes_nodes_deinit(&n);
    /* without lines->radii, and with a derivative companion */
    free(ds->lines.radii);
    ds->lines.radii = NULL;
    float *d = sl_lines_add_attribute(&ds->lines, "speed" SL_ATTR_DERIVATIVE_SUFFIX, 0, &err);
    SL_CHECK(d != NULL);
    if (d)
        for (int v = 0; v < 5; v++)
            d[v] = 0.5f * (float)v;
    SL_CHECK(sl_tubes_nodes_build(&ds->lines, SL_TUBES_TANGENTS_AUTO, -1, &n, &err) == SL_OK);
    SL_CHECK(n.has_radii == 0);
    sl_tubes_nodes_set_radii(&ds->lines, 0, &n);
    SL_CHECK(n.has_radii == 1);
    SL_CHECK_NEAR(n.geometry[2 * SL_TUBES_NODE_FLOATS + 3], 30, 0);
    SL_CHECK_NEAR(n.geometry[2 * SL_TUBES_NODE_FLOATS + 7], 1.0, 0);
    sl_tubes_nodes_deinit(&n);
    sl_dataset_destroy(ds);
}

int main(void)
{
    test_catmull_rom();
    test_tangent_modes();
    test_json();
    test_radius_attribute();
    SL_TEST_END();
}
