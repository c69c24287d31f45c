/* voxelize_cpu.c — exact clipping of curves against the voxel grid and the CPU
 * build of the per-voxel line lists (Kanzler et al., Sec. 3.1 and 3.3).
 *
 * Clipping walks each segment with a 3D DDA in double precision: the next
 * crossing is the smallest t = (plane - a) / d over the axes; axes whose t is
 * exactly equal are crossed together (edges, corners), so a corner yields one
 * crossing and no zero-length piece. The crossed coordinate is set to the
 * plane value exactly, so endpoints lie on their faces bit-exactly and the
 * face id follows from the crossed axis (lowest axis first at edges and
 * corners). Cells are tracked as integers, never re-derived with floor().
 * The build is a counting sort by voxel id that keeps curve order within a
 * voxel, so the cap rule (first max_per_voxel lines kept) is deterministic.
 * Any thread; no GL. Does not upload anything (voxel_lines.c does).
 */
#include "voxel_grid.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../lines/sl_lines_prep.h"

/* --- Clipping ------------------------------------------------------------- */

typedef struct clip_state {
    const int *dims;
    int cell[3];
    int have_entry;
    double entry[3];
    int entry_face;
    double entry_attr;
    uint32_t entry_seg, seg;
    uint32_t curve;
    sl_voxel_piece_fn fn;
    void *user;
    sl_voxel_clip_stats *stats;
    int stop;
} clip_state;

static void emit(clip_state *s, const double p[3], int exit_face, double attr)
{
    if (!s->have_entry)
        return;
    if (s->entry[0] == p[0] && s->entry[1] == p[1] && s->entry[2] == p[2]) {
        s->stats->degenerate++;
        return;
    }
    sl_voxel_piece piece;
    memcpy(piece.cell, s->cell, sizeof piece.cell);
    piece.curve = s->curve;
    memcpy(piece.a, s->entry, sizeof piece.a);
    memcpy(piece.b, p, sizeof piece.b);
    piece.face_a = s->entry_face;
    piece.face_b = exit_face;
    piece.attr_a = s->entry_attr;
    piece.attr_b = attr;
    piece.seg_a = s->entry_seg;
    piece.seg_b = s->seg;
    s->stats->pieces++;
    if (s->fn(s->user, &piece))
        s->stop = 1;
}

static void set_entry(clip_state *s, const double p[3], int face, double attr)
{
    s->have_entry = 1;
    memcpy(s->entry, p, sizeof s->entry);
    s->entry_face = face;
    s->entry_attr = attr;
    s->entry_seg = s->seg;
}

static double clampd(double x, double lo, double hi)
{
    return x < lo ? lo : (x > hi ? hi : x);
}

