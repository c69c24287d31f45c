/* load_lines.h — private helpers shared by the line-set loaders (TrackVis,
 * MRtrix tck, legacy VTK, OBJ): unaligned endian-aware reads, a bounded text
 * cursor for the ASCII formats, and the expansion of indexed polylines
 * (shared points + index lists) into the per-line vertex copies sl_lines holds.
 *
 * Not part of the public contract (that is sl_load.h); renderer/data only.
 * Does not allocate from a header count: callers check counts against the
 * bytes present first. Any thread; no GL; no global state.
 * Invariant: the text cursor never reads at or past `size` — the input
 * buffer is not NUL-terminated.
 */
#ifndef SL_LOAD_LINES_H
#define SL_LOAD_LINES_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "sl_load.h"

/* ---- binary reads (no alignment needed) ---- */

static inline uint32_t sl_rd_u32(const uint8_t *p, int big_endian)
{
    return big_endian ? ((uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3])
                      : ((uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0]);
}

static inline uint64_t sl_rd_u64(const uint8_t *p, int big_endian)
{
    uint64_t a = sl_rd_u32(p, big_endian), b = sl_rd_u32(p + 4, big_endian);
    return big_endian ? (a << 32 | b) : (b << 32 | a);
}

static inline int16_t sl_rd_s16(const uint8_t *p, int big_endian)
{
    uint16_t v = big_endian ? (uint16_t)(p[0] << 8 | p[1]) : (uint16_t)(p[1] << 8 | p[0]);
    int16_t s;
    memcpy(&s, &v, 2);
    return s;
}

static inline int32_t sl_rd_s32(const uint8_t *p, int big_endian)
{
    uint32_t v = sl_rd_u32(p, big_endian);
    int32_t s;
    memcpy(&s, &v, 4);
    return s;
}

static inline float sl_rd_f32(const uint8_t *p, int big_endian)
{
    uint32_t v = sl_rd_u32(p, big_endian);
    float f;
    memcpy(&f, &v, 4);
    return f;
}

static inline double sl_rd_f64(const uint8_t *p, int big_endian)
{
    uint64_t v = sl_rd_u64(p, big_endian);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

/* A double narrowed to float without undefined behaviour: values beyond the
 * float range become +-inf (which sl_dataset_finish_lines then rejects). */
float sl_load_narrow(double v);

/* ---- text cursor ---- */

typedef struct sl_text {
    const uint8_t *data;
    size_t size;
    size_t pos;
    size_t line;   /* 1-based line of `pos`, for messages */
} sl_text;

void sl_text_init(sl_text *t, const uint8_t *data, size_t size);

/* Next whitespace-separated token, crossing newlines; 0 at end of input. */
int sl_text_token(sl_text *t, const char **tok, size_t *len);

/* Next token on the current line only; 0 at a newline (not consumed) or end. */
int sl_text_token_inline(sl_text *t, const char **tok, size_t *len);

/* Moves past the next '\n' (or to the end). */
void sl_text_skip_line(sl_text *t);

/* 1 when the token equals word, ignoring ASCII case. */
int sl_text_is(const char *tok, size_t len, const char *word);

/* Parses a whole token as a double (strtod syntax); 0 when it is not one. */
int sl_text_double(const char *tok, size_t len, double *v);

/* Parses a whole token as a decimal integer in [lo, hi]; 0 otherwise. */
int sl_text_long(const char *tok, size_t len, long long lo, long long hi, long long *v);

/* ---- indexed polylines ---- */

/* Fills ds->lines (which must be empty) from shared points and index lists:
 * cell k uses indices[cell_offsets[k] .. cell_offsets[k+1]), each < point_count
 * (checked by the caller). Every use of a point becomes its own vertex.
 * SL_ERR_LIMIT above SL_MAX_VERTICES / SL_MAX_LINES, SL_ERR_NOMEM. */
sl_status sl_lines_from_indexed(sl_dataset *ds, const float *points, size_t point_count,
                                const uint64_t *cell_offsets, size_t cell_count,
                                const uint32_t *indices, sl_err *err);

/* Adds a per-vertex attribute to a line set built by sl_lines_from_indexed,
 * gathering values[indices[v]] for every vertex v. */
sl_status sl_lines_gather_attribute(sl_lines *lines, const char *name, const float *per_point,
                                    const uint32_t *indices, sl_err *err);

/* Picks a name not yet used by the per-vertex (per_line 0) or per-line
 * attributes: `want`, else want_2, want_3, ...; `fallback` when want is empty. */
void sl_lines_unique_name(const sl_lines *lines, int per_line, const char *want, const char *fallback,
                          char *out, size_t cap);

#endif
