/* load_vtk.c — legacy VTK files (ASCII or big-endian BINARY): POLYDATA
 * lines into a line set, STRUCTURED_POINTS into a scalar volume or a
 * vector field.
 *
 * POLYDATA: POINTS, LINES (classic "count i0 i1 ..." cells or the 5.1
 * OFFSETS/CONNECTIVITY form), VERTICES/POLYGONS/TRIANGLE_STRIPS (skipped),
 * POINT_DATA SCALARS / FIELD arrays (per-vertex attributes, one per
 * component: "name" or "name[c]"), NORMALS (vertex normals), VECTORS (three
 * attributes), CELL_DATA for the line cells (per-line attributes). A point
 * used by several lines is copied into each. STRUCTURED_POINTS: DIMENSIONS,
 * SPACING or ASPECT_RATIO, ORIGIN; the first POINT_DATA SCALARS (1
 * component) or VECTORS array becomes the volume, later ones are skipped.
 * u8/u16/s16 are kept, char widens to s16, every other type becomes f32.
 * Does not read other datasets (UNSTRUCTURED_GRID, RECTILINEAR_GRID, ...),
 * "bit" or string arrays, or XML .vtp/.vti. Attributes past
 * SL_MAX_ATTRIBUTES are skipped. Every count is checked against the bytes
 * left before anything is allocated. Any thread; no GL.
 */
#include "load_common.h"
#include "load_lines.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum vtype { VT_U8, VT_S8, VT_U16, VT_S16, VT_U32, VT_S32, VT_U64, VT_S64, VT_F32, VT_F64 } vtype;

typedef enum dst_kind { DST_SKIP, DST_F32, DST_F64, DST_I64, DST_U8, DST_U16, DST_S16 } dst_kind;

static const struct { const char *name; vtype t; } vtk_types[] = {
    {"unsigned_char", VT_U8}, {"char", VT_S8}, {"unsigned_short", VT_U16}, {"short", VT_S16},
    {"unsigned_int", VT_U32}, {"int", VT_S32}, {"unsigned_long", VT_U64}, {"long", VT_S64},
    {"float", VT_F32}, {"double", VT_F64},
    {"vtktypeuint8", VT_U8}, {"vtktypeint8", VT_S8}, {"vtktypeuint16", VT_U16}, {"vtktypeint16", VT_S16},
    {"vtktypeuint32", VT_U32}, {"vtktypeint32", VT_S32}, {"vtktypeuint64", VT_U64}, {"vtktypeint64", VT_S64},
    {"vtkidtype", VT_S64}, {"vtktypefloat32", VT_F32}, {"vtktypefloat64", VT_F64},
};

static size_t vtype_size(vtype t)
{
    switch (t) {
    case VT_U8: case VT_S8: return 1;
    case VT_U16: case VT_S16: return 2;
    case VT_U32: case VT_S32: case VT_F32: return 4;
    case VT_U64: case VT_S64: case VT_F64: return 8;
    }
    return 1;
}

typedef struct vtk {
    sl_text t;
    int binary;
    sl_err *err;
} vtk;

