/* voxel_cast_cpu.c — voxel_cast_cpu.h: voxel_lines.frag.glsl and voxel_lines_light.glsl
 * step by step in C (float, as the GLSL), one ray per pixel, tiles on all cores. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../core/sl_parallel.h"
#include "voxel_cast_cpu.h"

#define MAX_HITS 32 /* voxel_lines.frag.glsl */
#define MAX_OPEN 32
#define TILE 16

static inline float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* --- The model ------------------------------------------------------------ */

void sl_voxel_cast_model_deinit(sl_voxel_cast_model *m)
{
    if (!m)
        return;
    free(m->first);
    free(m->count);
    free(m->ab);
    free(m->key);
    free(m->abs_ab);
    free(m->reach_first);
    free(m->reach_line);
    sl_voxel_occupancy_deinit(&m->reach_occupancy);
    for (int L = 0; L < SL_VOXEL_CAST_MAX_LEVELS; L++)
        free(m->density[L]);
    free(m->ao);
    *m = (sl_voxel_cast_model){0};
}

sl_status sl_voxel_cast_model_build(sl_voxel_cast_model *m, const sl_voxel_grid *g, sl_err *err)
{
    *m = (sl_voxel_cast_model){0};
    memcpy(m->dims, g->frame.dims, sizeof m->dims);
    size_t nv = g->voxel_count ? g->voxel_count : 1, nl = g->line_count ? g->line_count : 1;
    m->first = malloc(nv * sizeof *m->first);
    m->count = malloc(nv);
    m->ab = malloc(nl * 6 * sizeof *m->ab);
    m->key = malloc(nl * sizeof *m->key);
    m->abs_ab = malloc(nl * SL_VOXEL_CAST_SPAN * sizeof *m->abs_ab);
    if (!m->first || !m->count || !m->ab || !m->key || !m->abs_ab) {
        sl_voxel_cast_model_deinit(m);
        return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines (cpu): out of memory for %zu lines", g->line_count);
    }
    if (g->voxel_count) {
        memcpy(m->first, g->offsets, g->voxel_count * sizeof *m->first);
        memcpy(m->count, g->counts, g->voxel_count);
    }
    m->line_count = g->line_count;
    for (size_t i = 0; i < g->line_count; i++) {
        sl_voxel_line line;
        sl_voxel_decode_line(g->quant_bits, sl_voxel_grid_line(g, i), &line);
        double a[3], b[3];
        sl_voxel_dequantize(line.face_a, line.bin_a, g->quant, a);
        sl_voxel_dequantize(line.face_b, line.bin_b, g->quant, b);
        for (int c = 0; c < 3; c++) {
            m->ab[6 * i + c] = (float)a[c];
            m->ab[6 * i + 3 + c] = (float)b[c];
        }
        m->key[i] = line.attr << 16 | (line.id & 0xffffu);
    }
    for (int z = 0; z < m->dims[2]; z++)
        for (int y = 0; y < m->dims[1]; y++)
            for (int x = 0; x < m->dims[0]; x++) {
                size_t v = (size_t)x + (size_t)m->dims[0] * ((size_t)y + (size_t)m->dims[1] * z);
                float corner[3] = {(float)x, (float)y, (float)z};
                for (uint32_t l = 0; l < m->count[v]; l++) {
                    size_t i = (size_t)m->first[v] + l;
                    float *span = m->abs_ab + SL_VOXEL_CAST_SPAN * i;
                    for (int c = 0; c < 6; c++)
                        span[c] = corner[c % 3] + m->ab[6 * i + c];
                    float ba[3] = {span[3] - span[0], span[4] - span[1], span[5] - span[2]};
                    span[6] = 0.5f * sqrtf(dot3(ba, ba));
                    span[7] = 0.0f;
                }
            }
    return SL_OK;
}

/* The voxels [lo, hi] (per axis, clamped to the grid and to home +- R) that the box of
 * line i's tube, grown by reach, overlaps. */
static void reach_range(const sl_voxel_cast_model *m, size_t i, const int home[3], int R, float reach, int lo[3],
                        int hi[3])
{
    const float *ab = m->abs_ab + SL_VOXEL_CAST_SPAN * i;
    for (int c = 0; c < 3; c++) {
        float a = ab[c], b = ab[3 + c];
        int l = (int)floorf((a < b ? a : b) - reach), h = (int)floorf((a > b ? a : b) + reach);
        l = l < home[c] - R ? home[c] - R : l;
        h = h > home[c] + R ? home[c] + R : h;
        lo[c] = l < 0 ? 0 : l;
        hi[c] = h > m->dims[c] - 1 ? m->dims[c] - 1 : h;
    }
}

