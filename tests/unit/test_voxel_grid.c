/* test_voxel_grid.c — the CPU voxel model of voxel_lines (renderer/voxel_lines/voxel_grid.h).
 *
 * Checks exact clipping against an independent brute-force reference (all
 * plane crossings enumerated and sorted, tolerance 1e-9 voxel), face
 * quantization (error <= 0.5/N per in-face axis), bit packing (round trip,
 * 4/5/6 bytes per line as in the paper's Sec. 5.2), header invariants, the
 * overflow cap (never wraps, counts reported), lines on faces, edges and
 * corners, axis-parallel lines, zero-length pieces, bad input, a dataset
 * 1e6 units from the origin, and the attribute byte's definition
 * (normalization, round half up = lround). CPU only.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sl_test.h"
#include "voxel_lines/voxel_grid.h"
#include "voxel_lines/voxel_lod.h"
#include "voxel_lines/voxel_quality.h"

/* --- helpers ------------------------------------------------------------ */

typedef struct piece_list {
    sl_voxel_piece p[4096];
    int n;
} piece_list;

static int keep_piece(void *user, const sl_voxel_piece *p)
{
    piece_list *l = user;
    if (l->n < 4096)
        l->p[l->n++] = *p;
    return 0;
}

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* Reference: every plane crossing of every segment, by enumeration. */
typedef struct ref_cross {
    double p[3];
} ref_cross;

static int ref_pieces(const int dims[3], const double *pts, int n, double out_a[][3], double out_b[][3],
                      int out_cell[][3], int max)
{
    ref_cross cr[2048];
    int nc = 0;
    int seg_of[2048];
    for (int s = 0; s + 1 < n; s++) {
        const double *a = pts + 3 * s, *b = pts + 3 * s + 3;
        double ts[256];
        int nt = 0;
        for (int ax = 0; ax < 3; ax++) {
            if (a[ax] == b[ax])
                continue;
            for (int plane = 0; plane <= dims[ax]; plane++) {
                double t = (plane - a[ax]) / (b[ax] - a[ax]);
                if (t > 0.0 && t <= 1.0)
                    ts[nt++] = t;
            }
        }
        /* sort */
        for (int i = 1; i < nt; i++)
            for (int j = i; j > 0 && ts[j] < ts[j - 1]; j--) {
                double x = ts[j]; ts[j] = ts[j - 1]; ts[j - 1] = x;
            }
        for (int i = 0; i < nt; i++) {
            if (i > 0 && ts[i] == ts[i - 1])
                continue;
            for (int ax = 0; ax < 3; ax++)
                cr[nc].p[ax] = a[ax] * (1.0 - ts[i]) + b[ax] * ts[i];
            seg_of[nc] = s;
            nc++;
        }
    }
    int np = 0;
    for (int i = 0; i + 1 < nc && np < max; i++) {
        double len2 = 0.0;
        for (int ax = 0; ax < 3; ax++)
            len2 += (cr[i + 1].p[ax] - cr[i].p[ax]) * (cr[i + 1].p[ax] - cr[i].p[ax]);
        if (len2 < 1e-24)
            continue; /* zero-length piece (the curve touches a plane and turns back) */
        /* A sample strictly inside the piece: a vertex between, else the chord middle. */
        double m[3];
        if (seg_of[i + 1] > seg_of[i]) {
            for (int ax = 0; ax < 3; ax++)
                m[ax] = pts[3 * (seg_of[i] + 1) + ax];
        } else {
            for (int ax = 0; ax < 3; ax++)
                m[ax] = 0.5 * (cr[i].p[ax] + cr[i + 1].p[ax]);
        }
        for (int ax = 0; ax < 3; ax++) {
            out_a[np][ax] = cr[i].p[ax];
            out_b[np][ax] = cr[i + 1].p[ax];
            out_cell[np][ax] = (int)floor(m[ax]);
        }
        np++;
    }
    return np;
}

static int clip(const int dims[3], const double *pts, int n, piece_list *out, sl_voxel_clip_stats *st)
{
    sl_err err;
    out->n = 0;
    memset(st, 0, sizeof *st);
    return sl_voxel_clip_polyline(dims, pts, NULL, (size_t)n, 7, keep_piece, out, st, &err) == SL_OK;
}

