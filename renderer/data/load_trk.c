/* load_trk.c — TrackVis .trk streamlines (versions 1 and 2) into a line set.
 *
 * Layout: a 1000-byte header (hdr_size 1000 at offset 996 gives the byte
 * order: read swapped, the file is big-endian), then per track an int32
 * point count m, m points of (x, y, z, n_scalars floats) and n_properties
 * floats. n_count 0 means "read tracks until the end of the file".
 * Coordinates are kept as stored: TrackVis "voxmm" space (millimetres from
 * the corner of voxel 0). vox_to_ras is NOT applied — it is often zero or
 * inconsistent in files in the wild, and a rigid frame change does not
 * affect rendering; the header's voxel size is checked but not applied.
 * Per-point scalars become per-vertex attributes, per-track properties
 * per-line attributes (names from scalar_name / property_name, else
 * "scalar<i>" / "property<i>"). Two passes: the first validates every record
 * against the bytes present and counts, the second fills exact-size arrays,
 * so a lying header cannot cause a large allocation. Any thread; no GL.
 */
#include "load_common.h"
#include "load_lines.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define TRK_HEADER 1000
#define TRK_NAMES 10
#define TRK_NAME_LEN 20

typedef struct trk_header {
    int big_endian;
    int version;
    int n_scalars;
    int n_properties;
    int32_t n_count;
    float voxel_size[3];
} trk_header;

static sl_status parse_header(const uint8_t *d, size_t size, trk_header *h, sl_err *err)
{
    if (size < TRK_HEADER)
        return sl_err_set(err, SL_ERR_FORMAT, "%zu bytes is shorter than the 1000-byte TrackVis header", size);
    if (memcmp(d, "TRACK", 5) != 0)
        return sl_err_set(err, SL_ERR_FORMAT, "id_string is not \"TRACK\"");
    uint32_t le = sl_rd_u32(d + 996, 0), be = sl_rd_u32(d + 996, 1);
    if (le == TRK_HEADER)
        h->big_endian = 0;
    else if (be == TRK_HEADER)
        h->big_endian = 1;
    else
        return sl_err_set(err, SL_ERR_FORMAT, "hdr_size is %u in either byte order, expected 1000", le);
    int bo = h->big_endian;
    h->version = sl_rd_s32(d + 992, bo);
    if (h->version != 1 && h->version != 2)
        return sl_err_set(err, SL_ERR_FORMAT, "version %d is not 1 or 2", h->version);
    h->n_scalars = sl_rd_s16(d + 36, bo);
    h->n_properties = sl_rd_s16(d + 238, bo);
    h->n_count = sl_rd_s32(d + 988, bo);
    if (h->n_scalars < 0 || h->n_scalars > SL_MAX_ATTRIBUTES)
        return sl_err_set(err, SL_ERR_LIMIT, "n_scalars %d is outside [0, %d]", h->n_scalars, SL_MAX_ATTRIBUTES);
    if (h->n_properties < 0 || h->n_properties > SL_MAX_ATTRIBUTES)
        return sl_err_set(err, SL_ERR_LIMIT, "n_properties %d is outside [0, %d]", h->n_properties, SL_MAX_ATTRIBUTES);
    if (h->n_count < 0)
        return sl_err_set(err, SL_ERR_FORMAT, "n_count %d is negative", h->n_count);
    if ((uint32_t)h->n_count > SL_MAX_LINES)
        return sl_err_set(err, SL_ERR_LIMIT, "n_count %d exceeds the limit of %u lines", h->n_count, SL_MAX_LINES);
    for (int c = 0; c < 3; c++) {
        h->voxel_size[c] = sl_rd_f32(d + 12 + 4 * c, bo);
        /* 0 is common in v1 files written without an image; only garbage is refused. */
        if (!isfinite(h->voxel_size[c]) || h->voxel_size[c] < 0.0f)
            return sl_err_set(err, SL_ERR_FORMAT, "voxel_size[%d] is %g", c, (double)h->voxel_size[c]);
    }
    return SL_OK;
}