/* Sets err with the message plus where the parser is; returns status. */
static sl_status fail(vtk *p, sl_status st, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static sl_status fail(vtk *p, sl_status st, const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (p->binary)
        return sl_err_set(p->err, st, "%s (near byte %zu)", msg, p->t.pos);
    return sl_err_set(p->err, st, "%s (line %zu)", msg, p->t.line);
}

#define TOK_SHOW(len) (int)((len) > 40 ? 40 : (len))

static sl_status need_token(vtk *p, const char *field, const char **tok, size_t *len)
{
    if (!sl_text_token(&p->t, tok, len))
        return fail(p, SL_ERR_FORMAT, "file ends where %s was expected", field);
    return SL_OK;
}

static sl_status need_inline(vtk *p, const char *field, const char **tok, size_t *len)
{
    if (!sl_text_token_inline(&p->t, tok, len))
        return fail(p, SL_ERR_FORMAT, "%s is missing", field);
    return SL_OK;
}

/* A count on the current line, in [0, max]. */
static sl_status read_count(vtk *p, const char *field, unsigned long long max, size_t *out)
{
    const char *tok;
    size_t len;
    sl_status st = need_inline(p, field, &tok, &len);
    if (st != SL_OK)
        return st;
    long long v;
    if (!sl_text_long(tok, len, -((long long)1 << 62), (long long)1 << 62, &v))
        return fail(p, SL_ERR_FORMAT, "%s \"%.*s\" is not an integer", field, TOK_SHOW(len), tok);
    if (v < 0)
        return fail(p, SL_ERR_FORMAT, "%s %lld is negative", field, v);
    if ((unsigned long long)v > max)
        return fail(p, SL_ERR_LIMIT, "%s %lld exceeds the limit of %llu", field, v, max);
    *out = (size_t)v;
    return SL_OK;
}

static sl_status read_type(vtk *p, const char *field, vtype *out)
{
    const char *tok;
    size_t len;
    sl_status st = need_inline(p, field, &tok, &len);
    if (st != SL_OK)
        return st;
    for (size_t i = 0; i < sizeof vtk_types / sizeof vtk_types[0]; i++)
        if (sl_text_is(tok, len, vtk_types[i].name)) {
            *out = vtk_types[i].t;
            return SL_OK;
        }
    return fail(p, SL_ERR_UNSUPPORTED, "%s \"%.*s\" is not a supported data type", field, TOK_SHOW(len), tok);
}

static sl_status read_reals(vtk *p, const char *field, double *v, int n)
{
    for (int i = 0; i < n; i++) {
        const char *tok;
        size_t len;
        sl_status st = need_inline(p, field, &tok, &len);
        if (st != SL_OK)
            return st;
        if (!sl_text_double(tok, len, &v[i]) || !isfinite(v[i]))
            return fail(p, SL_ERR_FORMAT, "%s value %d \"%.*s\" is not a finite number", field, i, TOK_SHOW(len), tok);
    }
    return SL_OK;
}

/* Ends a keyword line: in BINARY files the data starts after its newline. */
static void end_line(vtk *p)
{
    if (p->binary)
        sl_text_skip_line(&p->t);
}

/* Checks that `count` values of type t can still be present. */
static sl_status check_room(vtk *p, vtype t, size_t count, const char *field)
{
    size_t left = p->t.size - p->t.pos;
    size_t need_each = p->binary ? vtype_size(t) : 2; /* ASCII: a digit and a separator */
    if (count > (left + (p->binary ? 0 : 1)) / need_each)
        return fail(p, SL_ERR_FORMAT, "%s: %zu values do not fit in the %zu bytes left (truncated or corrupt count)",
                    field, count, left);
    return SL_OK;
}

static double binary_value(const uint8_t *b, vtype t)
{
    switch (t) {
    case VT_U8: return b[0];
    case VT_S8: return (int8_t)b[0];
    case VT_U16: return (uint16_t)sl_rd_s16(b, 1);
    case VT_S16: return sl_rd_s16(b, 1);
    case VT_U32: return sl_rd_u32(b, 1);
    case VT_S32: return sl_rd_s32(b, 1);
    case VT_U64: return (double)sl_rd_u64(b, 1);
    case VT_S64: { uint64_t u = sl_rd_u64(b, 1); int64_t s; memcpy(&s, &u, 8); return (double)s; }
    case VT_F32: return sl_rd_f32(b, 1);
    case VT_F64: return sl_rd_f64(b, 1);
    }
    return 0.0;
}

/* Reads `count` values of file type t into dst (converted per kind). */
static sl_status read_values(vtk *p, vtype t, size_t count, dst_kind kind, void *dst, const char *field)
{
    sl_status st = check_room(p, t, count, field);
    if (st != SL_OK)
        return st;
    if (p->binary && kind == DST_SKIP) {
        p->t.pos += count * vtype_size(t);
        return SL_OK;
    }
    size_t w = vtype_size(t);
    for (size_t i = 0; i < count; i++) {
        double v;
        if (p->binary) {
            if (p->t.size - p->t.pos < w)
                return fail(p, SL_ERR_FORMAT, "%s: data ends at value %zu of %zu", field, i, count);
            v = binary_value(p->t.data + p->t.pos, t);
            p->t.pos += w;
        } else {
            const char *tok;
            size_t len;
            if (!sl_text_token(&p->t, &tok, &len))
                return fail(p, SL_ERR_FORMAT, "%s: file ends at value %zu of %zu", field, i, count);
            if (!sl_text_double(tok, len, &v))
                return fail(p, SL_ERR_FORMAT, "%s: value %zu \"%.*s\" is not a number", field, i, TOK_SHOW(len), tok);
        }
        switch (kind) {
        case DST_SKIP:
            break;
        case DST_F32:
            ((float *)dst)[i] = sl_load_narrow(v);
            break;
        case DST_F64:
            ((double *)dst)[i] = v;
            break;
        case DST_I64:
            if (!(v >= -9007199254740992.0 && v <= 9007199254740992.0) || v != floor(v))
                return fail(p, SL_ERR_FORMAT, "%s: value %zu (%g) is not an integer", field, i, v);
            ((int64_t *)dst)[i] = (int64_t)v;
            break;
        case DST_U8:
            if (!(v >= 0.0 && v <= 255.0))
                return fail(p, SL_ERR_FORMAT, "%s: value %zu (%g) is outside unsigned_char", field, i, v);
            ((uint8_t *)dst)[i] = (uint8_t)v;
            break;
        case DST_U16:
            if (!(v >= 0.0 && v <= 65535.0))
                return fail(p, SL_ERR_FORMAT, "%s: value %zu (%g) is outside unsigned_short", field, i, v);
            ((uint16_t *)dst)[i] = (uint16_t)v;
            break;
        case DST_S16:
            if (!(v >= -32768.0 && v <= 32767.0))
                return fail(p, SL_ERR_FORMAT, "%s: value %zu (%g) is outside short", field, i, v);
            ((int16_t *)dst)[i] = (int16_t)v;
            break;
        }
    }
    return SL_OK;
}

/* Reads count integers (any integer type) into a new int64 array. */
static sl_status read_ints(vtk *p, vtype t, size_t count, const char *field, int64_t **out)
{
    *out = NULL;
    sl_status st = check_room(p, t, count, field);
    if (st != SL_OK)
        return st;
    int64_t *a = malloc((count ? count : 1) * sizeof *a);
    if (!a)
        return fail(p, SL_ERR_NOMEM, "%s: out of memory for %zu integers", field, count);
    st = read_values(p, t, count, DST_I64, a, field);
    if (st != SL_OK) {
        free(a);
        return st;
    }
    *out = a;
    return SL_OK;
}

/* Peeks the next token; consumes it only when it equals word. */
static int accept_word(vtk *p, const char *word)
{
    sl_text save = p->t;
    const char *tok;
    size_t len;
    if (sl_text_token(&p->t, &tok, &len) && sl_text_is(tok, len, word))
        return 1;
    p->t = save;
    return 0;
}

/* ---------------- cells (LINES and the skipped cell kinds) ---------------- */

typedef struct cells {
    size_t count;
    uint64_t *offsets;   /* count + 1 */
    uint32_t *indices;   /* offsets[count] */
} cells;

/* Parses the body of "KEYWORD n size" (classic) or "KEYWORD n_offsets n_conn"
 * followed by OFFSETS/CONNECTIVITY (5.1). With out NULL the cells are only
 * counted and skipped. Indices are checked < point_count. */
static sl_status read_cells(vtk *p, const char *kw, size_t point_count, cells *out, size_t *cell_count)
{
    size_t a, b;
    char field[64];
    snprintf(field, sizeof field, "%s count", kw);
    sl_status st = read_count(p, field, (unsigned long long)1 << 40, &a);
    if (st == SL_OK) {
        snprintf(field, sizeof field, "%s size", kw);
        st = read_count(p, field, (unsigned long long)1 << 40, &b);
    }
    if (st != SL_OK)
        return st;
    end_line(p);
    int64_t *offs = NULL, *conn = NULL;
    size_t n_cells;
    if (accept_word(p, "OFFSETS")) {
        /* 5.1: a offsets (cells + 1) then b connectivity entries. */
        vtype t;
        snprintf(field, sizeof field, "%s OFFSETS type", kw);
        if ((st = read_type(p, field, &t)) != SL_OK)
            return st;
        end_line(p);
        snprintf(field, sizeof field, "%s OFFSETS", kw);
        if ((st = read_ints(p, t, a, field, &offs)) != SL_OK)
            return st;
        if (!accept_word(p, "CONNECTIVITY")) {
            free(offs);
            return fail(p, SL_ERR_FORMAT, "%s: OFFSETS is not followed by CONNECTIVITY", kw);
        }
        snprintf(field, sizeof field, "%s CONNECTIVITY type", kw);
        if ((st = read_type(p, field, &t)) != SL_OK) {
            free(offs);
            return st;
        }
        end_line(p);
        snprintf(field, sizeof field, "%s CONNECTIVITY", kw);
        if ((st = read_ints(p, t, b, field, &conn)) != SL_OK) {
            free(offs);
            return st;
        }
        n_cells = a ? a - 1 : 0;
        if ((a == 0 && b != 0) || (a > 0 && (offs[0] != 0 || offs[a - 1] != (int64_t)b))) {
            st = fail(p, SL_ERR_FORMAT, "%s: OFFSETS do not start at 0 and end at the %zu CONNECTIVITY entries", kw, b);
            goto done;
        }
        for (size_t k = 0; k < n_cells; k++)
            if (offs[k + 1] < offs[k]) {
                st = fail(p, SL_ERR_FORMAT, "%s: OFFSETS decrease at cell %zu", kw, k);
                goto done;
            }
    } else {
        /* classic: a cells, b integers "count i0 i1 ..." */
        snprintf(field, sizeof field, "%s cells", kw);
        if ((st = read_ints(p, VT_S32, b, field, &conn)) != SL_OK)
            return st;
        n_cells = a;
        if (a > b) {
            st = fail(p, SL_ERR_FORMAT, "%s: %zu cells cannot fit in %zu integers", kw, a, b);
            goto done;
        }
        offs = malloc((a + 1) * sizeof *offs);
        if (!offs) {
            st = fail(p, SL_ERR_NOMEM, "%s: out of memory", kw);
            goto done;
        }
        /* Rewrite in place: conn becomes the bare indices, offs their ranges. */
        size_t r = 0, w = 0;
        offs[0] = 0;
        for (size_t k = 0; k < a; k++) {
            if (r >= b) {
                st = fail(p, SL_ERR_FORMAT, "%s: cell %zu starts past the %zu integers", kw, k, b);
                goto done;
            }
            int64_t m = conn[r++];
            if (m < 0 || (uint64_t)m > b - r) {
                st = fail(p, SL_ERR_FORMAT, "%s: cell %zu has point count %lld (%zu integers left)", kw, k, (long long)m, b - r);
                goto done;
            }
            for (int64_t i = 0; i < m; i++)
                conn[w++] = conn[r++];
            offs[k + 1] = (int64_t)w;
        }
        if (r != b) {
            st = fail(p, SL_ERR_FORMAT, "%s: cells use %zu of the %zu integers declared", kw, r, b);
            goto done;
        }
    }
    *cell_count = n_cells;
    if (out) {
        size_t n_idx = (size_t)offs[n_cells];
        if (n_cells > SL_MAX_LINES) {
            st = fail(p, SL_ERR_LIMIT, "%s: %zu cells exceed the limit of %u lines", kw, n_cells, SL_MAX_LINES);
            goto done;
        }
        if (n_idx > SL_MAX_VERTICES) {
            st = fail(p, SL_ERR_LIMIT, "%s: %zu line vertices exceed the limit of %u", kw, n_idx, SL_MAX_VERTICES);
            goto done;
        }
        out->offsets = malloc((n_cells + 1) * sizeof *out->offsets);
        out->indices = malloc((n_idx ? n_idx : 1) * sizeof *out->indices);
        if (!out->offsets || !out->indices) {
            st = fail(p, SL_ERR_NOMEM, "%s: out of memory for %zu indices", kw, n_idx);
            goto done;
        }
        for (size_t k = 0; k <= n_cells; k++)
            out->offsets[k] = (uint64_t)offs[k];
        for (size_t i = 0; i < n_idx; i++) {
            if (conn[i] < 0 || (uint64_t)conn[i] >= point_count) {
                st = fail(p, SL_ERR_FORMAT, "%s: point index %lld is outside the %zu POINTS", kw, (long long)conn[i], point_count);
                goto done;
            }
            out->indices[i] = (uint32_t)conn[i];
        }
        out->count = n_cells;
    }
done:
    free(offs);
    free(conn);
    return st;
}

/* ---------------- attributes ---------------- */

typedef struct attr_set {
    int count;
    char names[SL_MAX_ATTRIBUTES][SL_NAME_MAX];
    float *values[SL_MAX_ATTRIBUTES];  /* n each, owned */
    float *normals;                    /* 3n, owned (POINT_DATA NORMALS) */
} attr_set;

static void attr_set_free(attr_set *s)
{
    for (int i = 0; i < s->count; i++)
        free(s->values[i]);
    free(s->normals);
    s->count = 0;
    s->normals = NULL;
}

/* Reads n tuples of ncomp values and splits them into ncomp attributes
 * (skipped, data still consumed, when they would pass SL_MAX_ATTRIBUTES). */
static sl_status read_components(vtk *p, attr_set *s, const char *name, vtype t, size_t n, size_t ncomp,
                                 const char *field)
{
    sl_status st = check_room(p, t, n * ncomp, field);
    if (st != SL_OK)
        return st;
    if (!s || s->count + (int)ncomp > SL_MAX_ATTRIBUTES)
        return read_values(p, t, n * ncomp, DST_SKIP, NULL, field);
    size_t total = n * ncomp;
    float *tmp = malloc((total ? total : 1) * sizeof(float));
    if (!tmp)
        return fail(p, SL_ERR_NOMEM, "%s: out of memory for %zu values", field, n * ncomp);
    st = read_values(p, t, n * ncomp, DST_F32, tmp, field);
    if (st != SL_OK || ncomp == 1) {
        if (st == SL_OK) {
            snprintf(s->names[s->count], SL_NAME_MAX, "%s", name);
            s->values[s->count++] = tmp;
        } else {
            free(tmp);
        }
        return st;
    }
    for (size_t c = 0; c < ncomp; c++) {
        float *v = malloc((n ? n : 1) * sizeof(float));
        if (!v) {
            free(tmp);
            return fail(p, SL_ERR_NOMEM, "%s: out of memory", field);
        }
        for (size_t i = 0; i < n; i++)
            v[i] = tmp[i * ncomp + c];
        snprintf(s->names[s->count], SL_NAME_MAX, "%.*s[%u]", SL_NAME_MAX - 14, name, (unsigned)c);
        s->values[s->count++] = v;
    }
    free(tmp);
    return SL_OK;
}

/* Copies an attribute name token (bounded) for storage and messages. */
static void token_name(const char *tok, size_t len, char *out, size_t cap)
{
    size_t n = len < cap - 1 ? len : cap - 1;
    for (size_t i = 0; i < n; i++)
        out[i] = (tok[i] >= 0x20 && tok[i] < 0x7f) ? tok[i] : '?';
    out[n] = '\0';
}

/* Skips a 5.1 METADATA block (its keyword already read) up to the blank
 * line that ends it, or to the end of the file. */
static void skip_metadata(vtk *p)
{
    while (p->t.pos < p->t.size) {
        sl_text_skip_line(&p->t);
        size_t q = p->t.pos;
        while (q < p->t.size && (p->t.data[q] == ' ' || p->t.data[q] == '\t' || p->t.data[q] == '\r'))
            q++;
        if (q >= p->t.size || p->t.data[q] == '\n')
            break;
    }
}

/* FIELD name nArrays, then per array "name ncomp ntuples type" and data.
 * Arrays whose tuple count is n go into s (when s is given). */
static sl_status read_field(vtk *p, attr_set *s, size_t n)
{
    const char *tok;
    size_t len, arrays;
    sl_status st = need_inline(p, "FIELD name", &tok, &len);
    if (st == SL_OK)
        st = read_count(p, "FIELD array count", 1u << 16, &arrays);
    if (st != SL_OK)
        return st;
    end_line(p);
    for (size_t a = 0; a < arrays; a++) {
        char name[SL_NAME_MAX];
        size_t ncomp, ntuples;
        vtype t;
        /* VTK 5.1 may put a METADATA block after an array. */
        while (accept_word(p, "METADATA"))
            skip_metadata(p);
        if ((st = need_token(p, "FIELD array name", &tok, &len)) != SL_OK)
            return st;
        token_name(tok, len, name, sizeof name);
        if ((st = read_count(p, "FIELD array components", 64, &ncomp)) != SL_OK ||
            (st = read_count(p, "FIELD array tuples", (unsigned long long)1 << 40, &ntuples)) != SL_OK ||
            (st = read_type(p, "FIELD array type", &t)) != SL_OK)
            return st;
        if (ncomp == 0)
            return fail(p, SL_ERR_FORMAT, "FIELD array '%s' has 0 components", name);
        end_line(p);
        if (ntuples > ((size_t)1 << 40) / ncomp)
            return fail(p, SL_ERR_LIMIT, "FIELD array '%s' is too large", name);
        st = read_components(p, (s && ntuples == n) ? s : NULL, name, t, ntuples, ncomp, "FIELD array data");
        if (st != SL_OK)
            return st;
    }
    return SL_OK;
}

/* Handles one attribute keyword (already read as tok) of a POINT_DATA or
 * CELL_DATA block of n tuples. Stored into s when s is non-NULL; NORMALS
 * stored only when keep_normals. *handled 0 means tok is not an attribute. */
static sl_status read_attribute(vtk *p, const char *tok, size_t len, size_t n, attr_set *s,
                                int keep_normals, int *handled)
{
    *handled = 1;
    sl_status st;
    const char *nt;
    size_t nlen;
    char name[SL_NAME_MAX];
    vtype t;
    if (sl_text_is(tok, len, "SCALARS")) {
        size_t ncomp = 1;
        if ((st = need_inline(p, "SCALARS name", &nt, &nlen)) != SL_OK)
            return st;
        token_name(nt, nlen, name, sizeof name);
        if ((st = read_type(p, "SCALARS type", &t)) != SL_OK)
            return st;
        sl_text save = p->t;
        if (sl_text_token_inline(&p->t, &nt, &nlen)) {
            p->t = save;
            if ((st = read_count(p, "SCALARS components", 4, &ncomp)) != SL_OK)
                return st;
            if (ncomp == 0)
                return fail(p, SL_ERR_FORMAT, "SCALARS '%s' has 0 components", name);
        }
        end_line(p);
        if (accept_word(p, "LOOKUP_TABLE")) {
            if ((st = need_inline(p, "LOOKUP_TABLE name", &nt, &nlen)) != SL_OK)
                return st;
            end_line(p);
        }
        return read_components(p, s, name, t, n, ncomp, "SCALARS data");
    }
    if (sl_text_is(tok, len, "LOOKUP_TABLE")) {
        size_t entries;
        if ((st = need_inline(p, "LOOKUP_TABLE name", &nt, &nlen)) != SL_OK ||
            (st = read_count(p, "LOOKUP_TABLE size", (unsigned long long)1 << 32, &entries)) != SL_OK)
            return st;
        end_line(p);
        return read_values(p, p->binary ? VT_U8 : VT_F32, entries * 4, DST_SKIP, NULL, "LOOKUP_TABLE data");
    }
    if (sl_text_is(tok, len, "COLOR_SCALARS")) {
        size_t ncomp;
        if ((st = need_inline(p, "COLOR_SCALARS name", &nt, &nlen)) != SL_OK ||
            (st = read_count(p, "COLOR_SCALARS components", 4, &ncomp)) != SL_OK)
            return st;
        end_line(p);
        return read_values(p, p->binary ? VT_U8 : VT_F32, n * ncomp, DST_SKIP, NULL, "COLOR_SCALARS data");
    }
    if (sl_text_is(tok, len, "VECTORS") || sl_text_is(tok, len, "NORMALS")) {
        int normals = sl_text_is(tok, len, "NORMALS");
        if ((st = need_inline(p, normals ? "NORMALS name" : "VECTORS name", &nt, &nlen)) != SL_OK)
            return st;
        token_name(nt, nlen, name, sizeof name);
        if ((st = read_type(p, normals ? "NORMALS type" : "VECTORS type", &t)) != SL_OK)
            return st;
        end_line(p);
        if (normals) {
            if (!s || !keep_normals || s->normals)
                return read_values(p, t, 3 * n, DST_SKIP, NULL, "NORMALS data");
            if ((st = check_room(p, t, 3 * n, "NORMALS data")) != SL_OK)
                return st;
            s->normals = malloc((n ? 3 * n : 1) * sizeof(float));
            if (!s->normals)
                return fail(p, SL_ERR_NOMEM, "NORMALS: out of memory");
            return read_values(p, t, 3 * n, DST_F32, s->normals, "NORMALS data");
        }
        return read_components(p, s, name, t, n, 3, "VECTORS data");
    }
    if (sl_text_is(tok, len, "TEXTURE_COORDINATES")) {
        size_t dim;
        if ((st = need_inline(p, "TEXTURE_COORDINATES name", &nt, &nlen)) != SL_OK ||
            (st = read_count(p, "TEXTURE_COORDINATES dimension", 3, &dim)) != SL_OK ||
            (st = read_type(p, "TEXTURE_COORDINATES type", &t)) != SL_OK)
            return st;
        end_line(p);
        return read_values(p, t, n * dim, DST_SKIP, NULL, "TEXTURE_COORDINATES data");
    }
    if (sl_text_is(tok, len, "TENSORS") || sl_text_is(tok, len, "TENSORS6")) {
        size_t k = sl_text_is(tok, len, "TENSORS") ? 9 : 6;
        if ((st = need_inline(p, "TENSORS name", &nt, &nlen)) != SL_OK ||
            (st = read_type(p, "TENSORS type", &t)) != SL_OK)
            return st;
        end_line(p);
        return read_values(p, t, n * k, DST_SKIP, NULL, "TENSORS data");
    }
    if (sl_text_is(tok, len, "FIELD"))
        return read_field(p, s, n);
    if (sl_text_is(tok, len, "METADATA")) {
        skip_metadata(p);
        return SL_OK;
    }
    *handled = 0;
    return SL_OK;
}

/* ---------------- POLYDATA ---------------- */

typedef struct poly {
    size_t point_count;
    float *points;              /* relative to centre */
    double centre[3];           /* bounds centre of the points, the dataset origin */
    cells lines;
    int have_lines;
    size_t cells_before_lines;  /* VERTICES precede LINES in cell numbering */
    size_t cells_total;
    size_t cell_data_n;         /* tuples in each cell_data array */
    attr_set point_data, cell_data;
} poly;

/* Reads POINTS in double and keeps them as float relative to their bounds
 * centre, so data far from the origin keeps float precision (sl_dataset.h). */
static sl_status read_points(vtk *p, vtype t, poly *g)
{
    size_t n = 3 * g->point_count;
    double *xyz = malloc((n ? n : 1) * sizeof *xyz);
    g->points = malloc((n ? n : 1) * sizeof(float));
    if (!xyz || !g->points) {
        free(xyz);
        return fail(p, SL_ERR_NOMEM, "POINTS: out of memory for %zu points", g->point_count);
    }
    sl_status st = read_values(p, t, n, DST_F64, xyz, "POINTS data");
    if (st != SL_OK) {
        free(xyz);
        return st;
    }
    for (int c = 0; c < 3; c++) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = (size_t)c; i < n; i += 3)
            if (isfinite(xyz[i])) {
                lo = xyz[i] < lo ? xyz[i] : lo;
                hi = xyz[i] > hi ? xyz[i] : hi;
            }
        g->centre[c] = lo <= hi ? 0.5 * (lo + hi) : 0.0;
        for (size_t i = (size_t)c; i < n; i += 3)
            g->points[i] = sl_load_narrow(xyz[i] - g->centre[c]);
    }
    free(xyz);
    return SL_OK;
}