static int on_face(const sl_voxel_piece *p, const double x[3], int face)
{
    int ax = face / 2;
    double want = p->cell[ax] + (face & 1);
    if (x[ax] != want)
        return 0;
    for (int c = 0; c < 3; c++)
        if (x[c] < p->cell[c] || x[c] > p->cell[c] + 1)
            return 0;
    return 1;
}

/* --- tests ---------------------------------------------------------------- */

static void test_encode(void)
{
    int expect_bytes[9] = {0, 3, 4, 4, 5, 5, 6, 6, 7}; /* k = 1..8 */
    for (int k = 1; k <= 8; k++) {
        SL_CHECK(sl_voxel_quant_bits(1 << k) == k);
        SL_CHECK_MSG(sl_voxel_line_bytes(k) == expect_bytes[k], "k=%d bytes=%d", k, sl_voxel_line_bytes(k));
        /* The id takes the bits the whole bytes leave: never fewer than the paper's 5. */
        int id_bits = sl_voxel_line_id_bits(k);
        SL_CHECK_MSG(id_bits == 8 * expect_bytes[k] - 2 * (3 + 2 * k) - 8 && id_bits >= 5 && id_bits <= 10,
                     "k=%d id bits %d", k, id_bits);
        for (int i = 0; i < 2000; i++) {
            uint32_t nb = 1u << (2 * k);
            sl_voxel_line l = {.face_a = (int)(rnd() * 6), .face_b = (int)(rnd() * 6),
                               .bin_a = (uint32_t)(rnd() * nb), .bin_b = (uint32_t)(rnd() * nb),
                               .attr = (uint32_t)(rnd() * 256),
                               .id = (uint32_t)(rnd() * (double)(1u << sl_voxel_line_id_bits(k)))};
            uint64_t code = sl_voxel_encode_line(k, &l);
            SL_CHECK(code < (1ull << sl_voxel_line_bits(k)));
            sl_voxel_line d;
            sl_voxel_decode_line(k, code, &d);
            if (d.face_a != l.face_a || d.face_b != l.face_b || d.bin_a != l.bin_a || d.bin_b != l.bin_b ||
                d.attr != l.attr || d.id != l.id) {
                SL_CHECK_MSG(0, "round trip k=%d", k);
                break;
            }
        }
    }
    SL_CHECK(sl_voxel_quant_bits(3) < 0 && sl_voxel_quant_bits(512) < 0 && sl_voxel_quant_bits(1) < 0);
    /* Paper Sec. 5.2: 4, 5, 6 bytes for N in (4,8), (16,32), (64,128). */
    SL_CHECK(sl_voxel_line_bytes(2) == 4 && sl_voxel_line_bytes(3) == 4);
    SL_CHECK(sl_voxel_line_bytes(4) == 5 && sl_voxel_line_bytes(5) == 5);
    SL_CHECK(sl_voxel_line_bytes(6) == 6 && sl_voxel_line_bytes(7) == 6);
}

/* The attribute byte (voxel_grid.h): per-vertex normalization and the
 * written-out round half up, which must equal lround of the clamped mean
 * (the CPU build's earlier definition), ties and neighbours of ties included. */
static void test_attr_byte(void)
{
    float values[7] = {1.0f, 2.0f, 3.0f, NAN, INFINITY, 5.0f, -1.0f};
    sl_attribute at = {.values = values, .min = 1.0f, .max = 3.0f};
    double out[7];
    sl_voxel_attr_normalize(&at, values, 7, out);
    SL_CHECK(out[0] == 0.0 && out[1] == 0.5 && out[2] == 1.0 && out[3] == 0.0 && out[4] == 0.0);
    SL_CHECK(out[5] == 2.0 && out[6] == -1.0);
    at.max = at.min; /* constant attribute: all 0 */
    sl_voxel_attr_normalize(&at, values, 7, out);
    int zero = 1;
    for (int i = 0; i < 7; i++)
        zero &= out[i] == 0.0;
    SL_CHECK(zero);

    SL_CHECK(sl_voxel_attr_byte(0.0, 0.0) == 0 && sl_voxel_attr_byte(1.0, 1.0) == 255);
    SL_CHECK(sl_voxel_attr_byte(0.0, 1.0) == 128);   /* 127.5: half up */
    SL_CHECK(sl_voxel_attr_byte(-3.0, -1.0) == 0 && sl_voxel_attr_byte(2.0, 4.0) == 255);
    SL_CHECK(sl_voxel_attr_byte(-1.0, 1.0) == 0 && sl_voxel_attr_byte(0.5, 2.0) == 255);
    int same = 1;
    for (int k = 0; k <= 255 && same; k++)
        for (int h = 0; h < 2; h++) {
            double m = (k + 0.5 * h) / 255.0;
            double probe[3] = {nextafter(m, -1.0), m, nextafter(m, 2.0)};
            for (int j = 0; j < 3; j++) {
                double x = probe[j];
                long want = lround(fmin(fmax(x, 0.0), 1.0) * 255.0);
                same &= (long)sl_voxel_attr_byte(x, x) == want;
            }
        }
    for (int i = 0; i < 100000 && same; i++) {
        double a = rnd() * 1.2 - 0.1, b = rnd() * 1.2 - 0.1;
        same &= (long)sl_voxel_attr_byte(a, b) == lround(fmin(fmax(0.5 * (a + b), 0.0), 1.0) * 255.0);
    }
    SL_CHECK(same);
}

