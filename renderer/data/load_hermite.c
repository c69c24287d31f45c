/* load_hermite.c — explicit Hermite line data in JSON (see sl_load.h).
 *
 * {"nodes":[{"p":[x,y,z],"t":[x,y,z],"r":r,"dr":dr,"c":s,"dc":ds},...],
 *  "segments":[[i,j],...]}: every segment becomes one two-vertex line with
 * the nodes' radii and tangents and the attributes "scalar",
 * "scalar_derivative" and "radius_derivative", so the tubes technique can
 * render exactly the curve the file describes. Any thread; no GL.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sl_load.h"

int sl_hermite_json_detect(const cJSON *root)
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

sl_status sl_hermite_dataset_from_json(const cJSON *root, const char *name, sl_dataset **out, sl_err *err)
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
    float *sc = sl_lines_add_attribute(l, SL_ATTR_SCALAR, 0, err);
    float *dsc = sc ? sl_lines_add_attribute(l, SL_ATTR_SCALAR SL_ATTR_DERIVATIVE_SUFFIX, 0, err) : NULL;
    float *dr = dsc ? sl_lines_add_attribute(l, SL_ATTR_RADIUS_DERIVATIVE, 0, err) : NULL;
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

sl_status sl_load_hermite_json(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    cJSON *root = cJSON_ParseWithLength((const char *)data, size);
    if (!root)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: not valid JSON", path ? path : "Hermite tube data");
    const char *base = path ? strrchr(path, '/') : NULL;
    sl_status st = sl_hermite_dataset_from_json(root, base ? base + 1 : (path ? path : "hermite"), out, err);
    cJSON_Delete(root);
    if (st != SL_OK && path)
        sl_err_prefix(err, "%s", path);
    return st;
}
