/* load_lines.c — text cursor, safe narrowing and indexed-polyline expansion
 * for the line-set loaders (see load_lines.h).
 *
 * Does not parse any format by itself. Any thread; no GL; no global state.
 * Invariant: every read is checked against the cursor's size; numbers are
 * copied into a bounded NUL-terminated buffer before strtod/strtoll sees them.
 */
#include "load_lines.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

float sl_load_narrow(double v)
{
    if (v > FLT_MAX)
        return INFINITY;
    if (v < -FLT_MAX)
        return -INFINITY;
    return (float)v; /* NaN stays NaN */
}

void sl_text_init(sl_text *t, const uint8_t *data, size_t size)
{
    t->data = data;
    t->size = data ? size : 0;
    t->pos = 0;
    t->line = 1;
}

static int is_space(uint8_t c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

static void read_token(sl_text *t, const char **tok, size_t *len)
{
    size_t start = t->pos;
    while (t->pos < t->size && !is_space(t->data[t->pos]))
        t->pos++;
    *tok = (const char *)t->data + start;
    *len = t->pos - start;
}

int sl_text_token(sl_text *t, const char **tok, size_t *len)
{
    while (t->pos < t->size && is_space(t->data[t->pos])) {
        if (t->data[t->pos] == '\n')
            t->line++;
        t->pos++;
    }
    if (t->pos >= t->size)
        return 0;
    read_token(t, tok, len);
    return 1;
}

int sl_text_token_inline(sl_text *t, const char **tok, size_t *len)
{
    while (t->pos < t->size && t->data[t->pos] != '\n' && is_space(t->data[t->pos]))
        t->pos++;
    if (t->pos >= t->size || t->data[t->pos] == '\n')
        return 0;
    read_token(t, tok, len);
    return 1;
}

void sl_text_skip_line(sl_text *t)
{
    while (t->pos < t->size && t->data[t->pos] != '\n')
        t->pos++;
    if (t->pos < t->size) {
        t->pos++;
        t->line++;
    }
}

int sl_text_is(const char *tok, size_t len, const char *word)
{
    size_t n = strlen(word);
    if (n != len)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char a = tok[i], b = word[i];
        if (a >= 'A' && a <= 'Z') a = (char)(a - 'A' + 'a');
        if (b >= 'A' && b <= 'Z') b = (char)(b - 'A' + 'a');
        if (a != b)
            return 0;
    }
    return 1;
}

/* Copies a token into buf (NUL-terminated); 0 when it does not fit or is empty. */
static int token_copy(const char *tok, size_t len, char *buf, size_t cap)
{
    if (len == 0 || len >= cap)
        return 0;
    memcpy(buf, tok, len);
    buf[len] = '\0';
    return 1;
}

int sl_text_double(const char *tok, size_t len, double *v)
{
    char buf[96];
    if (!token_copy(tok, len, buf, sizeof buf))
        return 0;
    char *end = NULL;
    errno = 0;
    double d = strtod(buf, &end);
    if (end != buf + len)
        return 0;
    /* ERANGE underflow gives a usable denormal/zero; overflow gives +-HUGE_VAL,
     * which the finite checks downstream reject with a clear message. */
    *v = d;
    return 1;
}

int sl_text_long(const char *tok, size_t len, long long lo, long long hi, long long *v)
{
    char buf[32];
    if (!token_copy(tok, len, buf, sizeof buf))
        return 0;
    char *end = NULL;
    errno = 0;
    long long x = strtoll(buf, &end, 10);
    if (end != buf + len || errno == ERANGE || x < lo || x > hi)
        return 0;
    *v = x;
    return 1;
}

sl_status sl_lines_from_indexed(sl_dataset *ds, const float *points, size_t point_count,
                                const uint64_t *cell_offsets, size_t cell_count,
                                const uint32_t *indices, sl_err *err)
{
    uint64_t n = cell_offsets[cell_count];
    if (n > SL_MAX_VERTICES)
        return sl_err_set(err, SL_ERR_LIMIT, "%llu line vertices exceed the limit of %u",
                          (unsigned long long)n, SL_MAX_VERTICES);
    sl_lines *l = &ds->lines;
    sl_status st = sl_lines_alloc(l, cell_count, (size_t)n, 0, 0, err);
    if (st != SL_OK)
        return st;
    for (size_t k = 0; k <= cell_count; k++)
        l->line_offsets[k] = (uint32_t)cell_offsets[k];
    for (size_t v = 0; v < (size_t)n; v++) {
        uint32_t i = indices[v];
        if (i >= point_count) /* callers check; keep the copy safe regardless */
            return sl_err_set(err, SL_ERR_FORMAT, "point index %u out of range (%zu points)", i, point_count);
        memcpy(&l->positions[3 * v], &points[3 * (size_t)i], 3 * sizeof(float));
    }
    return SL_OK;
}

sl_status sl_lines_gather_attribute(sl_lines *l, const char *name, const float *per_point,
                                    const uint32_t *indices, sl_err *err)
{
    char unique[SL_NAME_MAX];
    sl_lines_unique_name(l, 0, name, "scalar", unique, sizeof unique);
    float *dst = sl_lines_add_attribute(l, unique, 0, err);
    if (!dst)
        return err ? err->status : SL_ERR_LIMIT;
    for (size_t v = 0; v < l->vertex_count; v++)
        dst[v] = per_point[indices[v]];
    return SL_OK;
}

static int name_used(const sl_lines *l, int per_line, const char *name)
{
    int n = per_line ? l->line_attribute_count : l->attribute_count;
    const sl_attribute *set = per_line ? l->line_attributes : l->attributes;
    for (int i = 0; i < n; i++)
        if (strcmp(set[i].name, name) == 0)
            return 1;
    return 0;
}

void sl_lines_unique_name(const sl_lines *l, int per_line, const char *want, const char *fallback,
                          char *out, size_t cap)
{
    const char *base = want && want[0] ? want : fallback;
    snprintf(out, cap, "%s", base);
    for (int k = 2; name_used(l, per_line, out) && k < 1000; k++) {
        char suffix[16];
        int sn = snprintf(suffix, sizeof suffix, "_%d", k);
        size_t room = cap - 1 - (size_t)sn;
        snprintf(out, cap, "%.*s%s", (int)room, base, suffix);
    }
}