static void poly_free(poly *g)
{
    free(g->points);
    free(g->lines.offsets);
    free(g->lines.indices);
    attr_set_free(&g->point_data);
    attr_set_free(&g->cell_data);
    memset(g, 0, sizeof *g);
}

static sl_status parse_polydata(vtk *p, poly *g)
{
    enum { NONE, POINT_DATA, CELL_DATA } block = NONE;
    size_t block_n = 0, verts = 0;
    const char *tok;
    size_t len;
    sl_status st;
    while (sl_text_token(&p->t, &tok, &len)) {
        if (block != NONE) {
            int handled = 0;
            attr_set *s = block == POINT_DATA ? &g->point_data : &g->cell_data;
            st = read_attribute(p, tok, len, block_n, s, block == POINT_DATA, &handled);
            if (st != SL_OK)
                return st;
            if (handled)
                continue;
        }
        if (sl_text_is(tok, len, "POINTS")) {
            vtype t;
            if (g->points)
                return fail(p, SL_ERR_FORMAT, "a second POINTS section");
            if ((st = read_count(p, "POINTS count", SL_MAX_VERTICES, &g->point_count)) != SL_OK ||
                (st = read_type(p, "POINTS type", &t)) != SL_OK)
                return st;
            end_line(p);
            if ((st = check_room(p, t, 3 * g->point_count, "POINTS data")) != SL_OK)
                return st;
            if ((st = read_points(p, t, g)) != SL_OK)
                return st;
        } else if (sl_text_is(tok, len, "LINES")) {
            if (!g->points)
                return fail(p, SL_ERR_FORMAT, "LINES before POINTS");
            if (g->have_lines)
                return fail(p, SL_ERR_FORMAT, "a second LINES section");
            size_t n;
            if ((st = read_cells(p, "LINES", g->point_count, &g->lines, &n)) != SL_OK)
                return st;
            g->have_lines = 1;
            g->cells_before_lines = verts;
            g->cells_total += n;
        } else if (sl_text_is(tok, len, "VERTICES") || sl_text_is(tok, len, "POLYGONS") ||
                   sl_text_is(tok, len, "TRIANGLE_STRIPS")) {
            char kw[20];
            token_name(tok, len, kw, sizeof kw);
            size_t n;
            if ((st = read_cells(p, kw, g->point_count, NULL, &n)) != SL_OK)
                return st;
            if (sl_text_is(tok, len, "VERTICES"))
                verts += n;
            g->cells_total += n;
        } else if (sl_text_is(tok, len, "POINT_DATA") || sl_text_is(tok, len, "CELL_DATA")) {
            int pd = sl_text_is(tok, len, "POINT_DATA");
            if ((st = read_count(p, pd ? "POINT_DATA count" : "CELL_DATA count", (unsigned long long)1 << 40,
                                 &block_n)) != SL_OK)
                return st;
            if (pd ? !g->points : !g->have_lines)
                return fail(p, SL_ERR_FORMAT, "%s before %s", pd ? "POINT_DATA" : "CELL_DATA", pd ? "POINTS" : "LINES");
            size_t want = pd ? g->point_count : g->cells_total;
            if (block_n != want)
                return fail(p, SL_ERR_FORMAT, "%s count %zu does not match the %zu %s", pd ? "POINT_DATA" : "CELL_DATA",
                            block_n, want, pd ? "POINTS" : "cells");
            block = pd ? POINT_DATA : CELL_DATA;
            if (!pd) {
                if (g->cell_data.count)
                    return fail(p, SL_ERR_FORMAT, "a second CELL_DATA section");
                g->cell_data_n = block_n;
            }
        } else if (sl_text_is(tok, len, "FIELD") || sl_text_is(tok, len, "METADATA")) {
            int handled;
            if ((st = read_attribute(p, tok, len, 0, NULL, 0, &handled)) != SL_OK)
                return st;
        } else {
            return fail(p, SL_ERR_FORMAT, "unexpected keyword \"%.*s\" in POLYDATA", TOK_SHOW(len), tok);
        }
    }
    if (!g->points)
        return fail(p, SL_ERR_FORMAT, "no POINTS section");
    if (!g->have_lines || g->lines.count == 0)
        return fail(p, SL_ERR_FORMAT, "no LINES cells (only POLYDATA lines are loaded)");
    return SL_OK;
}

