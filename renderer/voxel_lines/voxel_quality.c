/* voxel_quality.c — Fig. 16 style accuracy metrics of the voxel model
 * (Kanzler et al., Sec. 5.1); definitions in voxel_quality.h.
 *
 * Brute force on purpose: every sample is compared with every segment of the
 * same curve (with a bounding-box early-out), so the numbers are a reference,
 * not an estimate from the same code that builds the grid; only the clipping
 * (tested against its own brute-force reference) is shared. Duplicates are
 * counted over all curves, distances over the sampled ones. CPU, any thread.
 */
#include "voxel_quality.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct vec_list {
    sl_voxel_piece *p;
    size_t n, cap;
    int failed;
} vec_list;

static int push_piece(void *user, const sl_voxel_piece *p)
{
    vec_list *l = user;
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 256;
        sl_voxel_piece *n = realloc(l->p, cap * sizeof *n);
        if (!n) {
            l->failed = 1;
            return 1;
        }
        l->p = n;
        l->cap = cap;
    }
    l->p[l->n++] = *p;
    return 0;
}

typedef struct dup_key {
    uint64_t voxel, key;
} dup_key;

static int cmp_dup(const void *a, const void *b)
{
    const dup_key *x = a, *y = b;
    if (x->voxel != y->voxel)
        return x->voxel < y->voxel ? -1 : 1;
    return x->key < y->key ? -1 : (x->key > y->key);
}

static double dist2_point_segment(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3], dd = 0.0, t = 0.0;
    for (int c = 0; c < 3; c++) {
        ab[c] = b[c] - a[c];
        ap[c] = p[c] - a[c];
        dd += ab[c] * ab[c];
        t += ab[c] * ap[c];
    }
    t = dd > 0.0 ? t / dd : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    double r = 0.0;
    for (int c = 0; c < 3; c++) {
        double x = a[c] + t * ab[c] - p[c];
        r += x * x;
    }
    return r;
}

/* Squared distance from p to the axis-aligned box of segment (a, b): a lower bound. */
static double dist2_box(const double p[3], const double a[3], const double b[3])
{
    double r = 0.0;
    for (int c = 0; c < 3; c++) {
        double lo = fmin(a[c], b[c]), hi = fmax(a[c], b[c]);
        double x = p[c] < lo ? lo - p[c] : (p[c] > hi ? p[c] - hi : 0.0);
        r += x * x;
    }
    return r;
}

/* Nearest of m segments (s[2j], s[2j+1]) to p: returns the squared distance, *which the index. */
static double nearest(const double p[3], const double (*s)[3], size_t m, size_t *which)
{
    double best = DBL_MAX;
    size_t arg = 0;
    for (size_t j = 0; j < m; j++) {
        if (dist2_box(p, s[2 * j], s[2 * j + 1]) >= best)
            continue;
        double d = dist2_point_segment(p, s[2 * j], s[2 * j + 1]);
        if (d < best) {
            best = d;
            arg = j;
        }
    }
    if (which)
        *which = arg;
    return best;
}

typedef struct curve_metrics {
    double hausdorff;       /* grid voxels */
    double tangent_sum;
    size_t tangent_count;
} curve_metrics;

