/* tubes_nodes.c — line sets to Hermite nodes and segments (see tubes_nodes.h).
 *
 * Tangents are derivatives with respect to the segment parameter t in [0, 1]
 * (a data tangent in other units, e.g. velocity, only gives the direction),
 * so that the quadratic split of the geometry shader (a2 = n_i + t_i / 3) is
 * the Hermite/Bezier basis change of the paper (Russig et al., 3.2). For
 * Catmull-Rom: t_i = (x_{i+1} - x_{i-1}) / 2 inside a line, x_1 - x_0 and
 * x_n - x_{n-1} at its ends (positions: sl_lines_tangents of lines/); the
 * same rule gives dr and dc. Any thread; no GL.
 */
#include "tubes_nodes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lines/sl_lines_prep.h"

/* Derivative of a per-vertex scalar series at vertex v of a line [lo, hi)
 * (the Catmull-Rom rule sl_lines_tangents applies to positions). */
static float series_derivative(const float *x, size_t lo, size_t hi, size_t v)
{
    if (hi - lo < 2)
        return 0.0f;
    if (v == lo)
        return x[v + 1] - x[v];
    if (v + 1 == hi)
        return x[v] - x[v - 1];
    return 0.5f * (x[v + 1] - x[v - 1]);
}

static int find_derivative_attribute(const sl_lines *lines, const char *base)
{
    char name[SL_NAME_MAX + 16];
    snprintf(name, sizeof name, "%s%s", base, SL_ATTR_DERIVATIVE_SUFFIX);
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
            n->color[2 * v + 1] = dc ? dc[v] : series_derivative(c, lo, hi, v);
            if (!isfinite(n->color[2 * v + 1]))
                n->color[2 * v + 1] = 0.0f;
        }
    }
    n->color_attribute = color_attribute;
}

void sl_tubes_nodes_set_radii(const sl_lines *lines, int radius_attribute, sl_tubes_nodes *n)
{
    if (!n->geometry || radius_attribute < 0 || radius_attribute >= lines->attribute_count)
        return;
    const float *r = lines->attributes[radius_attribute].values;
    int d = find_derivative_attribute(lines, lines->attributes[radius_attribute].name);
    const float *dr = d >= 0 ? lines->attributes[d].values : NULL;
    sl_lines_attribute_radii(lines, radius_attribute, n->geometry + 3, SL_TUBES_NODE_FLOATS);
    for (size_t k = 0; k < lines->line_count; k++) {
        size_t lo = lines->line_offsets[k], hi = lines->line_offsets[k + 1];
        for (size_t v = lo; v < hi; v++) {
            float *g = n->geometry + v * SL_TUBES_NODE_FLOATS;
            g[7] = dr ? dr[v] : series_derivative(r, lo, hi, v);
            if (!isfinite(g[7]))
                g[7] = 0.0f;
        }
    }
    n->has_radii = 1;
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
    float *fd3 = malloc((nv ? nv : 1) * 3 * sizeof(float)); /* Catmull-Rom position tangents */
    if (!out->geometry || !out->color || !out->segments || !fd3) {
        free(fd3);
        sl_tubes_nodes_deinit(out);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu tube nodes and %zu segments", nv, ns);
    }
    out->node_count = nv;
    out->segment_count = ns;
    out->has_radii = lines->radii != NULL;

    int explicit_hermite = sl_lines_find_attribute(lines, SL_ATTR_RADIUS_DERIVATIVE) >= 0;
    int exact = lines->tangents && (tangents == SL_TUBES_TANGENTS_DATA_EXACT ||
                                    (tangents == SL_TUBES_TANGENTS_AUTO && explicit_hermite));
    int directions = lines->tangents && tangents == SL_TUBES_TANGENTS_AUTO && !explicit_hermite;
    int dr_attr = exact ? sl_lines_find_attribute(lines, SL_ATTR_RADIUS_DERIVATIVE) : -1;
    sl_lines_tangents(lines, SL_LINES_TANGENT_CATMULL_ROM, fd3);
    size_t s = 0;
    for (size_t k = 0; k < lines->line_count; k++) {
        size_t lo = lines->line_offsets[k], hi = lines->line_offsets[k + 1];
        for (size_t v = lo; v < hi; v++) {
            float *g = out->geometry + v * SL_TUBES_NODE_FLOATS;
            double fd[3], fd_len = 0.0, data_len = 0.0;
            for (int c = 0; c < 3; c++) {
                g[c] = lines->positions[3 * v + c];
                fd[c] = fd3[3 * v + c];
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
                                    : series_derivative(lines->radii, lo, hi, v);
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
    free(fd3);
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
