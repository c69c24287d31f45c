/* dataset_cache.c — datasets by source: shared when loaded, loaded off the render thread.
 *
 * A source is a file path or a generator call (resolved by the catalog).
 * sl_dataset_cache_request never blocks on a load: it returns the cached
 * dataset, or a reference to the load of that source, which one of
 * SL_DATASET_LOADERS loader threads runs (file read / generation: CPU work
 * only; no GL). Two sessions asking for the same source share one loaded
 * copy, and also one load while it is in flight (same file identity). A
 * finished load enters the cache (the last SL_DATASET_CACHE_SLOTS sources,
 * least recently used out first) and calls desc.on_done on the loader
 * thread, without the cache's lock, so the render thread can be woken and
 * the load counted (also one that nobody waits for any more).
 * A failed load is not cached: the next request tries again. A cached file
 * is used only while the file on disk is the one loaded (same inode, size
 * and modification time), so a rewritten file is reloaded and a vanished one
 * fails as it would without the cache. A file registered with a checksum is
 * checked against it on the loader thread before it is parsed, and a cache
 * entry serves only requests for the checksum it was verified with (or
 * none). Each owner of a dataset (the cache,
 * a load's result, every pipeline) holds a reference (sl_dataset_retain).
 * Threads: any caller thread (the render thread) and the loaders; every
 * field below is guarded by `lock`. Lock order: a caller may hold its own
 * lock (sl_server.lock) when calling in; on_done is called with no lock.
 * Bounds: a load is queued only for a request, one per waiting session, so
 * the queue is bounded by --max-sessions; a queued load nobody waits for any
 * more is dropped.
 */
#include "sl_render.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "data/sl_generate.h"
#include "data/sl_dataset_open.h"
#include "data/sl_load.h"

enum load_state { LOAD_QUEUED, LOAD_RUNNING, LOAD_DONE };

struct sl_dataset_load {
    int refs;                    /* waiters, plus one while queued or running */
    enum load_state state;
    char source[SL_SOURCE_MAX];  /* immutable */
    int is_file;
    char checksum[SL_CATALOG_CHECKSUM_SIZE]; /* immutable; "" none */
    uint64_t stamp[4];           /* the file's identity when requested */
    sl_status status;            /* LOAD_DONE: the result */
    sl_err err;
    sl_dataset *dataset;         /* LOAD_DONE and SL_OK: one reference */
    double load_ms;              /* on the loader thread */
    sl_dataset_load *next;       /* in the cache's queue while not done */
};

struct sl_dataset_cache {
    pthread_mutex_t lock;
    pthread_cond_t work;          /* loaders wait for a queued load */
    pthread_t threads[SL_DATASET_LOADERS];
    int thread_count, stop;
    sl_dataset_cache_desc desc;
    struct {
        char source[SL_SOURCE_MAX];
        sl_dataset *dataset;  /* one reference, NULL when empty */
        uint64_t used;        /* clock of the last use */
        uint64_t stamp[4];    /* files: inode, size, mtime s/ns when loaded */
        char checksum[SL_CATALOG_CHECKSUM_SIZE]; /* what the file was checked against; "" none */
    } slot[SL_DATASET_CACHE_SLOTS];
    sl_dataset_load *queue;       /* queued and running loads, oldest first */
    uint64_t clock;
};

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

static void drop_slot(sl_dataset_cache *c, int i)
{
    sl_dataset_destroy(c->slot[i].dataset);
    c->slot[i].dataset = NULL;
    c->slot[i].source[0] = '\0';
}

static void unlink_load(sl_dataset_cache *c, sl_dataset_load *l)
{
    for (sl_dataset_load **pp = &c->queue; *pp; pp = &(*pp)->next)
        if (*pp == l) {
            *pp = l->next;
            break;
        }
    l->next = NULL;
}

static void free_load(sl_dataset_load *l)
{
    sl_dataset_destroy(l->dataset);
    free(l);
}

/* Keeps ds (a new reference) for source; lock held. */
static void insert_locked(sl_dataset_cache *c, const char *source, const uint64_t stamp[4], const char *checksum,
                          sl_dataset *ds)
{
    if (strlen(source) >= sizeof c->slot[0].source)
        return; /* too long a key to keep; its waiters own their copies alone */
    int victim = 0;
    for (int i = 0; i < SL_DATASET_CACHE_SLOTS; i++) {
        if (c->slot[i].dataset && strcmp(c->slot[i].source, source) == 0) {
            victim = i; /* a reload of a changed file replaces the old entry */
            break;
        }
        if (!c->slot[i].dataset || (c->slot[victim].dataset && c->slot[i].used < c->slot[victim].used))
            victim = i;
    }
    drop_slot(c, victim);
    c->slot[victim].dataset = sl_dataset_retain(ds);
    memcpy(c->slot[victim].stamp, stamp, sizeof c->slot[victim].stamp);
    snprintf(c->slot[victim].checksum, sizeof c->slot[victim].checksum, "%s", checksum);
    c->slot[victim].used = ++c->clock;
    snprintf(c->slot[victim].source, sizeof c->slot[victim].source, "%s", source);
}

