/* load_file.c — whole-file reading, gunzip and the loader table (sl_load.h).
 *
 * sl_read_file reads a file into memory and, when it starts with the gzip
 * magic 1f 8b, inflates it; sl_load_file picks a loader by extension.
 * Does not parse any format itself and does not memory-map (every loader
 * sees one contiguous, owned buffer). Any thread; no GL; no global state.
 * Invariants: no buffer ever grows past limit + 1 bytes, so a gzip bomb or
 * a lying size costs at most the limit; output grows geometrically (x2), so
 * a small stream allocates little. A gzip file may hold several members
 * (concatenated gzip is legal); bytes after the last member that do not
 * start another member are ignored, as gzip(1) does.
 */
#include "load_common.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <zlib.h>

sl_status sl_load_read_raw(const char *path, uint64_t limit, uint8_t **data, size_t *size, sl_err *err)
{
    *data = NULL;
    *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) != 0) {
        int e = errno;
        fclose(f);
        return sl_err_set(err, SL_ERR_IO, "%s: cannot stat: %s", path, strerror(e));
    }
    if (S_ISDIR(st.st_mode)) {
        fclose(f);
        return sl_err_set(err, SL_ERR_IO, "%s: is a directory, not a file", path);
    }
    if (S_ISREG(st.st_mode) && (uint64_t)st.st_size > limit) {
        fclose(f);
        return sl_err_set(err, SL_ERR_LIMIT, "%s: file of %llu bytes exceeds the limit of %llu bytes", path,
                          (unsigned long long)st.st_size, (unsigned long long)limit);
    }
    size_t cap_max = limit < (uint64_t)SIZE_MAX ? (size_t)limit + 1 : SIZE_MAX;
    size_t cap = S_ISREG(st.st_mode) ? (size_t)st.st_size + 1 : 65536;
    if (cap > cap_max)
        cap = cap_max;
    uint8_t *buf = malloc(cap ? cap : 1);
    size_t n = 0;
    sl_status st_out = SL_OK;
    if (!buf) {
        st_out = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for %zu bytes", path, cap);
        goto fail;
    }
    for (;;) {
        if (n == cap) {
            if (cap >= cap_max)
                break;
            size_t grown_cap = cap > cap_max / 2 ? cap_max : cap * 2;
            uint8_t *grown = realloc(buf, grown_cap);
            if (!grown) {
                st_out = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for %zu bytes", path, grown_cap);
                goto fail;
            }
            buf = grown;
            cap = grown_cap;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) {
            if (ferror(f)) {
                st_out = sl_err_set(err, SL_ERR_IO, "%s: read error after %zu bytes: %s", path, n, strerror(errno));
                goto fail;
            }
            break;
        }
    }
    if ((uint64_t)n > limit) {
        st_out = sl_err_set(err, SL_ERR_LIMIT, "%s: file exceeds the limit of %llu bytes", path,
                            (unsigned long long)limit);
        goto fail;
    }
    fclose(f);
    *data = buf;
    *size = n;
    return SL_OK;
fail:
    free(buf);
    fclose(f);
    return st_out;
}

sl_status sl_gunzip(const uint8_t *data, size_t size, uint64_t limit, uint8_t **out, size_t *out_size, sl_err *err)
{
    *out = NULL;
    *out_size = 0;
    if (size < 18 || data[0] != 0x1f || data[1] != 0x8b)
        return sl_err_set(err, SL_ERR_FORMAT, "gzip stream of %zu bytes has no gzip header (1f 8b) or is too short",
                          size);
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK)
        return sl_err_set(err, SL_ERR_NOMEM, "gzip: cannot initialise zlib");
    size_t cap_max = limit < (uint64_t)SIZE_MAX ? (size_t)limit + 1 : SIZE_MAX;
    size_t cap = size < SIZE_MAX / 4 ? size * 4 : SIZE_MAX;
    if (cap < 4096)
        cap = 4096;
    if (cap > cap_max)
        cap = cap_max;
    uint8_t *buf = malloc(cap ? cap : 1);
    size_t n = 0, in_pos = 0;
    sl_status st = SL_OK;
    if (!buf) {
        st = sl_err_set(err, SL_ERR_NOMEM, "gzip: out of memory for %zu bytes", cap);
        goto done;
    }
    for (;;) {
        if (n == cap) {
            if (cap >= cap_max) {
                st = sl_err_set(err, SL_ERR_LIMIT, "gzip stream inflates past the limit of %llu bytes",
                                (unsigned long long)limit);
                goto done;
            }
            size_t grown_cap = cap > cap_max / 2 ? cap_max : cap * 2;
            uint8_t *grown = realloc(buf, grown_cap);
            if (!grown) {
                st = sl_err_set(err, SL_ERR_NOMEM, "gzip: out of memory for %zu bytes", grown_cap);
                goto done;
            }
            buf = grown;
            cap = grown_cap;
        }
        size_t in_chunk = size - in_pos < UINT_MAX ? size - in_pos : UINT_MAX;
        size_t out_chunk = cap - n < UINT_MAX ? cap - n : UINT_MAX;
        zs.next_in = (Bytef *)(uintptr_t)(data + in_pos);
        zs.avail_in = (uInt)in_chunk;
        zs.next_out = buf + n;
        zs.avail_out = (uInt)out_chunk;
        int ret = inflate(&zs, Z_NO_FLUSH);
        in_pos += in_chunk - zs.avail_in;
        n += out_chunk - zs.avail_out;
        if ((uint64_t)n > limit) {
            st = sl_err_set(err, SL_ERR_LIMIT, "gzip stream inflates past the limit of %llu bytes",
                            (unsigned long long)limit);
            goto done;
        }
        if (ret == Z_STREAM_END) {
            /* Another member follows only when its magic does. */
            if (size - in_pos >= 2 && data[in_pos] == 0x1f && data[in_pos + 1] == 0x8b) {
                if (inflateReset(&zs) != Z_OK) {
                    st = sl_err_set(err, SL_ERR_FORMAT, "gzip: cannot restart for the member at byte %zu", in_pos);
                    goto done;
                }
                continue;
            }
            break;
        }
        if (ret == Z_DATA_ERROR || ret == Z_NEED_DICT) {
            st = sl_err_set(err, SL_ERR_FORMAT, "gzip stream is corrupt near input byte %zu: %s", in_pos,
                            zs.msg ? zs.msg : "invalid data");
            goto done;
        }
        if (ret == Z_MEM_ERROR) {
            st = sl_err_set(err, SL_ERR_NOMEM, "gzip: zlib is out of memory");
            goto done;
        }
        if (ret != Z_OK && ret != Z_BUF_ERROR) {
            st = sl_err_set(err, SL_ERR_FORMAT, "gzip: zlib error %d near input byte %zu", ret, in_pos);
            goto done;
        }
        if (in_pos == size && zs.avail_out > 0) {
            st = sl_err_set(err, SL_ERR_FORMAT, "gzip stream is truncated: input ends after %zu bytes (%zu inflated)",
                            size, n);
            goto done;
        }
    }
    if (n + 1 < cap) {
        uint8_t *shrunk = realloc(buf, n ? n : 1);
        if (shrunk)
            buf = shrunk;
    }
    *out = buf;
    *out_size = n;
    buf = NULL;
