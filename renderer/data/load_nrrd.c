/* load_nrrd.c — NRRD volumes (.nrrd with attached data, .nhdr with a
 * detached "data file"), NRRD0001–0005 headers as written by Teem.
 *
 * Reads: type (8/16-bit ints kept, s8 -> s16, 32-bit ints and double -> f32),
 * dimension 3 (scalar) or 4 with a first axis of size 3 (vector field, f32),
 * sizes, spacings (absolute values), space directions, space origin, endian
 * (little when absent), encoding raw / gzip / ascii, data file, line skip,
 * byte skip (-1 only with raw; for a data file it means "the last bytes",
 * read by seeking, and line skip is then not checked).
 * Space directions along world axes in any order and sign (LPS data, axes
 * stored z-first) are honoured: the voxels are permuted / mirrored so every
 * world position is kept (sl_load_orient_volume). Oblique (rotated)
 * directions are not: their lengths become the spacing along the storage
 * axes and their rotation and sign are dropped. World coordinates are the
 * file's own space (LPS stays LPS; no conversion to RAS).
 * Does not read: bzip2 / hex encodings, multi-file "data file" forms (LIST,
 * patterns), block or 64-bit types, > 4 axes. Unknown fields and key:=value
 * pairs are ignored. Any thread; no GL.
 * Invariants: binary data must hold exactly the bytes sizes x type imply; no
 * voxel memory before that is known (gzip output is capped at the expected
 * size); ascii data needs >= 1 byte per value before allocation. A data
 * file is never read past what the header can use (data_region_bound), so
 * a link to /dev/zero or a huge file behind a tiny .nhdr fails at once.
 */
#include "load_common.h"

#include <ctype.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NRRD_MAX_AXES 16
#define NRRD_LINE_MAX 4096
/* Bytes a "line skip" may pass over in a data file whose size the header
 * does not fix, and bytes an ascii value may take (128 characters plus a
 * separator): the bounds on what is read for a detached data file. */
#define NRRD_LINE_SKIP_MAX_BYTES (1024u * 1024u)
#define NRRD_ASCII_MAX_BYTES_PER_VALUE 129u

enum { ENC_NONE, ENC_RAW, ENC_GZIP, ENC_ASCII };
enum { END_NONE, END_LITTLE, END_BIG };

/* Fields seen, to refuse duplicates. */
enum {
    F_TYPE = 1 << 0, F_DIMENSION = 1 << 1, F_SIZES = 1 << 2, F_SPACINGS = 1 << 3,
    F_DIRECTIONS = 1 << 4, F_ORIGIN = 1 << 5, F_ENDIAN = 1 << 6, F_ENCODING = 1 << 7,
    F_DATAFILE = 1 << 8, F_BYTESKIP = 1 << 9, F_LINESKIP = 1 << 10
};

typedef struct nrrd_header {
    unsigned seen;
    sl_src_type type;
    int dimension;
    long long sizes[NRRD_MAX_AXES];
    int n_sizes;
    double spacings[NRRD_MAX_AXES];
    int n_spacings;
    double dirs[NRRD_MAX_AXES][3];
    int dir_none[NRRD_MAX_AXES];
    int n_dirs;
    double origin[3];
    int endian;
    int encoding;
    char data_file[NRRD_LINE_MAX];
    long long byte_skip;
    long long line_skip;
    int blank_line;       /* the header ended with a blank line */
    size_t data_offset;   /* first byte after the blank line */
} nrrd_header;

static const char *skip_ws(const char *p)
{
    while (*p == ' ' || *p == '\t')
        p++;
    return p;
}

static void trim_right(char *s)
{
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r'))
        s[--n] = '\0';
}

