/* load_file.c — the loader table: picks a loader by file extension (sl_load.h).
 *
 * sl_load_file reads the file (read_file.c: gunzip included) and hands the
 * bytes to the loader of its extension. Parses no format itself. Any
 * thread; no GL; no global state.
 */
#include "load_common.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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
