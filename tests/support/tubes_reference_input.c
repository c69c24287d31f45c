/* tubes_reference_input.c — reference segments from Hermite JSON or polylines
 * (see tubes_reference_input.h). Written from the documented rules, not from
 * renderer/tubes/tubes_nodes.c.
 */
#include "tubes_reference_input.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

static int fail(char *msg, size_t size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, size, fmt, ap);
    va_end(ap);
    return -1;
}

int tubes_ref_is_hermite_json(const cJSON *root)
{
    return cJSON_IsObject(root) && cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(root, "nodes")) &&
           cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(root, "segments"));
}

/* A finite number member, or `fallback` when absent; -1 when present but not a finite number. */
static int number(const cJSON *obj, const char *key, double fallback, double *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        *out = fallback;
        return 0;
    }
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble))
        return -1;
    *out = v->valuedouble;
    return 0;
}

static int vec3(const cJSON *obj, const char *key, sl_vec3 *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
        return -1;
    double x[3];
    for (int c = 0; c < 3; c++) {
        const cJSON *e = cJSON_GetArrayItem(v, c);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
            return -1;
        x[c] = e->valuedouble;
    }
    *out = sl_v3(x[0], x[1], x[2]);
    return 0;
}

typedef struct json_node {
    sl_vec3 p, t;
    double r, dr;
} json_node;

int tubes_ref_input_hermite_json(const cJSON *root, int radius_from_scalar, double radius, double radius_scale,
                                 tubes_ref_input *out, char *msg, size_t msg_size)
{
    memset(out, 0, sizeof *out);
    if (!tubes_ref_is_hermite_json(root))
        return fail(msg, msg_size, "not Hermite JSON (an object with \"nodes\" and \"segments\")");
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    const cJSON *segs = cJSON_GetObjectItemCaseSensitive(root, "segments");
    int nn = cJSON_GetArraySize(nodes), ns = cJSON_GetArraySize(segs);
    json_node *nd = calloc(nn > 0 ? (size_t)nn : 1, sizeof *nd);
    out->segments = calloc(ns > 0 ? (size_t)ns : 1, sizeof *out->segments);
    if (!nd || !out->segments) {
        free(nd);
        tubes_ref_input_free(out);
        return fail(msg, msg_size, "out of memory for %d nodes", nn);
    }
    int k = 0;
    const cJSON *n;
    cJSON_ArrayForEach(n, nodes) {
        double r, dr, c, dc;
        if (vec3(n, "p", &nd[k].p) || vec3(n, "t", &nd[k].t) || number(n, "r", radius, &r) ||
            number(n, "dr", 0.0, &dr) || number(n, "c", 0.0, &c) || number(n, "dc", 0.0, &dc)) {
            free(nd);
            tubes_ref_input_free(out);
            return fail(msg, msg_size, "nodes[%d]: p and t must be 3 finite numbers, r/dr/c/dc finite numbers", k);
        }
        nd[k].r = (radius_from_scalar ? fabs(c) : fabs(r)) * radius_scale;
        nd[k].dr = (radius_from_scalar ? dc : dr) * radius_scale;
        k++;
    }
    const cJSON *s;
    cJSON_ArrayForEach(s, segs) {
        const cJSON *a = cJSON_GetArrayItem(s, 0), *b = cJSON_GetArrayItem(s, 1);
        if (!cJSON_IsArray(s) || cJSON_GetArraySize(s) != 2 || !cJSON_IsNumber(a) || !cJSON_IsNumber(b) ||
            a->valuedouble < 0 || b->valuedouble < 0 || a->valuedouble >= nn || b->valuedouble >= nn) {
            free(nd);
            int bad = (int)out->count;
            tubes_ref_input_free(out);
            return fail(msg, msg_size, "segments[%d]: two node indices in 0..%d expected", bad, nn - 1);
        }
        const json_node *x = &nd[(int)a->valuedouble], *y = &nd[(int)b->valuedouble];
        out->segments[out->count++] = (tubes_ref_segment){
            .p0 = x->p, .t0 = x->t, .p1 = y->p, .t1 = y->t, .r0 = x->r, .dr0 = x->dr, .r1 = y->r, .dr1 = y->dr};
    }
    free(nd);
    out->origin = sl_v3(0, 0, 0);
    return 0;
}

/* Finite-difference derivative of component c of a series x (stride values
 * per vertex) at vertex v of the line [lo, hi): central inside, one-sided at
 * the ends, 0 for a single vertex. */
