/* load_lr.c — SINTEF LRsplines text volumes (.lr; .lr.gz arrives gunzipped)
 * into an SL_DATASET_LR dataset (model: lrspline/sl_lr.h).
 *
 * The layout is LR::LRSplineVolume::write's (VikingScientist/LRsplines:
 * LRSplineVolume.cpp, Basisfunction.cpp, MeshRectangle.cpp, Element.cpp;
 * summarised in proto/scene.md): "# LRSPLINE VOLUME", the line p1 p2 p3
 * Nbasis Nline Nel dim rat, then the records. Whitespace between tokens is
 * free (the reference reader's ws()); '#' lines are comments between
 * records; basis and element ids must be their position 0..N-1 (the
 * writer's numbering, which element lists index). Refused, by line number:
 * surfaces, rat = 1 and orders above 4 (SL_ERR_UNSUPPORTED), counts above
 * sl_lr.h's limits or beyond what the bytes can hold (before allocating),
 * fewer or more records than announced, a second patch, malformed records,
 * mesh rectangles that are not flat, are points, reach outside the domain
 * (the elements' union) or repeat a knot beyond the order. Mesh rectangles
 * flat in two directions (segments) are accepted and kept as read: the
 * reference library writes them (issue 31); they split nothing.
 * sl_lr_finish then checks coverage, partition of unity, gaps and overlaps.
 * Two passes (check and count, then fill exact arrays). Any thread; no GL.
 */
#include "load_common.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lrspline/sl_lr.h"

static const char axis_name[3] = {'u', 'v', 'w'};

typedef struct lr_cursor {
    const uint8_t *d;
    size_t n, pos, line; /* line: 1-based line of pos, for messages */
} lr_cursor;

static void skip_ws(lr_cursor *c)
{
    while (c->pos < c->n && isspace(c->d[c->pos])) {
        c->line += c->d[c->pos] == '\n';
        c->pos++;
    }
}

static int at_end(lr_cursor *c)
{
    skip_ws(c);
    return c->pos >= c->n;
}

/* Skips whitespace and '#' comment lines (allowed between records only). */
static void skip_comments(lr_cursor *c)
{
    while (!at_end(c) && c->d[c->pos] == '#')
        while (c->pos < c->n && c->d[c->pos] != '\n')
            c->pos++;
}

/* The next character for a message: printable, or its code. */
static const char *shown(lr_cursor *c, char *buf, size_t cap)
{
    if (c->pos >= c->n)
        snprintf(buf, cap, "the end of the file");
    else if (isprint(c->d[c->pos]))
        snprintf(buf, cap, "'%c'", c->d[c->pos]);
    else
        snprintf(buf, cap, "byte 0x%02x", c->d[c->pos]);
    return buf;
}

/* `what` names the record for messages ("basis function 3"). */
static sl_status expect(lr_cursor *c, char ch, const char *what, sl_err *err)
{
    if (at_end(c))
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: the file ends inside %s (truncated)", c->line, what);
    if (c->d[c->pos] != (uint8_t)ch) {
        char buf[32];
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: expected '%c', found %s", c->line, what, ch,
                          shown(c, buf, sizeof buf));
    }
    c->pos++;
    return SL_OK;
}

/* Copies the next run of characters from `set` into buf (NUL-terminated). */
static size_t take_run(lr_cursor *c, const char *set, char *buf, size_t cap)
{
    size_t len = 0;
    while (c->pos + len < c->n && c->d[c->pos + len] && strchr(set, c->d[c->pos + len]) && len + 1 < cap) {
        buf[len] = (char)c->d[c->pos + len];
        len++;
    }
    buf[len] = '\0';
    return len;
}

/* A finite decimal number (strtod syntax without inf/nan/hex). */
static sl_status number(lr_cursor *c, double *v, const char *what, const char *field, sl_err *err)
{
    if (at_end(c))
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: the file ends inside %s (truncated)", c->line, what);
    char buf[64];
    size_t len = take_run(c, "0123456789+-.eE", buf, sizeof buf);
    char *end = NULL;
    errno = 0;
    double x = len ? strtod(buf, &end) : 0.0;
    if (!len || (size_t)(end - buf) != len) {
        char b2[32];
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: %s is not a number (found %s)", c->line, what, field,
                          len ? buf : shown(c, b2, sizeof b2));
    }
    if (!isfinite(x))
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: %s %s is not a finite double", c->line, what, field,
                          buf);
    c->pos += len;
    *v = x;
    return SL_OK;
}