sl_status sl_voxel_cast_model_reach(sl_voxel_cast_model *m, float radius_g, int R, sl_err *err)
{
    if (m->reach_valid && m->reach_radius == radius_g && m->reach_r == R)
        return SL_OK;
    m->reach_valid = 0;
    float reach = radius_g + 2e-3f; /* the walk's box reach (radius + 1e-3) and a margin */
    size_t nv = (size_t)m->dims[0] * m->dims[1] * m->dims[2];
    free(m->reach_first);
    free(m->reach_line);
    m->reach_line = NULL;
    m->reach_first = malloc((nv + 1) * sizeof *m->reach_first);
    uint32_t *fill = calloc(nv ? nv : 1, sizeof *fill); /* pass 0: each voxel's count; 1: entries placed */
    if (!m->reach_first || !fill) {
        free(fill);
        return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines (cpu): out of memory for the reach lists");
    }
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            size_t total = 0;
            for (size_t v = 0; v < nv; v++) {
                if (total > UINT32_MAX - fill[v]) {
                    free(fill);
                    return sl_err_set(err, SL_ERR_LIMIT, "voxel_lines (cpu): reach lists above 2^32 entries");
                }
                m->reach_first[v] = (uint32_t)total;
                total += fill[v];
                fill[v] = 0;
            }
            m->reach_first[nv] = (uint32_t)total;
            m->reach_line = malloc((total ? total : 1) * sizeof *m->reach_line);
            if (!m->reach_line) {
                free(fill);
                return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines (cpu): out of memory for %zu reach entries", total);
            }
        }
        for (int z = 0; z < m->dims[2]; z++)
            for (int y = 0; y < m->dims[1]; y++)
                for (int x = 0; x < m->dims[0]; x++) {
                    size_t hv = (size_t)x + (size_t)m->dims[0] * ((size_t)y + (size_t)m->dims[1] * z);
                    int home[3] = {x, y, z};
                    for (uint32_t l = 0; l < m->count[hv]; l++) {
                        size_t i = (size_t)m->first[hv] + l;
                        int lo[3], hi[3];
                        reach_range(m, i, home, R, reach, lo, hi);
                        for (int cz = lo[2]; cz <= hi[2]; cz++)
                            for (int cy = lo[1]; cy <= hi[1]; cy++)
                                for (int cx = lo[0]; cx <= hi[0]; cx++) {
                                    size_t v = (size_t)cx + (size_t)m->dims[0] * ((size_t)cy + (size_t)m->dims[1] * cz);
                                    if (pass == 1)
                                        m->reach_line[m->reach_first[v] + fill[v]] = (uint32_t)i;
                                    fill[v]++;
                                }
                    }
                }
    }
    free(fill);
    uint8_t *listed = malloc(nv ? nv : 1);
    if (!listed)
        return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines (cpu): out of memory for the reach occupancy");
    for (size_t v = 0; v < nv; v++)
        listed[v] = m->reach_first[v + 1] != m->reach_first[v];
    sl_voxel_occupancy_deinit(&m->reach_occupancy);
    sl_status st = sl_voxel_occupancy_build(m->dims, listed, 0, &m->reach_occupancy, err);
    free(listed);
    if (st != SL_OK)
        return st;
    m->reach_radius = radius_g;
    m->reach_r = R;
    m->reach_valid = 1;
    return SL_OK;
}

float *sl_voxel_cast_density_level(sl_voxel_cast_model *m, int level, const int d[3], sl_err *err)
{
    if (level < 0 || level >= SL_VOXEL_CAST_MAX_LEVELS) {
        sl_err_set(err, SL_ERR_LIMIT, "voxel_lines (cpu): density level %d above %d", level,
                   SL_VOXEL_CAST_MAX_LEVELS - 1);
        return NULL;
    }
    free(m->density[level]);
    m->density[level] = malloc((size_t)d[0] * d[1] * d[2] * sizeof(float));
    if (!m->density[level]) {
        sl_err_set(err, SL_ERR_NOMEM, "voxel_lines (cpu): out of memory for density level %d", level);
        return NULL;
    }
    memcpy(m->density_dims[level], d, sizeof m->density_dims[level]);
    if (level + 1 > m->density_levels)
        m->density_levels = level + 1;
    return m->density[level];
}

uint8_t *sl_voxel_cast_ao(sl_voxel_cast_model *m, const int d[3], sl_err *err)
{
    free(m->ao);
    m->ao = malloc((size_t)d[0] * d[1] * d[2]);
    if (!m->ao) {
        sl_err_set(err, SL_ERR_NOMEM, "voxel_lines (cpu): out of memory for the AO field");
        return NULL;
    }
    memcpy(m->ao_dims, d, sizeof m->ao_dims);
    return m->ao;
}

/* --- Small helpers (float, as GLSL) ------------------------------------------ */

/* GLSL's min and max (undefined for NaN there); libm's fminf/fmaxf are calls that
 * keep NaN rules and cost a third of the frame. */
static inline float min_f(float a, float b) { return b < a ? b : a; }
static inline float max_f(float a, float b) { return b > a ? b : a; }

/* --- Capsule (voxel_lines.frag.glsl: capsule) -------------------------------- */

/* Solved from the ray's point nearest a (parameter s0), as the shader does,
 * so a far eye's large |o - a| does not cancel the quadratics' terms. */