static double fd(const float *x, int stride, size_t lo, size_t hi, size_t v, int c)
{
    if (hi - lo < 2)
        return 0.0;
    size_t a = v > lo ? v - 1 : v, b = v + 1 < hi ? v + 1 : v;
    double scale = (v > lo && v + 1 < hi) ? 0.5 : 1.0;
    return scale * ((double)x[b * (size_t)stride + (size_t)c] - (double)x[a * (size_t)stride + (size_t)c]);
}

static double finite_or_zero(double x) { return isfinite(x) ? x : 0.0; }

int tubes_ref_input_lines(const sl_dataset *ds, tubes_ref_tangents tangents, int radius_attribute, double radius,
                          double radius_scale, tubes_ref_input *out, char *msg, size_t msg_size)
{
    memset(out, 0, sizeof *out);
    if (!ds || ds->kind != SL_DATASET_LINES)
        return fail(msg, msg_size, "not a line set");
    const sl_lines *L = &ds->lines;
    size_t ns = 0;
    for (size_t k = 0; k < L->line_count; k++)
        if (L->line_offsets[k + 1] - L->line_offsets[k] >= 2)
            ns += L->line_offsets[k + 1] - L->line_offsets[k] - 1;
    /* Explicit Hermite data as a line set (it carries "radius_derivative"):
     * in auto mode its tangents and radius derivatives exactly. */
    const float *hermite_dr = NULL;
    for (int a = 0; a < L->attribute_count; a++)
        if (strcmp(L->attributes[a].name, "radius_derivative") == 0)
            hermite_dr = L->attributes[a].values;
    int exact = L->tangents && (tangents == TUBES_REF_TANGENTS_DATA || (tangents == TUBES_REF_TANGENTS_AUTO && hermite_dr));
    /* Radii and their derivatives (NULL: finite differences). */
    const float *rad = NULL, *drad = NULL;
    if (radius_attribute >= 0 && radius_attribute < L->attribute_count) {
        rad = L->attributes[radius_attribute].values;
        char name[SL_NAME_MAX + 16];
        snprintf(name, sizeof name, "%s_derivative", L->attributes[radius_attribute].name);
        for (int a = 0; a < L->attribute_count; a++)
            if (strcmp(L->attributes[a].name, name) == 0)
                drad = L->attributes[a].values;
    } else if (L->radii) {
        rad = L->radii;
        drad = exact ? hermite_dr : NULL;
    }
    out->segments = calloc(ns ? ns : 1, sizeof *out->segments);
    if (!out->segments)
        return fail(msg, msg_size, "out of memory for %zu segments", ns);
    for (size_t k = 0; k < L->line_count; k++) {
        size_t lo = L->line_offsets[k], hi = L->line_offsets[k + 1];
        for (size_t v = lo; v + 1 < hi; v++) {
            tubes_ref_segment *g = &out->segments[out->count++];
            for (int e = 0; e < 2; e++) {
                size_t w = v + (size_t)e;
                double p[3], t[3], cr_len = 0.0, data_len = 0.0;
                for (int c = 0; c < 3; c++) {
                    p[c] = L->positions[3 * w + c];
                    t[c] = fd(L->positions, 3, lo, hi, w, c);
                    cr_len += t[c] * t[c];
                    if (L->tangents)
                        data_len += (double)L->tangents[3 * w + c] * L->tangents[3 * w + c];
                }
                cr_len = sqrt(cr_len);
                data_len = sqrt(data_len);
                if (exact)
                    for (int c = 0; c < 3; c++)
                        t[c] = L->tangents[3 * w + c];
                else if (L->tangents && tangents == TUBES_REF_TANGENTS_AUTO && data_len > 0.0 && isfinite(data_len))
                    for (int c = 0; c < 3; c++)
                        t[c] = L->tangents[3 * w + c] / data_len * cr_len;
                double r = radius, dr = 0.0;
                if (rad) {
                    r = finite_or_zero(fabs((double)rad[w])) * radius_scale;
                    dr = finite_or_zero(drad ? (double)drad[w] : fd(rad, 1, lo, hi, w, 0)) * radius_scale;
                }
                sl_vec3 P = sl_v3(p[0], p[1], p[2]), T = sl_v3(finite_or_zero(t[0]), finite_or_zero(t[1]), finite_or_zero(t[2]));
                if (e == 0) {
                    g->p0 = P;
                    g->t0 = T;
                    g->r0 = r;
                    g->dr0 = dr;
                } else {
                    g->p1 = P;
                    g->t1 = T;
                    g->r1 = r;
                    g->dr1 = dr;
                }
            }
        }
    }
    out->origin = ds->origin;
    return 0;
}

void tubes_ref_input_free(tubes_ref_input *in)
{
    if (!in)
        return;
    free(in->segments);
    memset(in, 0, sizeof *in);
}