static int parse_type(const char *v, sl_src_type *t)
{
    static const struct { const char *name; sl_src_type type; } names[] = {
        {"uchar", SL_SRC_U8}, {"unsigned char", SL_SRC_U8}, {"uint8", SL_SRC_U8}, {"uint8_t", SL_SRC_U8},
        {"signed char", SL_SRC_S8}, {"int8", SL_SRC_S8}, {"int8_t", SL_SRC_S8},
        {"short", SL_SRC_S16}, {"short int", SL_SRC_S16}, {"signed short", SL_SRC_S16},
        {"signed short int", SL_SRC_S16}, {"int16", SL_SRC_S16}, {"int16_t", SL_SRC_S16},
        {"ushort", SL_SRC_U16}, {"unsigned short", SL_SRC_U16}, {"unsigned short int", SL_SRC_U16},
        {"uint16", SL_SRC_U16}, {"uint16_t", SL_SRC_U16},
        {"int", SL_SRC_S32}, {"signed int", SL_SRC_S32}, {"int32", SL_SRC_S32}, {"int32_t", SL_SRC_S32},
        {"uint", SL_SRC_U32}, {"unsigned int", SL_SRC_U32}, {"uint32", SL_SRC_U32}, {"uint32_t", SL_SRC_U32},
        {"float", SL_SRC_F32}, {"double", SL_SRC_F64},
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(v, names[i].name) == 0) {
            *t = names[i].type;
            return 1;
        }
    return 0;
}

/* Parses whitespace-separated integers; 0 on a malformed token or too many. */
static int parse_ints(const char *v, long long *out, int max, int *count)
{
    int n = 0;
    const char *p = skip_ws(v);
    while (*p) {
        char *end;
        long long x = strtoll(p, &end, 10);
        if (end == p || (*end && *end != ' ' && *end != '\t') || n >= max)
            return 0;
        out[n++] = x;
        p = skip_ws(end);
    }
    *count = n;
    return 1;
}

static int parse_doubles(const char *v, double *out, int max, int *count)
{
    int n = 0;
    const char *p = skip_ws(v);
    while (*p) {
        char *end;
        double x = strtod(p, &end);
        if (end == p || (*end && *end != ' ' && *end != '\t') || n >= max)
            return 0;
        out[n++] = x;
        p = skip_ws(end);
    }
    *count = n;
    return 1;
}

/* "(a,b,c)" -> v (exactly 3 components); advances *pp. */
static int parse_vector3(const char **pp, double v[3])
{
    const char *p = skip_ws(*pp);
    if (*p != '(')
        return 0;
    p++;
    int n = 0;
    for (;;) {
        p = skip_ws(p);
        char *end;
        double x = strtod(p, &end);
        if (end == p || n >= 3)
            return 0;
        v[n++] = x;
        p = skip_ws(end);
        if (*p == ',') {
            p++;
            continue;
        }
        if (*p == ')') {
            p++;
            break;
        }
        return 0;
    }
    *pp = p;
    return n == 3;
}

static int parse_directions(const char *v, nrrd_header *h)
{
    const char *p = skip_ws(v);
    int n = 0;
    while (*p) {
        if (n >= NRRD_MAX_AXES)
            return 0;
        if (strncmp(p, "none", 4) == 0) {
            h->dir_none[n] = 1;
            p += 4;
        } else if (!parse_vector3(&p, h->dirs[n])) {
            return 0;
        }
        n++;
        if (*p && *p != ' ' && *p != '\t')
            return 0;
        p = skip_ws(p);
    }
    h->n_dirs = n;
    return 1;
}

