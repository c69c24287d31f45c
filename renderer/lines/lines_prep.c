/* lines_prep.c — shared CPU line preparation (see sl_lines_prep.h).
 *
 * Tangents and transported normals use float arithmetic in exactly the order
 * the tube sweep used before it moved here (tube_mesh.c), so the swept meshes
 * (and their golden images) are bit-identical; test_lines_prep.c keeps a copy
 * of that loop to guard it. Sums along lines (accumulate, bounds, box test)
 * are in double. Any thread; no GL.
 */
#include "sl_lines_prep.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "lines_v3f.h"

static int finite3(v3f a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

/* Any unit vector orthogonal to the unit vector t. */
static v3f any_orthogonal(v3f t)
{
    v3f axis = fabsf(t.x) < 0.6f ? (v3f){1, 0, 0} : (fabsf(t.y) < 0.6f ? (v3f){0, 1, 0} : (v3f){0, 0, 1});
    return vnorm(vcross(t, axis));
}

static v3f position(const sl_lines *l, size_t v) { return load(&l->positions[3 * v]); }

/* The first vertex after kept vertex v (before end) at a non-zero distance from it, or end. */
static size_t next_kept(const sl_lines *l, size_t v, size_t end)
{
    size_t w = v + 1;
    while (w < end && vlen(vsub(position(l, w), position(l, v))) == 0.0f)
        w++;
    return w;
}

size_t sl_lines_kept(const sl_lines *l, size_t line, size_t *kept)
{
    size_t first = l->line_offsets[line], end = l->line_offsets[line + 1], n = 0;
    for (size_t v = first; v < end; v = next_kept(l, v, end))
        kept[n++] = v;
    return n;
}

/* Fills t3 from kept vertex v to the next kept vertex (exclusive) with t. */
static void fill3(float *a3, size_t from, size_t to, v3f t)
{
    for (size_t w = from; w < to; w++)
        store(&a3[3 * w], t);
}

static size_t bisector_tangents(const sl_lines *l, float *t3)
{
    size_t segments = 0;
    for (size_t li = 0; li < l->line_count; li++) {
        size_t first = l->line_offsets[li], end = l->line_offsets[li + 1];
        size_t prev = end; /* none */
        for (size_t v = first; v < end;) {
            size_t next = next_kept(l, v, end);
            v3f p = position(l, v);
            v3f d_in = prev < end ? vnorm(vsub(p, position(l, prev))) : (v3f){0, 0, 0};
            v3f d_out = next < end ? vnorm(vsub(position(l, next), p)) : (v3f){0, 0, 0};
            v3f t = vnorm(vadd(d_in, d_out));
            if (vlen(t) < 1e-6f)
                t = prev < end ? d_in : d_out;
            fill3(t3, v, next, t);
            if (next < end)
                segments++;
            prev = v;
            v = next;
        }
    }
    return segments;
}

static size_t catmull_rom_tangents(const sl_lines *l, float *t3)
{
    size_t segments = 0;
    for (size_t li = 0; li < l->line_count; li++) {
        size_t lo = l->line_offsets[li], hi = l->line_offsets[li + 1];
        for (size_t v = lo; v < hi; v++)
            for (int c = 0; c < 3; c++) {
                const float *x = l->positions;
                float d = 0.0f;
                if (hi - lo < 2)
                    d = 0.0f;
                else if (v == lo)
                    d = x[3 * (v + 1) + c] - x[3 * v + c];
                else if (v + 1 == hi)
                    d = x[3 * v + c] - x[3 * (v - 1) + c];
                else
                    d = 0.5f * (x[3 * (v + 1) + c] - x[3 * (v - 1) + c]);
                t3[3 * v + c] = d;
            }
        for (size_t v = lo; v < hi; v = next_kept(l, v, hi))
            if (next_kept(l, v, hi) < hi)
                segments++;
    }
    return segments;
}

size_t sl_lines_tangents(const sl_lines *l, sl_lines_tangent_rule rule, float *t3)
{
    return rule == SL_LINES_TANGENT_CATMULL_ROM ? catmull_rom_tangents(l, t3) : bisector_tangents(l, t3);
}

void sl_lines_transport_normals(const sl_lines *l, const float *t3, const float *seed3, float *n3)
{
    for (size_t li = 0; li < l->line_count; li++) {
        size_t first = l->line_offsets[li], end = l->line_offsets[li + 1];
        if (first == end)
            continue;
        if (next_kept(l, first, end) == end) {
            fill3(n3, first, end, (v3f){1, 0, 0});
            continue;
        }
        v3f normal = {0, 0, 0};
        for (size_t v = first; v < end;) {
            size_t next = next_kept(l, v, end);
            v3f t = load(&t3[3 * v]);
            if (v == first) {
                v3f seed = seed3 ? load(&seed3[3 * v]) : (v3f){0, 0, 0};
                normal = seed3 && finite3(seed) ? vnorm(vsub(seed, vscale(t, vdot(seed, t)))) : any_orthogonal(t);
            } else {
                normal = vnorm(vsub(normal, vscale(t, vdot(normal, t))));
            }
            if (vlen(normal) < 0.5f)
                normal = any_orthogonal(t);
            fill3(n3, v, next, normal);
            v = next;
        }
    }
}

size_t sl_lines_project_normals(const sl_lines *l, const float *t3, const float *given3, float *n3)
{
    size_t fallbacks = 0;
    for (size_t li = 0; li < l->line_count; li++) {
        size_t first = l->line_offsets[li], end = l->line_offsets[li + 1];
        v3f prev = {0, 0, 0};
        for (size_t v = first; v < end; v++) {
            v3f t = load(&t3[3 * v]), g = load(&given3[3 * v]);
            v3f n = vsub(g, vscale(t, vdot(g, t)));
            float glen = vlen(g), nlen = vlen(n);
            if (finite3(g) && finite3(n) && glen > 0.0f && nlen >= 1e-3f * glen) {
                n = vscale(n, 1.0f / nlen);
                if (v > first && vdot(n, prev) < 0.0f)
                    n = vscale(n, -1.0f);
            } else {
                fallbacks++;
                n = v > first ? vnorm(vsub(prev, vscale(t, vdot(prev, t)))) : (v3f){0, 0, 0};
                if (vlen(n) < 0.5f)
                    n = vlen(t) > 0.0f ? any_orthogonal(t) : (v > first ? prev : (v3f){1, 0, 0});
            }
            store(&n3[3 * v], n);
            prev = n;
        }
    }
    return fallbacks;
}

void sl_lines_attribute_radii(const sl_lines *l, int attribute, float *out, size_t stride)
{
    const float *v = l->attributes[attribute].values;
    for (size_t i = 0; i < l->vertex_count; i++)
        out[i * stride] = isfinite(v[i]) ? fabsf(v[i]) : 0.0f;
}

static double value_at(const float *values, size_t v)
{
    if (!values)
        return 1.0;
    return isfinite(values[v]) ? (double)values[v] : 0.0;
}

static double segment_length(const sl_lines *l, size_t v) /* |x[v] - x[v-1]| */
{
    const float *p = &l->positions[3 * v], *q = p - 3;
    double dx = (double)p[0] - q[0], dy = (double)p[1] - q[1], dz = (double)p[2] - q[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

void sl_lines_accumulate(const sl_lines *l, const float *values, double limit, float *out, float *d_ds)
{
    for (size_t li = 0; li < l->line_count; li++) {
        size_t first = l->line_offsets[li], end = l->line_offsets[li + 1];
        if (first == end)
            continue;
        /* Sliding window over (s, R) of vertices v - 1, v, v + 1. */
        double s_prev = 0.0, r_prev = 0.0, s = 0.0, r = 0.0;
        for (size_t v = first; v < end; v++) {
            double s_next = s, r_next = r;
            if (v + 1 < end) {
                double len = segment_length(l, v + 1);
                s_next = s + len;
                r_next = r + 0.5 * (value_at(values, v) + value_at(values, v + 1)) * len;
                r_next = fmin(fmax(r_next, -limit), limit);
            }
            out[v] = (float)r;
            if (d_ds) {
                double ds = (v + 1 < end ? s_next : s) - (v > first ? s_prev : s);
                double dr = (v + 1 < end ? r_next : r) - (v > first ? r_prev : r);
                d_ds[v] = ds > 0.0 ? (float)(dr / ds) : 0.0f;
            }
            s_prev = s, r_prev = r;
            s = s_next, r = r_next;
        }
    }
}

sl_status sl_lines_chunks_build(const sl_lines *l, uint32_t max_segments, sl_line_chunk **out, size_t *count,
                                sl_err *err)
{
    *out = NULL;
    *count = 0;
    if (max_segments == 0)
        return sl_err_set(err, SL_ERR_INVALID, "line chunks need at least 1 segment each, got 0");
    size_t n = 0;
    for (size_t li = 0; li < l->line_count; li++) {
        size_t len = l->line_offsets[li + 1] - l->line_offsets[li];
        if (len >= 2)
            n += (len - 2) / max_segments + 1;
    }
    if (n == 0)
        return SL_OK;
    sl_line_chunk *c = malloc(n * sizeof *c);
    if (!c)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu line chunks", n);
    size_t k = 0;
    for (size_t li = 0; li < l->line_count; li++) {
        uint32_t first = l->line_offsets[li], end = l->line_offsets[li + 1];
        for (uint32_t p = first; p + 1 < end; p += max_segments) {
            uint32_t segs = end - 1 - p < max_segments ? end - 1 - p : max_segments;
            sl_line_chunk *ch = &c[k++];
            ch->first_point = p;
            ch->segments = segs;
            ch->line = (uint32_t)li;
            for (int a = 0; a < 3; a++)
                ch->lo[a] = ch->hi[a] = l->positions[3 * (size_t)p + a];
            for (uint32_t v = p + 1; v <= p + segs; v++)
                for (int a = 0; a < 3; a++) {
                    float x = l->positions[3 * (size_t)v + a];
                    ch->lo[a] = fminf(ch->lo[a], x);
                    ch->hi[a] = fmaxf(ch->hi[a], x);
                }
        }
    }
    *out = c;
    *count = k;
    return SL_OK;
}

int sl_lines_box_visible(const sl_view *view, sl_vec3 origin, const float lo[3], const float hi[3], double grow)
{
    /* Eye-space corners: z along F (forward), x along R, y along U. */
    double ex[8], ey[8], ez[8];
    for (int k = 0; k < 8; k++) {
        sl_vec3 corner = sl_v3(origin.x + (k & 1 ? hi[0] + grow : lo[0] - grow),
                               origin.y + (k & 2 ? hi[1] + grow : lo[1] - grow),
                               origin.z + (k & 4 ? hi[2] + grow : lo[2] - grow));
        sl_vec3 d = sl_v3_sub(corner, view->camera.eye);
        ex[k] = sl_v3_dot(d, view->right);
        ey[k] = sl_v3_dot(d, view->upv);
        ez[k] = sl_v3_dot(d, view->forward);
    }
    double tx = view->tan_half_fov * view->aspect, ty = view->tan_half_fov;
    int out_near = 1, out_right = 1, out_left = 1, out_top = 1, out_bottom = 1;
    for (int k = 0; k < 8; k++) {
        out_near &= ez[k] < view->near_plane;
        out_right &= ex[k] > tx * ez[k];
        out_left &= ex[k] < -tx * ez[k];
        out_top &= ey[k] > ty * ez[k];
        out_bottom &= ey[k] < -ty * ez[k];
    }
    return !(out_near || out_right || out_left || out_top || out_bottom);
}

void sl_lines_position_bounds(const sl_lines *l, double lo[3], double hi[3])
{
    for (int c = 0; c < 3; c++) {
        lo[c] = DBL_MAX;
        hi[c] = -DBL_MAX;
    }
    for (size_t v = 0; v < l->vertex_count; v++)
        for (int c = 0; c < 3; c++) {
            double x = l->positions[3 * v + c];
            if (x < lo[c]) lo[c] = x;
            if (x > hi[c]) hi[c] = x;
        }
    if (l->vertex_count == 0)
        for (int c = 0; c < 3; c++)
            lo[c] = hi[c] = 0.0;
}