static int capsule(const float o_eye[3], const float d[3], const float a[3], const float b[3], float r,
                   float *t_in_out, float *t_out_out, float n[3])
{
    float t_in = 1e30f, t_out = -1e30f;
    float dd = dot3(d, d);
    float ao[3] = {a[0] - o_eye[0], a[1] - o_eye[1], a[2] - o_eye[2]};
    float s0 = dot3(ao, d) / dd;
    float o[3] = {o_eye[0] + s0 * d[0], o_eye[1] + s0 * d[1], o_eye[2] + s0 * d[2]};
    float ba[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, oa[3] = {o[0] - a[0], o[1] - a[1], o[2] - a[2]};
    float baba = dot3(ba, ba), bard = dot3(ba, d), baoa = dot3(ba, oa);
    float rdoa = dot3(d, oa), oaoa = dot3(oa, oa);
    float qa = baba * dd - bard * bard;
    if (qa > 1e-12f * baba * dd) {
        float qb = baba * rdoa - baoa * bard;
        float qc = baba * oaoa - baoa * baoa - r * r * baba;
        float h = qb * qb - qa * qc;
        if (h < 0.0f) {
            if (h < -1e-3f * qb * qb)
                return 0;
        } else {
            h = sqrtf(h);
            float t0 = (-qb - h) / qa, t1 = (-qb + h) / qa;
            float y0 = baoa + t0 * bard, y1 = baoa + t1 * bard;
            if (y0 > 0.0f && y0 < baba) {
                t_in = t0;
                for (int c = 0; c < 3; c++)
                    n[c] = (oa[c] + t0 * d[c] - ba[c] * (y0 / baba)) / r;
            }
            if (y1 > 0.0f && y1 < baba)
                t_out = t1;
        }
    }
    for (int e = 0; e < 2; e++) {
        const float *c = e == 0 ? a : b;
        float oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
        float sb = dot3(oc, d), sc = dot3(oc, oc) - r * r;
        float h = sb * sb - dd * sc;
        if (h < 0.0f)
            continue;
        h = sqrtf(h);
        float t0 = (-sb - h) / dd, t1 = (-sb + h) / dd;
        if (t0 < t_in) {
            t_in = t0;
            for (int k = 0; k < 3; k++)
                n[k] = (oc[k] + t0 * d[k]) / r;
        }
        t_out = max_f(t_out, t1);
    }
    *t_in_out = t_in + s0;
    *t_out_out = t_out + s0;
    return t_in < 1e29f;
}

/* 0 when ray o + s d (s >= 0) surely misses the sphere of radius br around the
 * midpoint of span's a, b (inv_dd = 1 / d.d): a cheap test before the capsule's,
 * for the reach walk, whose lists hold mostly lines a ray passes by. The
 * closest point is measured from the centre (its error grows with |c - o|:
 * that margin is added), and a sphere wholly behind the eye is missed. */
static inline int near_sphere(const float o[3], const float d[3], float inv_dd, const float *span, float br)
{
    float co[3] = {0.5f * (span[0] + span[3]) - o[0], 0.5f * (span[1] + span[4]) - o[1],
                   0.5f * (span[2] + span[5]) - o[2]};
    float s = dot3(co, d) * inv_dd;
    float q[3] = {co[0] - s * d[0], co[1] - s * d[1], co[2] - s * d[2]};
    float margin = br + 1e-6f * (fabsf(co[0]) + fabsf(co[1]) + fabsf(co[2]));
    float m2 = margin * margin;
    if (dot3(q, q) > m2)
        return 0;
    return s >= 0.0f || dot3(co, co) <= m2;
}

/* --- Per-ray state: pending hits and open intervals ---------------------------- */

typedef struct ray_state {
    float h_in[MAX_HITS], h_out[MAX_HITS], h_n[MAX_HITS][3];
    uint32_t h_key[MAX_HITS];
    int h_count;
    float open_out[MAX_OPEN];
    uint32_t open_id[MAX_OPEN];
    int open_count;
} ray_state;

static int join_open(ray_state *r, int i)
{
    uint32_t hid = r->h_key[i] & 0xffffu;
    int victim = 0;
    float victim_out = 1e30f;
    for (int j = 0; j < r->open_count; j++) {
        if (r->open_id[j] == hid && r->h_in[i] <= r->open_out[j] + 1e-4f * r->h_in[i]) {
            r->open_out[j] = max_f(r->open_out[j], r->h_out[i]);
            return 1;
        }
        if (r->open_out[j] < victim_out) {
            victim_out = r->open_out[j];
            victim = j;
        }
    }
    if (r->open_count < MAX_OPEN && victim_out >= r->h_in[i])
        victim = r->open_count++;
    r->open_id[victim] = hid;
    r->open_out[victim] = r->h_out[i];
    return 0;
}

static void move_hit(ray_state *r, int to, int from)
{
    r->h_in[to] = r->h_in[from];
    r->h_out[to] = r->h_out[from];
    memcpy(r->h_n[to], r->h_n[from], sizeof r->h_n[to]);
    r->h_key[to] = r->h_key[from];
}

static void add_hit(ray_state *r, float tin, float tout, const float n[3], uint32_t key)
{
    uint32_t id = key & 0xffffu;
    for (int k = 0; k < r->h_count; k++) {
        if ((r->h_key[k] & 0xffffu) != id || tin > r->h_out[k] || tout < r->h_in[k])
            continue;
        r->h_out[k] = max_f(r->h_out[k], tout);
        if (tin >= r->h_in[k])
            return;
        tout = r->h_out[k];
        r->h_count--;
        for (int m = k; m < r->h_count; m++)
            move_hit(r, m, m + 1);
        break;
    }
    int i = r->h_count;
    if (r->h_count == MAX_HITS) {
        if (tin >= r->h_in[MAX_HITS - 1])
            return;
        i = MAX_HITS - 1;
    } else {
        r->h_count++;
    }
    while (i > 0 && r->h_in[i - 1] > tin) {
        move_hit(r, i, i - 1);
        i--;
    }
    r->h_in[i] = tin;
    r->h_out[i] = tout;
    memcpy(r->h_n[i], n, sizeof r->h_n[i]);
    r->h_key[i] = key;
}

/* --- Light (voxel_lines_light.glsl) ------------------------------------------------ */

static float clampf(float x, float lo, float hi) { return min_f(max_f(x, lo), hi); }

/* texture() of a 3D R32F level with GL_LINEAR, CLAMP_TO_BORDER (border 0), at normalized q. */
static float sample_level(const float *v, const int d[3], const float q[3])
{
    float x = q[0] * d[0] - 0.5f, y = q[1] * d[1] - 0.5f, z = q[2] * d[2] - 0.5f;
    int x0 = (int)floorf(x), y0 = (int)floorf(y), z0 = (int)floorf(z);
    float fx = x - x0, fy = y - y0, fz = z - z0;
    float sum = 0.0f;
    for (int k = 0; k < 8; k++) {
        int xi = x0 + (k & 1), yi = y0 + ((k >> 1) & 1), zi = z0 + (k >> 2);
        if (xi < 0 || yi < 0 || zi < 0 || xi >= d[0] || yi >= d[1] || zi >= d[2])
            continue;
        float w = ((k & 1) ? fx : 1.0f - fx) * (((k >> 1) & 1) ? fy : 1.0f - fy) * ((k >> 2) ? fz : 1.0f - fz);
        sum += w * v[(size_t)xi + (size_t)d[0] * ((size_t)yi + (size_t)d[1] * zi)];
    }
    return sum;
}

/* textureLod with GL_LINEAR_MIPMAP_LINEAR. */
static float density_lod(const sl_voxel_cast_model *m, const float q[3], float lod)
{
    lod = clampf(lod, 0.0f, (float)(m->density_levels - 1));
    int l0 = (int)floorf(lod);
    float f = lod - l0;
    float v0 = sample_level(m->density[l0], m->density_dims[l0], q);
    if (f <= 0.0f || l0 + 1 >= m->density_levels)
        return v0;
    return v0 + f * (sample_level(m->density[l0 + 1], m->density_dims[l0 + 1], q) - v0);
}

static float vx_shadow(const sl_voxel_cast_model *m, const sl_voxel_cast_params *p, const float pos[3],
                       const float l[3])
{
    const int *d0 = m->density_dims[0];
    float tau = 0.0f, s = 1.0f;
    for (int i = 0; i < 128 && tau < 6.0f; i++) {
        float q[3] = {pos[0] + l[0] * s, pos[1] + l[1] * s, pos[2] + l[2] * s};
        float qn[3] = {q[0] / d0[0], q[1] / d0[1], q[2] / d0[2]};
        if (q[0] < 0.0f || q[1] < 0.0f || q[2] < 0.0f || qn[0] > 1.0f || qn[1] > 1.0f || qn[2] > 1.0f)
            break;
        float lod = clampf(p->shadow_lod + log2f(max_f(s, 1.0f)) - 1.0f, p->shadow_lod, p->max_lod);
        float step_len = exp2f(lod);
        tau += density_lod(m, qn, lod) * p->extinction * step_len;
        s += step_len;
    }
    return expf(-tau);
}

static float vx_shadow_lines(const sl_voxel_cast_params *p, const float pos[3], const float l[3])
{
    float o[3];
    for (int c = 0; c < 3; c++)
        o[c] = (pos[c] + 1.5f * l[c]) / p->rep_scale;
    int cell[3], step[3];
    float t_max[3], t_delta[3];
    for (int c = 0; c < 3; c++) {
        cell[c] = (int)floorf(o[c]);
        if (cell[c] < 0 || cell[c] >= p->rep_dims[c])
            return 1.0f;
    }
    for (int c = 0; c < 3; c++) {
        float inv = 1.0f / l[c];
        step[c] = l[c] > 0.0f ? 1 : (l[c] < 0.0f ? -1 : 0);
        t_max[c] = step[c] == 0 ? 1e30f : ((float)cell[c] + (step[c] > 0 ? 1.0f : 0.0f) - o[c]) * inv;
        t_delta[c] = step[c] == 0 ? 1e30f : fabsf(inv);
    }
    float r = min_f(p->radius_g, 0.5f);
    int its = p->rep_dims[0] + p->rep_dims[1] + p->rep_dims[2];
    for (int it = 0; it < its; it++) {
        const float *rep = p->reps + 6 * ((size_t)cell[0] + (size_t)p->rep_dims[0] *
                                                                ((size_t)cell[1] + (size_t)p->rep_dims[1] * cell[2]));
        if (!isnan(rep[0])) {
            float a[3], b[3], n[3], tin, tout;
            for (int c = 0; c < 3; c++) {
                a[c] = (float)cell[c] + rep[c];
                b[c] = (float)cell[c] + rep[3 + c];
            }
            if (capsule(o, l, a, b, r, &tin, &tout, n) && tout > 0.0f)
                return 0.0f;
        }
        int ax = t_max[0] <= t_max[1] && t_max[0] <= t_max[2] ? 0 : (t_max[1] <= t_max[2] ? 1 : 2);
        cell[ax] += step[ax];
        t_max[ax] += t_delta[ax];
        if (cell[ax] < 0 || cell[ax] >= p->rep_dims[ax])
            break;
    }
    return 1.0f;
}

/* texture() of the R8 AO field with GL_LINEAR, CLAMP_TO_EDGE. */
static float sample_ao(const sl_voxel_cast_model *m, const float q[3])
{
    const int *d = m->ao_dims;
    float x = q[0] * d[0] - 0.5f, y = q[1] * d[1] - 0.5f, z = q[2] * d[2] - 0.5f;
    int x0 = (int)floorf(x), y0 = (int)floorf(y), z0 = (int)floorf(z);
    float fx = x - x0, fy = y - y0, fz = z - z0, sum = 0.0f;
    for (int k = 0; k < 8; k++) {
        int xi = x0 + (k & 1), yi = y0 + ((k >> 1) & 1), zi = z0 + (k >> 2);
        xi = xi < 0 ? 0 : (xi >= d[0] ? d[0] - 1 : xi);
        yi = yi < 0 ? 0 : (yi >= d[1] ? d[1] - 1 : yi);
        zi = zi < 0 ? 0 : (zi >= d[2] ? d[2] - 1 : zi);
        float w = ((k & 1) ? fx : 1.0f - fx) * (((k >> 1) & 1) ? fy : 1.0f - fy) * ((k >> 2) ? fz : 1.0f - fz);
        sum += w * (float)m->ao[(size_t)xi + (size_t)d[0] * ((size_t)yi + (size_t)d[1] * zi)] / 255.0f;
    }
    return sum;
}

static float light_factor(const sl_voxel_cast_model *m, const sl_voxel_cast_params *p, const float pos[3],
                          const float n[3], const float l[3])
{
    float f = 1.0f;
    if (p->shadows) {
        float s = p->shadow_lines ? vx_shadow_lines(p, pos, l) : vx_shadow(m, p, pos, l);
        f *= 1.0f + (s - 1.0f) * p->shadow_strength;
    }
    if (p->ao_on) {
        const int *d0 = m->density_dims[0];
        float q[3] = {(pos[0] + n[0]) / d0[0], (pos[1] + n[1]) / d0[1], (pos[2] + n[2]) / d0[2]};
        f *= 1.0f - p->ao_strength * sample_ao(m, q);
    }
    return f;
}

/* --- The ray (voxel_lines.frag.glsl: main) -------------------------------------------- */

typedef struct frame_job {
    const sl_voxel_cast_model *m;
    const sl_voxel_cast_params *p;
    int width, height, tiles_x;
    float forward[3], right[3], up[3], tan_half, aspect, near_s;
    float light[3];
    sl_host_frame *frame;
    uint32_t *marks;          /* reach lists: line_count marks per worker, else NULL */
    _Atomic long long voxels, lines, hits;
} frame_job;

static int occupied(const sl_voxel_occupancy *o, int level, const int c[3])
{
    const int *d = o->dims[level];
    int x = c[0] >> level, y = c[1] >> level, z = c[2] >> level;
    x = x < d[0] - 1 ? x : d[0] - 1;
    y = y < d[1] - 1 ? y : d[1] - 1;
    z = z < d[2] - 1 ? z : d[2] - 1;
    return o->level[level][(size_t)x + (size_t)d[0] * ((size_t)y + (size_t)d[1] * z)] != 0;
}

static int outside(const int c[3], const int d[3])
{
    return c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= d[0] || c[1] >= d[1] || c[2] >= d[2];
}

/* mark (reach lists): per line, the last ray_id of this worker that tested it. */
static void cast_ray(frame_job *job, int px, int py, ray_state *r, uint32_t *mark, uint32_t ray_id, uint8_t rgba[4],
                     float *depth, long long work[3])
{
    const sl_voxel_cast_model *m = job->m;
    const sl_voxel_cast_params *p = job->p;
    const int *dims = m->dims;
    rgba[0] = rgba[1] = rgba[2] = rgba[3] = 0;
    *depth = 0.0f;
    float sx = (2.0f * ((float)px + 0.5f) / (float)job->width - 1.0f) * job->tan_half * job->aspect;
    float sy = (2.0f * ((float)py + 0.5f) / (float)job->height - 1.0f) * job->tan_half;
    float d[3], o[3], inv[3];
    for (int c = 0; c < 3; c++) {
        d[c] = (job->forward[c] + sx * job->right[c] + sy * job->up[c]) * p->inv_h;
        o[c] = p->eye_g[c];
        inv[c] = 1.0f / d[c];
    }
    float s_near = job->near_s;
    float tlo[3], thi[3];
    for (int c = 0; c < 3; c++) {
        float t0 = (0.0f - o[c]) * inv[c], t1 = ((float)dims[c] - o[c]) * inv[c];
        tlo[c] = fminf(t0, t1); /* once per ray: libm's NaN rule (0 x inf on a grid plane) drops the axis */
        thi[c] = fmaxf(t0, t1);
    }
    float s_enter = fmaxf(fmaxf(fmaxf(tlo[0], tlo[1]), tlo[2]), s_near);
    float s_exit = fminf(fminf(thi[0], thi[1]), thi[2]);
    if (!(s_enter < s_exit))
        return;
    int cell[3], step[3];
    float t_max[3], t_delta[3], inv_b[3];
    for (int c = 0; c < 3; c++) {
        float pc = o[c] + s_enter * d[c];
        int ci = (int)floorf(pc);
        cell[c] = ci < 0 ? 0 : (ci > dims[c] - 1 ? dims[c] - 1 : ci);
        step[c] = d[c] > 0.0f ? 1 : (d[c] < 0.0f ? -1 : 0);
        float next_plane = (float)cell[c] + (step[c] > 0 ? 1.0f : 0.0f);
        t_max[c] = step[c] == 0 ? 1e30f : (next_plane - o[c]) * inv[c];
        t_delta[c] = step[c] == 0 ? 1e30f : fabsf(inv[c]);
        float db = fabsf(d[c]) < 1e-20f ? (d[c] + 1e-30f >= 0.0f ? 1e-20f : -1e-20f) : d[c];
        inv_b[c] = 1.0f / db;
    }
    float reach = p->radius_g + 1e-3f;
    float inv_dd = 1.0f / dot3(d, d), bound_pad = 1.01f * p->radius_g + 0.01f;
    float dl = sqrtf(dot3(d, d));
    float view_dir[3] = {-d[0] / dl, -d[1] / dl, -d[2] / dl};
    const float *light = job->light;

    float acc[3] = {0.0f, 0.0f, 0.0f}, alpha = 0.0f, first_s = -1.0f;
    r->open_count = 0;
    r->h_count = 0;
    int steps = dims[0] + dims[1] + dims[2] + 3;
    int R = p->neighbors, W = 2 * R + 1;
    int fresh_next = 1;
    int step_axis = 0;

    /* The reach walk skips by its lists' own pyramid, and steps through a lone empty voxel
     * (one with an occupied parent) as through one with an empty list. */
    const sl_voxel_occupancy *occ = p->reach_lists ? &m->reach_occupancy : p->occupancy;
    int top = p->skip_levels;
    if (p->reach_lists && top > m->reach_occupancy.levels - 1)
        top = m->reach_occupancy.levels - 1;

    for (int it = 0; it < steps; it++) {
        work[0]++;
        int empty = -1; /* the level of the empty block holding cell; -1: cell is occupied */
        if (p->skip_levels >= 0 && !occupied(occ, 0, cell)) {
            /* upwards: a level's cell is the max of its children, so above the first
             * occupied level all are, and a lone empty voxel costs one more load */
            empty = 0;
            while (empty < top && !occupied(occ, empty + 1, cell))
                empty++;
        }
        if (empty > 0 || (empty == 0 && !p->reach_lists)) {
            int L = empty;
            float bmin[3], bmax[3], tb[3];
            for (int c = 0; c < 3; c++) {
                bmin[c] = (float)((cell[c] >> L) << L);
                bmax[c] = bmin[c] + (float)(1 << L);
                tb[c] = max_f((bmin[c] - o[c]) * inv[c], (bmax[c] - o[c]) * inv[c]);
            }
            float s_skip = min_f(min_f(tb[0], tb[1]), tb[2]);
            if (s_skip >= s_exit)
                break;
            int axis = tb[0] <= tb[1] && tb[0] <= tb[2] ? 0 : (tb[1] <= tb[2] ? 1 : 2);
            int nc[3];
            for (int c = 0; c < 3; c++) {
                int q = (int)floorf(o[c] + s_skip * d[c]);
                int lo = (int)bmin[c], hi = (int)bmax[c] - 1;
                nc[c] = q < lo ? lo : (q > hi ? hi : q);
            }
            nc[axis] = step[axis] > 0 ? (int)bmax[axis] : (int)bmin[axis] - 1;
            if (outside(nc, dims))
                break;
            memcpy(cell, nc, sizeof cell);
            for (int c = 0; c < 3; c++) {
                float next_plane = (float)cell[c] + (step[c] > 0 ? 1.0f : 0.0f);
                t_max[c] = step[c] == 0 ? 1e30f : (next_plane - o[c]) * inv[c];
            }
            fresh_next = 1;
            continue;
        }
        float s_leave = min_f(min_f(t_max[0], t_max[1]), min_f(t_max[2], s_exit));
        if (p->reach_lists) {
            /* Every tube that reaches into this voxel is on its list; a line already on an
             * earlier voxel's list was tested there (mark), so each is tested once a ray. */
            size_t v = (size_t)cell[0] + (size_t)dims[0] * ((size_t)cell[1] + (size_t)dims[1] * cell[2]);
            const uint32_t *list = m->reach_line + m->reach_first[v];
            uint32_t count = empty == 0 ? 0 : m->reach_first[v + 1] - m->reach_first[v];
            for (uint32_t l = 0; l < count; l++) {
                uint32_t li = list[l];
                if (mark[li] == ray_id)
                    continue;
                mark[li] = ray_id;
                const float *ab = m->abs_ab + SL_VOXEL_CAST_SPAN * (size_t)li;
                work[1]++;
                if (!near_sphere(o, d, inv_dd, ab, ab[6] + bound_pad))
                    continue;
                float tin, tout, n[3] = {0.0f, 0.0f, 0.0f};
                if (!capsule(o, d, ab, ab + 3, p->radius_g, &tin, &tout, n))
                    continue;
                if (tout < s_near)
                    continue;
                add_hit(r, max_f(tin, s_near), tout, n, m->key[li]);
            }
        } else {
        int fresh = fresh_next;
        int slabs = fresh ? W : 1;
        for (int sl = 0; sl < slabs; sl++) {
            int ax = fresh ? 2 : step_axis;
            int off = fresh ? sl - R : R * step[step_axis];
            for (int dv = -R; dv <= R; dv++)
                for (int du = -R; du <= R; du++) {
                    int c[3];
                    if (ax == 0) {
                        c[0] = cell[0] + off; c[1] = cell[1] + du; c[2] = cell[2] + dv;
                    } else if (ax == 1) {
                        c[0] = cell[0] + du; c[1] = cell[1] + off; c[2] = cell[2] + dv;
                    } else {
                        c[0] = cell[0] + du; c[1] = cell[1] + dv; c[2] = cell[2] + off;
                    }
                    if (outside(c, dims))
                        continue;
                    /* an empty voxel adds nothing: skip it before its box test */
                    size_t v = (size_t)c[0] + (size_t)dims[0] * ((size_t)c[1] + (size_t)dims[1] * c[2]);
                    uint32_t count = m->count[v];
                    if (!count)
                        continue;
                    float bn = -1e30f, bf = 1e30f;
                    for (int k = 0; k < 3; k++) {
                        float b0 = ((float)c[k] - reach - o[k]) * inv_b[k];
                        float b1 = ((float)c[k] + (1.0f + reach) - o[k]) * inv_b[k];
                        bn = max_f(bn, min_f(b0, b1));
                        bf = min_f(bf, max_f(b0, b1));
                    }
                    if (bn > min_f(bf, s_exit))
                        continue;
                    uint32_t first = m->first[v];
                    float corner[3] = {(float)c[0], (float)c[1], (float)c[2]};
                    for (uint32_t l = 0; l < count; l++) {
                        const float *ab = m->ab + 6 * (size_t)(first + l);
                        float a[3] = {corner[0] + ab[0], corner[1] + ab[1], corner[2] + ab[2]};
                        float b[3] = {corner[0] + ab[3], corner[1] + ab[4], corner[2] + ab[5]};
                        float tin, tout, n[3] = {0.0f, 0.0f, 0.0f};
                        work[1]++;
                        if (!capsule(o, d, a, b, p->radius_g, &tin, &tout, n))
                            continue;
                        if (tout < s_near)
                            continue;
                        add_hit(r, max_f(tin, s_near), tout, n, m->key[first + l]);
                    }
                }
        }
        fresh_next = R > 0 ? 0 : 1;
        }
        int used = 0;
        for (int i = 0; i < r->h_count; i++) {
            if (R > 0 && r->h_in[i] >= s_leave)
                break;
            used++;
            if (join_open(r, i))
                continue;
            work[2]++;
            float t = p->attr_range[0] + (p->attr_range[1] - p->attr_range[0]) * ((float)(r->h_key[i] >> 16) / 255.0f);
            float base[3];
            sl_line_shader_base(p->shader, t, base);
            float pos[3], n[3];
            float nl = sqrtf(dot3(r->h_n[i], r->h_n[i]));
            for (int c = 0; c < 3; c++) {
                pos[c] = o[c] + r->h_in[i] * d[c];
                n[c] = r->h_n[i][c] / nl;
            }
            float col[3];
            sl_line_shader_lit(p->shader, base, n, view_dir, col);
            float f = (p->shadows || p->ao_on) ? light_factor(m, p, pos, n, light) : 1.0f;
            float a = p->opacity_ramp ? p->opacity * clampf(t, 0.0f, 1.0f) : p->opacity;
            if (p->opacity_by_distance && a < 1.0f) {
                float dist = (r->h_out[i] - r->h_in[i]) * dl;
                a = 1.0f - powf(1.0f - a, clampf(dist / (2.0f * p->radius_g), 0.0f, 1.0f));
            }
            if (first_s < 0.0f)
                first_s = r->h_in[i];
            for (int c = 0; c < 3; c++)
                acc[c] += (1.0f - alpha) * a * (col[c] * f);
            alpha += (1.0f - alpha) * a;
            if (alpha >= p->alpha_stop)
                break;
        }
        for (int i = used; i < r->h_count; i++)
            move_hit(r, i - used, i);
        r->h_count -= used;
        if (alpha >= p->alpha_stop || s_leave >= s_exit)
            break;
        if (t_max[0] <= t_max[1] && t_max[0] <= t_max[2])
            step_axis = 0;
        else if (t_max[1] <= t_max[2])
            step_axis = 1;
        else
            step_axis = 2;
        cell[step_axis] += step[step_axis];
        t_max[step_axis] += t_delta[step_axis];
        if (outside(cell, dims))
            break;
    }
    if (first_s < 0.0f)
        return;
    *depth = s_near / first_s;
    for (int c = 0; c < 3; c++)
        rgba[c] = (uint8_t)lrintf(clampf(acc[c], 0.0f, 1.0f) * 255.0f);
    rgba[3] = (uint8_t)lrintf(clampf(alpha, 0.0f, 1.0f) * 255.0f);
}

static void cast_tile(void *opaque, int tile, int worker)
{
    frame_job *job = opaque;
    int x0 = (tile % job->tiles_x) * TILE, y0 = (tile / job->tiles_x) * TILE;
    int x1 = x0 + TILE < job->width ? x0 + TILE : job->width, y1 = y0 + TILE < job->height ? y0 + TILE : job->height;
    ray_state r;
    long long work[3] = {0, 0, 0};
    uint32_t *mark = job->marks ? job->marks + (size_t)worker * job->m->line_count : NULL;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            size_t i = (size_t)y * (size_t)job->width + (size_t)x;
            /* a ray's id, unique per worker in the frame (rays < 2^32) */
            uint32_t ray_id = (uint32_t)i + 1;
            cast_ray(job, x, y, &r, mark, ray_id, job->frame->rgba + 4 * i, job->frame->depth + i, work);
        }
    atomic_fetch_add(&job->voxels, work[0]);
    atomic_fetch_add(&job->lines, work[1]);
    atomic_fetch_add(&job->hits, work[2]);
}