/* Pass 1: walks the tracks, checking each record fits, and counts them. */
static sl_status count_tracks(const uint8_t *d, size_t size, const trk_header *h,
                              size_t *lines_out, size_t *vertices_out, sl_err *err)
{
    size_t pos = TRK_HEADER, lines = 0, vertices = 0;
    size_t point_bytes = 4u * (3u + (size_t)h->n_scalars);
    size_t prop_bytes = 4u * (size_t)h->n_properties;
    while (h->n_count ? lines < (size_t)h->n_count : pos < size) {
        if (size - pos < 4)
            return sl_err_set(err, SL_ERR_FORMAT, "track %zu: point count truncated at byte %zu (n_count %d)",
                              lines, pos, h->n_count);
        int32_t m = sl_rd_s32(d + pos, h->big_endian);
        pos += 4;
        if (m < 0)
            return sl_err_set(err, SL_ERR_FORMAT, "track %zu: point count %d is negative", lines, m);
        size_t left = size - pos;
        if ((size_t)m > left / point_bytes || left - (size_t)m * point_bytes < prop_bytes)
            return sl_err_set(err, SL_ERR_FORMAT,
                              "track %zu: %d points of %zu bytes (+%zu property bytes) exceed the %zu bytes left",
                              lines, m, point_bytes, prop_bytes, left);
        pos += (size_t)m * point_bytes + prop_bytes;
        vertices += (size_t)m;
        lines++;
        if (vertices > SL_MAX_VERTICES)
            return sl_err_set(err, SL_ERR_LIMIT, "more than %u vertices", SL_MAX_VERTICES);
        if (lines > SL_MAX_LINES)
            return sl_err_set(err, SL_ERR_LIMIT, "more than %u tracks", SL_MAX_LINES);
    }
    if (lines == 0)
        return sl_err_set(err, SL_ERR_FORMAT, "no tracks after the header");
    *lines_out = lines;
    *vertices_out = vertices;
    return SL_OK;
}

/* Entry i of a 10 x 20 name table as a printable name, or "" when empty or
 * garbage; *count gets the TrackVis 2 value count kept in byte 19 (1 when 0). */
static void table_entry(const uint8_t *table, int i, char *out, size_t cap, int *count)
{
    const uint8_t *s = table + TRK_NAME_LEN * i;
    size_t n = 0;
    while (n < TRK_NAME_LEN - 1 && s[n] >= 0x20 && s[n] < 0x7f)
        n++;
    if (n < TRK_NAME_LEN - 1 && s[n] != 0)
        n = 0; /* a name must end at a NUL (or the count byte), not mid-garbage */
    while (n > 0 && s[n - 1] == ' ')
        n--;
    if (n >= cap)
        n = cap - 1;
    memcpy(out, s, n);
    out[n] = '\0';
    *count = s[TRK_NAME_LEN - 1] > 1 ? s[TRK_NAME_LEN - 1] : 1;
}

/* Names of the `total` values per point (or per track) from a name table:
 * an entry with value count k > 1 names k consecutive values "name[0]"...
 * When the counts do not add up to total, entry i names value i. Empty or
 * missing names become "<fallback><i>". */