/* Walks segment a -> b (clamped grid coordinates) from the current cell. */
static void clip_segment(clip_state *s, const double a[3], const double b[3], double attr_a, double attr_b)
{
    double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    int blocked[3] = {0, 0, 0}; /* axes that reached the grid boundary in this segment */
    for (;;) {
        double tmin = DBL_MAX;
        double plane[3] = {0, 0, 0};
        double t[3] = {DBL_MAX, DBL_MAX, DBL_MAX};
        for (int ax = 0; ax < 3; ax++) {
            if (blocked[ax]) {
                continue;
            } else if (d[ax] > 0.0) {
                plane[ax] = (double)(s->cell[ax] + 1);
                t[ax] = (plane[ax] - a[ax]) / d[ax];
            } else if (d[ax] < 0.0) {
                plane[ax] = (double)s->cell[ax];
                t[ax] = (plane[ax] - a[ax]) / d[ax];
            }
            if (t[ax] < tmin)
                tmin = t[ax];
        }
        if (!(tmin <= 1.0))
            return;
        if (tmin < 0.0)
            tmin = 0.0; /* a point on a plane behind the walk: cross at the start */
        double p[3];
        int next[3] = {s->cell[0], s->cell[1], s->cell[2]};
        int first_axis = -1, out_of_grid = 0;
        for (int ax = 0; ax < 3; ax++) {
            p[ax] = a[ax] + tmin * d[ax];
            if (t[ax] == tmin || (tmin == 0.0 && t[ax] <= 0.0)) {
                p[ax] = plane[ax];
                next[ax] += d[ax] > 0.0 ? 1 : -1;
                if (next[ax] < 0 || next[ax] >= s->dims[ax]) {
                    out_of_grid = 1;
                    blocked[ax] = 1;
                    next[ax] = s->cell[ax];
                }
                if (first_axis < 0)
                    first_axis = ax;
            } else {
                /* Rounding must not move the point out of the cell it is in. */
                p[ax] = clampd(p[ax], (double)s->cell[ax], (double)(s->cell[ax] + 1));
            }
        }
        /* Attribute at the crossing (voxel_grid.h, step 2; mirrored in voxelize_gpu.comp.glsl). */
        double attr = attr_a + tmin * (attr_b - attr_a);
        int up = d[first_axis] > 0.0;
        emit(s, p, 2 * first_axis + (up ? 1 : 0), attr);
        if (s->stop)
            return;
        if (out_of_grid) {
            /* Reaching the grid boundary (a clamped point exactly on it): the
             * piece up to it is complete; what follows starts a new curve part. */
            s->have_entry = 0;
            memcpy(s->cell, next, sizeof s->cell);
            continue;
        }
        memcpy(s->cell, next, sizeof s->cell);
        set_entry(s, p, 2 * first_axis + (up ? 0 : 1), attr);
    }
}

sl_status sl_voxel_clip_polyline(const int dims[3], const double *points, const double *attr, size_t n,
                                 uint32_t curve, sl_voxel_piece_fn fn, void *user,
                                 sl_voxel_clip_stats *stats, sl_err *err)
{
    sl_voxel_clip_stats local = {0};
    if (!stats)
        stats = &local;
    if (n == 0)
        return SL_OK;
    for (size_t i = 0; i < 3 * n; i++)
        if (!isfinite(points[i]))
            return sl_err_set(err, SL_ERR_INVALID, "curve %u: point %zu is not finite", curve, i / 3);
    clip_state s = {.dims = dims, .curve = curve, .fn = fn, .user = user, .stats = stats};
    double a[3];
    for (int ax = 0; ax < 3; ax++) {
        a[ax] = clampd(points[ax], 0.0, (double)dims[ax]);
        int c = (int)floor(a[ax]);
        s.cell[ax] = c >= dims[ax] ? dims[ax] - 1 : c;
    }
    /* A first vertex exactly on the lower face of its cell, moving into the
     * cell, starts a complete piece (the first segment with motion decides). */
    for (size_t i = 1; i < n && !s.have_entry; i++) {
        double d[3];
        int moving = 0;
        for (int ax = 0; ax < 3; ax++) {
            d[ax] = clampd(points[3 * i + ax], 0.0, (double)dims[ax]) - a[ax];
            moving |= d[ax] != 0.0;
        }
        if (!moving)
            continue;
        for (int ax = 0; ax < 3; ax++)
            if (a[ax] == (double)s.cell[ax] && d[ax] > 0.0) {
                set_entry(&s, a, 2 * ax, attr ? attr[0] : 0.0);
                break;
            }
        break;
    }
    for (size_t i = 1; i < n && !s.stop; i++) {
        double b[3];
        for (int ax = 0; ax < 3; ax++)
            b[ax] = clampd(points[3 * i + ax], 0.0, (double)dims[ax]);
        s.seg = (uint32_t)(i - 1);
        clip_segment(&s, a, b, attr ? attr[i - 1] : 0.0, attr ? attr[i] : 0.0);
        memcpy(a, b, sizeof a);
    }
    return SL_OK;
}

/* --- Grid placement --------------------------------------------------------- */