done:
    inflateEnd(&zs);
    free(buf);
    return st;
}

sl_status sl_read_file(const char *path, uint64_t limit, uint8_t **data, size_t *size, sl_err *err)
{
    *data = NULL;
    *size = 0;
    if (!path)
        return sl_err_set(err, SL_ERR_INVALID, "sl_read_file: no path given");
    uint8_t *raw = NULL;
    size_t raw_size = 0;
    sl_status st = sl_load_read_raw(path, limit, &raw, &raw_size, err);
    if (st != SL_OK)
        return st;
    if (raw_size >= 2 && raw[0] == 0x1f && raw[1] == 0x8b) {
        st = sl_gunzip(raw, raw_size, limit, data, size, err);
        free(raw);
        if (st != SL_OK)
            sl_err_prefix(err, "%s", path);
        return st;
    }
    *data = raw;
    *size = raw_size;
    return SL_OK;
}

/* A .json dataset is either explicit Hermite line data or a raw volume's sidecar. */
static sl_status load_json_dataset(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    cJSON *root = cJSON_ParseWithLength((const char *)data, size);
    int hermite = sl_hermite_json_detect(root);
    cJSON_Delete(root);
    return hermite ? sl_load_hermite_json(data, size, path, out, err) : sl_load_raw_json(data, size, path, out, err);
}

typedef struct loader_entry {
    const char *ext;
    sl_loader_fn fn;
} loader_entry;

static const loader_entry loaders[] = {
    {".trk", sl_load_trk},   {".tck", sl_load_tck},   {".vtk", sl_load_vtk},
    {".obj", sl_load_obj},   {".nrrd", sl_load_nrrd}, {".nhdr", sl_load_nrrd},
    {".nii", sl_load_nifti}, {".json", load_json_dataset},
};

#define SL_SUPPORTED_EXTENSIONS ".trk .tck .vtk .obj .nrrd .nhdr .nii .nii.gz .json (each may also be gzipped as NAME.EXT.gz)"

/* Loader for the file name, ignoring case and one trailing ".gz"; NULL when unknown. */
static sl_loader_fn loader_for(const char *path)
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
            return loaders[k].fn;
    }
    return NULL;
}

sl_status sl_load_file(const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    if (!path || !path[0])
        return sl_err_set(err, SL_ERR_INVALID, "sl_load_file: no path given");
    sl_loader_fn fn = loader_for(path);
    if (!fn)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "%s: unknown file extension; supported: " SL_SUPPORTED_EXTENSIONS,
                          path);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    uint8_t *data = NULL;
    size_t size = 0;
    sl_status st = sl_read_file(path, SL_MAX_FILE_BYTES, &data, &size, err);
    if (st != SL_OK)
        return st;
    sl_dataset *ds = NULL;
    st = fn(data, size, path, &ds, err);
    free(data);
    if (st != SL_OK) {
        sl_dataset_destroy(ds);
        return st;
    }
    sl_load_base_name(path, "dataset", ds->name, sizeof ds->name);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    ds->load_ms = (double)(t1.tv_sec - t0.tv_sec) * 1e3 + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-6;
    *out = ds;
    return SL_OK;
}