/* Handles one "field: value" line. */
static sl_status parse_field(nrrd_header *h, const char *name, char *key, char *value, int line_no, sl_err *err)
{
    for (char *k = key; *k; k++)
        *k = (char)tolower((unsigned char)*k);
    unsigned bit = 0;
    const char *field = key;
    if (strcmp(key, "type") == 0) {
        bit = F_TYPE;
        if (strcmp(value, "block") == 0 || strcmp(value, "longlong") == 0 || strcmp(value, "int64") == 0 ||
            strcmp(value, "ulonglong") == 0 || strcmp(value, "uint64") == 0 || strstr(value, "long long") ||
            strcmp(value, "int64_t") == 0 || strcmp(value, "uint64_t") == 0)
            return sl_err_set(err, SL_ERR_UNSUPPORTED,
                              "%s: line %d: field 'type' is '%s', unsupported (8/16/32-bit integers, float, double)",
                              name, line_no, value);
        if (!parse_type(value, &h->type))
            return sl_err_set(err, SL_ERR_FORMAT, "%s: line %d: field 'type' has unknown value '%s'", name, line_no, value);
    } else if (strcmp(key, "dimension") == 0) {
        bit = F_DIMENSION;
        long long d;
        int n;
        if (!parse_ints(value, &d, 1, &n) || n != 1 || d < 1 || d > NRRD_MAX_AXES)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: line %d: field 'dimension' is '%s', must be 1..%d", name, line_no,
                              value, NRRD_MAX_AXES);
        h->dimension = (int)d;
    } else if (strcmp(key, "sizes") == 0) {
        bit = F_SIZES;
        if (!parse_ints(value, h->sizes, NRRD_MAX_AXES, &h->n_sizes))
            return sl_err_set(err, SL_ERR_FORMAT, "%s: line %d: field 'sizes' is malformed: '%s'", name, line_no, value);
    } else if (strcmp(key, "spacings") == 0) {
        bit = F_SPACINGS;
        if (!parse_doubles(value, h->spacings, NRRD_MAX_AXES, &h->n_spacings))
            return sl_err_set(err, SL_ERR_FORMAT, "%s: line %d: field 'spacings' is malformed: '%s'", name, line_no,
                              value);
    } else if (strcmp(key, "space directions") == 0) {
        bit = F_DIRECTIONS;
        if (!parse_directions(value, h))
            return sl_err_set(err, SL_ERR_FORMAT,
                              "%s: line %d: field 'space directions' is malformed (expect '(x,y,z)' or 'none' per axis, "
                              "3D spaces only): '%s'",
                              name, line_no, value);
    } else if (strcmp(key, "space origin") == 0) {
        bit = F_ORIGIN;
        const char *p = value;
        if (!parse_vector3(&p, h->origin) || *skip_ws(p))
            return sl_err_set(err, SL_ERR_FORMAT,
                              "%s: line %d: field 'space origin' is malformed (expect '(x,y,z)'): '%s'", name, line_no,
                              value);
    } else if (strcmp(key, "endian") == 0) {
        bit = F_ENDIAN;
        if (strcmp(value, "little") == 0)
            h->endian = END_LITTLE;
        else if (strcmp(value, "big") == 0)
            h->endian = END_BIG;
        else
            return sl_err_set(err, SL_ERR_FORMAT, "%s: line %d: field 'endian' is '%s', must be little or big", name,
                              line_no, value);
    } else if (strcmp(key, "encoding") == 0) {
        bit = F_ENCODING;
        if (strcmp(value, "raw") == 0)
            h->encoding = ENC_RAW;
        else if (strcmp(value, "gzip") == 0 || strcmp(value, "gz") == 0)
            h->encoding = ENC_GZIP;
        else if (strcmp(value, "ascii") == 0 || strcmp(value, "text") == 0 || strcmp(value, "txt") == 0)
            h->encoding = ENC_ASCII;
        else
            return sl_err_set(err, SL_ERR_UNSUPPORTED,
                              "%s: line %d: field 'encoding' is '%s', unsupported (raw, gzip, ascii)", name, line_no,
                              value);
    } else if (strcmp(key, "data file") == 0 || strcmp(key, "datafile") == 0) {
        bit = F_DATAFILE;
        field = "data file";
        if (strncmp(value, "LIST", 4) == 0 && (value[4] == '\0' || value[4] == ' '))
            return sl_err_set(err, SL_ERR_UNSUPPORTED,
                              "%s: line %d: field 'data file' is a LIST of files, unsupported (one file only)", name,
                              line_no);
        if (strchr(value, '%') && strchr(value, ' '))
            return sl_err_set(err, SL_ERR_UNSUPPORTED,
                              "%s: line %d: field 'data file' is a numbered file pattern '%s', unsupported (one file only)",
                              name, line_no, value);
        snprintf(h->data_file, sizeof h->data_file, "%s", value);
    } else if (strcmp(key, "byte skip") == 0 || strcmp(key, "byteskip") == 0) {
        bit = F_BYTESKIP;
        field = "byte skip";
        int n;
        if (!parse_ints(value, &h->byte_skip, 1, &n) || n != 1 || h->byte_skip < -1)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: line %d: field 'byte skip' is '%s', must be >= -1", name, line_no,
                              value);
    } else if (strcmp(key, "line skip") == 0 || strcmp(key, "lineskip") == 0) {
        bit = F_LINESKIP;
        field = "line skip";
        int n;
        if (!parse_ints(value, &h->line_skip, 1, &n) || n != 1 || h->line_skip < 0)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: line %d: field 'line skip' is '%s', must be >= 0", name, line_no,
                              value);
    } else {
        return SL_OK; /* a field Sightline does not need */
    }
    if (h->seen & bit)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: line %d: field '%s' appears twice", name, line_no, field);
    h->seen |= bit;
    return SL_OK;
}