int sl_voxel_auto_resolution(const sl_dataset *ds)
{
    const sl_lines *l = &ds->lines;
    double lo[3], hi[3];
    sl_lines_position_bounds(l, lo, hi);
    double longest = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    double total = 0.0;
    size_t segments = 0;
    for (size_t k = 0; k < l->line_count; k++)
        for (uint32_t v = l->line_offsets[k] + 1; v < l->line_offsets[k + 1]; v++) {
            const float *p = l->positions + 3 * (size_t)v, *q = p - 3;
            total += sqrt((double)(p[0] - q[0]) * (p[0] - q[0]) + (double)(p[1] - q[1]) * (p[1] - q[1]) +
                          (double)(p[2] - q[2]) * (p[2] - q[2]));
            segments++;
        }
    if (segments == 0 || !(total > 0.0) || !(longest > 0.0))
        return 32;
    double want = longest / (2.0 * total / (double)segments);
    int r = 32;
    while (r < 256 && r < want)
        r *= 2;
    return r;
}

sl_status sl_voxel_frame_init(sl_voxel_frame *f, const sl_dataset *ds, int resolution, int padding, sl_err *err)
{
    memset(f, 0, sizeof *f);
    if (!ds || ds->kind != SL_DATASET_LINES)
        return sl_err_set(err, SL_ERR_INVALID, "voxelization needs a line dataset");
    if (resolution < 0 || resolution > SL_VOXEL_MAX_DIM || padding < 0 || padding > 16)
        return sl_err_set(err, SL_ERR_INVALID, "grid resolution %d (0..%d) or padding %d (0..16) out of range",
                          resolution, SL_VOXEL_MAX_DIM, padding);
    if (resolution == 0)
        resolution = sl_voxel_auto_resolution(ds);
    double lo[3], hi[3];
    sl_lines_position_bounds(&ds->lines, lo, hi);
    double longest = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    if (!(longest > 0.0))
        longest = 1.0;
    f->h = longest / resolution;
    size_t total = 1;
    for (int c = 0; c < 3; c++) {
        double ext = (hi[c] - lo[c]) / f->h;
        int n = (int)ceil(ext - 1e-9);
        if (n < 1)
            n = 1;
        f->dims[c] = n + 2 * padding;
        /* Centre the data in its voxels along the short axes. */
        f->lo[c] = 0.5 * (lo[c] + hi[c]) - 0.5 * n * f->h - padding * f->h;
        if (f->dims[c] > SL_VOXEL_MAX_DIM)
            return sl_err_set(err, SL_ERR_LIMIT, "voxel grid axis %d needs %d voxels, above the limit %d", c,
                              f->dims[c], SL_VOXEL_MAX_DIM);
        total *= (size_t)f->dims[c];
    }
    if (total > SL_VOXEL_MAX_VOXELS)
        return sl_err_set(err, SL_ERR_LIMIT, "voxel grid %dx%dx%d has %zu voxels, above the limit %llu",
                          f->dims[0], f->dims[1], f->dims[2], total, SL_VOXEL_MAX_VOXELS);
    return SL_OK;
}

/* --- Attribute byte (definition: voxel_grid.h) ----------------------------- */

void sl_voxel_attr_normalize(const sl_attribute *at, const float *values, size_t n, double *out)
{
    double amin = (double)at->min, aspan = (double)at->max - (double)at->min;
    for (size_t i = 0; i < n; i++) {
        double v = (double)values[i];
        out[i] = aspan > 0.0 && isfinite(v) ? (v - amin) / aspan : 0.0;
    }
}

uint32_t sl_voxel_attr_byte(double attr_a, double attr_b)
{
    double m = 0.5 * (attr_a + attr_b);
    if (!(m > 0.0))
        m = 0.0;
    if (m > 1.0)
        m = 1.0;
    double y = m * 255.0;
    double q = floor(y);
    return (uint32_t)q + (y - q >= 0.5 ? 1u : 0u);
}

/* --- Build ---------------------------------------------------------------- */

typedef struct build_item {
    uint32_t voxel;
    uint64_t code;
} build_item;

typedef struct build_state {
    const sl_voxel_frame *frame;
    int quant, k;
    build_item *items;
    size_t count, capacity;
    size_t degenerate;
    int failed;
} build_state;

