/* load_file.c — the loader table: picks a loader by file extension (sl_load.h),
 * or for an unknown extension by the first bytes (the LR-spline header).
 *
 * sl_load_file reads the file (read_file.c: gunzip included) and hands the
 * bytes to the loader of its extension. Parses no format itself: a format
 * whose header states its size (NIfTI, NRRD) supplies a content-size
 * function, and the file is read and inflated only as far as that header
 * says, so a 1 MB gzip bomb behind a valid header costs the header's bytes.
 * Formats that state no size (the line formats, JSON) are read whole; when
 * gzipped they may inflate to at most max(64 MiB, 64 x the compressed
 * size) (line data compresses 2-5x; 64x is a bomb). Any thread; no GL; no
 * global state.
 */
#include "load_common.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"

/* A .json dataset is either explicit Hermite line data or a raw volume's sidecar. */
static sl_status load_json_dataset(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    cJSON *root = cJSON_ParseWithLength((const char *)data, size);
    int hermite = sl_hermite_json_detect(root);
    cJSON_Delete(root);
    return hermite ? sl_load_hermite_json(data, size, path, out, err) : sl_load_raw_json(data, size, path, out, err);
}

typedef uint64_t (*content_size_fn)(const uint8_t *head, size_t n, int complete);

typedef struct loader_entry {
    const char *ext;
    sl_loader_fn fn;
    content_size_fn content_size; /* NULL: the header states no size, read it all */
} loader_entry;

static const loader_entry loaders[] = {
    {".trk", sl_load_trk, NULL},
    {".tck", sl_load_tck, NULL},
    {".vtk", sl_load_vtk, NULL},
    {".obj", sl_load_obj, NULL},
    {".nrrd", sl_load_nrrd, sl_load_nrrd_content_size},
    {".nhdr", sl_load_nrrd, sl_load_nrrd_content_size},
    {".nii", sl_load_nifti, sl_load_nifti_content_size},
    {".json", load_json_dataset, NULL},
    {".lr", sl_load_lr, NULL},
};

/* Files of an unknown extension are recognised by their first bytes. */
#define SNIFF_BYTES 256u

/* Header bytes a content-size function may ask for before it must decide. */
#define PROBE_START 4096u
#define PROBE_MAX (16u * 1024u * 1024u)
/* Gzipped files whose header states no size: at most this many times their compressed size... */
#define GZ_RATIO_MAX 64u
/* ...or this much, whichever is larger. */
#define GZ_FLOOR_BYTES (64ull * 1024ull * 1024ull)

#define SL_SUPPORTED_EXTENSIONS ".trk .tck .vtk .obj .nrrd .nhdr .nii .nii.gz .json .lr (each may also be gzipped as NAME.EXT.gz; an LR-spline volume is also recognised by its header)"

/* Loader for the file name, ignoring case and one trailing ".gz"; NULL when unknown. */
static const loader_entry *loader_for(const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    char lower[256];
    size_t len = strlen(base);
    if (len >= sizeof lower)
        len = sizeof lower - 1;
    /* Keep the end of long names: the extension is what matters. */
    const char *tail = base + strlen(base) - len;
    for (size_t i = 0; i < len; i++)
        lower[i] = (char)tolower((unsigned char)tail[i]);
    lower[len] = '\0';
    if (len > 3 && strcmp(lower + len - 3, ".gz") == 0)
        lower[len -= 3] = '\0';
    for (size_t k = 0; k < sizeof loaders / sizeof loaders[0]; k++) {
        size_t el = strlen(loaders[k].ext);
        if (len > el && strcmp(lower + len - el, loaders[k].ext) == 0)
            return &loaders[k];
    }
    return NULL;
}

/* Reads the content `entry` will parse: as far as its header says, or all of
 * it within the limits in the file comment. */
