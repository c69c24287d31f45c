/* load_tck.c — MRtrix .tck streamlines into a line set.
 *
 * Layout: a text header starting "mrtrix tracks", lines "key: value", ended
 * by a line "END"; the keys used are "file: . OFFSET" (data in the same file
 * at byte OFFSET) and "datatype: Float32LE|Float32BE|Float64LE|Float64BE".
 * The data is a stream of (x, y, z) triplets: an all-NaN triplet ends a
 * streamline, an all-Inf triplet ends the data. A file whose data stops
 * without the Inf triplet is reported as truncated. Coordinates are scanner
 * millimetres and kept as they are. Streamlines with no points (two NaN
 * triplets in a row) are kept as empty lines so line indices match the file
 * (and any .tsf beside it). Does not read .tsf scalar files or detached
 * data ("file: other.dat"). Two passes (count, then fill exact arrays).
 * Any thread; no GL.
 */
#include "load_common.h"
#include "load_lines.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct tck_info {
    size_t offset;
    int f64;
    int big_endian;
} tck_info;

/* Copies the header line [start, end) into buf without trailing blanks. */
static void line_copy(const uint8_t *d, size_t start, size_t end, char *buf, size_t cap)
{
    while (end > start && (d[end - 1] == '\r' || d[end - 1] == ' ' || d[end - 1] == '\t'))
        end--;
    size_t n = end - start;
    if (n >= cap)
        n = cap - 1;
    memcpy(buf, d + start, n);
    buf[n] = '\0';
}

static sl_status parse_header(const uint8_t *d, size_t size, tck_info *info, sl_err *err)
{
    size_t pos = 0, lineno = 0;
    int have_file = 0, have_type = 0, ended = 0;
    while (pos < size && !ended) {
        size_t start = pos;
        while (pos < size && d[pos] != '\n')
            pos++;
        if (pos >= size)
            return sl_err_set(err, SL_ERR_FORMAT, "header line %zu has no end (no \"END\" line)", lineno + 1);
        char line[1024]; /* longer lines (command history) are cut; the keys read are short */
        line_copy(d, start, pos, line, sizeof line);
        pos++;
        lineno++;
        if (lineno == 1) {
            if (strcmp(line, "mrtrix tracks") != 0)
                return sl_err_set(err, SL_ERR_FORMAT, "first line is not \"mrtrix tracks\"");
            continue;
        }
        if (strcmp(line, "END") == 0) {
            ended = 1;
            break;
        }
        char *colon = strchr(line, ':');
        if (!colon)
            continue; /* MRtrix tolerates free lines; so do we */
        *colon = '\0';
        const char *value = colon + 1;
        while (*value == ' ' || *value == '\t')
            value++;
        if (strcmp(line, "file") == 0) {
            unsigned long long off = 0;
            char dot[4] = {0}, extra = 0;
            if (sscanf(value, "%3s %llu %c", dot, &off, &extra) != 2 || strcmp(dot, ".") != 0)
                return sl_err_set(err, SL_ERR_UNSUPPORTED, "field 'file' is \"%s\"; only \". OFFSET\" (data in this file) is supported", value);
            if (off > size)
                return sl_err_set(err, SL_ERR_FORMAT, "field 'file' offset %llu is past the end (%zu bytes)", off, size);
            info->offset = (size_t)off;
            have_file = 1;
        } else if (strcmp(line, "datatype") == 0) {
            if (strcmp(value, "Float32LE") == 0) { info->f64 = 0; info->big_endian = 0; }
            else if (strcmp(value, "Float32BE") == 0) { info->f64 = 0; info->big_endian = 1; }
            else if (strcmp(value, "Float64LE") == 0) { info->f64 = 1; info->big_endian = 0; }
            else if (strcmp(value, "Float64BE") == 0) { info->f64 = 1; info->big_endian = 1; }
            else
                return sl_err_set(err, SL_ERR_FORMAT, "field 'datatype' is \"%s\", not Float32LE/BE or Float64LE/BE", value);
            have_type = 1;
        }
    }
    if (!ended)
        return sl_err_set(err, SL_ERR_FORMAT, "header has no \"END\" line");
    if (!have_file)
        return sl_err_set(err, SL_ERR_FORMAT, "header has no 'file' field");
    if (!have_type)
        return sl_err_set(err, SL_ERR_FORMAT, "header has no 'datatype' field");
    if (info->offset < pos)
        return sl_err_set(err, SL_ERR_FORMAT, "field 'file' offset %zu lies inside the header (which ends at byte %zu)",
                          info->offset, pos);
    return SL_OK;
}