static sl_status parse_header(const uint8_t *data, size_t size, const char *name, nrrd_header *h, sl_err *err)
{
    if (size < 8 || memcmp(data, "NRRD000", 7) != 0 || data[7] < '1' || data[7] > '9')
        return sl_err_set(err, SL_ERR_FORMAT, "%s: not a NRRD file (no 'NRRD000X' magic)", name);
    size_t pos = 0;
    int line_no = 0;
    char line[NRRD_LINE_MAX];
    while (pos < size) {
        const uint8_t *nl = memchr(data + pos, '\n', size - pos);
        size_t len = nl ? (size_t)(nl - (data + pos)) : size - pos;
        size_t next = nl ? pos + len + 1 : size;
        line_no++;
        if (line_no == 1) {
            pos = next;
            continue;
        }
        int comment = len > 0 && data[pos] == '#';
        if (comment) {
            pos = next;
            continue;
        }
        if (len >= sizeof line)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: header line %d is longer than %d bytes", name, line_no,
                              NRRD_LINE_MAX - 1);
        memcpy(line, data + pos, len);
        line[len] = '\0';
        if (memchr(line, '\0', len))
            return sl_err_set(err, SL_ERR_FORMAT, "%s: header line %d contains a NUL byte", name, line_no);
        trim_right(line);
        pos = next;
        if (line[0] == '\0') {
            h->blank_line = 1;
            h->data_offset = pos;
            return SL_OK;
        }
        char *colon = strchr(line, ':');
        if (!colon)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: header line %d is not 'field: value': '%.80s'", name, line_no,
                              line);
        if (colon[1] == '=')
            continue; /* key:=value pair */
        if (colon[1] != ' ')
            return sl_err_set(err, SL_ERR_FORMAT, "%s: header line %d is not 'field: value': '%.80s'", name, line_no,
                              line);
        *colon = '\0';
        char *value = (char *)skip_ws(colon + 2);
        sl_status st = parse_field(h, name, line, value, line_no, err);
        if (st != SL_OK)
            return st;
    }
    h->data_offset = size;
    return SL_OK;
}