static void test_quantize(void)
{
    for (int k = 1; k <= 8; k++) {
        int n = 1 << k;
        for (int i = 0; i < 500; i++) {
            int face = (int)(rnd() * 6);
            double u[3] = {rnd(), rnd(), rnd()};
            u[face / 2] = (double)(face & 1);
            if (i == 0) { u[0] = u[1] = u[2] = 1.0; u[face / 2] = face & 1; } /* top corner: last bin */
            uint32_t bin = sl_voxel_quantize(u, face, n);
            SL_CHECK(bin < (uint32_t)(n * n));
            double q[3];
            sl_voxel_dequantize(face, bin, n, q);
            for (int c = 0; c < 3; c++)
                if (fabs(q[c] - u[c]) > 0.5 / n + 1e-15) {
                    SL_CHECK_MSG(0, "k=%d face %d axis %d: %g vs %g", k, face, c, q[c], u[c]);
                    i = 500;
                }
        }
    }
    /* Exact bins: face +x, y = 0.3, z = 0.7 with N = 4 -> (1, 2) -> 1 + 4 * 2. */
    double u[3] = {1.0, 0.3, 0.7};
    SL_CHECK(sl_voxel_quantize(u, SL_VOXEL_FACE_XP, 4) == 9);
    double q[3];
    sl_voxel_dequantize(SL_VOXEL_FACE_ZN, 1 + 4 * 3, 4, q);
    SL_CHECK(q[0] == 0.375 && q[1] == 0.875 && q[2] == 0.0);
}

static void test_clip_random(void)
{
    int dims[3] = {6, 5, 4};
    static double ra[2048][3], rb[2048][3];
    static int rc[2048][3];
    static piece_list got;
    int mismatches = 0, total = 0;
    for (int trial = 0; trial < 300; trial++) {
        double pts[3 * 40];
        int n = 2 + (int)(rnd() * 38);
        for (int c = 0; c < 3; c++)
            pts[c] = 0.2 + rnd() * (dims[c] - 0.4);
        for (int i = 1; i < n; i++)
            for (int c = 0; c < 3; c++) {
                double x = pts[3 * (i - 1) + c] + (rnd() - 0.5) * 1.6;
                pts[3 * i + c] = fmin(fmax(x, 0.01), dims[c] - 0.01);
            }
        sl_voxel_clip_stats st;
        SL_CHECK(clip(dims, pts, n, &got, &st));
        int nr = ref_pieces(dims, pts, n, ra, rb, rc, 2048);
        total += nr;
        if (nr != got.n) {
            SL_CHECK_MSG(0, "trial %d: %d pieces, reference %d", trial, got.n, nr);
            continue;
        }
        for (int i = 0; i < nr; i++) {
            const sl_voxel_piece *p = &got.p[i];
            int ok = p->curve == 7 && on_face(p, p->a, p->face_a) && on_face(p, p->b, p->face_b);
            for (int c = 0; c < 3; c++)
                ok = ok && p->cell[c] == rc[i][c] && fabs(p->a[c] - ra[i][c]) < 1e-9 &&
                     fabs(p->b[c] - rb[i][c]) < 1e-9;
            if (i > 0) /* consecutive pieces share their face point exactly */
                ok = ok && memcmp(got.p[i - 1].b, p->a, sizeof p->a) == 0;
            mismatches += !ok;
        }
    }
    SL_CHECK_MSG(mismatches == 0, "%d of %d pieces differ from the reference", mismatches, total);
    SL_CHECK(total > 1000);
}

