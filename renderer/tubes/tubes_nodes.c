/* tubes_nodes.c — line sets and explicit JSON to Hermite nodes and segments (see tubes_nodes.h).
 *
 * Tangents are derivatives with respect to the segment parameter t in [0, 1]
 * (a data tangent in other units, e.g. velocity, only gives the direction),
 * so that the quadratic split of the geometry shader (a2 = n_i + t_i / 3) is
 * the Hermite/Bezier basis change of the paper (Russig et al., 3.2). For
 * Catmull-Rom: t_i = (x_{i+1} - x_{i-1}) / 2 inside a line, x_1 - x_0 and
 * x_n - x_{n-1} at its ends; the same rule gives dr and dc. Any thread; no GL.
 */
#include "tubes_nodes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../data/sl_load.h"

/* Derivative of a per-vertex scalar series at vertex v of a line [lo, hi). */
static float series_derivative(const float *x, size_t stride, size_t lo, size_t hi, size_t v, int c)
{
    if (hi - lo < 2)
        return 0.0f;
    if (v == lo)
        return x[(v + 1) * stride + c] - x[v * stride + c];
    if (v + 1 == hi)
        return x[v * stride + c] - x[(v - 1) * stride + c];
    return 0.5f * (x[(v + 1) * stride + c] - x[(v - 1) * stride + c]);
}

static int find_derivative_attribute(const sl_lines *lines, const char *base)
{
    char name[SL_NAME_MAX + 16];
    snprintf(name, sizeof name, "%s%s", base, SL_TUBES_DERIVATIVE_SUFFIX);
    return sl_lines_find_attribute(lines, name);
}

void sl_tubes_nodes_set_color(const sl_lines *lines, int color_attribute, sl_tubes_nodes *n)
{
    if (!n->color)
        return;
    if (color_attribute < 0 || color_attribute >= lines->attribute_count) {
        memset(n->color, 0, n->node_count * 2 * sizeof(float));
        n->color_attribute = -1;
        return;
    }
    const float *c = lines->attributes[color_attribute].values;
    int d = find_derivative_attribute(lines, lines->attributes[color_attribute].name);
    const float *dc = d >= 0 ? lines->attributes[d].values : NULL;
    for (size_t k = 0; k < lines->line_count; k++) {
        size_t lo = lines->line_offsets[k], hi = lines->line_offsets[k + 1];
        for (size_t v = lo; v < hi; v++) {
            float value = isfinite(c[v]) ? c[v] : 0.0f;
            n->color[2 * v] = value;
            n->color[2 * v + 1] = dc ? dc[v] : series_derivative(c, 1, lo, hi, v, 0);
            if (!isfinite(n->color[2 * v + 1]))
                n->color[2 * v + 1] = 0.0f;
        }
    }
    n->color_attribute = color_attribute;
}

sl_status sl_tubes_nodes_build(const sl_lines *lines, sl_tubes_tangents tangents, int color_attribute,
                               sl_tubes_nodes *out, sl_err *err)
{
    memset(out, 0, sizeof *out);
    out->color_attribute = -1;
    size_t nv = lines->vertex_count;
    if (nv > UINT32_MAX)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu vertices exceed the 2^32 node indices of tubes", nv);
    size_t ns = 0;
    for (size_t k = 0; k < lines->line_count; k++) {
        size_t len = lines->line_offsets[k + 1] - lines->line_offsets[k];
        if (len >= 2)
            ns += len - 1;
    }
    out->geometry = malloc((nv ? nv : 1) * SL_TUBES_NODE_FLOATS * sizeof(float));
    out->color = calloc((nv ? nv : 1) * 2, sizeof(float));
    out->segments = malloc((ns ? ns : 1) * 2 * sizeof(uint32_t));
    if (!out->geometry || !out->color || !out->segments) {
        sl_tubes_nodes_deinit(out);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu tube nodes and %zu segments", nv, ns);
    }
    out->node_count = nv;
    out->segment_count = ns;
    out->has_radii = lines->radii != NULL;

    int explicit_hermite = sl_lines_find_attribute(lines, SL_TUBES_RADIUS_DERIVATIVE) >= 0;
    int exact = lines->tangents && (tangents == SL_TUBES_TANGENTS_DATA_EXACT ||
                                    (tangents == SL_TUBES_TANGENTS_AUTO && explicit_hermite));
    int directions = lines->tangents && tangents == SL_TUBES_TANGENTS_AUTO && !explicit_hermite;
    int dr_attr = exact ? sl_lines_find_attribute(lines, SL_TUBES_RADIUS_DERIVATIVE) : -1;
    size_t s = 0;
    for (size_t k = 0; k < lines->line_count; k++) {
        size_t lo = lines->line_offsets[k], hi = lines->line_offsets[k + 1];
        for (size_t v = lo; v < hi; v++) {
            float *g = out->geometry + v * SL_TUBES_NODE_FLOATS;
            double fd[3], fd_len = 0.0, data_len = 0.0;
            for (int c = 0; c < 3; c++) {
                g[c] = lines->positions[3 * v + c];
                fd[c] = series_derivative(lines->positions, 3, lo, hi, v, c);
                fd_len += fd[c] * fd[c];
                if (lines->tangents)
                    data_len += (double)lines->tangents[3 * v + c] * lines->tangents[3 * v + c];
            }
            fd_len = sqrt(fd_len);
            data_len = sqrt(data_len);
            for (int c = 0; c < 3; c++) {
                double t = fd[c];
                if (exact)
                    t = lines->tangents[3 * v + c];
                else if (directions && data_len > 0.0 && isfinite(data_len))
                    t = lines->tangents[3 * v + c] / data_len * fd_len;
                g[4 + c] = isfinite(t) ? (float)t : 0.0f;
            }
            if (lines->radii) {
                g[3] = fabsf(lines->radii[v]);
                g[7] = dr_attr >= 0 ? lines->attributes[dr_attr].values[v]
                                    : series_derivative(lines->radii, 1, lo, hi, v, 0);
                if (!isfinite(g[7]))
                    g[7] = 0.0f;
            } else {
                g[3] = 0.0f;
                g[7] = 0.0f;
            }
            if (v + 1 < hi) {
                out->segments[2 * s] = (uint32_t)v;
                out->segments[2 * s + 1] = (uint32_t)(v + 1);
                s++;
            }
        }
    }
    sl_tubes_nodes_set_color(lines, color_attribute, out);
    return SL_OK;
}