/* A decimal integer in [lo, hi]. */
static sl_status integer(lr_cursor *c, long long lo, long long hi, long long *v, const char *what,
                         const char *field, sl_err *err)
{
    if (at_end(c))
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: the file ends inside %s (truncated)", c->line, what);
    char buf[32];
    size_t len = take_run(c, "0123456789+-", buf, sizeof buf);
    char *end = NULL;
    errno = 0;
    long long x = len ? strtoll(buf, &end, 10) : 0;
    if (!len || (size_t)(end - buf) != len || errno == ERANGE) {
        char b2[32];
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: %s is not an integer (found %s)", c->line, what,
                          field, len ? buf : shown(c, b2, sizeof b2));
    }
    if (x < lo || x > hi)
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: %s %lld is outside %lld..%lld", c->line, what, field, x,
                          lo, hi);
    c->pos += len;
    *v = x;
    return SL_OK;
}

typedef struct lr_header {
    int order[3], dim;
    size_t basis, rects, elements;
} lr_header;

/* The domain box: the union of the element boxes, gathered by the first
 * pass so the second can check the mesh rectangles (read before the
 * elements) against it, with their line numbers. */
typedef struct lr_domain {
    double lo[3], hi[3];
    int known;
} lr_domain;

static int starts_with(lr_cursor *c, const char *s)
{
    size_t k = strlen(s);
    return c->n - c->pos >= k && memcmp(c->d + c->pos, s, k) == 0;
}

static sl_status read_header(lr_cursor *c, lr_header *h, sl_err *err)
{
    skip_ws(c);
    if (!starts_with(c, "# LRSPLINE")) {
        char buf[32];
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: not an LR-spline file: it must start with"
                          " \"# LRSPLINE VOLUME\" (found %s)", c->line, shown(c, buf, sizeof buf));
    }
    if (!starts_with(c, "# LRSPLINE VOLUME"))
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "line %zu: an LR-spline surface (\"# LRSPLINE\" without"
                          " VOLUME); only LR-spline volumes are supported", c->line);
    skip_comments(c);
    static const char *const names[8] = {"p1", "p2", "p3", "Nbasis", "Nline", "Nel", "dim", "rat"};
    long long v[8];
    for (int i = 0; i < 8; i++) {
        sl_status st = integer(c, 0, i >= 3 && i <= 5 ? (long long)1 << 40 : 1000, &v[i], "the header line",
                               names[i], err);
        if (st != SL_OK)
            return st;
    }
    for (int d = 0; d < 3; d++) {
        if (v[d] < 1)
            return sl_err_set(err, SL_ERR_FORMAT, "header: order p%d = %lld (orders are degree + 1 >= 1)", d + 1,
                              v[d]);
        if (v[d] > SL_LR_MAX_ORDER)
            return sl_err_set(err, SL_ERR_UNSUPPORTED, "header: order p%d = %lld is degree %lld; degrees up to %d"
                              " (order %d) are supported", d + 1, v[d], v[d] - 1, SL_LR_MAX_ORDER - 1,
                              SL_LR_MAX_ORDER);
        h->order[d] = (int)v[d];
    }
    if (v[7] == 1)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "header: rat = 1 (a rational LR-spline); only polynomial"
                          " ones (rat = 0) are supported");
    if (v[7] != 0)
        return sl_err_set(err, SL_ERR_FORMAT, "header: rat = %lld (must be 0 or 1)", v[7]);
    if (v[6] != 1 && v[6] != 3)
        return sl_err_set(err, v[6] < 1 ? SL_ERR_FORMAT : SL_ERR_UNSUPPORTED,
                          "header: dim = %lld; scalar (1) and vector (3) volumes are supported", v[6]);
    h->dim = (int)v[6];
    if (v[3] < 1 || v[5] < 1)
        return sl_err_set(err, SL_ERR_FORMAT, "header: %lld basis functions and %lld elements (each needs"
                          " at least 1)", v[3], v[5]);
    if (v[3] > SL_LR_MAX_BASIS)
        return sl_err_set(err, SL_ERR_LIMIT, "header: %lld basis functions exceed the limit of %u", v[3],
                          SL_LR_MAX_BASIS);
    if (v[4] > SL_LR_MAX_MESHRECTS)
        return sl_err_set(err, SL_ERR_LIMIT, "header: %lld mesh rectangles exceed the limit of %u", v[4],
                          SL_LR_MAX_MESHRECTS);
    if (v[5] > SL_LR_MAX_ELEMENTS)
        return sl_err_set(err, SL_ERR_LIMIT, "header: %lld elements exceed the limit of %u", v[5],
                          SL_LR_MAX_ELEMENTS);
    h->basis = (size_t)v[3];
    h->rects = (size_t)v[4];
    h->elements = (size_t)v[5];
    /* The fewest bytes each record can take (one-digit numbers, one space
     * where two numbers meet), so a lying count fails before allocating. */
    uint64_t per_basis = 15u + 2u * (uint64_t)(h->order[0] + h->order[1] + h->order[2]) + 2u * (uint64_t)h->dim;
    uint64_t need = per_basis * h->basis + 20u * (uint64_t)h->rects + 23u * (uint64_t)h->elements;
    if (need > c->n - c->pos)
        return sl_err_set(err, SL_ERR_FORMAT, "header: %zu basis functions, %zu mesh rectangles and %zu elements"
                          " need at least %llu bytes; the file has %zu more (truncated, or lying counts)",
                          h->basis, h->rects, h->elements, (unsigned long long)need, c->n - c->pos);
    return SL_OK;
}