static void test_clip_stress(void)
{
    int dims[3] = {8, 8, 8};
    piece_list *got = malloc(sizeof *got);
    sl_voxel_clip_stats st;

    /* Axis-parallel through voxel centres: 4 unit pieces -x -> +x. */
    double axis[] = {0.5, 2.5, 2.5, 5.5, 2.5, 2.5};
    SL_CHECK(clip(dims, axis, 2, got, &st));
    SL_CHECK(got->n == 4);
    for (int i = 0; i < got->n; i++) {
        const sl_voxel_piece *p = &got->p[i];
        SL_CHECK(p->cell[0] == i + 1 && p->cell[1] == 2 && p->cell[2] == 2);
        SL_CHECK(p->face_a == SL_VOXEL_FACE_XN && p->face_b == SL_VOXEL_FACE_XP);
        SL_CHECK(p->b[0] - p->a[0] == 1.0 && p->a[1] == 2.5 && p->b[1] == 2.5);
    }

    /* Exactly on the face y = 2 (and z = 3: an edge): cells take the upper side. */
    double edge[] = {0.5, 2.0, 3.0, 4.5, 2.0, 3.0};
    SL_CHECK(clip(dims, edge, 2, got, &st));
    SL_CHECK(got->n == 3);
    for (int i = 0; i < got->n; i++) {
        const sl_voxel_piece *p = &got->p[i];
        SL_CHECK(p->cell[1] == 2 && p->cell[2] == 3);
        double u[3] = {p->a[0] - p->cell[0], p->a[1] - p->cell[1], p->a[2] - p->cell[2]};
        SL_CHECK(sl_voxel_quantize(u, p->face_a, 8) == 0); /* bin row and column 0 */
    }

    /* Through corners: (0.5,0.5,0.5) -> (5.5,5.5,5.5) crosses corners 1..5. */
    double diag[] = {0.5, 0.5, 0.5, 5.5, 5.5, 5.5};
    SL_CHECK(clip(dims, diag, 2, got, &st));
    SL_CHECK(got->n == 4 && st.degenerate == 0);
    for (int i = 0; i < got->n; i++) {
        const sl_voxel_piece *p = &got->p[i];
        SL_CHECK(p->cell[0] == i + 1 && p->cell[1] == i + 1 && p->cell[2] == i + 1);
        SL_CHECK(p->a[0] == i + 1 && p->a[1] == i + 1 && p->a[2] == i + 1);
        SL_CHECK(p->b[0] == i + 2 && p->b[1] == i + 2 && p->b[2] == i + 2);
        SL_CHECK(p->face_a == SL_VOXEL_FACE_XN && p->face_b == SL_VOXEL_FACE_XP); /* lowest axis wins */
    }

    /* Touch the plane x = 2 at a vertex and turn back: one zero-length piece dropped. */
    double touch[] = {0.5, 0.5, 0.5, 2.0, 0.6, 0.5, 0.5, 0.7, 0.5};
    SL_CHECK(clip(dims, touch, 3, got, &st));
    SL_CHECK(got->n == 2 && st.degenerate == 1);
    if (got->n == 2) {
        SL_CHECK(got->p[0].cell[0] == 1 && got->p[1].cell[0] == 1);
        SL_CHECK(got->p[0].b[0] == 2.0 && got->p[1].a[0] == 2.0);
        SL_CHECK(got->p[0].face_b == SL_VOXEL_FACE_XP && got->p[1].face_a == SL_VOXEL_FACE_XP);
    }

    /* Starting exactly on a face, moving into the cell: the first piece is complete. */
    double start[] = {1.0, 0.5, 0.5, 3.5, 0.5, 0.5};
    SL_CHECK(clip(dims, start, 2, got, &st));
    SL_CHECK(got->n == 2 && got->p[0].a[0] == 1.0 && got->p[0].face_a == SL_VOXEL_FACE_XN);

    /* Inside one voxel, and repeated vertices: nothing. */
    double inside[] = {0.2, 0.2, 0.2, 0.8, 0.3, 0.9, 0.8, 0.3, 0.9};
    SL_CHECK(clip(dims, inside, 3, got, &st));
    SL_CHECK(got->n == 0);

    /* Outside the grid: clamped, never a cell outside. */
    double outside[] = {-5.0, 0.5, 0.5, 20.0, 0.5, 0.5};
    SL_CHECK(clip(dims, outside, 2, got, &st));
    SL_CHECK(got->n == 8); /* starts and ends exactly on the grid boundary: all complete */
    for (int i = 0; i < got->n; i++)
        SL_CHECK(got->p[i].cell[0] >= 0 && got->p[i].cell[0] < 8);

    /* Non-finite input: an error, no pieces. */
    double bad[] = {0.5, 0.5, 0.5, NAN, 0.5, 0.5};
    sl_err err;
    got->n = 0;
    SL_CHECK(sl_voxel_clip_polyline(dims, bad, NULL, 2, 0, keep_piece, got, NULL, &err) == SL_ERR_INVALID);
    SL_CHECK(got->n == 0);
    free(got);
}