/* Parses the ascii samples into vol (already allocated, n values). */
static sl_status decode_ascii(const uint8_t *p, size_t avail, sl_src_type type, sl_volume *vol, size_t n,
                              const char *name, sl_err *err)
{
    size_t pos = 0, count = 0;
    char tok[128];
    while (pos < avail) {
        while (pos < avail && (isspace(p[pos]) || p[pos] == ','))
            pos++;
        if (pos >= avail)
            break;
        size_t start = pos;
        while (pos < avail && !isspace(p[pos]) && p[pos] != ',')
            pos++;
        size_t len = pos - start;
        if (len >= sizeof tok)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: ascii data: value %zu is longer than %zu characters", name,
                              count, sizeof tok - 1);
        if (count >= n)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: ascii data has more than the %zu values in 'sizes'", name, n);
        memcpy(tok, p + start, len);
        tok[len] = '\0';
        char *end;
        double v = strtod(tok, &end);
        if (end == tok || *end)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: ascii data: value %zu '%s' is not a number", name, count, tok);
        double lo = 0, hi = 0;
        int integral = 1;
        switch (type) {
        case SL_SRC_U8: lo = 0; hi = 255; break;
        case SL_SRC_S8: lo = -128; hi = 127; break;
        case SL_SRC_U16: lo = 0; hi = 65535; break;
        case SL_SRC_S16: lo = -32768; hi = 32767; break;
        default: integral = 0; break;
        }
        if (integral && !(v >= lo && v <= hi && v == floor(v)))
            return sl_err_set(err, SL_ERR_FORMAT, "%s: ascii data: value %zu '%s' is not an integer in [%g, %g] of field 'type'",
                              name, count, tok, lo, hi);
        switch (vol->type) {
        case SL_VOXEL_U8: ((uint8_t *)vol->data)[count] = (uint8_t)v; break;
        case SL_VOXEL_U16: ((uint16_t *)vol->data)[count] = (uint16_t)v; break;
        case SL_VOXEL_S16: ((int16_t *)vol->data)[count] = (int16_t)v; break;
        case SL_VOXEL_F32:
            ((float *)vol->data)[count] = v > FLT_MAX ? INFINITY : v < -FLT_MAX ? -INFINITY : (float)v;
            break;
        }
        count++;
    }
    if (count != n)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: ascii data has %zu values, field 'sizes' needs %zu", name, count, n);
    return SL_OK;
}

/* Values the header's sizes describe (components included), or 0 when
 * they are missing or out of range (the loader will say why). */
static unsigned long long header_values(const nrrd_header *h)
{
    if (!(h->seen & F_SIZES) || !(h->seen & F_TYPE) || h->n_sizes < 1)
        return 0;
    unsigned long long values = 1;
    for (int a = 0; a < h->n_sizes; a++) {
        if (h->sizes[a] < 1 || h->sizes[a] > INT_MAX)
            return 0;
        values *= (unsigned long long)h->sizes[a];
        if (values > SL_MAX_VOXELS)
            return 0;
    }
    return values;
}

/* The most bytes the data region (after the header, or the data file) can
 * take for this header: exact for raw data at a known byte skip (the
 * region must be exactly that long), a bound for gzip (the compressed
 * stream of skip + needed bytes), ascii (129 bytes a value) and line skip
 * (1 MiB of skipped lines); UINT64_MAX when byte skip is -1 (the data is at
 * the end, so all of it is read). */
static uint64_t data_region_bound(const nrrd_header *h, unsigned long long values)
{
    uint64_t needed = (uint64_t)values * sl_src_type_size(h->type);
    uint64_t skip = h->byte_skip > 0 ? (uint64_t)h->byte_skip : 0;
    uint64_t lines = h->line_skip > 0 ? NRRD_LINE_SKIP_MAX_BYTES : 0;
    if (h->byte_skip < 0)
        return UINT64_MAX;
    if (skip > SL_MAX_FILE_BYTES)
        skip = SL_MAX_FILE_BYTES; /* the loader refuses it later */
    switch (h->encoding) {
    case ENC_GZIP: return lines + sl_load_gzip_input_bound(skip + needed);
    case ENC_ASCII: return lines + skip + (uint64_t)values * NRRD_ASCII_MAX_BYTES_PER_VALUE;
    default: return lines + skip + needed;
    }
}