static sl_status build_polydata(poly *g, sl_dataset *ds, sl_err *err)
{
    ds->origin = sl_v3(g->centre[0], g->centre[1], g->centre[2]);
    sl_status st = sl_lines_from_indexed(ds, g->points, g->point_count, g->lines.offsets, g->lines.count,
                                         g->lines.indices, err);
    if (st != SL_OK)
        return st;
    sl_lines *l = &ds->lines;
    for (int i = 0; i < g->point_data.count; i++)
        if ((st = sl_lines_gather_attribute(l, g->point_data.names[i], g->point_data.values[i],
                                            g->lines.indices, err)) != SL_OK)
            return st;
    if (g->point_data.normals) {
        l->normals = malloc((l->vertex_count ? 3 * l->vertex_count : 1) * sizeof(float));
        if (!l->normals)
            return sl_err_set(err, SL_ERR_NOMEM, "out of memory for normals");
        for (size_t v = 0; v < l->vertex_count; v++)
            memcpy(&l->normals[3 * v], &g->point_data.normals[3 * (size_t)g->lines.indices[v]], 3 * sizeof(float));
    }
    if (g->cells_before_lines + l->line_count > g->cell_data_n)
        return SL_OK; /* cell sections after CELL_DATA: the tuples cannot be matched to lines */
    for (int i = 0; i < g->cell_data.count; i++) {
        char name[SL_NAME_MAX];
        sl_lines_unique_name(l, 1, g->cell_data.names[i], "cell_scalar", name, sizeof name);
        float *dst = sl_lines_add_attribute(l, name, 1, err);
        if (!dst)
            return err ? err->status : SL_ERR_LIMIT;
        memcpy(dst, g->cell_data.values[i] + g->cells_before_lines, l->line_count * sizeof(float));
    }
    return SL_OK;
}