/* A dataset of straight lines given in world coordinates plus an offset. */
static sl_dataset *make_lines(int count, int points, double offset, unsigned seed)
{
    sl_err err;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "test");
    if (!ds || sl_lines_alloc(&ds->lines, (size_t)count, (size_t)count * points, 0, 0, &err) != SL_OK)
        return ds;
    rng_state = seed * 0x2545F4914F6CDD1Dull + 1;
    ds->origin = sl_v3(offset, -offset, offset);
    for (int c = 0; c < count; c++) {
        ds->lines.line_offsets[c] = (uint32_t)(c * points);
        double p[3] = {rnd() * 10, rnd() * 10, rnd() * 10};
        double d[3] = {rnd() - 0.5, rnd() - 0.5, rnd() - 0.5};
        for (int i = 0; i < points; i++)
            for (int a = 0; a < 3; a++) {
                p[a] += d[a] * 0.7 + (rnd() - 0.5) * 0.2;
                ds->lines.positions[3 * (c * points + i) + a] = (float)p[a];
            }
    }
    ds->lines.line_offsets[count] = (uint32_t)(count * points);
    if (sl_dataset_finish_lines(ds, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

static void test_build(void)
{
    sl_err err;
    sl_dataset *ds = make_lines(200, 60, 0.0, 3);
    SL_CHECK(ds != NULL);
    if (!ds)
        return;
    sl_voxel_grid g;
    sl_voxel_grid_desc desc = {.resolution = 24, .quant = 16, .padding = 1};
    SL_CHECK(sl_voxel_grid_build(&g, ds, &desc, &err) == SL_OK);
    SL_CHECK(g.line_bytes == 5 && g.line_count > 1000);
    /* Longest side: 24 voxels + 2 padding. */
    int maxdim = g.frame.dims[0] > g.frame.dims[1] ? g.frame.dims[0] : g.frame.dims[1];
    maxdim = maxdim > g.frame.dims[2] ? maxdim : g.frame.dims[2];
    SL_CHECK(maxdim == 26);
    /* Headers: contiguous, in voxel order, covering all lines; padding empty. */
    size_t next = 0, sum = 0;
    int ok = 1, pad_ok = 1;
    for (size_t v = 0; v < g.voxel_count; v++) {
        ok &= g.offsets[v] == next;
        next += g.counts[v];
        sum += g.counts[v];
        int c[3] = {(int)(v % g.frame.dims[0]), (int)(v / g.frame.dims[0] % g.frame.dims[1]),
                    (int)(v / g.frame.dims[0] / g.frame.dims[1])};
        for (int a = 0; a < 3; a++)
            if ((c[a] == 0 || c[a] == g.frame.dims[a] - 1) && g.counts[v])
                pad_ok = 0;
    }
    SL_CHECK(ok && sum == g.line_count && pad_ok);
    /* Every line: decodable, faces distinct points, id = curve mod 32 range, density = lengths. */
    double dens_err = 0.0;
    for (size_t v = 0; v < g.voxel_count; v++) {
        double len = 0.0;
        for (size_t i = g.offsets[v]; i < (size_t)g.offsets[v] + g.counts[v]; i++) {
            sl_voxel_line l;
            sl_voxel_decode_line(g.quant_bits, sl_voxel_grid_line(&g, i), &l);
            double a[3], b[3];
            sl_voxel_dequantize(l.face_a, l.bin_a, g.quant, a);
            sl_voxel_dequantize(l.face_b, l.bin_b, g.quant, b);
            len += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
            if (l.face_a > 5 || l.face_b > 5 || len == 0.0)
                ok = 0;
        }
        dens_err = fmax(dens_err, fabs(len - g.density[v]));
    }
    SL_CHECK(ok);
    SL_CHECK_NEAR(dens_err, 0.0, 1e-4);
    SL_CHECK(g.dropped_overflow == 0 && g.capped_voxels == 0);

    /* Same relative data 1e6 units from the origin: identical grid. */
    sl_dataset *far = make_lines(200, 60, 1e6, 3);
    sl_voxel_grid g2;
    SL_CHECK(far && sl_voxel_grid_build(&g2, far, &desc, &err) == SL_OK);
    if (far) {
        SL_CHECK(g2.line_count == g.line_count && g2.voxel_count == g.voxel_count);
        if (g2.line_count == g.line_count && g2.voxel_count == g.voxel_count) {
            SL_CHECK(memcmp(g.lines, g2.lines, g.line_count * g.line_bytes) == 0);
            SL_CHECK(memcmp(g.counts, g2.counts, g.voxel_count) == 0);
        }
        SL_CHECK(fabs(far->origin.x - 1e6) < 20.0);
    }
    sl_voxel_grid_deinit(&g2);
    sl_dataset_destroy(far);
    sl_voxel_grid_deinit(&g);

    /* Bad descriptors. */
    desc.quant = 12;
    SL_CHECK(sl_voxel_grid_build(&g, ds, &desc, &err) == SL_ERR_INVALID && g.offsets == NULL);
    desc.quant = 16;
    desc.resolution = 5000;
    SL_CHECK(sl_voxel_grid_build(&g, ds, &desc, &err) == SL_ERR_INVALID);
    desc.resolution = 900;
    SL_CHECK(sl_voxel_grid_build(&g, ds, &desc, &err) == SL_ERR_LIMIT);
    sl_voxel_grid_deinit(&g);
    sl_dataset *vol = sl_dataset_create(SL_DATASET_VOLUME, "v");
    desc.resolution = 8;
    SL_CHECK(sl_voxel_grid_build(&g, vol, &desc, &err) == SL_ERR_INVALID);
    sl_dataset_destroy(vol);
    sl_dataset_destroy(ds);
}

static void test_overflow(void)
{
    /* 300 distinct parallel lines through one voxel column of a 4-voxel grid. */
    sl_err err;
    const int count = 300;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "overflow");
    SL_CHECK(ds && sl_lines_alloc(&ds->lines, count + 1, (count + 1) * 2, 0, 0, &err) == SL_OK);
    for (int c = 0; c < count; c++) {
        ds->lines.line_offsets[c] = (uint32_t)(2 * c);
        float y = 1.05f + 0.9f * (float)(c % 17) / 17.0f, z = 1.05f + 0.9f * (float)(c / 17) / 18.0f;
        float *p = ds->lines.positions + 6 * c;
        p[0] = 0.5f; p[1] = y; p[2] = z;
        p[3] = 3.5f; p[4] = y; p[5] = z;
    }
    /* One long diagonal line fixes the bounding box to [0, 4]^3. */
    float *p = ds->lines.positions + 6 * count;
    p[0] = p[1] = p[2] = 0.0f;
    p[3] = p[4] = p[5] = 4.0f;
    ds->lines.line_offsets[count] = 2 * count;
    ds->lines.line_offsets[count + 1] = 2 * count + 2;
    SL_CHECK(sl_dataset_finish_lines(ds, &err) == SL_OK);
    sl_voxel_grid g;
    sl_voxel_grid_desc desc = {.resolution = 4, .quant = 128, .padding = 0};
    SL_CHECK(sl_voxel_grid_build(&g, ds, &desc, &err) == SL_OK);
    int c1[3] = {1, 1, 1}, c2[3] = {2, 1, 1};
    size_t v1 = sl_voxel_index(g.frame.dims, c1), v2 = sl_voxel_index(g.frame.dims, c2);
    SL_CHECK(g.max_count == 301);                  /* 300 parallel + the diagonal in (1,1,1) */
    SL_CHECK(g.counts[v1] == 255 && g.counts[v2] == 255); /* capped, not 301 mod 256 = 45 */
    SL_CHECK(g.capped_voxels == 2);
    SL_CHECK(g.dropped_overflow == (301 - 255) + (300 - 255));
    /* The kept lines are the first in curve order: ids cycle from curve 0
     * with the record's 6 id bits at N = 128 (0..63). */
    sl_voxel_line l;
    SL_CHECK(sl_voxel_line_id_bits(g.quant_bits) == 6);
    sl_voxel_decode_line(g.quant_bits, sl_voxel_grid_line(&g, g.offsets[v2] + 40), &l);
    SL_CHECK(l.id == 40);
    sl_voxel_decode_line(g.quant_bits, sl_voxel_grid_line(&g, g.offsets[v2] + 100), &l);
    SL_CHECK(l.id == 100 % 64);
    sl_voxel_grid_deinit(&g);
    desc.max_per_voxel = 10;
    SL_CHECK(sl_voxel_grid_build(&g, ds, &desc, &err) == SL_OK);
    SL_CHECK(g.counts[v2] == 10 && g.dropped_overflow == (301 - 10) + (300 - 10));
    sl_voxel_grid_deinit(&g);
    sl_dataset_destroy(ds);
}

/* Quality metrics on lines with known answers: two lines along grid edges
 * (in-face offset 0.5/N on both axes) and one offset by 0.1/N inside the
 * same bins (a duplicate of the first in every voxel). */
static void test_quality(void)
{
    sl_err err;
    const int nq = 4;
    const double off = 0.1 / nq;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "quality");
    SL_CHECK(ds && sl_lines_alloc(&ds->lines, 3, 9, 0, 0, &err) == SL_OK);
    const double pts[9][3] = {{0, 0, 0}, {4, 0, 0}, {8, 0, 0},
                              {0, 8, 8}, {4, 8, 8}, {8, 8, 8},
                              {0, off, 0}, {4, off, 0}, {8, off, 0}};
    for (int i = 0; i < 9; i++)
        for (int c = 0; c < 3; c++)
            ds->lines.positions[3 * i + c] = (float)pts[i][c];
    for (int k = 0; k <= 3; k++)
        ds->lines.line_offsets[k] = (uint32_t)(3 * k);
    SL_CHECK(sl_dataset_finish_lines(ds, &err) == SL_OK);
    int quant[2] = {nq, 256};
    sl_voxel_quality q[2];
    SL_CHECK(sl_voxel_quality_measure(ds, 8, quant, 2, 0, q, &err) == SL_OK);
    double e = 0.5 / nq;
    double h_edge = sqrt(2.0) * e, h_off = sqrt((e - (float)off) * (e - (float)off) + e * e);
    double want = (2.0 * h_edge + h_off) / 3.0 * 64.0 / 8.0; /* 64-grid voxel units */
    SL_CHECK_NEAR(q[0].hausdorff_mean, want, 1e-6);
    SL_CHECK_NEAR(q[0].tangent_deg_mean, 0.0, 1e-9);
    SL_CHECK(q[0].curves == 3 && q[0].lines == 24);
    SL_CHECK(q[0].duplicates == 8);
    SL_CHECK_NEAR(q[0].duplicate_share, 8.0 / 24.0, 1e-12);
    /* N = 256 separates the offset line (0.025 > 1/256) and halves nothing else. */
    SL_CHECK(q[1].duplicates == 0);
    SL_CHECK(q[1].hausdorff_mean < q[0].hausdorff_mean / 10.0);
    int badq = 6;
    SL_CHECK(sl_voxel_quality_measure(ds, 8, &badq, 1, 0, q, &err) == SL_ERR_INVALID);
    sl_dataset_destroy(ds);
}