/* The record that starts at the cursor, for a "found X where Y was
 * expected" message: 'b' basis function (id ':'), 'e' element (id '['),
 * 'r' mesh rectangle ('['), 0 anything else. Does not move the cursor. */
static char record_kind(const lr_cursor *c)
{
    size_t p = c->pos;
    if (p < c->n && c->d[p] == '[')
        return 'r';
    if (p >= c->n || !isdigit(c->d[p]))
        return 0;
    while (p < c->n && isdigit(c->d[p]))
        p++;
    while (p < c->n && isspace(c->d[p]))
        p++;
    return p < c->n && c->d[p] == ':' ? 'b' : p < c->n && c->d[p] == '[' ? 'e' : 0;
}

static const char *record_name(char k)
{
    return k == 'b' ? "a basis function" : k == 'r' ? "a mesh rectangle" : k == 'e' ? "an element" : "garbage";
}

/* At the start of record i of `count` of kind `want`: refuses the end of the
 * file and records of another kind as a count the file does not hold. */
static sl_status record_start(lr_cursor *c, char want, size_t i, size_t count, sl_err *err)
{
    skip_comments(c);
    const char *plural = want == 'b' ? "basis functions" : want == 'r' ? "mesh rectangles" : "elements";
    const char *one = want == 'b' ? "basis function" : want == 'r' ? "mesh rectangle" : "element";
    if (c->pos >= c->n)
        return sl_err_set(err, SL_ERR_FORMAT, "the file ends after %zu of the %zu %s the header announces"
                          " (truncated, or a lying count)", i, count, plural);
    char k = record_kind(c);
    if (k != want)
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s where %s %zu of %zu was expected (the header's"
                          " counts do not match the records)", c->line, record_name(k), one, i + 1, count);
    return SL_OK;
}

static sl_status read_basis(lr_cursor *c, const lr_header *h, size_t i, sl_lr_basis *out, sl_err *err)
{
    char what[64];
    snprintf(what, sizeof what, "basis function %zu", i);
    size_t line = c->line;
    long long id;
    sl_status st = integer(c, 0, (long long)h->basis, &id, what, "the id", err);
    if (st == SL_OK && (size_t)id != i)
        st = sl_err_set(err, SL_ERR_FORMAT, "line %zu: basis function %zu is numbered %lld (ids must count"
                        " 0, 1, 2, ... in file order)", line, i, id);
    if (st == SL_OK)
        st = expect(c, ':', what, err);
    sl_lr_basis b = {0};
    for (int d = 0; d < 3 && st == SL_OK; d++) {
        if (d > 0)
            st = expect(c, 'x', what, err);
        if (st == SL_OK)
            st = expect(c, '[', what, err);
        for (int k = 0; k <= h->order[d] && st == SL_OK; k++) {
            char field[32];
            snprintf(field, sizeof field, "%c knot %d", axis_name[d], k);
            st = number(c, &b.knots[d][k], what, field, err);
            if (st == SL_OK && k > 0 && b.knots[d][k] < b.knots[d][k - 1])
                st = sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: %c knots out of order (%.17g after %.17g)",
                                c->line, what, axis_name[d], b.knots[d][k], b.knots[d][k - 1]);
        }
        if (st == SL_OK)
            st = expect(c, ']', what, err);
        if (st == SL_OK && !(b.knots[d][h->order[d]] > b.knots[d][0]))
            st = sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: empty support in %c (all %d knots equal %.17g)",
                            c->line, what, axis_name[d], h->order[d] + 1, b.knots[d][0]);
    }
    for (int k = 0; k < h->dim && st == SL_OK; k++) {
        char field[32];
        snprintf(field, sizeof field, "coefficient %d", k);
        st = number(c, &b.coef[k], what, field, err);
    }
    if (st == SL_OK)
        st = expect(c, '(', what, err);
    if (st == SL_OK)
        st = number(c, &b.gamma, what, "the scaling weight", err);
    if (st == SL_OK && !(b.gamma > 0.0))
        st = sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: scaling weight %.17g is not positive", c->line, what,
                        b.gamma);
    if (st == SL_OK)
        st = expect(c, ')', what, err);
    if (st == SL_OK && out)
        *out = b;
    return st;
}