/* Metrics of one curve: pts (n grid points), its pieces, quantization n_q. */
static int measure_curve(const double *pts, size_t n, const vec_list *pieces, int nq, double (*orig)[3],
                         double (*approx)[3], curve_metrics *out)
{
    size_t m = 0;
    for (size_t j = 0; j < pieces->n; j++) {
        const sl_voxel_piece *p = &pieces->p[j];
        double ua[3], ub[3];
        for (int c = 0; c < 3; c++) {
            ua[c] = p->a[c] - p->cell[c];
            ub[c] = p->b[c] - p->cell[c];
        }
        uint32_t ba = sl_voxel_quantize(ua, p->face_a, nq), bb = sl_voxel_quantize(ub, p->face_b, nq);
        if (p->face_a == p->face_b && ba == bb)
            continue;
        sl_voxel_dequantize(p->face_a, ba, nq, approx[2 * m]);
        sl_voxel_dequantize(p->face_b, bb, nq, approx[2 * m + 1]);
        for (int c = 0; c < 3; c++) {
            approx[2 * m][c] += p->cell[c];
            approx[2 * m + 1][c] += p->cell[c];
        }
        m++;
    }
    if (m == 0)
        return 0;
    /* The covered original polyline: first crossing, inner vertices, last crossing. */
    uint32_t first = pieces->p[0].seg_a, last = pieces->p[pieces->n - 1].seg_b;
    size_t no = 0;
    memcpy(orig[no++], pieces->p[0].a, sizeof orig[0]);
    for (size_t v = (size_t)first + 1; v <= last && v < n; v++)
        memcpy(orig[no++], pts + 3 * v, sizeof orig[0]);
    memcpy(orig[no++], pieces->p[pieces->n - 1].b, sizeof orig[0]);
    /* orig as segments for nearest(): duplicate points into pairs. */
    double (*oseg)[3] = orig + no;
    for (size_t i = 0; i + 1 < no; i++) {
        memcpy(oseg[2 * i], orig[i], sizeof orig[0]);
        memcpy(oseg[2 * i + 1], orig[i + 1], sizeof orig[0]);
    }
    size_t nos = no - 1;
    double h2 = 0.0;
    out->tangent_sum = 0.0;
    out->tangent_count = 0;
    for (size_t i = 0; i < no; i++) {
        size_t j;
        h2 = fmax(h2, nearest(orig[i], (const double (*)[3])approx, m, &j));
        if (i + 1 < no) {
            double mid[3];
            for (int c = 0; c < 3; c++)
                mid[c] = 0.5 * (orig[i][c] + orig[i + 1][c]);
            h2 = fmax(h2, nearest(mid, (const double (*)[3])approx, m, NULL));
        }
        if (i > 0 && i + 1 < no) { /* inner original vertex */
            double t[3], a[3], tt = 0.0, aa = 0.0, ta = 0.0;
            for (int c = 0; c < 3; c++) {
                t[c] = orig[i + 1][c] - orig[i - 1][c];
                a[c] = approx[2 * j + 1][c] - approx[2 * j][c];
                tt += t[c] * t[c];
                aa += a[c] * a[c];
                ta += t[c] * a[c];
            }
            if (tt > 0.0 && aa > 0.0) {
                double cs = ta / sqrt(tt * aa);
                cs = cs > 1.0 ? 1.0 : (cs < -1.0 ? -1.0 : cs);
                out->tangent_sum += acos(cs) * 180.0 / SL_PI;
                out->tangent_count++;
            }
        }
    }
    for (size_t j = 0; j < m; j++) {
        double mid[3];
        for (int c = 0; c < 3; c++)
            mid[c] = 0.5 * (approx[2 * j][c] + approx[2 * j + 1][c]);
        h2 = fmax(h2, nearest(approx[2 * j], (const double (*)[3])oseg, nos, NULL));
        h2 = fmax(h2, nearest(approx[2 * j + 1], (const double (*)[3])oseg, nos, NULL));
        h2 = fmax(h2, nearest(mid, (const double (*)[3])oseg, nos, NULL));
    }
    out->hausdorff = sqrt(h2);
    return 1;
}