uint64_t sl_load_nrrd_content_size(const uint8_t *head, size_t n, int complete)
{
    nrrd_header *h = calloc(1, sizeof *h);
    if (!h)
        return UINT64_MAX;
    sl_err err = {0};
    uint64_t total;
    if (parse_header(head, n, "(probe)", h, &err) != SL_OK)
        total = n; /* refused from the header alone */
    else if (!h->blank_line)
        total = complete ? n : 0; /* a detached header is all header; else read on */
    else if (h->seen & F_DATAFILE)
        total = h->data_offset; /* anything after the blank line is not read */
    else {
        unsigned long long values = header_values(h);
        uint64_t bound = values ? data_region_bound(h, values) : 0;
        if (!values)
            total = h->data_offset;
        else if (bound == UINT64_MAX || bound > UINT64_MAX - h->data_offset - 1)
            total = UINT64_MAX;
        else
            total = h->data_offset + bound + 1; /* + 1: the loader sees a file that is too long */
    }
    free(h);
    return total;
}

sl_status sl_load_nrrd(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *name = sl_load_display_name(path);
    nrrd_header *h = calloc(1, sizeof *h);
    sl_dataset *ds = NULL;
    uint8_t *file_bytes = NULL, *inflated = NULL;
    if (!h)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", name);
    sl_status st = parse_header(data, size, name, h, err);
    if (st != SL_OK)
        goto fail;

    static const struct { unsigned bit; const char *field; } required[] = {
        {F_TYPE, "type"}, {F_DIMENSION, "dimension"}, {F_SIZES, "sizes"}, {F_ENCODING, "encoding"}};
    for (size_t i = 0; i < sizeof required / sizeof required[0]; i++)
        if (!(h->seen & required[i].bit)) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: required field '%s' is missing", name, required[i].field);
            goto fail;
        }
    if (h->n_sizes != h->dimension) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'sizes' has %d values, field 'dimension' is %d", name,
                        h->n_sizes, h->dimension);
        goto fail;
    }
    int comps, first;
    if (h->dimension == 3) {
        comps = 1;
        first = 0;
    } else if (h->dimension == 4 && h->sizes[0] == 3) {
        comps = 3;
        first = 1;
    } else {
        st = sl_err_set(err, SL_ERR_UNSUPPORTED,
                        "%s: field 'dimension' is %d (sizes start %lld), unsupported: 3 for a scalar volume, "
                        "4 with a first axis of size 3 for a vector field",
                        name, h->dimension, h->sizes[0]);
        goto fail;
    }
    int dims[3];
    unsigned long long values = (unsigned long long)comps;
    for (int a = 0; a < h->dimension; a++) {
        if (h->sizes[a] < 1) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'sizes': axis %d is %lld, must be >= 1", name, a, h->sizes[a]);
            goto fail;
        }
        if (h->sizes[a] > INT_MAX) {
            st = sl_err_set(err, SL_ERR_LIMIT, "%s: field 'sizes': axis %d is %lld, above the limit of %d", name, a,
                            h->sizes[a], INT_MAX);
            goto fail;
        }
    }
    for (int c = 0; c < 3; c++) {
        dims[c] = (int)h->sizes[first + c];
        values *= (unsigned long long)dims[c];
        if (values > SL_MAX_VOXELS) {
            st = sl_err_set(err, SL_ERR_LIMIT, "%s: field 'sizes' describes more than the limit of %llu values", name,
                            SL_MAX_VOXELS);
            goto fail;
        }
    }
    double spacing[3] = {1.0, 1.0, 1.0};
    double axes[3][3];
    if (h->seen & F_DIRECTIONS) {
        if (h->n_dirs != h->dimension) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'space directions' has %d entries, field 'dimension' is %d",
                            name, h->n_dirs, h->dimension);
            goto fail;
        }
        for (int c = 0; c < 3; c++) {
            const double *d = h->dirs[first + c];
            double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (h->dir_none[first + c] || !(len > 0.0) || !isfinite(len)) {
                st = sl_err_set(err, SL_ERR_FORMAT,
                                "%s: field 'space directions': spatial axis %d is 'none', zero or not finite", name,
                                first + c);
                goto fail;
            }
            spacing[c] = len;
            memcpy(axes[c], d, sizeof axes[c]);
        }
    } else if (h->seen & F_SPACINGS) {
        if (h->n_spacings != h->dimension) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'spacings' has %d values, field 'dimension' is %d", name,
                            h->n_spacings, h->dimension);
            goto fail;
        }
        for (int c = 0; c < 3; c++) {
            double s = h->spacings[first + c];
            if (isnan(s))
                continue; /* NaN means "unknown" in NRRD: keep 1 */
            if (!isfinite(s) || s == 0.0) {
                st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'spacings': axis %d is %g, must be finite and non-zero",
                                name, first + c, s);
                goto fail;
            }
            spacing[c] = fabs(s);
        }
    }
    for (int c = 0; c < 3; c++)
        if (!isfinite(h->origin[c])) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'space origin' is not finite", name);
            goto fail;
        }

    /* The bytes holding the data: attached after the blank line, or the data file. */
    const uint8_t *p;
    size_t avail;
    size_t tsize = sl_src_type_size(h->type);
    size_t n = (size_t)values;
    size_t needed = n * tsize;
    if (h->byte_skip == -1 && h->encoding != ENC_RAW) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'byte skip' is -1, allowed only with encoding raw", name);
        goto fail;
    }
    int tail = 0; /* the data file's last `needed` bytes were read: no skipping */
    if (h->seen & F_DATAFILE) {
        char resolved[PATH_MAX];
        st = sl_load_resolve_sibling(path, h->data_file, "data file", resolved, sizeof resolved, err);
        if (st != SL_OK)
            goto fail;
        size_t file_size = needed;
        if (h->byte_skip == -1) {
            /* Data at the end: seek there (a regular file only), whatever comes before. */
            st = sl_load_read_tail(resolved, needed, &file_bytes, err);
            tail = 1;
        } else {
            /* Never read more than the header can use: a data file that is a
             * link to /dev/zero or a huge file costs the header's size. */
            uint64_t bound = data_region_bound(h, values);
            if (bound > SL_MAX_FILE_BYTES)
                bound = SL_MAX_FILE_BYTES;
            st = sl_load_read_raw(resolved, bound, &file_bytes, &file_size, err);
            if (st == SL_ERR_LIMIT)
                st = sl_err_set(err, SL_ERR_FORMAT,
                                "%s: field 'data file': %s holds more than the %llu bytes fields 'sizes', 'type', "
                                "'encoding', 'byte skip' and 'line skip' allow",
                                name, resolved, (unsigned long long)bound);
        }
        if (st != SL_OK) {
            if (st != SL_ERR_FORMAT || tail)
                sl_err_prefix(err, "%s: field 'data file'", name);
            goto fail;
        }
        p = file_bytes;
        avail = file_size;
    } else if (h->blank_line) {
        p = data + h->data_offset;
        avail = size - h->data_offset;
    } else {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: header has no blank line before the data and no field 'data file'",
                        name);
        goto fail;
    }
    for (long long k = 0; k < h->line_skip && !tail; k++) {
        const uint8_t *nl = avail ? memchr(p, '\n', avail) : NULL;
        if (!nl) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'line skip' is %lld, the data has only %lld lines", name,
                            h->line_skip, k);
            goto fail;
        }
        avail -= (size_t)(nl + 1 - p);
        p = nl + 1;
    }

    if (h->encoding == ENC_GZIP) {
        size_t inflated_size;
        uint64_t want = (uint64_t)needed + (uint64_t)h->byte_skip;
        if (want > SL_MAX_FILE_BYTES) {
            st = sl_err_set(err, SL_ERR_LIMIT, "%s: fields 'sizes' and 'byte skip' need %llu bytes, above the limit of %llu",
                            name, (unsigned long long)want, SL_MAX_FILE_BYTES);
            goto fail;
        }
        st = sl_gunzip(p, avail, want, &inflated, &inflated_size, err);
        if (st != SL_OK) {
            sl_err_prefix(err, "%s: gzip data (field 'sizes' needs %zu bytes)", name, needed);
            goto fail;
        }
        if (inflated_size != want) {
            st = sl_err_set(err, SL_ERR_FORMAT,
                            "%s: gzip data inflates to %zu bytes, fields 'sizes', 'type' and 'byte skip' need %llu",
                            name, inflated_size, (unsigned long long)want);
            goto fail;
        }
        p = inflated + h->byte_skip;
        avail = needed;
    } else {
        size_t skip = tail ? 0 : (size_t)h->byte_skip;
        if (h->byte_skip == -1 && !tail)
            skip = avail >= needed ? avail - needed : 0;
        if (h->byte_skip >= 0 && (unsigned long long)h->byte_skip > avail) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'byte skip' is %lld, the data has only %zu bytes", name,
                            h->byte_skip, avail);
            goto fail;
        }
        p += skip;
        avail -= skip;
    }
    if (h->encoding != ENC_ASCII && avail != needed) {
        st = sl_err_set(err, SL_ERR_FORMAT,
                        "%s: data has %zu bytes, fields 'sizes' and 'type' need exactly %zu (truncated or wrong header)",
                        name, avail, needed);
        goto fail;
    }
    if (h->encoding == ENC_ASCII && avail < n) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: ascii data has %zu bytes, too few for the %zu values in 'sizes'", name,
                        avail, n);
        goto fail;
    }

    char ds_name[SL_NAME_MAX];
    sl_load_base_name(path, "nrrd", ds_name, sizeof ds_name);
    ds = sl_dataset_create(comps == 3 ? SL_DATASET_VECTORS : SL_DATASET_VOLUME, ds_name);
    if (!ds) {
        st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", name);
        goto fail;
    }
    sl_voxel_type target = comps == 3 ? SL_VOXEL_F32 : sl_src_type_target(h->type);
    st = sl_volume_alloc(&ds->volume, dims, comps, target, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s", name);
        goto fail;
    }
    if (h->encoding == ENC_ASCII) {
        st = decode_ascii(p, avail, h->type, &ds->volume, n, name, err);
        if (st != SL_OK)
            goto fail;
    } else {
        int big = h->endian == END_BIG;
        sl_load_convert(ds->volume.data, target, p, h->type, tsize > 1 && big != sl_load_host_big_endian(), n, 0, 1.0,
                        0.0);
    }
    int oriented = 0;
    if (h->seen & F_DIRECTIONS) {
        st = sl_load_orient_volume(ds, (const double(*)[3])axes, h->origin, &oriented, err);
        if (st != SL_OK) {
            sl_err_prefix(err, "%s", name);
            goto fail;
        }
    }
    if (!oriented) {
        /* spacings, or oblique directions: vector lengths along the storage axes. */
        for (int c = 0; c < 3; c++)
            ds->volume.spacing[c] = spacing[c];
        ds->origin = sl_v3(h->origin[0], h->origin[1], h->origin[2]);
    }
    st = sl_dataset_finish_volume(ds, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s", name);
        goto fail;
    }
    free(h);
    free(file_bytes);
    free(inflated);
    *out = ds;
    return SL_OK;
fail:
    sl_dataset_destroy(ds);
    free(h);
    free(file_bytes);
    free(inflated);
    return st;
}