/* Degenerate datasets: no lines, a single-vertex line, a flat (2D) set. */
static void test_degenerate_data(void)
{
    sl_err err;
    sl_voxel_grid g;
    sl_voxel_grid_desc desc = {.resolution = 16, .quant = 8};
    sl_dataset *empty = sl_dataset_create(SL_DATASET_LINES, "empty");
    SL_CHECK(empty && sl_lines_alloc(&empty->lines, 0, 0, 0, 0, &err) == SL_OK);
    if (empty && empty->lines.line_offsets)
        empty->lines.line_offsets[0] = 0;
    SL_CHECK(empty && sl_dataset_finish_lines(empty, &err) == SL_OK);
    SL_CHECK(sl_voxel_grid_build(&g, empty, &desc, &err) == SL_OK);
    SL_CHECK(g.line_count == 0 && g.voxel_count >= 1 && g.lines != NULL);
    sl_voxel_grid_deinit(&g);
    sl_dataset_destroy(empty);

    sl_dataset *flat = sl_dataset_create(SL_DATASET_LINES, "flat");
    SL_CHECK(flat && sl_lines_alloc(&flat->lines, 2, 3, 0, 0, &err) == SL_OK);
    const float p[9] = {0, 0, 0, 10, 5, 0, 7, 7, 0}; /* a 2-point line and a 1-point line, all z = 0 */
    memcpy(flat->lines.positions, p, sizeof p);
    flat->lines.line_offsets[0] = 0;
    flat->lines.line_offsets[1] = 2;
    flat->lines.line_offsets[2] = 3;
    SL_CHECK(sl_dataset_finish_lines(flat, &err) == SL_OK);
    desc.padding = 0;
    SL_CHECK(sl_voxel_grid_build(&g, flat, &desc, &err) == SL_OK);
    SL_CHECK(g.frame.dims[0] == 16 && g.frame.dims[2] == 1);
    SL_CHECK(g.line_count > 10 && g.curves_without_pieces == 1);
    sl_voxel_grid_deinit(&g);
    sl_dataset_destroy(flat);
}

