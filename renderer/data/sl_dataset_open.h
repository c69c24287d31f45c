/* sl_dataset_open.h — the one way to open a dataset from a source string.
 *
 * A source is, tried in this order:
 *   1. a built-in name (sl_builtin_lookup: "tornado", "head", ...);
 *   2. JSON text (first non-blank character '{'): inline Hermite data
 *      ({"nodes":..,"segments":..}) or a generator call ({"generator":..});
 *   3. a file path, loaded by sl_load_file. A relative path is looked up in
 *      each of dirs->dirs in order (the first that holds it wins; with no
 *      dirs, relative to the working directory). With dirs->confine, the
 *      file's realpath must lie inside one of dirs->dirs (so "../" or a
 *      symlink cannot reach outside): what a server needs for paths that come
 *      from clients or a catalog.
 * A bare word that is neither a built-in nor a file is reported as a
 * probably mistyped name, listing the built-ins. proto/scene.c (CLI, tests)
 * and server/render/dataset_cache.c both open datasets only through here. Any thread.
 */
#ifndef SL_DATASET_OPEN_H
#define SL_DATASET_OPEN_H

#include "sl_dataset.h"

typedef struct sl_dataset_dirs {
    const char *const *dirs; /* may be NULL when count == 0 */
    int count;
    int confine;             /* 1: a file must resolve inside one of dirs */
} sl_dataset_dirs;

/* Opens source into *out (NULL on failure). dirs may be NULL (no dirs, no
 * confinement). Errors: SL_ERR_INVALID (unknown name, a path outside the
 * allowed directories, bad JSON), and whatever the generator or loader
 * reports (SL_ERR_IO, SL_ERR_PARSE, SL_ERR_LIMIT, ...). */
sl_status sl_dataset_open(const char *source, const sl_dataset_dirs *dirs, sl_dataset **out, sl_err *err);

#endif