/* Mesh rectangle i. Flat in one direction, or in two: a segment, which the
 * reference library keeps from merging overlapping rectangles (it splits
 * nothing, so the spline does not depend on it; kept as read). The constant
 * direction whose order bounds the multiplicity is the reference reader's
 * (sl_lr_meshrect_const_dir). With `domain` known, the extent must lie in it. */
static sl_status read_rect(lr_cursor *c, const lr_header *h, const lr_domain *domain, size_t i,
                           sl_lr_meshrect *out, sl_err *err)
{
    char what[64];
    snprintf(what, sizeof what, "mesh rectangle %zu", i);
    size_t line = c->line;
    sl_lr_meshrect m = {0};
    sl_status st = SL_OK;
    for (int d = 0; d < 3 && st == SL_OK; d++) {
        char field[32];
        if (d > 0)
            st = expect(c, 'x', what, err);
        if (st == SL_OK)
            st = expect(c, '[', what, err);
        snprintf(field, sizeof field, "%c start", axis_name[d]);
        if (st == SL_OK)
            st = number(c, &m.lo[d], what, field, err);
        if (st == SL_OK)
            st = expect(c, ',', what, err);
        snprintf(field, sizeof field, "%c stop", axis_name[d]);
        if (st == SL_OK)
            st = number(c, &m.hi[d], what, field, err);
        if (st == SL_OK)
            st = expect(c, ']', what, err);
    }
    long long mult = 0;
    if (st == SL_OK)
        st = expect(c, '(', what, err);
    if (st == SL_OK)
        st = integer(c, 1, SL_LR_MAX_ORDER, &mult, what, "the multiplicity", err);
    if (st == SL_OK)
        st = expect(c, ')', what, err);
    if (st != SL_OK)
        return st;
    int flats = 0;
    for (int d = 0; d < 3; d++) {
        if (m.hi[d] < m.lo[d])
            return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: %c extent [%.17g, %.17g] is reversed", line, what,
                              axis_name[d], m.lo[d], m.hi[d]);
        if (domain && domain->known && (m.lo[d] < domain->lo[d] || m.hi[d] > domain->hi[d]))
            return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: %c extent [%.17g, %.17g] is outside the domain"
                              " [%.17g, %.17g] (the union of the elements)", line, what, axis_name[d], m.lo[d],
                              m.hi[d], domain->lo[d], domain->hi[d]);
        flats += m.hi[d] == m.lo[d];
    }
    if (flats == 0)
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s has 0 constant directions (a mesh rectangle is"
                          " constant in one, or in two for the segments the reference library keeps)", line,
                          what);
    if (flats == 3)
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s has 3 constant directions (a point, not a mesh"
                          " rectangle)", line, what);
    int flat = sl_lr_meshrect_const_dir(&m);
    /* A knot repeated more than `order` times leaves no basis function with support across it. */
    if (mult > h->order[flat])
        return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: multiplicity %lld exceeds the order %d in %c", line,
                          what, mult, h->order[flat], axis_name[flat]);
    m.multiplicity = (int)mult;
    if (out)
        *out = m;
    return SL_OK;
}

/* Element i; with `lr` set, fills it (ids at lr->element_basis + *offset,
 * `stamp` catching a basis id listed twice); always adds its id count; with
 * `domain` set, grows it by the element's box. */