/* Representative lines: a voxel with two antiparallel lines along x keeps
 * the x direction (flipped before averaging); a straight x line through a
 * 2^3 block gives the same line one level up; empty cells have none. */
static void test_representatives(void)
{
    sl_err err;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "rep");
    SL_CHECK(ds && sl_lines_alloc(&ds->lines, 3, 6, 0, 0, &err) == SL_OK);
    /* grid 8, bounds [0,8]^3, no padding: grid coords = positions. */
    const float p[18] = {0.5f, 1.5f, 1.5f, 7.5f, 1.5f, 1.5f,   /* +x at y = z = 1.5 */
                         7.5f, 1.6f, 1.5f, 0.5f, 1.6f, 1.5f,   /* -x, nearly the same */
                         0, 0, 0, 8, 8, 8};                     /* bounds */
    memcpy(ds->lines.positions, p, sizeof p);
    for (int k = 0; k <= 3; k++)
        ds->lines.line_offsets[k] = (uint32_t)(2 * k);
    SL_CHECK(sl_dataset_finish_lines(ds, &err) == SL_OK);
    sl_voxel_grid g;
    sl_voxel_grid_desc desc = {.resolution = 8, .quant = 16, .padding = 0};
    SL_CHECK(sl_voxel_grid_build(&g, ds, &desc, &err) == SL_OK);
    sl_voxel_lod lod;
    SL_CHECK(sl_voxel_lod_build(&g, 3, &lod, &err) == SL_OK);
    SL_CHECK(lod.levels == 3 && lod.level[1].dims[0] == 4 && lod.level[2].dims[0] == 2);
    int c0[3] = {3, 1, 1};
    const float *r = lod.level[0].lines + 6 * sl_voxel_index(lod.level[0].dims, c0);
    /* Along x from face -x to face +x (or reverse), y, z within a bin of the data. */
    SL_CHECK(fabsf(fabsf(r[3] - r[0]) - 1.0f) < 1e-6f);
    SL_CHECK(fabsf(r[1] - 0.55f) < 1.0f / 16 && fabsf(r[4] - 0.55f) < 1.0f / 16);
    SL_CHECK(fabsf(r[2] - 0.5f) <= 1.0f / 32 + 1e-6f);
    /* Level 1: block (1, 0, 0) holds voxels x = 2, 3 at y = z = 1: local y = (1 + 0.55) / 2. */
    int c1[3] = {1, 0, 0};
    r = lod.level[1].lines + 6 * sl_voxel_index(lod.level[1].dims, c1);
    SL_CHECK(fabsf(fabsf(r[3] - r[0]) - 1.0f) < 1e-6f);
    SL_CHECK(fabsf(r[1] - 0.775f) < 1.0f / 16 && fabsf(r[2] - 0.75f) < 1.0f / 16);
    int empty[3] = {0, 3, 3};
    SL_CHECK(isnan(lod.level[1].lines[6 * sl_voxel_index(lod.level[1].dims, empty)]));
    sl_voxel_lod_deinit(&lod);
    SL_CHECK(sl_voxel_lod_build(&g, 0, &lod, &err) == SL_ERR_INVALID);
    sl_voxel_grid_deinit(&g);
    sl_dataset_destroy(ds);
}

int main(void)
{
    test_representatives();
    test_degenerate_data();
    test_quality();
    test_encode();
    test_attr_byte();
    test_quantize();
    test_clip_random();
    test_clip_stress();
    test_build();
    test_overflow();
    SL_TEST_END();
}