/* ---------------- STRUCTURED_POINTS ---------------- */

static sl_status parse_structured(vtk *p, sl_dataset *ds)
{
    int dims[3] = {0, 0, 0}, have_dims = 0, have_data = 0;
    double spacing[3] = {1, 1, 1}, origin[3] = {0, 0, 0};
    enum { NONE, POINT_DATA, CELL_DATA } block = NONE;
    size_t block_n = 0;
    const char *tok;
    size_t len;
    sl_status st;
    while (sl_text_token(&p->t, &tok, &len)) {
        if (block == POINT_DATA && !have_data &&
            (sl_text_is(tok, len, "SCALARS") || sl_text_is(tok, len, "VECTORS"))) {
            int vec = sl_text_is(tok, len, "VECTORS");
            const char *nt;
            size_t nlen;
            vtype t;
            size_t ncomp = 1;
            if ((st = need_inline(p, vec ? "VECTORS name" : "SCALARS name", &nt, &nlen)) != SL_OK ||
                (st = read_type(p, vec ? "VECTORS type" : "SCALARS type", &t)) != SL_OK)
                return st;
            if (!vec) {
                sl_text save = p->t;
                if (sl_text_token_inline(&p->t, &nt, &nlen)) {
                    p->t = save;
                    if ((st = read_count(p, "SCALARS components", 4, &ncomp)) != SL_OK)
                        return st;
                    if (ncomp != 1)
                        return fail(p, SL_ERR_UNSUPPORTED, "SCALARS with %zu components (a volume has 1; use VECTORS for 3)", ncomp);
                }
            }
            end_line(p);
            if (!vec && accept_word(p, "LOOKUP_TABLE")) {
                if ((st = need_inline(p, "LOOKUP_TABLE name", &nt, &nlen)) != SL_OK)
                    return st;
                end_line(p);
            }
            sl_voxel_type vt = SL_VOXEL_F32;
            dst_kind dk = DST_F32;
            if (!vec) {
                if (t == VT_U8) { vt = SL_VOXEL_U8; dk = DST_U8; }
                else if (t == VT_S8 || t == VT_S16) { vt = SL_VOXEL_S16; dk = DST_S16; }
                else if (t == VT_U16) { vt = SL_VOXEL_U16; dk = DST_U16; }
            }
            size_t comps = vec ? 3 : 1;
            if ((st = check_room(p, t, block_n * comps, vec ? "VECTORS data" : "SCALARS data")) != SL_OK)
                return st;
            ds->kind = vec ? SL_DATASET_VECTORS : SL_DATASET_VOLUME;
            if ((st = sl_volume_alloc(&ds->volume, dims, (int)comps, vt, p->err)) != SL_OK)
                return st;
            if ((st = read_values(p, t, block_n * comps, dk, ds->volume.data, vec ? "VECTORS data" : "SCALARS data")) != SL_OK)
                return st;
            have_data = 1;
            continue;
        }
        if (block != NONE) {
            int handled = 0;
            if ((st = read_attribute(p, tok, len, block_n, NULL, 0, &handled)) != SL_OK)
                return st;
            if (handled)
                continue;
        }
        if (sl_text_is(tok, len, "DIMENSIONS")) {
            for (int c = 0; c < 3; c++) {
                size_t d;
                if ((st = read_count(p, "DIMENSIONS", 1u << 30, &d)) != SL_OK)
                    return st;
                if (d == 0)
                    return fail(p, SL_ERR_FORMAT, "DIMENSIONS %d is 0", c);
                dims[c] = (int)d;
            }
            have_dims = 1;
        } else if (sl_text_is(tok, len, "SPACING") || sl_text_is(tok, len, "ASPECT_RATIO")) {
            if ((st = read_reals(p, "SPACING", spacing, 3)) != SL_OK)
                return st;
            for (int c = 0; c < 3; c++)
                if (!(spacing[c] > 0.0))
                    return fail(p, SL_ERR_FORMAT, "SPACING %d is %g, must be > 0", c, spacing[c]);
        } else if (sl_text_is(tok, len, "ORIGIN")) {
            if ((st = read_reals(p, "ORIGIN", origin, 3)) != SL_OK)
                return st;
        } else if (sl_text_is(tok, len, "POINT_DATA") || sl_text_is(tok, len, "CELL_DATA")) {
            int pd = sl_text_is(tok, len, "POINT_DATA");
            if (!have_dims)
                return fail(p, SL_ERR_FORMAT, "%s before DIMENSIONS", pd ? "POINT_DATA" : "CELL_DATA");
            if ((st = read_count(p, pd ? "POINT_DATA count" : "CELL_DATA count", (unsigned long long)1 << 40,
                                 &block_n)) != SL_OK)
                return st;
            size_t want = 1;
            for (int c = 0; c < 3; c++)
                want *= pd ? (size_t)dims[c] : (size_t)(dims[c] > 1 ? dims[c] - 1 : 1);
            if (block_n != want)
                return fail(p, SL_ERR_FORMAT, "%s count %zu does not match DIMENSIONS %dx%dx%d (%zu)",
                            pd ? "POINT_DATA" : "CELL_DATA", block_n, dims[0], dims[1], dims[2], want);
            block = pd ? POINT_DATA : CELL_DATA;
        } else if (sl_text_is(tok, len, "FIELD") || sl_text_is(tok, len, "METADATA")) {
            int handled;
            if ((st = read_attribute(p, tok, len, 0, NULL, 0, &handled)) != SL_OK)
                return st;
        } else {
            return fail(p, SL_ERR_FORMAT, "unexpected keyword \"%.*s\" in STRUCTURED_POINTS", TOK_SHOW(len), tok);
        }
    }
    if (!have_dims)
        return fail(p, SL_ERR_FORMAT, "no DIMENSIONS");
    if (!have_data)
        return fail(p, SL_ERR_FORMAT, "no POINT_DATA SCALARS or VECTORS array");
    for (int c = 0; c < 3; c++)
        ds->volume.spacing[c] = spacing[c];
    ds->origin = sl_v3(origin[0], origin[1], origin[2]);
    return sl_dataset_finish_volume(ds, p->err);
}