static sl_status read_element(lr_cursor *c, const lr_header *h, size_t i, sl_lr_volume *lr, uint32_t *stamp,
                              size_t *offset, lr_domain *domain, sl_err *err)
{
    char what[64];
    snprintf(what, sizeof what, "element %zu", i);
    size_t line = c->line;
    long long id, nvar = 0;
    sl_status st = integer(c, 0, (long long)h->elements, &id, what, "the id", err);
    if (st == SL_OK && (size_t)id != i)
        st = sl_err_set(err, SL_ERR_FORMAT, "line %zu: element %zu is numbered %lld (ids must count 0, 1, 2, ..."
                        " in file order)", line, i, id);
    if (st == SL_OK)
        st = expect(c, '[', what, err);
    if (st == SL_OK)
        st = integer(c, 0, 1000, &nvar, what, "the parameter count", err);
    if (st == SL_OK && nvar != 3)
        st = sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s has %lld parameters; a volume's elements have 3",
                        c->line, what, nvar);
    if (st == SL_OK)
        st = expect(c, ']', what, err);
    if (st == SL_OK)
        st = expect(c, ':', what, err);
    double box[2][3];
    for (int s = 0; s < 2 && st == SL_OK; s++) {
        if (s == 1)
            st = expect(c, 'x', what, err);
        if (st == SL_OK)
            st = expect(c, '(', what, err);
        for (int d = 0; d < 3 && st == SL_OK; d++) {
            char field[32];
            snprintf(field, sizeof field, "%c %s", axis_name[d], s ? "max" : "min");
            if (d > 0)
                st = expect(c, ',', what, err);
            if (st == SL_OK)
                st = number(c, &box[s][d], what, field, err);
        }
        if (st == SL_OK)
            st = expect(c, ')', what, err);
    }
    for (int d = 0; d < 3 && st == SL_OK; d++)
        if (!(box[1][d] > box[0][d]))
            st = sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: empty box in %c (%.17g .. %.17g)", line, what,
                            axis_name[d], box[0][d], box[1][d]);
    if (st == SL_OK)
        st = expect(c, '{', what, err);
    size_t count = 0;
    while (st == SL_OK) {
        long long b;
        st = integer(c, 0, LLONG_MAX, &b, what, "a basis id", err);
        if (st != SL_OK)
            break;
        if ((unsigned long long)b >= h->basis)
            return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s: basis id %lld out of range (the file has %zu"
                              " basis functions)", c->line, what, b, h->basis);
        if (lr) {
            if (stamp[b] == (uint32_t)i + 1)
                return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s lists basis function %lld twice", c->line,
                                  what, b);
            stamp[b] = (uint32_t)i + 1;
            lr->element_basis[*offset + count] = (uint32_t)b;
        }
        count++;
        if (count > SL_LR_MAX_ELEMENT_BASIS)
            return sl_err_set(err, SL_ERR_LIMIT, "line %zu: %s lists more than %u basis functions", c->line, what,
                              SL_LR_MAX_ELEMENT_BASIS);
        if (at_end(c) || c->d[c->pos] != ',')
            break;
        c->pos++;
    }
    if (st == SL_OK)
        st = expect(c, '}', what, err);
    if (st != SL_OK)
        return st;
    if (domain) {
        for (int d = 0; d < 3; d++) {
            domain->lo[d] = domain->known ? fmin(domain->lo[d], box[0][d]) : box[0][d];
            domain->hi[d] = domain->known ? fmax(domain->hi[d], box[1][d]) : box[1][d];
        }
        domain->known = 1;
    }
    if (lr) {
        sl_lr_element *e = &lr->elements[i];
        for (int d = 0; d < 3; d++) {
            e->lo[d] = box[0][d];
            e->hi[d] = box[1][d];
        }
        e->basis_offset = (uint32_t)*offset;
        e->basis_count = (uint32_t)count;
    }
    *offset += count;
    return SL_OK;
}

/* One pass over the records after the header; with lr NULL it only checks,
 * counts the element basis entries into *element_basis and gathers the
 * domain; with lr set it fills lr and checks the mesh rectangles against the
 * domain the first pass gathered. */
