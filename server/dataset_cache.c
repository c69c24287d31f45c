/* dataset_cache.c — loaded datasets shared by the sessions that draw them.
 *
 * Render thread only (it is the one that loads datasets), so no lock. Two
 * sessions on the same source (a file path or a generator call, after
 * resolution by the catalog) share one loaded copy: the second session's
 * first frame skips the load, and memory holds the data once. Each session's
 * pipeline and the cache are owners of the dataset (sl_dataset_retain); the
 * data is freed when the last of them lets go. The cache keeps at most
 * SL_DATASET_CACHE_SLOTS sources, least recently used out first; a dataset
 * evicted while a session still draws it lives on in that session. It holds
 * no GPU state: each pipeline prepares (uploads) its own copy, since prepared
 * state depends on the technique and its parameters. A cached file is used
 * only while the file on disk is the one loaded (same inode, size and
 * modification time), so a rewritten file is reloaded and a vanished one
 * fails to load as it would without the cache.
 */
#include "sl_server.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "data/sl_generate.h"
#include "data/sl_load.h"

/* What identifies the loaded version of a file; all zero when absent. */
static void file_stamp(const char *path, uint64_t stamp[4])
{
    struct stat st;
    memset(stamp, 0, 4 * sizeof stamp[0]);
    if (stat(path, &st) != 0)
        return;
    stamp[0] = (uint64_t)st.st_ino;
    stamp[1] = (uint64_t)st.st_size;
    stamp[2] = (uint64_t)st.st_mtim.tv_sec;
    stamp[3] = (uint64_t)st.st_mtim.tv_nsec;
}

static void drop(sl_dataset_cache *c, int i)
{
    sl_dataset_destroy(c->slot[i].dataset);
    c->slot[i].dataset = NULL;
    c->slot[i].source[0] = '\0';
}

void sl_dataset_cache_deinit(sl_dataset_cache *c)
{
    for (int i = 0; i < SL_DATASET_CACHE_SLOTS; i++)
        drop(c, i);
}

sl_status sl_dataset_cache_get(sl_dataset_cache *c, const char *source, int is_file, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    c->clock++;
    uint64_t stamp[4] = {0};
    if (is_file)
        file_stamp(source, stamp);
    for (int i = 0; i < SL_DATASET_CACHE_SLOTS; i++) {
        if (c->slot[i].dataset && strcmp(c->slot[i].source, source) == 0) {
            if (memcmp(c->slot[i].stamp, stamp, sizeof stamp) != 0) {
                drop(c, i); /* the file changed or vanished: load it again */
                break;
            }
            c->slot[i].used = c->clock;
            c->hits++;
            *out = sl_dataset_retain(c->slot[i].dataset);
            return SL_OK;
        }
    }
    sl_dataset *ds = NULL;
    sl_status rc = is_file ? sl_load_file(source, &ds, err) : sl_generate_json(source, &ds, err);
    if (rc != SL_OK)
        return rc;
    c->loads++;
    if (strlen(source) < sizeof c->slot[0].source) {
        int victim = 0;
        for (int i = 1; i < SL_DATASET_CACHE_SLOTS; i++)
            if (!c->slot[i].dataset || (c->slot[victim].dataset && c->slot[i].used < c->slot[victim].used))
                victim = i;
        drop(c, victim);
        c->slot[victim].dataset = sl_dataset_retain(ds);
        memcpy(c->slot[victim].stamp, stamp, sizeof stamp);
        c->slot[victim].used = c->clock;
        snprintf(c->slot[victim].source, sizeof c->slot[victim].source, "%s", source);
    } /* else: too long a key to keep; the session owns its copy alone */
    *out = ds;
    return SL_OK;
}