/* SL_OK when the file's bytes have the checksum the catalog registered (or none is known). */
static sl_status check_file(const char *path, const char *want, sl_err *err)
{
    if (!want[0])
        return SL_OK;
    long long size = 0;
    char have[SL_CATALOG_CHECKSUM_SIZE];
    sl_status st = sl_catalog_file_checksum(path, &size, have, err);
    if (st == SL_OK && strcmp(have, want) != 0) {
        const char *base = strrchr(path, '/');
        st = sl_err_set(err, SL_ERR_INVALID,
                        "the file %s on this node is not the one the catalog registered (checksum %s, catalog %s): "
                        "every node must read the same data directory; after a deliberate change run "
                        "`sightline-server catalog refresh NAME`",
                        base ? base + 1 : path, have, want);
    }
    return st;
}

static void sleep_ms(double ms)
{
    struct timespec ts = {.tv_sec = (time_t)(ms / 1000.0), .tv_nsec = (long)(fmod(ms, 1000.0) * 1e6)};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

static void *loader_main(void *arg)
{
    sl_dataset_cache *c = arg;
    pthread_mutex_lock(&c->lock);
    while (!c->stop) {
        sl_dataset_load *l = c->queue;
        while (l && l->state != LOAD_QUEUED)
            l = l->next;
        if (!l) {
            pthread_cond_wait(&c->work, &c->lock);
            continue;
        }
        l->state = LOAD_RUNNING;
        pthread_mutex_unlock(&c->lock);
        /* source and is_file are immutable; nobody else touches the result fields until LOAD_DONE. */
        double t0 = sl_clock_ms();
        if (c->desc.test_delay_ms > 0)
            sleep_ms(c->desc.test_delay_ms);
        sl_dataset *ds = NULL;
        sl_err err = {0};
        /* Files confined to the data directories (the catalog resolved them there; a
         * file swapped for a symlink since is refused), generator JSON as it is. */
        sl_dataset_dirs dirs = {.dirs = c->desc.data_dirs, .count = c->desc.data_dir_count, .confine = 1};
        sl_status rc = l->is_file ? check_file(l->source, l->checksum, &err) : SL_OK;
        if (rc == SL_OK)
            rc = sl_dataset_open(l->source, l->is_file ? &dirs : NULL, &ds, &err);
        double ms = sl_clock_ms() - t0;
        pthread_mutex_lock(&c->lock);
        l->status = rc;
        l->err = err;
        l->dataset = ds;
        l->load_ms = ms;
        l->state = LOAD_DONE;
        unlink_load(c, l);
        if (rc == SL_OK)
            insert_locked(c, l->source, l->stamp, l->checksum, ds);
        if (--l->refs == 0)
            free_load(l);
        pthread_mutex_unlock(&c->lock);
        if (c->desc.on_done)
            c->desc.on_done(c->desc.arg, rc, ms);
        pthread_mutex_lock(&c->lock);
    }
    pthread_mutex_unlock(&c->lock);
    return NULL;
}

sl_status sl_dataset_cache_create(const sl_dataset_cache_desc *desc, sl_dataset_cache **out, sl_err *err)
{
    *out = NULL;
    sl_dataset_cache *c = calloc(1, sizeof *c);
    if (!c)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the dataset cache");
    c->desc = *desc;
    pthread_mutex_init(&c->lock, NULL);
    pthread_cond_init(&c->work, NULL);
    int n = desc->loaders > 0 && desc->loaders <= SL_DATASET_LOADERS ? desc->loaders : SL_DATASET_LOADERS;
    for (int i = 0; i < n; i++) {
        if (pthread_create(&c->threads[i], NULL, loader_main, c) != 0) {
            sl_err_set(err, SL_ERR_NOMEM, "cannot start dataset loader thread %d: %s", i, strerror(errno));
            sl_dataset_cache_destroy(c);
            return err->status;
        }
        c->thread_count++;
    }
    *out = c;
    return SL_OK;
}

void sl_dataset_cache_destroy(sl_dataset_cache *c)
{
    if (!c)
        return;
    pthread_mutex_lock(&c->lock);
    c->stop = 1;
    pthread_cond_broadcast(&c->work);
    pthread_mutex_unlock(&c->lock);
    for (int i = 0; i < c->thread_count; i++)
        pthread_join(c->threads[i], NULL); /* a running load finishes first */
    /* Every waiter has released its load (the caller's contract), so what is
     * left in the queue is held by the queue alone. */
    while (c->queue) {
        sl_dataset_load *l = c->queue;
        c->queue = l->next;
        free_load(l);
    }
    for (int i = 0; i < SL_DATASET_CACHE_SLOTS; i++)
        drop_slot(c, i);
    pthread_cond_destroy(&c->work);
    pthread_mutex_destroy(&c->lock);
    free(c);
}

sl_status sl_dataset_cache_request(sl_dataset_cache *c, const char *source, int is_file, const char *checksum,
                                   sl_dataset **out, sl_dataset_load **load, sl_dataset_origin *origin, sl_err *err)
{
    *out = NULL;
    *load = NULL;
    if (!is_file || !checksum)
        checksum = "";
    uint64_t stamp[4] = {0};
    if (is_file)
        file_stamp(source, stamp);
    pthread_mutex_lock(&c->lock);
    for (int i = 0; i < SL_DATASET_CACHE_SLOTS; i++) {
        if (!c->slot[i].dataset || strcmp(c->slot[i].source, source) != 0 ||
            (checksum[0] && strcmp(c->slot[i].checksum, checksum) != 0))
            continue;
        if (memcmp(c->slot[i].stamp, stamp, sizeof stamp) != 0) {
            drop_slot(c, i); /* the file changed or vanished: load it again */
            break;
        }
        c->slot[i].used = ++c->clock;
        *out = sl_dataset_retain(c->slot[i].dataset);
        *origin = SL_DATASET_CACHED;
        pthread_mutex_unlock(&c->lock);
        return SL_OK;
    }
    for (sl_dataset_load *l = c->queue; l; l = l->next)
        if (strcmp(l->source, source) == 0 && l->is_file == is_file && strcmp(l->checksum, checksum) == 0 &&
            memcmp(l->stamp, stamp, sizeof stamp) == 0) {
            l->refs++;
            *load = l;
            *origin = SL_DATASET_SHARED_LOAD;
            pthread_mutex_unlock(&c->lock);
            return SL_OK;
        }
    sl_dataset_load *l = calloc(1, sizeof *l);
    if (!l || strlen(source) >= sizeof l->source) {
        pthread_mutex_unlock(&c->lock);
        free(l);
        return l ? sl_err_set(err, SL_ERR_LIMIT, "dataset source longer than %d bytes", SL_SOURCE_MAX - 1)
                 : sl_err_set(err, SL_ERR_NOMEM, "out of memory queueing a dataset load");
    }
    snprintf(l->source, sizeof l->source, "%s", source);
    l->is_file = is_file;
    snprintf(l->checksum, sizeof l->checksum, "%s", checksum);
    memcpy(l->stamp, stamp, sizeof stamp);
    l->refs = 2; /* the caller, the queue */
    sl_dataset_load **tail = &c->queue;
    while (*tail)
        tail = &(*tail)->next;
    *tail = l;
    pthread_cond_signal(&c->work);
    pthread_mutex_unlock(&c->lock);
    *load = l;
    *origin = SL_DATASET_NEW_LOAD;
    return SL_OK;
}

int sl_dataset_load_poll(sl_dataset_cache *c, sl_dataset_load *l, sl_dataset **out, double *load_ms,
                         sl_status *status, sl_err *err)
{
    pthread_mutex_lock(&c->lock);
    int done = l->state == LOAD_DONE;
    if (done && out) {
        *out = l->status == SL_OK ? sl_dataset_retain(l->dataset) : NULL;
        *load_ms = l->load_ms;
        *status = l->status;
        if (l->status != SL_OK)
            *err = l->err;
    }
    pthread_mutex_unlock(&c->lock);
    return done;
}

const char *sl_dataset_load_source(const sl_dataset_load *l) { return l->source; }

void sl_dataset_load_release(sl_dataset_cache *c, sl_dataset_load *l)
{
    if (!l)
        return;
    pthread_mutex_lock(&c->lock);
    l->refs--;
    if (l->refs == 1 && l->state == LOAD_QUEUED) {
        unlink_load(c, l); /* nobody waits for it and no loader has started it */
        l->refs = 0;
    }
    if (l->refs == 0)
        free_load(l);
    pthread_mutex_unlock(&c->lock);
}