sl_status sl_voxel_quality_measure(const sl_dataset *ds, int resolution, const int *quant, int nquant,
                                   size_t curves, sl_voxel_quality *out, sl_err *err)
{
    if (nquant < 1 || nquant > SL_VOXEL_QUALITY_MAX_QUANT)
        return sl_err_set(err, SL_ERR_INVALID, "%d quantizations given, allowed 1..%d", nquant,
                          SL_VOXEL_QUALITY_MAX_QUANT);
    for (int q = 0; q < nquant; q++)
        if (sl_voxel_quant_bits(quant[q]) < 0)
            return sl_err_set(err, SL_ERR_INVALID, "face quantization %d must be a power of two in 2..256", quant[q]);
    if (resolution < 1)
        return sl_err_set(err, SL_ERR_INVALID, "grid resolution %d must be at least 1", resolution);
    sl_voxel_frame f;
    sl_status st = sl_voxel_frame_init(&f, ds, resolution, 0, err);
    if (st != SL_OK)
        return st;
    const sl_lines *l = &ds->lines;
    size_t stride = curves && curves < l->line_count ? l->line_count / curves : 1;
    size_t longest = 1;
    for (size_t c = 0; c < l->line_count; c++)
        if (l->line_offsets[c + 1] - l->line_offsets[c] > longest)
            longest = l->line_offsets[c + 1] - l->line_offsets[c];
    vec_list pieces = {0};
    double *pts = malloc(longest * 3 * sizeof *pts);
    double (*orig)[3] = NULL, (*approx)[3] = NULL;
    size_t orig_cap = 0, approx_cap = 0;
    dup_key *dups = NULL;
    size_t dup_n = 0, dup_cap = 0;
    st = SL_OK;
    if (!pts) {
        st = sl_err_set(err, SL_ERR_NOMEM, "quality: out of memory");
        goto done;
    }
    for (int q = 0; q < nquant; q++) {
        sl_voxel_quality *o = &out[q];
        memset(o, 0, sizeof *o);
        o->resolution = resolution;
        o->quant = quant[q];
        double hsum = 0.0, tsum = 0.0;
        size_t tcount = 0;
        dup_n = 0;
        for (size_t c = 0; c < l->line_count; c++) {
            size_t first = l->line_offsets[c], n = l->line_offsets[c + 1] - first;
            for (size_t i = 0; i < 3 * n; i++)
                pts[i] = ((double)l->positions[3 * first + i] - f.lo[i % 3]) / f.h;
            pieces.n = 0;
            st = sl_voxel_clip_polyline(f.dims, pts, NULL, n, (uint32_t)c, push_piece, &pieces, NULL, err);
            if (st != SL_OK)
                goto done;
            if (pieces.failed || dup_n + pieces.n > SIZE_MAX / sizeof *dups / 2) {
                st = sl_err_set(err, SL_ERR_NOMEM, "quality: out of memory at curve %zu", c);
                goto done;
            }
            if (dup_n + pieces.n > dup_cap) {
                size_t cap = 2 * (dup_n + pieces.n);
                dup_key *nd = realloc(dups, cap * sizeof *nd);
                if (!nd) {
                    st = sl_err_set(err, SL_ERR_NOMEM, "quality: out of memory at curve %zu", c);
                    goto done;
                }
                dups = nd;
                dup_cap = cap;
            }
            for (size_t j = 0; j < pieces.n; j++) {
                const sl_voxel_piece *p = &pieces.p[j];
                double ua[3], ub[3];
                for (int a = 0; a < 3; a++) {
                    ua[a] = p->a[a] - p->cell[a];
                    ub[a] = p->b[a] - p->cell[a];
                }
                uint64_t ea = (uint64_t)p->face_a | (uint64_t)sl_voxel_quantize(ua, p->face_a, quant[q]) << 3;
                uint64_t eb = (uint64_t)p->face_b | (uint64_t)sl_voxel_quantize(ub, p->face_b, quant[q]) << 3;
                if (ea == eb)
                    continue;
                dups[dup_n].voxel = sl_voxel_index(f.dims, p->cell);
                dups[dup_n].key = ea < eb ? (ea << 32 | eb) : (eb << 32 | ea);
                dup_n++;
            }
            if (c % stride != 0 || pieces.n == 0)
                continue;
            if (4 * (n + 2) > orig_cap || 2 * pieces.n > approx_cap) {
                free(orig);
                free(approx);
                orig_cap = 4 * (n + 2) > orig_cap ? 4 * (n + 2) : orig_cap;
                approx_cap = 2 * pieces.n > approx_cap ? 2 * pieces.n : approx_cap;
                orig = malloc(orig_cap * sizeof *orig);
                approx = malloc(approx_cap * sizeof *approx);
                if (!orig || !approx) {
                    st = sl_err_set(err, SL_ERR_NOMEM, "quality: out of memory at curve %zu", c);
                    goto done;
                }
            }
            curve_metrics cm;
            if (measure_curve(pts, n, &pieces, quant[q], orig, approx, &cm)) {
                hsum += cm.hausdorff;
                tsum += cm.tangent_sum;
                tcount += cm.tangent_count;
                o->curves++;
            }
        }
        qsort(dups, dup_n, sizeof *dups, cmp_dup);
        o->lines = dup_n;
        for (size_t i = 1; i < dup_n; i++)
            if (dups[i].voxel == dups[i - 1].voxel && dups[i].key == dups[i - 1].key)
                o->duplicates++;
        o->duplicate_share = dup_n ? (double)o->duplicates / (double)dup_n : 0.0;
        o->hausdorff_mean = o->curves ? hsum / (double)o->curves * 64.0 / resolution : 0.0;
        o->tangent_deg_mean = tcount ? tsum / (double)tcount : 0.0;
    }
done:
    free(pieces.p);
    free(pts);
    free(orig);
    free(approx);
    free(dups);
    return st;
}