static sl_status read_content(const char *path, const loader_entry *entry, uint8_t **data, size_t *size, sl_err *err)
{
    sl_load_stream *s = NULL;
    sl_status st = sl_load_stream_open(path, SL_STREAM_AUTO, &s, err);
    if (st != SL_OK)
        return st;
    const uint8_t *p;
    size_t n;
    uint64_t total = UINT64_MAX;
    if (entry->content_size) {
        for (size_t want = PROBE_START;; want *= 4) {
            st = sl_load_stream_fill(s, want, &p, &n, err);
            if (st != SL_OK)
                goto done;
            int complete = n < want || want >= PROBE_MAX;
            total = entry->content_size(p, n, complete);
            if (total != 0 || complete)
                break; /* 0 with complete: an empty file, nothing to read */
        }
    }
    uint64_t file_size = 0;
    int regular = sl_load_stream_regular(s, &file_size);
    int gz = sl_load_stream_gzipped(s);
    uint64_t limit = SL_MAX_FILE_BYTES;
    const char *why = "the general limit";
    if (total != UINT64_MAX) {
        if (total < limit) {
            limit = total;
            why = NULL; /* the header's size: the loader checks what it gets */
        }
    } else if (gz) {
        uint64_t by_ratio = regular && file_size < UINT64_MAX / GZ_RATIO_MAX ? file_size * GZ_RATIO_MAX : 0;
        uint64_t cap = by_ratio > GZ_FLOOR_BYTES ? by_ratio : GZ_FLOOR_BYTES;
        if (cap < limit) {
            limit = cap;
            why = "64 x the compressed size (at least 64 MiB) for a format whose header states no size";
        }
    }
    if (!gz && regular && why && file_size > limit) {
        st = sl_err_set(err, SL_ERR_LIMIT, "%s: file of %llu bytes exceeds %s of %llu bytes", path,
                        (unsigned long long)file_size, why, (unsigned long long)limit);
        goto done;
    }
    st = sl_load_stream_fill(s, why ? limit + 1 : limit, &p, &n, err);
    if (st != SL_OK)
        goto done;
    if (why && (uint64_t)n > limit) {
        st = sl_err_set(err, SL_ERR_LIMIT, "%s: %s exceeds %s of %llu bytes", path,
                        gz ? "inflated content" : "file", why, (unsigned long long)limit);
        goto done;
    }
    *data = sl_load_stream_take(s, size);
    if (!*data)
        st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", path);
    else if ((uint64_t)*size > limit)
        *size = (size_t)limit; /* the header probe read further than the header's size */
done:
    sl_load_stream_close(s);
    return st;
}

/* The loader whose header the file's first bytes (gunzipped) carry; NULL
 * when none does or the file cannot be read (the caller reports it). */
static const loader_entry *loader_by_content(const char *path)
{
    sl_load_stream *s = NULL;
    sl_err ignored = {0};
    if (sl_load_stream_open(path, SL_STREAM_AUTO, &s, &ignored) != SL_OK)
        return NULL;
    const uint8_t *p;
    size_t n;
    const loader_entry *found = NULL;
    if (sl_load_stream_fill(s, SNIFF_BYTES, &p, &n, &ignored) == SL_OK && sl_load_lr_detect(p, n))
        for (size_t k = 0; k < sizeof loaders / sizeof loaders[0]; k++)
            if (loaders[k].fn == sl_load_lr)
                found = &loaders[k];
    sl_load_stream_close(s);
    return found;
}

sl_status sl_load_file(const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    if (!path || !path[0])
        return sl_err_set(err, SL_ERR_INVALID, "sl_load_file: no path given");
    const loader_entry *entry = loader_for(path);
    if (!entry)
        entry = loader_by_content(path);
    if (!entry)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "%s: unknown file extension; supported: " SL_SUPPORTED_EXTENSIONS,
                          path);
    double t0 = sl_clock_ms();
    uint8_t *data = NULL;
    size_t size = 0;
    sl_status st = read_content(path, entry, &data, &size, err);
    if (st != SL_OK)
        return st;
    sl_dataset *ds = NULL;
    st = entry->fn(data, size, path, &ds, err);
    free(data);
    if (st != SL_OK) {
        sl_dataset_destroy(ds);
        return st;
    }
    sl_load_base_name(path, "dataset", ds->name, sizeof ds->name);
    ds->load_ms = sl_clock_ms() - t0;
    *out = ds;
    return SL_OK;
}