/* ---------------- entry ---------------- */

static sl_status parse_header(vtk *p, int *polydata)
{
    static const char magic[] = "# vtk DataFile Version";
    size_t n = sizeof magic - 1;
    if (p->t.size < n)
        return sl_err_set(p->err, SL_ERR_FORMAT, "%zu bytes is too short for the \"# vtk DataFile Version\" line", p->t.size);
    for (size_t i = 0; i < n; i++) {
        char a = (char)p->t.data[i], b = magic[i];
        if (a >= 'A' && a <= 'Z') a = (char)(a - 'A' + 'a');
        if (b >= 'A' && b <= 'Z') b = (char)(b - 'A' + 'a');
        if (a != b)
            return sl_err_set(p->err, SL_ERR_FORMAT, "first line is not \"# vtk DataFile Version x.x\"");
    }
    sl_text_skip_line(&p->t); /* version line */
    if (p->t.pos >= p->t.size)
        return fail(p, SL_ERR_FORMAT, "file ends before the title line");
    sl_text_skip_line(&p->t); /* title */
    const char *tok;
    size_t len;
    sl_status st = need_token(p, "ASCII or BINARY", &tok, &len);
    if (st != SL_OK)
        return st;
    if (sl_text_is(tok, len, "BINARY"))
        p->binary = 1;
    else if (!sl_text_is(tok, len, "ASCII"))
        return fail(p, SL_ERR_FORMAT, "third line is \"%.*s\", not ASCII or BINARY", TOK_SHOW(len), tok);
    if ((st = need_token(p, "DATASET", &tok, &len)) != SL_OK)
        return st;
    if (!sl_text_is(tok, len, "DATASET"))
        return fail(p, SL_ERR_FORMAT, "expected DATASET, found \"%.*s\"", TOK_SHOW(len), tok);
    if ((st = need_inline(p, "DATASET type", &tok, &len)) != SL_OK)
        return st;
    if (sl_text_is(tok, len, "POLYDATA"))
        *polydata = 1;
    else if (sl_text_is(tok, len, "STRUCTURED_POINTS"))
        *polydata = 0;
    else
        return fail(p, SL_ERR_UNSUPPORTED, "DATASET %.*s is not supported (POLYDATA or STRUCTURED_POINTS)", TOK_SHOW(len), tok);
    return SL_OK;
}

sl_status sl_load_vtk(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *who = sl_load_display_name(path);
    vtk p = {.err = err};
    sl_text_init(&p.t, data, size);
    int polydata = 0;
    char name[128];
    sl_load_base_name(path, "vtk", name, sizeof name);
    sl_dataset *ds = NULL;
    poly g;
    memset(&g, 0, sizeof g);
    sl_status st = parse_header(&p, &polydata);
    if (st != SL_OK)
        goto fail;
    ds = sl_dataset_create(polydata ? SL_DATASET_LINES : SL_DATASET_VOLUME, name);
    if (!ds) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for the dataset");
        goto fail;
    }
    if (polydata) {
        st = parse_polydata(&p, &g);
        if (st == SL_OK)
            st = build_polydata(&g, ds, err);
        if (st == SL_OK)
            st = sl_dataset_finish_lines(ds, err);
        poly_free(&g);
    } else {
        st = parse_structured(&p, ds);
    }
    if (st != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    poly_free(&g);
    sl_err_prefix(err, "%s (VTK)", who);
    sl_dataset_destroy(ds);
    return st;
}