void sl_tubes_nodes_deinit(sl_tubes_nodes *n)
{
    if (!n)
        return;
    free(n->geometry);
    free(n->color);
    free(n->segments);
    memset(n, 0, sizeof *n);
    n->color_attribute = -1;
}

int sl_tubes_json_is_hermite(const cJSON *root)
{
    return cJSON_IsObject(root) && cJSON_GetObjectItemCaseSensitive(root, "nodes") &&
           cJSON_GetObjectItemCaseSensitive(root, "segments");
}

/* Reads a finite number; missing -> def (when optional) or an error. */
static sl_status get_number(const cJSON *obj, const char *key, int required, double def, size_t index,
                            double *out, sl_err *err)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        if (required)
            return sl_err_set(err, SL_ERR_INVALID, "nodes[%zu].%s is required", index, key);
        *out = def;
        return SL_OK;
    }
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble))
        return sl_err_set(err, SL_ERR_INVALID, "nodes[%zu].%s must be a finite number", index, key);
    *out = item->valuedouble;
    return SL_OK;
}

static sl_status get_vec3(const cJSON *obj, const char *key, size_t index, double out[3], sl_err *err)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3)
        return sl_err_set(err, SL_ERR_INVALID, "nodes[%zu].%s must be an array of 3 numbers", index, key);
    for (int c = 0; c < 3; c++) {
        const cJSON *x = cJSON_GetArrayItem(item, c);
        if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble))
            return sl_err_set(err, SL_ERR_INVALID, "nodes[%zu].%s[%d] must be a finite number", index, key, c);
        out[c] = x->valuedouble;
    }
    return SL_OK;
}

static const char *const node_keys[] = {"p", "t", "r", "dr", "c", "dc", NULL};

/* One parsed node, in double until the dataset origin is known. */
typedef struct json_node { double p[3], t[3], r, dr, c, dc; } json_node;

static sl_status parse_node(const cJSON *obj, size_t i, json_node *n, sl_err *err)
{
    if (!cJSON_IsObject(obj))
        return sl_err_set(err, SL_ERR_INVALID, "nodes[%zu] must be an object", i);
    for (const cJSON *kv = obj->child; kv; kv = kv->next) {
        int known = 0;
        for (int k = 0; node_keys[k]; k++)
            known |= kv->string && strcmp(kv->string, node_keys[k]) == 0;
        if (!known)
            return sl_err_set(err, SL_ERR_INVALID, "nodes[%zu].%s is not a node field (p, t, r, dr, c, dc)",
                              i, kv->string ? kv->string : "?");
    }
    sl_status st;
    if ((st = get_vec3(obj, "p", i, n->p, err)) != SL_OK || (st = get_vec3(obj, "t", i, n->t, err)) != SL_OK ||
        (st = get_number(obj, "r", 1, 0.0, i, &n->r, err)) != SL_OK ||
        (st = get_number(obj, "dr", 0, 0.0, i, &n->dr, err)) != SL_OK ||
        (st = get_number(obj, "c", 0, 0.0, i, &n->c, err)) != SL_OK ||
        (st = get_number(obj, "dc", 0, 0.0, i, &n->dc, err)) != SL_OK)
        return st;
    if (n->r < 0.0 || n->r > 3.0e38)
        return sl_err_set(err, SL_ERR_INVALID, "nodes[%zu].r must be in [0, 3e38], got %g", i, n->r);
    return SL_OK;
}