static void table_names(const uint8_t *table, int total, const char *fallback, char names[][SL_NAME_MAX])
{
    char entry[TRK_NAMES][TRK_NAME_LEN];
    int counts[TRK_NAMES], sum = 0, used = 0;
    for (int i = 0; i < TRK_NAMES; i++) {
        table_entry(table, i, entry[i], sizeof entry[i], &counts[i]);
        if (sum < total) {
            sum += counts[i];
            used = i + 1;
        }
    }
    int grouped = sum == total;
    for (int v = 0; v < total; v++)
        names[v][0] = '\0';
    if (grouped) {
        int v = 0;
        for (int i = 0; i < used; i++)
            for (int c = 0; c < counts[i]; c++, v++) {
                if (!entry[i][0])
                    continue;
                if (counts[i] > 1)
                    snprintf(names[v], SL_NAME_MAX, "%.19s[%u]", entry[i], (unsigned)(unsigned char)c);
                else
                    snprintf(names[v], SL_NAME_MAX, "%.19s", entry[i]);
            }
    } else {
        for (int v = 0; v < total && v < TRK_NAMES; v++)
            snprintf(names[v], SL_NAME_MAX, "%.19s", entry[v]);
    }
    for (int v = 0; v < total; v++)
        if (!names[v][0])
            snprintf(names[v], SL_NAME_MAX, "%s%d", fallback, v);
}

static sl_status fill(const uint8_t *d, const trk_header *h, sl_dataset *ds, sl_err *err)
{
    sl_lines *l = &ds->lines;
    float *scal[SL_MAX_ATTRIBUTES] = {0}, *prop[SL_MAX_ATTRIBUTES] = {0};
    char names[SL_MAX_ATTRIBUTES][SL_NAME_MAX];
    table_names(d + 38, h->n_scalars, "scalar", names);
    for (int i = 0; i < h->n_scalars; i++) {
        char name[SL_NAME_MAX];
        sl_lines_unique_name(l, 0, names[i], "scalar", name, sizeof name);
        if (!(scal[i] = sl_lines_add_attribute(l, name, 0, err)))
            return err ? err->status : SL_ERR_NOMEM;
    }
    table_names(d + 240, h->n_properties, "property", names);
    for (int i = 0; i < h->n_properties; i++) {
        char name[SL_NAME_MAX];
        sl_lines_unique_name(l, 1, names[i], "property", name, sizeof name);
        if (!(prop[i] = sl_lines_add_attribute(l, name, 1, err)))
            return err ? err->status : SL_ERR_NOMEM;
    }
    size_t pos = TRK_HEADER, v = 0;
    int bo = h->big_endian;
    for (size_t k = 0; k < l->line_count; k++) {
        size_t m = (size_t)sl_rd_s32(d + pos, bo); /* validated in pass 1 */
        pos += 4;
        l->line_offsets[k] = (uint32_t)v;
        for (size_t i = 0; i < m; i++, v++) {
            for (int c = 0; c < 3; c++) {
                float x = sl_rd_f32(d + pos, bo);
                pos += 4;
                if (!isfinite(x))
                    return sl_err_set(err, SL_ERR_FORMAT, "track %zu point %zu: coordinate %d is %g",
                                      k, i, c, (double)x);
                l->positions[3 * v + c] = x;
            }
            for (int s = 0; s < h->n_scalars; s++, pos += 4)
                scal[s][v] = sl_rd_f32(d + pos, bo);
        }
        for (int p = 0; p < h->n_properties; p++, pos += 4)
            prop[p][k] = sl_rd_f32(d + pos, bo);
    }
    l->line_offsets[l->line_count] = (uint32_t)v;
    return SL_OK;
}

sl_status sl_load_trk(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *who = sl_load_display_name(path);
    if (!data)
        size = 0;
    trk_header h = {0};
    size_t lines = 0, vertices = 0;
    sl_status st = parse_header(data, size, &h, err);
    if (st == SL_OK)
        st = count_tracks(data, size, &h, &lines, &vertices, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s (TrackVis)", who);
        return st;
    }
    char name[128];
    sl_load_base_name(path, "trk", name, sizeof name);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, name);
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for the dataset", who);
    st = sl_lines_alloc(&ds->lines, lines, vertices, 0, 0, err);
    if (st == SL_OK)
        st = fill(data, &h, ds, err);
    if (st == SL_OK)
        st = sl_dataset_finish_lines(ds, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s (TrackVis)", who);
        sl_dataset_destroy(ds);
        return st;
    }
    *out = ds;
    return SL_OK;
}
