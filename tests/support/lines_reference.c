/* lines_reference.c — exact tube crossings per ray, composited (see lines_reference.h).
 *
 * A capsule is convex, so a ray meets it in one interval: the hull of the
 * intervals of its three parts (two spheres, the cylinder between the end
 * planes), each solved in closed form in double. One polyline's capsule
 * intervals are sorted and merged into crossings; all crossings of a pixel
 * are sorted and blended.
 */
#include "lines_reference.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct hit {
    double t_in, t_out; /* Euclidean distance along the unit ray */
    double n[3];        /* outward unit normal at t_in */
    int surface;        /* 0: entered through an open end's disk (no surface there) */
    size_t curve;
} hit;

typedef struct hits {
    hit *v;
    size_t n, cap;
} hits;

static int hits_push(hits *h, hit x)
{
    if (h->n == h->cap) {
        size_t cap = h->cap ? 2 * h->cap : 64;
        hit *v = realloc(h->v, cap * sizeof *v);
        if (!v)
            return -1;
        h->v = v;
        h->cap = cap;
    }
    h->v[h->n++] = x;
    return 0;
}

static int by_entry(const void *a, const void *b)
{
    double x = ((const hit *)a)->t_in, y = ((const hit *)b)->t_in;
    return x < y ? -1 : (x > y);
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Ray o + t d (|d| = 1) against the sphere (c, r): entry/exit, 0 when missed. */
static int sphere(const double *o, const double *d, const double *c, double r, double *t0, double *t1)
{
    double oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
    double b = dot3(oc, d), q = dot3(oc, oc) - r * r;
    double disc = b * b - q;
    if (disc < 0.0)
        return 0;
    double s = sqrt(disc);
    *t0 = -b - s;
    *t1 = -b + s;
    return 1;
}

/* Ray against the capsule a-b of radius r: its interval and the entry
 * normal. open_a / open_b leave out the sphere at that end (an open tube
 * end): an interval entering through the end disk has no surface entry
 * (surface = 0; it still merges with the next pieces, but blends nothing). */
static int capsule(const double *o, const double *d, const double *a, const double *b, double r, int open_a,
                   int open_b, hit *out)
{
    double t_in = INFINITY, t_out = -INFINITY, n[3] = {0, 0, 0};
    int surface = 1;
    const double *ends[2] = {a, b};
    int open[2] = {open_a, open_b};
    for (int e = 0; e < 2; e++) {
        double t0, t1;
        if (open[e] || !sphere(o, d, ends[e], r, &t0, &t1))
            continue;
        if (t0 < t_in) {
            t_in = t0;
            for (int k = 0; k < 3; k++)
                n[k] = (o[k] + t0 * d[k] - ends[e][k]) / r;
        }
        t_out = fmax(t_out, t1);
    }
    double axis[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double len = sqrt(dot3(axis, axis));
    if (len > 0.0) {
        double u[3] = {axis[0] / len, axis[1] / len, axis[2] / len};
        double oa[3] = {o[0] - a[0], o[1] - a[1], o[2] - a[2]};
        double du = dot3(d, u), ou = dot3(oa, u);
        double w[3], q[3];
        for (int k = 0; k < 3; k++) {
            w[k] = d[k] - du * u[k];
            q[k] = oa[k] - ou * u[k];
        }
        double ww = dot3(w, w), qw = dot3(q, w), qq = dot3(q, q) - r * r;
        double c0 = -INFINITY, c1 = INFINITY; /* inside the infinite cylinder */
        int inside = 1;
        if (ww > 1e-24) {
            double disc = qw * qw - ww * qq;
            if (disc < 0.0)
                inside = 0;
            else {
                double s = sqrt(disc);
                c0 = (-qw - s) / ww;
                c1 = (-qw + s) / ww;
            }
        } else if (qq >= 0.0) {
            inside = 0; /* parallel to the axis, outside the cylinder */
        }
        /* Between the end planes: 0 <= ou + t du <= len. */
        double s0 = -INFINITY, s1 = INFINITY;
        int s0_open = 0; /* the entry plane is an open end */
        if (fabs(du) > 1e-300) {
            double ta = -ou / du, tb = (len - ou) / du;
            s0 = fmin(ta, tb);
            s1 = fmax(ta, tb);
            s0_open = ta < tb ? open_a : open_b;
        } else if (ou < 0.0 || ou > len) {
            inside = 0;
        }
        double lo = fmax(c0, s0), hi = fmin(c1, s1);
        if (inside && lo <= hi) {
            /* An entry on the cylinder surface (not at an end plane, where a
             * sphere enters no later) sets the normal. */
            if (c0 >= s0 && lo < t_in) {
                t_in = lo;
                double p = ou + lo * du;
                for (int k = 0; k < 3; k++)
                    n[k] = (oa[k] + lo * d[k] - p * u[k]) / r;
            } else if (c0 < s0 && s0_open && lo < t_in) {
                t_in = lo; /* through the open end's disk */
                surface = 0;
            }
            t_out = fmax(t_out, hi);
        }
    }
    if (!(t_in <= t_out))
        return 0;
    out->t_in = t_in;
    out->t_out = t_out;
    out->surface = surface;
    double nl = sqrt(dot3(n, n));
    for (int k = 0; k < 3; k++)
        out->n[k] = nl > 0.0 ? n[k] / nl : 0.0;
    return 1;
}

#define CHUNK 8 /* segments per bounding box within a polyline */

/* Box of vertices [from, to) grown by r: lo in out[0..2], hi in out[3..5]. */
static void box_of(const sl_lines *L, const double *org, double r, uint32_t from, uint32_t to, double *out)
{
    for (int k = 0; k < 3; k++) {
        out[k] = INFINITY;
        out[3 + k] = -INFINITY;
    }
    for (uint32_t i = from; i < to; i++)
        for (int k = 0; k < 3; k++) {
            double p = org[k] + L->positions[3 * i + k];
            out[k] = fmin(out[k], p - r);
            out[3 + k] = fmax(out[3 + k], p + r);
        }
}

/* Slab test of the ray against [lo, hi]. */
static int box_hit(const double *o, const double *d, const double *lo, const double *hi)
{
    double t0 = -INFINITY, t1 = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (d[k] == 0.0) {
            if (o[k] < lo[k] || o[k] > hi[k])
                return 0;
            continue;
        }
        double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        t0 = fmax(t0, fmin(a, b));
        t1 = fmin(t1, fmax(a, b));
    }
    return t0 <= t1 && t1 >= 0.0;
}

static double shade_channel(double base, double diff, double spec, const lines_ref_desc *g)
{
    double c = base * (g->ambient + g->diffuse * diff) + g->specular * spec;
    return c < 0.0 ? 0.0 : (c > 1.0 ? 1.0 : c);
}

int lines_ref_render(const lines_ref_desc *g, uint8_t *rgba, lines_ref_stats *stats)
{
    const sl_view *v = g->view;
    if (!v || !g->lines || g->lines->kind != SL_DATASET_LINES || !g->curve_rgb || !(g->radius > 0.0) || !rgba)
        return -1;
    const sl_lines *L = &g->lines->lines;
    size_t nc = L->line_count;
    double r = g->radius;
    double org[3] = {g->lines->origin.x, g->lines->origin.y, g->lines->origin.z};
    /* Boxes (grown by r) per polyline and per chunk of CHUNK segments. */
    size_t chunks = 0;
    for (size_t c = 0; c < nc; c++) {
        uint32_t nv = L->line_offsets[c + 1] - L->line_offsets[c];
        chunks += nv > 1 ? (nv - 2) / CHUNK + 1 : 1;
    }
    double *box = malloc((nc + 1) * 6 * sizeof *box), *chunk_box = malloc((chunks + 1) * 6 * sizeof *chunk_box);
    size_t *curve_chunk = malloc((nc + 1) * sizeof *curve_chunk);
    hits curve = {0}, pixel = {0};
    if (!box || !chunk_box || !curve_chunk) {
        free(box);
        free(chunk_box);
        free(curve_chunk);
        return -1;
    }
    size_t ch = 0;
    for (size_t c = 0; c < nc; c++) {
        uint32_t first = L->line_offsets[c], end = L->line_offsets[c + 1];
        curve_chunk[c] = ch;
        box_of(L, org, r, first, end, box + 6 * c);
        for (uint32_t s0 = first; s0 + 1 < end || (s0 == first && end > first); s0 += CHUNK) {
            uint32_t s1 = s0 + CHUNK + 1 < end ? s0 + CHUNK + 1 : end; /* vertices [s0, s1) */
            box_of(L, org, r, s0, s1, chunk_box + 6 * ch++);
        }
    }
    curve_chunk[nc] = ch;
    double eye[3] = {v->camera.eye.x, v->camera.eye.y, v->camera.eye.z};
    double F[3] = {v->forward.x, v->forward.y, v->forward.z}, R[3] = {v->right.x, v->right.y, v->right.z},
           U[3] = {v->upv.x, v->upv.y, v->upv.z};
    double light[3];
    for (int k = 0; k < 3; k++)
        light[k] = g->light_eye[0] * R[k] + g->light_eye[1] * U[k] - g->light_eye[2] * F[k];
    lines_ref_stats st = {0};
    int rc = 0;
    for (int j = 0; j < v->height && rc == 0; j++)
        for (int i = 0; i < v->width && rc == 0; i++) {
            sl_vec3 dv = sl_view_ray_dir(v, i, j);
            double d[3] = {dv.x, dv.y, dv.z};
            double t_near = v->near_plane / dot3(d, F);
            pixel.n = 0;
            for (size_t c = 0; c < nc && rc == 0; c++) {
                if (L->line_offsets[c + 1] == L->line_offsets[c] || !box_hit(eye, d, box + 6 * c, box + 6 * c + 3))
                    continue;
                curve.n = 0;
                uint32_t first = L->line_offsets[c], last = L->line_offsets[c + 1] - 1;
                for (uint32_t s = first; s < last && rc == 0; s++) {
                    if ((s - first) % CHUNK == 0) {
                        const double *cb = chunk_box + 6 * (curve_chunk[c] + (s - first) / CHUNK);
                        if (!box_hit(eye, d, cb, cb + 3)) {
                            s += CHUNK - 1;
                            continue;
                        }
                    }
                    double a[3], b[3];
                    for (int k = 0; k < 3; k++) {
                        a[k] = org[k] + L->positions[3 * s + k];
                        b[k] = org[k] + L->positions[3 * (s + 1) + k];
                    }
                    hit h;
                    int open_a = g->open_ends && s == first, open_b = g->open_ends && s + 1 == last;
                    if (capsule(eye, d, a, b, r, open_a, open_b, &h) && h.t_out >= t_near) {
                        h.curve = c;
                        rc = hits_push(&curve, h);
                    }
                }
                /* A single-vertex polyline is a sphere. */
                if (last == first && !g->open_ends) {
                    double a[3];
                    for (int k = 0; k < 3; k++)
                        a[k] = org[k] + L->positions[3 * L->line_offsets[c] + k];
                    hit h;
                    if (capsule(eye, d, a, a, r, 0, 0, &h) && h.t_out >= t_near) {
                        h.curve = c;
                        rc = hits_push(&curve, h);
                    }
                }
                if (curve.n > 1)
                    qsort(curve.v, curve.n, sizeof *curve.v, by_entry);
                /* Merge overlapping capsule intervals into crossings. */
                size_t crossings_before = 0;
                for (size_t k = 0; k < curve.n && rc == 0;) {
                    hit x = curve.v[k];
                    size_t m = k + 1;
                    while (m < curve.n && curve.v[m].t_in <= x.t_out)
                        x.t_out = fmax(x.t_out, curve.v[m++].t_out);
                    x.t_in = fmax(x.t_in, t_near);
                    rc = hits_push(&pixel, x);
                    st.repeat_crossings += crossings_before++ > 0;
                    k = m;
                }
            }
            if (rc != 0)
                break;
            if (pixel.n > 1)
                qsort(pixel.v, pixel.n, sizeof *pixel.v, by_entry);
            double acc[3] = {0, 0, 0}, alpha = 0.0;
            double view_dir[3] = {-d[0], -d[1], -d[2]};
            for (size_t k = 0; k < pixel.n && alpha < g->alpha_stop; k++) {
                const hit *x = &pixel.v[k];
                if (!x->surface)
                    continue;
                double n[3] = {x->n[0], x->n[1], x->n[2]};
                if (dot3(n, view_dir) < 0.0)
                    for (int q = 0; q < 3; q++)
                        n[q] = -n[q];
                double diff = fmax(dot3(n, light), 0.0);
                double hv[3] = {light[0] + view_dir[0], light[1] + view_dir[1], light[2] + view_dir[2]};
                double hl = sqrt(dot3(hv, hv));
                double spec = 0.0;
                if (diff > 0.0 && hl > 0.0)
                    spec = pow(fmax(dot3(n, hv) / hl, 0.0), g->shininess);
                const float *base = g->curve_rgb + 3 * x->curve;
                for (int q = 0; q < 3; q++)
                    acc[q] += (1.0 - alpha) * g->opacity * shade_channel(base[q], diff, spec, g);
                alpha += (1.0 - alpha) * g->opacity;
            }
            uint8_t *px = rgba + 4 * ((size_t)j * v->width + i);
            for (int q = 0; q < 3; q++) {
                double c = acc[q] + (1.0 - alpha) * v->background[q];
                px[q] = (uint8_t)lround(255.0 * fmin(fmax(c, 0.0), 1.0));
            }
            px[3] = 255;
            st.pixels_hit += pixel.n > 0;
            st.crossings += pixel.n;
            if (pixel.n > st.max_crossings)
                st.max_crossings = pixel.n;
        }
    free(box);
    free(chunk_box);
    free(curve_chunk);
    free(curve.v);
    free(pixel.v);
    if (stats)
        *stats = st;
    return rc;
}