sl_status sl_tubes_dataset_from_json(const cJSON *root, const char *name, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    if (!cJSON_IsObject(root))
        return sl_err_set(err, SL_ERR_INVALID, "Hermite tube data must be a JSON object with nodes and segments");
    for (const cJSON *kv = root->child; kv; kv = kv->next)
        if (!kv->string || (strcmp(kv->string, "nodes") != 0 && strcmp(kv->string, "segments") != 0))
            return sl_err_set(err, SL_ERR_INVALID, "%s is not a field of Hermite tube data (nodes, segments)",
                              kv->string ? kv->string : "?");
    const cJSON *jn = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    const cJSON *js = cJSON_GetObjectItemCaseSensitive(root, "segments");
    if (!cJSON_IsArray(jn))
        return sl_err_set(err, SL_ERR_INVALID, "nodes must be an array");
    if (!cJSON_IsArray(js))
        return sl_err_set(err, SL_ERR_INVALID, "segments must be an array");
    size_t nn = (size_t)cJSON_GetArraySize(jn), ns = (size_t)cJSON_GetArraySize(js);
    if (nn > SL_MAX_VERTICES)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu nodes exceed the limit of %u", nn, SL_MAX_VERTICES);
    if (ns > SL_MAX_LINES || 2 * ns > SL_MAX_VERTICES)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu segments exceed the limit of %u", ns, SL_MAX_VERTICES / 2);

    json_node *nodes = malloc((nn ? nn : 1) * sizeof *nodes);
    sl_dataset *ds = NULL;
    sl_status st = SL_OK;
    if (!nodes) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu nodes", nn);
        goto fail;
    }
    size_t i = 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const cJSON *item = jn->child; item; item = item->next, i++) {
        if ((st = parse_node(item, i, &nodes[i], err)) != SL_OK)
            goto fail;
        for (int c = 0; c < 3; c++) {
            lo[c] = fmin(lo[c], nodes[i].p[c]);
            hi[c] = fmax(hi[c], nodes[i].p[c]);
        }
    }
    ds = sl_dataset_create(SL_DATASET_LINES, name ? name : "hermite");
    if (!ds) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for a dataset");
        goto fail;
    }
    /* Positions are stored relative to the bounds centre computed in double,
     * so coordinates far from the world origin keep float precision. */
    if (nn > 0)
        ds->origin = sl_v3(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]));
    const double origin[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    sl_lines *l = &ds->lines;
    if ((st = sl_lines_alloc(l, ns, 2 * ns, 1, 1, err)) != SL_OK)
        goto fail;
    float *sc = sl_lines_add_attribute(l, SL_TUBES_SCALAR, 0, err);
    float *dsc = sc ? sl_lines_add_attribute(l, SL_TUBES_SCALAR SL_TUBES_DERIVATIVE_SUFFIX, 0, err) : NULL;
    float *dr = dsc ? sl_lines_add_attribute(l, SL_TUBES_RADIUS_DERIVATIVE, 0, err) : NULL;
    if (!dr) {
        st = err ? err->status : SL_ERR_NOMEM;
        goto fail;
    }
    size_t k = 0;
    for (const cJSON *seg = js->child; seg; seg = seg->next, k++) {
        if (!cJSON_IsArray(seg) || cJSON_GetArraySize(seg) != 2) {
            st = sl_err_set(err, SL_ERR_INVALID, "segments[%zu] must be a pair [i, j] of node indices", k);
            goto fail;
        }
        l->line_offsets[k] = (uint32_t)(2 * k);
        for (int e = 0; e < 2; e++) {
            const cJSON *x = cJSON_GetArrayItem(seg, e);
            double idx = cJSON_IsNumber(x) ? x->valuedouble : -1.0;
            if (!(idx >= 0.0 && idx < (double)nn && idx == floor(idx))) {
                st = sl_err_set(err, SL_ERR_INVALID, "segments[%zu][%d] must be a node index in [0, %zu)", k, e, nn);
                goto fail;
            }
            const json_node *n = &nodes[(size_t)idx];
            size_t v = 2 * k + (size_t)e;
            for (int c = 0; c < 3; c++) {
                l->positions[3 * v + c] = (float)(n->p[c] - origin[c]);
                l->tangents[3 * v + c] = (float)n->t[c];
            }
            l->radii[v] = (float)n->r;
            dr[v] = (float)n->dr;
            sc[v] = (float)n->c;
            dsc[v] = (float)n->dc;
        }
    }
    l->line_offsets[ns] = (uint32_t)(2 * ns);
    if ((st = sl_dataset_finish_lines(ds, err)) != SL_OK)
        goto fail;
    free(nodes);
    *out = ds;
    return SL_OK;
fail:
    free(nodes);
    sl_dataset_destroy(ds);
    return st;
}

sl_status sl_tubes_load_json(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    cJSON *root = cJSON_ParseWithLength((const char *)data, size);
    if (!root)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: not valid JSON", path ? path : "Hermite tube data");
    const char *base = path ? strrchr(path, '/') : NULL;
    sl_status st = sl_tubes_dataset_from_json(root, base ? base + 1 : (path ? path : "hermite"), out, err);
    cJSON_Delete(root);
    if (st != SL_OK && path)
        sl_err_prefix(err, "%s", path);
    return st;
}