sl_status sl_voxel_cast_render(const sl_voxel_cast_model *m, const sl_voxel_cast_params *p, const sl_view *view,
                               sl_host_frame *frame, sl_voxel_cast_stats *stats, sl_err *err)
{
    if (frame->width != view->width || frame->height != view->height || !frame->rgba)
        return sl_err_set(err, SL_ERR_INVALID, "voxel_lines (cpu): host frame %dx%d for a %dx%d view", frame->width,
                          frame->height, view->width, view->height);
    if ((p->shadows && !p->shadow_lines && m->density_levels < 1) || (p->ao_on && (!m->ao || m->density_levels < 1)) ||
        (p->shadows && p->shadow_lines && !p->reps) || (p->skip_levels >= 0 && !p->occupancy))
        return sl_err_set(err, SL_ERR_INVALID, "voxel_lines (cpu): the frame needs a field the model has not got");
    double t0 = sl_clock_ms();
    frame_job job = {.m = m, .p = p, .width = view->width, .height = view->height, .frame = frame};
    job.tiles_x = (view->width + TILE - 1) / TILE;
    int tiles_y = (view->height + TILE - 1) / TILE;
    sl_vec3 f = view->forward, r = view->right, u = view->upv;
    float fw[3] = {(float)f.x, (float)f.y, (float)f.z}, rt[3] = {(float)r.x, (float)r.y, (float)r.z},
          up[3] = {(float)u.x, (float)u.y, (float)u.z};
    memcpy(job.forward, fw, sizeof fw);
    memcpy(job.right, rt, sizeof rt);
    memcpy(job.up, up, sizeof up);
    job.tan_half = (float)view->tan_half_fov;
    job.aspect = (float)view->aspect;
    job.near_s = (float)view->near_plane;
    for (int c = 0; c < 3; c++)
        job.light[c] = (float)p->shader->light[c];
    atomic_init(&job.voxels, 0);
    atomic_init(&job.lines, 0);
    atomic_init(&job.hits, 0);
    int workers = sl_parallel_threads();
    if (p->reach_lists) {
        if (!m->reach_valid)
            return sl_err_set(err, SL_ERR_INVALID, "voxel_lines (cpu): the frame needs reach lists the model has not got");
        job.marks = calloc((size_t)workers * (m->line_count ? m->line_count : 1), sizeof *job.marks);
        if (!job.marks)
            return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines (cpu): out of memory for %d x %zu line marks", workers,
                              m->line_count);
    }
    int threads = sl_parallel_run(job.tiles_x * tiles_y, workers, cast_tile, &job);
    free(job.marks);
    frame->premultiplied = 1;
    if (stats) {
        stats->threads = threads;
        stats->rays = (double)view->width * view->height;
        stats->voxels = (double)atomic_load(&job.voxels);
        stats->lines_tested = (double)atomic_load(&job.lines);
        stats->hits = (double)atomic_load(&job.hits);
        stats->cast_ms = sl_clock_ms() - t0;
    }
    return SL_OK;
}