enum { TRIPLET_POINT, TRIPLET_BREAK, TRIPLET_END, TRIPLET_BAD };

static int read_triplet(const uint8_t *p, const tck_info *info, double xyz[3])
{
    int nan = 0, inf = 0;
    for (int c = 0; c < 3; c++) {
        xyz[c] = info->f64 ? sl_rd_f64(p + 8 * c, info->big_endian) : (double)sl_rd_f32(p + 4 * c, info->big_endian);
        nan += isnan(xyz[c]) != 0;
        inf += isinf(xyz[c]) != 0;
    }
    if (nan == 3) return TRIPLET_BREAK;
    if (inf == 3) return TRIPLET_END;
    if (nan || inf) return TRIPLET_BAD;
    return TRIPLET_POINT;
}

/* Pass 1 (positions NULL) counts; pass 2 fills positions and offsets. */
static sl_status walk(const uint8_t *d, size_t size, const tck_info *info, sl_lines *l,
                      size_t *lines_out, size_t *vertices_out, sl_err *err)
{
    size_t w = info->f64 ? 24 : 12;
    size_t pos = info->offset, lines = 0, vertices = 0, in_line = 0;
    for (;;) {
        if (size - pos < w)
            return sl_err_set(err, SL_ERR_FORMAT, "data ends at byte %zu without the Inf end triplet (truncated?)", size);
        double xyz[3];
        int kind = read_triplet(d + pos, info, xyz);
        size_t triplet = (pos - info->offset) / w;
        pos += w;
        if (kind == TRIPLET_BAD)
            return sl_err_set(err, SL_ERR_FORMAT, "triplet %zu (%g, %g, %g) mixes non-finite and finite values",
                              triplet, xyz[0], xyz[1], xyz[2]);
        if (kind == TRIPLET_POINT) {
            if (vertices >= SL_MAX_VERTICES)
                return sl_err_set(err, SL_ERR_LIMIT, "more than %u vertices", SL_MAX_VERTICES);
            if (l) {
                for (int c = 0; c < 3; c++) {
                    float f = sl_load_narrow(xyz[c]);
                    if (!isfinite(f))
                        return sl_err_set(err, SL_ERR_FORMAT, "triplet %zu coordinate %d (%g) is beyond the float range",
                                          triplet, c, xyz[c]);
                    l->positions[3 * vertices + c] = f;
                }
            }
            vertices++;
            in_line = 1;
            continue;
        }
        /* A break closes the current streamline (possibly empty); the end
         * marker closes a final streamline that was not followed by a break. */
        if (kind == TRIPLET_BREAK || in_line) {
            if (lines >= SL_MAX_LINES)
                return sl_err_set(err, SL_ERR_LIMIT, "more than %u streamlines", SL_MAX_LINES);
            lines++;
            if (l)
                l->line_offsets[lines] = (uint32_t)vertices;
        }
        in_line = 0;
        if (kind == TRIPLET_END)
            break;
    }
    if (lines == 0)
        return sl_err_set(err, SL_ERR_FORMAT, "no streamlines before the end triplet");
    *lines_out = lines;
    *vertices_out = vertices;
    return SL_OK;
}

sl_status sl_load_tck(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *who = sl_load_display_name(path);
    if (!data)
        size = 0;
    tck_info info = {0};
    size_t lines = 0, vertices = 0;
    sl_status st = parse_header(data, size, &info, err);
    if (st == SL_OK)
        st = walk(data, size, &info, NULL, &lines, &vertices, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s (tck)", who);
        return st;
    }
    char name[128];
    sl_load_base_name(path, "tck", name, sizeof name);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, name);
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for the dataset", who);
    st = sl_lines_alloc(&ds->lines, lines, vertices, 0, 0, err);
    if (st == SL_OK)
        st = walk(data, size, &info, &ds->lines, &lines, &vertices, err);
    if (st == SL_OK)
        st = sl_dataset_finish_lines(ds, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s (tck)", who);
        sl_dataset_destroy(ds);
        return st;
    }
    *out = ds;
    return SL_OK;
}