static int collect(void *user, const sl_voxel_piece *p)
{
    build_state *b = user;
    double ua[3], ub[3];
    for (int c = 0; c < 3; c++) {
        ua[c] = p->a[c] - p->cell[c];
        ub[c] = p->b[c] - p->cell[c];
    }
    sl_voxel_line line = {
        .face_a = p->face_a, .face_b = p->face_b,
        .bin_a = sl_voxel_quantize(ua, p->face_a, b->quant),
        .bin_b = sl_voxel_quantize(ub, p->face_b, b->quant),
        .id = p->curve & ((1u << sl_voxel_line_id_bits(b->k)) - 1),
    };
    line.attr = sl_voxel_attr_byte(p->attr_a, p->attr_b);
    if (line.face_a == line.face_b && line.bin_a == line.bin_b) {
        b->degenerate++;
        return 0;
    }
    if (b->count == b->capacity) {
        size_t cap = b->capacity ? 2 * b->capacity : 4096;
        build_item *n = realloc(b->items, cap * sizeof *n);
        if (!n) {
            b->failed = 1;
            return 1;
        }
        b->items = n;
        b->capacity = cap;
    }
    b->items[b->count].voxel = (uint32_t)sl_voxel_index(b->frame->dims, p->cell);
    b->items[b->count].code = sl_voxel_encode_line(b->k, &line);
    b->count++;
    return 0;
}