static sl_status walk(lr_cursor *c, const lr_header *h, sl_lr_volume *lr, uint32_t *stamp,
                      size_t *element_basis, lr_domain *domain, sl_err *err)
{
    sl_status st = SL_OK;
    for (size_t i = 0; i < h->basis && st == SL_OK; i++) {
        st = record_start(c, 'b', i, h->basis, err);
        if (st == SL_OK)
            st = read_basis(c, h, i, lr ? &lr->basis[i] : NULL, err);
    }
    for (size_t i = 0; i < h->rects && st == SL_OK; i++) {
        st = record_start(c, 'r', i, h->rects, err);
        if (st == SL_OK)
            st = read_rect(c, h, lr ? domain : NULL, i, lr ? &lr->meshrects[i] : NULL, err);
    }
    size_t offset = 0;
    for (size_t i = 0; i < h->elements && st == SL_OK; i++) {
        st = record_start(c, 'e', i, h->elements, err);
        if (st == SL_OK)
            st = read_element(c, h, i, lr, stamp, &offset, lr ? NULL : domain, err);
        if (st == SL_OK && offset > SL_LR_MAX_ELEMENT_BASIS)
            st = sl_err_set(err, SL_ERR_LIMIT, "the elements list more than %u basis ids in all",
                            SL_LR_MAX_ELEMENT_BASIS);
    }
    if (st != SL_OK)
        return st;
    /* Nothing but comments may follow; a second patch is refused by name. */
    for (;;) {
        skip_ws(c);
        if (c->pos >= c->n)
            break;
        if (starts_with(c, "# LRSPLINE"))
            return sl_err_set(err, SL_ERR_UNSUPPORTED, "line %zu: a second LR-spline patch follows; files of"
                              " several patches are not supported", c->line);
        if (c->d[c->pos] != '#') {
            char k = record_kind(c);
            if (k)
                return sl_err_set(err, SL_ERR_FORMAT, "line %zu: %s after the %zu elements the header announces"
                                  " (the header's counts do not match the records)", c->line, record_name(k),
                                  h->elements);
            char buf[32];
            return sl_err_set(err, SL_ERR_FORMAT, "line %zu: unexpected %s after the last element", c->line,
                              shown(c, buf, sizeof buf));
        }
        while (c->pos < c->n && c->d[c->pos] != '\n')
            c->pos++;
    }
    *element_basis = offset;
    return SL_OK;
}

sl_status sl_load_lr(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *who = sl_load_display_name(path);
    if (!data)
        size = 0;
    lr_cursor c = {.d = data, .n = size, .line = 1};
    lr_header h = {0};
    lr_domain domain = {0};
    sl_dataset *ds = NULL;
    sl_lr_volume *lr = NULL;
    uint32_t *stamp = NULL;
    size_t element_basis = 0;
    sl_status st = read_header(&c, &h, err);
    lr_cursor body = c;
    if (st == SL_OK)
        st = walk(&c, &h, NULL, NULL, &element_basis, &domain, err);
    if (st != SL_OK)
        goto fail;
    lr = calloc(1, sizeof *lr);
    stamp = calloc(h.basis, sizeof *stamp);
    if (!lr || !stamp) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu basis functions", h.basis);
        goto fail;
    }
    st = sl_lr_alloc(lr, h.basis, h.rects, h.elements, element_basis, err);
    if (st != SL_OK)
        goto fail;
    for (int d = 0; d < 3; d++)
        lr->order[d] = h.order[d];
    lr->dim = h.dim;
    c = body;
    size_t again = 0;
    st = walk(&c, &h, lr, stamp, &again, &domain, err);
    if (st == SL_OK)
        st = sl_lr_finish(lr, err);
    if (st == SL_OK)
        st = sl_lr_index(lr, err);
    if (st != SL_OK)
        goto fail;
    free(stamp);
    stamp = NULL;
    char name[128];
    sl_load_base_name(path, "lr", name, sizeof name);
    ds = sl_dataset_create(SL_DATASET_LR, name);
    if (!ds) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for the dataset");
        goto fail;
    }
    ds->lr = lr;
    ds->origin = sl_v3(0.0, 0.0, 0.0);
    ds->bounds_min = sl_v3(lr->domain_lo[0], lr->domain_lo[1], lr->domain_lo[2]);
    ds->bounds_max = sl_v3(lr->domain_hi[0], lr->domain_hi[1], lr->domain_hi[2]);
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "%s (LR-spline)", who);
    sl_dataset_destroy(ds);
    if (lr)
        sl_lr_free(lr);
    free(lr);
    free(stamp);
    return st;
}

int sl_load_lr_detect(const uint8_t *data, size_t size)
{
    lr_cursor c = {.d = data, .n = data ? size : 0, .line = 1};
    skip_ws(&c);
    return starts_with(&c, "# LRSPLINE VOLUME");
}