static double line_length(int n, uint64_t code, int k)
{
    sl_voxel_line l;
    sl_voxel_decode_line(k, code, &l);
    double a[3], b[3];
    sl_voxel_dequantize(l.face_a, l.bin_a, n, a);
    sl_voxel_dequantize(l.face_b, l.bin_b, n, b);
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

sl_status sl_voxel_grid_build(sl_voxel_grid *g, const sl_dataset *ds, const sl_voxel_grid_desc *desc,
                              sl_err *err)
{
    memset(g, 0, sizeof *g);
    double t0 = sl_clock_ms();
    sl_voxel_grid_desc d = desc ? *desc : (sl_voxel_grid_desc){0};
    if (d.quant == 0)
        d.quant = 32;
    if (d.padding < 0)
        d.padding = 1;
    if (d.max_per_voxel == 0)
        d.max_per_voxel = SL_VOXEL_COUNT_MAX;
    int k = sl_voxel_quant_bits(d.quant);
    if (k < 0)
        return sl_err_set(err, SL_ERR_INVALID, "face quantization %d must be a power of two in 2..256", d.quant);
    if (d.max_per_voxel < 1 || d.max_per_voxel > SL_VOXEL_COUNT_MAX)
        return sl_err_set(err, SL_ERR_INVALID, "max lines per voxel %d must be in 1..%d", d.max_per_voxel,
                          SL_VOXEL_COUNT_MAX);
    sl_status st = sl_voxel_frame_init(&g->frame, ds, d.resolution, d.padding, err);
    if (st != SL_OK)
        return st;
    const sl_lines *l = &ds->lines;
    g->quant = d.quant;
    g->quant_bits = k;
    g->line_bytes = sl_voxel_line_bytes(k);
    g->voxel_count = (size_t)g->frame.dims[0] * g->frame.dims[1] * g->frame.dims[2];
    g->attribute_index = d.attribute >= 0 && d.attribute < l->attribute_count ? d.attribute : -1;

    build_state b = {.frame = &g->frame, .quant = d.quant, .k = k};
    double *pts = NULL, *attr = NULL;
    size_t longest = 0;
    for (size_t c = 0; c < l->line_count; c++) {
        size_t n = l->line_offsets[c + 1] - l->line_offsets[c];
        if (n > longest)
            longest = n;
    }
    pts = malloc((longest ? longest : 1) * 3 * sizeof *pts);
    attr = malloc((longest ? longest : 1) * sizeof *attr);
    g->offsets = calloc(g->voxel_count, sizeof *g->offsets);
    g->counts = calloc(g->voxel_count, 1);
    g->density = calloc(g->voxel_count, sizeof *g->density);
    uint32_t *fill = calloc(g->voxel_count, sizeof *fill);
    if (!pts || !attr || !g->offsets || !g->counts || !g->density || !fill) {
        st = sl_err_set(err, SL_ERR_NOMEM, "voxel grid of %zu voxels: out of memory", g->voxel_count);
        goto fail;
    }
    const sl_attribute *at = g->attribute_index >= 0 ? &l->attributes[g->attribute_index] : NULL;
    for (size_t c = 0; c < l->line_count; c++) {
        size_t first = l->line_offsets[c], n = l->line_offsets[c + 1] - first;
        for (size_t i = 0; i < n; i++)
            for (int ax = 0; ax < 3; ax++)
                pts[3 * i + ax] = ((double)l->positions[3 * (first + i) + ax] - g->frame.lo[ax]) / g->frame.h;
        if (at)
            sl_voxel_attr_normalize(at, at->values + first, n, attr);
        size_t before = b.count;
        sl_voxel_clip_stats cs = {0};
        st = sl_voxel_clip_polyline(g->frame.dims, pts, at ? attr : NULL, n, (uint32_t)c, collect, &b, &cs, err);
        if (st != SL_OK)
            goto fail;
        if (b.failed) {
            st = sl_err_set(err, SL_ERR_NOMEM, "voxelization: out of memory after %zu lines", b.count);
            goto fail;
        }
        g->degenerate += cs.degenerate;
        if (b.count == before)
            g->curves_without_pieces++;
    }
    g->degenerate += b.degenerate;
    g->pieces = b.count;

    /* Counting sort by voxel; the cap keeps the first lines in curve order. */
    for (size_t i = 0; i < b.count; i++)
        fill[b.items[i].voxel]++;
    size_t total = 0;
    for (size_t v = 0; v < g->voxel_count; v++) {
        uint32_t n = fill[v];
        if ((int)n > g->max_count)
            g->max_count = (int)n;
        if (n > (uint32_t)d.max_per_voxel) {
            g->dropped_overflow += n - (uint32_t)d.max_per_voxel;
            g->capped_voxels++;
            n = (uint32_t)d.max_per_voxel;
        }
        if (total + n > UINT32_MAX) {
            st = sl_err_set(err, SL_ERR_LIMIT, "voxelization produced more than %u lines", UINT32_MAX);
            goto fail;
        }
        g->offsets[v] = (uint32_t)total;
        g->counts[v] = (uint8_t)n;
        fill[v] = 0;
        total += n;
    }
    g->line_count = total;
    g->lines = calloc(total * (size_t)g->line_bytes + 8, 1);
    if (!g->lines) {
        st = sl_err_set(err, SL_ERR_NOMEM, "voxelization: %zu lines do not fit in memory", total);
        goto fail;
    }
    for (size_t i = 0; i < b.count; i++) {
        uint32_t v = b.items[i].voxel;
        if (fill[v] >= g->counts[v])
            continue;
        size_t at_line = (size_t)g->offsets[v] + fill[v]++;
        uint64_t code = b.items[i].code;
        for (int byte = 0; byte < g->line_bytes; byte++)
            g->lines[at_line * g->line_bytes + byte] = (uint8_t)(code >> (8 * byte));
        g->density[v] += (float)line_length(d.quant, code, k);
    }
    free(b.items);
    free(fill);
    free(pts);
    free(attr);
    g->build_ms = sl_clock_ms() - t0;
    return SL_OK;
fail:
    free(b.items);
    free(fill);
    free(pts);
    free(attr);
    sl_voxel_grid_deinit(g);
    return st;
}

void sl_voxel_grid_deinit(sl_voxel_grid *g)
{
    if (!g)
        return;
    free(g->offsets);
    free(g->counts);
    free(g->lines);
    free(g->density);
    memset(g, 0, sizeof *g);
}

uint64_t sl_voxel_grid_line(const sl_voxel_grid *g, size_t i)
{
    uint64_t code = 0;
    for (int byte = 0; byte < g->line_bytes; byte++)
        code |= (uint64_t)g->lines[i * g->line_bytes + byte] << (8 * byte);
    return code;
}

size_t sl_voxel_grid_bytes(const sl_voxel_grid *g)
{
    return g->voxel_count * 5 + g->line_count * (size_t)g->line_bytes + g->voxel_count * sizeof(float);
}
