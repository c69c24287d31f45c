/* catalog.c — the SQLite catalog: datasets, saved views, named camera paths, sessions.
 *
 * One database file in WAL mode (readers never block the writer). Every
 * statement is prepared with bound parameters; no SQL is ever built from
 * input text. File datasets must lie inside one of the allowed data
 * directories after realpath(), so "../" or a symlink cannot reach outside.
 * A dataset row records what the catalog needs to list it without loading
 * it: kind, source (generator JSON or absolute path), file size and an
 * FNV-1a 64 checksum, bounds, counts and attribute names. Does not render.
 * Removal sticks: `remove` leaves a row in `removed`, and the automatic
 * registration at start (built-ins, <data-dir>/samples) skips those names;
 * only an explicit add, add-generator, scan or add-builtins brings one back.
 * Saved views are capped at SL_CATALOG_MAX_VIEWS rows, named paths (scene.md
 * "Paths", stored as the JSON text the server checked) at
 * SL_CATALOG_MAX_PATHS rows of at most SL_CATALOG_MAX_PATH_BYTES each.
 * Schema 3 added `paths`; an older file gets the table at open (CREATE IF
 * NOT EXISTS) and its schema_version raised. Schema 4 made `sessions` the
 * session checkpoints of every node (id, node, token_hash, state).
 * Used by the lws service thread (server) or the `catalog` CLI, never both
 * on one connection, never from the render thread.
 */
#include "sl_server.h"

#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "data/sl_generate.h"
#include "data/sl_dataset_open.h"
#include "data/sl_load.h"
#include "lrspline/sl_lr.h"
#include "volume/sl_volume.h"

static const char *schema_sql =
    "CREATE TABLE IF NOT EXISTS datasets("
    " id INTEGER PRIMARY KEY, name TEXT UNIQUE NOT NULL, kind TEXT NOT NULL,"
    " source_path TEXT, generator_json TEXT, description TEXT,"
    " file_size INTEGER, checksum TEXT, bounds TEXT, counts TEXT, attributes TEXT,"
    " created TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ','now')));"
    "CREATE TABLE IF NOT EXISTS views("
    " id INTEGER PRIMARY KEY, name TEXT UNIQUE NOT NULL, dataset TEXT NOT NULL,"
    " technique TEXT NOT NULL, params TEXT NOT NULL, camera TEXT NOT NULL,"
    " created TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ','now')));"
    "CREATE TABLE IF NOT EXISTS sessions("
    " id TEXT PRIMARY KEY, node TEXT NOT NULL, token_hash TEXT NOT NULL, state TEXT NOT NULL,"
    " created TEXT DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ','now')),"
    " updated TEXT DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ','now')));"
    "CREATE TABLE IF NOT EXISTS removed("
    " name TEXT PRIMARY KEY,"
    " removed TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ','now')));"
    "CREATE TABLE IF NOT EXISTS paths("
    " id INTEGER PRIMARY KEY, name TEXT UNIQUE NOT NULL, technique TEXT NOT NULL, path TEXT NOT NULL,"
    " keys INTEGER NOT NULL, duration REAL NOT NULL,"
    " created TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ','now')));"
    "CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);"
    "INSERT OR IGNORE INTO meta(key, value) VALUES('schema_version', '4');"
    "UPDATE meta SET value = '4' WHERE key = 'schema_version' AND CAST(value AS INTEGER) < 4;";

static sl_status db_fail(sqlite3 *db, sl_err *err, const char *what)
{
    return sl_err_set(err, SL_ERR_IO, "catalog: %s: %s", what, sqlite3_errmsg(db));
}

/* Before schema 4, `sessions` held (id, state) rows that lived only while
 * their server ran; such a table is dropped at open and made anew with
 * node and token_hash (schema_sql). */
static int sessions_table_is_old(sqlite3 *db)
{
    sqlite3_stmt *q = NULL;
    int has_table = 0, has_node = 0;
    if (sqlite3_prepare_v2(db, "SELECT name FROM pragma_table_info('sessions')", -1, &q, NULL) == SQLITE_OK)
        while (sqlite3_step(q) == SQLITE_ROW) {
            has_table = 1;
            has_node |= strcmp((const char *)sqlite3_column_text(q, 0), "node") == 0;
        }
    sqlite3_finalize(q);
    return has_table && !has_node;
}

sl_status sl_catalog_open(const char *path, sqlite3 **out, sl_err *err)
{
    *out = NULL;
    sqlite3 *db = NULL;
    if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, NULL)
        != SQLITE_OK) {
        sl_status st = sl_err_set(err, SL_ERR_IO, "catalog: cannot open %s: %s", path,
                                  db ? sqlite3_errmsg(db) : "out of memory");
        sqlite3_close(db);
        return st;
    }
    sqlite3_busy_timeout(db, 2000);
    char *msg = NULL;
    if (sqlite3_exec(db, "PRAGMA journal_mode=WAL;", NULL, NULL, &msg) != SQLITE_OK ||
        sqlite3_exec(db, sessions_table_is_old(db) ? "DROP TABLE sessions" : "", NULL, NULL, &msg) != SQLITE_OK ||
        sqlite3_exec(db, schema_sql, NULL, NULL, &msg) != SQLITE_OK) {
        sl_status st = sl_err_set(err, SL_ERR_IO, "catalog: cannot initialise %s: %s", path, msg ? msg : "?");
        sqlite3_free(msg);
        sqlite3_close(db);
        return st;
    }
    *out = db;
    return SL_OK;
}

void sl_catalog_close(sqlite3 *db)
{
    sqlite3_close(db);
}

static int name_exists(sqlite3 *db, const char *name)
{
    sqlite3_stmt *q = NULL;
    int found = 0;
    if (sqlite3_prepare_v2(db, "SELECT 1 FROM datasets WHERE name = ?1", -1, &q, NULL) == SQLITE_OK) {
        sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
        found = sqlite3_step(q) == SQLITE_ROW;
    }
    sqlite3_finalize(q);
    return found;
}

/* Runs one statement with a single text parameter; for the tombstone table. */
static sl_status exec_name(sqlite3 *db, const char *sql, const char *name, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, sql, -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(q);
    sqlite3_finalize(q);
    return rc == SQLITE_DONE ? SL_OK : db_fail(db, err, "tombstone");
}

static int was_removed(sqlite3 *db, const char *name)
{
    sqlite3_stmt *q = NULL;
    int found = 0;
    if (sqlite3_prepare_v2(db, "SELECT 1 FROM removed WHERE name = ?1", -1, &q, NULL) == SQLITE_OK) {
        sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
        found = sqlite3_step(q) == SQLITE_ROW;
    }
    sqlite3_finalize(q);
    return found;
}

void sl_catalog_describe(const sl_dataset *ds, char **bounds, char **counts, char **attrs)
{
    cJSON *b = cJSON_CreateArray();
    double lo[3] = {ds->bounds_min.x, ds->bounds_min.y, ds->bounds_min.z};
    double hi[3] = {ds->bounds_max.x, ds->bounds_max.y, ds->bounds_max.z};
    cJSON_AddItemToArray(b, cJSON_CreateDoubleArray(lo, 3));
    cJSON_AddItemToArray(b, cJSON_CreateDoubleArray(hi, 3));
    cJSON *c = cJSON_CreateObject();
    cJSON *a = cJSON_CreateArray();
    if (ds->kind == SL_DATASET_LINES) {
        cJSON_AddNumberToObject(c, "lines", (double)ds->lines.line_count);
        cJSON_AddNumberToObject(c, "vertices", (double)ds->lines.vertex_count);
        for (int i = 0; i < ds->lines.attribute_count; i++)
            cJSON_AddItemToArray(a, cJSON_CreateString(ds->lines.attributes[i].name));
    } else if (ds->kind == SL_DATASET_LR) {
        /* No voxels, so no histogram; the value range is sl_lr_finish's sample. */
        const sl_lr_volume *lr = ds->lr;
        cJSON_AddNumberToObject(c, "elements", (double)lr->element_count);
        cJSON_AddNumberToObject(c, "basis_functions", (double)lr->basis_count);
        cJSON_AddNumberToObject(c, "components", lr->dim);
        int degree[3] = {lr->order[0] - 1, lr->order[1] - 1, lr->order[2] - 1};
        cJSON_AddItemToObject(c, "degree", cJSON_CreateIntArray(degree, 3));
        double range[2] = {lr->value_min, lr->value_max};
        if (isfinite(range[0]) && isfinite(range[1]))
            cJSON_AddItemToObject(c, "value_range", cJSON_CreateDoubleArray(range, 2));
    } else {
        cJSON_AddItemToObject(c, "dims", cJSON_CreateIntArray(ds->volume.dims, 3));
        cJSON_AddNumberToObject(c, "components", ds->volume.components);
        double range[2] = {ds->volume.value_min, ds->volume.value_max};
        if (isfinite(range[0]) && isfinite(range[1]))
            cJSON_AddItemToObject(c, "value_range", cJSON_CreateDoubleArray(range, 2));
        double bins[SL_VOLUME_HISTOGRAM_BINS], ramp[4][2];
        for (int k = 0; k < SL_VOLUME_HISTOGRAM_BINS; k++)
            bins[k] = (double)ds->volume.histogram[k];
        cJSON_AddItemToObject(c, "histogram", cJSON_CreateDoubleArray(bins, SL_VOLUME_HISTOGRAM_BINS));
        int n = sl_volume_tf_auto_opacity(&ds->volume, ramp);
        cJSON *a_ramp = cJSON_AddArrayToObject(c, "auto_opacity");
        for (int k = 0; a_ramp && k < n; k++)
            cJSON_AddItemToArray(a_ramp, cJSON_CreateDoubleArray(ramp[k], 2));
    }
    *bounds = cJSON_PrintUnformatted(b);
    *counts = cJSON_PrintUnformatted(c);
    *attrs = cJSON_PrintUnformatted(a);
    cJSON_Delete(b);
    cJSON_Delete(c);
    cJSON_Delete(a);
}

/* ds may be NULL (a built-in not generated yet): bounds/counts/attributes stay NULL. */
static sl_status insert_dataset(sqlite3 *db, const char *name, const char *kind, const sl_dataset *ds,
                                const char *path, const char *generator, const char *description,
                                long long file_size, const char *checksum, sl_err *err)
{
    char *bounds = NULL, *counts = NULL, *attrs = NULL;
    if (ds)
        sl_catalog_describe(ds, &bounds, &counts, &attrs);
    sqlite3_stmt *q = NULL;
    sl_status st = SL_OK;
    if (sqlite3_prepare_v2(db,
                           "INSERT INTO datasets(name, kind, source_path, generator_json, description,"
                           " file_size, checksum, bounds, counts, attributes)"
                           " VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
                           -1, &q, NULL) != SQLITE_OK) {
        st = db_fail(db, err, "prepare insert");
    } else {
        sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(q, 2, kind, -1, SQLITE_TRANSIENT);
        if (path) sqlite3_bind_text(q, 3, path, -1, SQLITE_TRANSIENT); else sqlite3_bind_null(q, 3);
        if (generator) sqlite3_bind_text(q, 4, generator, -1, SQLITE_TRANSIENT); else sqlite3_bind_null(q, 4);
        sqlite3_bind_text(q, 5, description ? description : "", -1, SQLITE_TRANSIENT);
        if (file_size >= 0) sqlite3_bind_int64(q, 6, file_size); else sqlite3_bind_null(q, 6);
        if (checksum) sqlite3_bind_text(q, 7, checksum, -1, SQLITE_TRANSIENT); else sqlite3_bind_null(q, 7);
        if (bounds) sqlite3_bind_text(q, 8, bounds, -1, SQLITE_TRANSIENT); else sqlite3_bind_null(q, 8);
        if (counts) sqlite3_bind_text(q, 9, counts, -1, SQLITE_TRANSIENT); else sqlite3_bind_null(q, 9);
        if (attrs) sqlite3_bind_text(q, 10, attrs, -1, SQLITE_TRANSIENT); else sqlite3_bind_null(q, 10);
        if (sqlite3_step(q) != SQLITE_DONE)
            st = sl_err_set(err, SL_ERR_INVALID, "catalog: cannot add \"%s\": %s", name, sqlite3_errmsg(db));
    }
    /* Every insert is deliberate (explicit, or automatic after checking
     * was_removed), so the name is no longer removed. */
    if (st == SL_OK)
        st = exec_name(db, "DELETE FROM removed WHERE name = ?1", name, err);
    sqlite3_finalize(q);
    free(bounds);
    free(counts);
    free(attrs);
    return st;
}

/* Registers the built-ins that are absent; revive=0 skips removed ones. */
static sl_status register_builtins(sqlite3 *db, int revive, int *added, sl_err *err)
{
    int n = 0;
    const sl_builtin_dataset *b = sl_builtin_datasets(&n);
    for (int i = 0; i < n; i++) {
        if (name_exists(db, b[i].name) || (!revive && was_removed(db, b[i].name)))
            continue;
        /* Built-ins are registered without generating them (some take seconds);
         * bounds and counts are filled in when one is first rendered. */
        cJSON *g = cJSON_Parse(b[i].generator_json);
        const cJSON *family = cJSON_GetObjectItemCaseSensitive(g, "generator");
        const char *kind = NULL;
        int nf = 0;
        const sl_generator_info *fams = sl_generator_list(&nf);
        for (int k = 0; k < nf && cJSON_IsString(family); k++)
            if (strcmp(fams[k].name, family->valuestring) == 0)
                kind = sl_dataset_kind_name(fams[k].kind);
        cJSON_Delete(g);
        if (!kind)
            return sl_err_set(err, SL_ERR_INVALID, "built-in dataset \"%s\" names an unknown generator", b[i].name);
        sl_status st = insert_dataset(db, b[i].name, kind, NULL, NULL, b[i].generator_json, b[i].description, -1,
                                      NULL, err);
        if (st)
            return st;
        if (added)
            (*added)++;
    }
    return SL_OK;
}

sl_status sl_catalog_add_builtins(sqlite3 *db, int *added, sl_err *err)
{
    *added = 0;
    return register_builtins(db, 1, added, err);
}

static sl_status scan_dir(sqlite3 *db, const char *dir, const char *const *data_dirs, int dir_count, int revive,
                          int *added, sl_err *err);

sl_status sl_catalog_init_defaults(sqlite3 *db, const char *const *data_dirs, int dir_count, sl_err *err)
{
    sl_status st = register_builtins(db, 0, NULL, err);
    if (st)
        return st;
    for (int i = 0; i < dir_count; i++) {
        char samples[PATH_MAX];
        snprintf(samples, sizeof samples, "%s/samples", data_dirs[i]);
        struct stat sb;
        if (stat(samples, &sb) == 0 && S_ISDIR(sb.st_mode)) {
            int added = 0;
            if ((st = scan_dir(db, samples, data_dirs, dir_count, 0, &added, err)) != SL_OK)
                return st;
        }
    }
    return SL_OK;
}

/* realpath(path) when it lies inside one of the allowed directories. */
static sl_status resolve_inside(const char *path, const char *const *dirs, int n, char out[PATH_MAX], sl_err *err)
{
    if (!realpath(path, out))
        return sl_err_set(err, SL_ERR_IO, "catalog: cannot resolve %s", path);
    for (int i = 0; i < n; i++) {
        char dir[PATH_MAX];
        if (!realpath(dirs[i], dir))
            continue;
        size_t len = strlen(dir);
        if (strncmp(out, dir, len) == 0 && (out[len] == '/' || out[len] == '\0'))
            return SL_OK;
    }
    return sl_err_set(err, SL_ERR_INVALID, "catalog: %s is outside the allowed data directories", path);
}

static sl_status checksum_file(const char *path, long long *size, char hex[17], sl_err *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "catalog: cannot open %s", path);
    uint64_t h = 0xcbf29ce484222325ull;
    unsigned char buf[65536];
    size_t n;
    long long total = 0;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
        for (size_t i = 0; i < n; i++) {
            h ^= buf[i];
            h *= 0x100000001b3ull;
        }
        total += (long long)n;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad)
        return sl_err_set(err, SL_ERR_IO, "catalog: read error in %s", path);
    *size = total;
    snprintf(hex, 17, "%016llx", (unsigned long long)h);
    return SL_OK;
}

sl_status sl_catalog_add_file(sqlite3 *db, const char *path, const char *const *data_dirs, int dir_count,
                              sl_err *err)
{
    char real[PATH_MAX];
    sl_status st = resolve_inside(path, data_dirs, dir_count, real, err);
    if (st)
        return st;
    const char *base = strrchr(real, '/');
    base = base ? base + 1 : real;
    if (name_exists(db, base) || sl_builtin_lookup(base))
        return sl_err_set(err, SL_ERR_INVALID, "catalog: a dataset named \"%s\" already exists", base);
    long long size = 0;
    char sum[17];
    if ((st = checksum_file(real, &size, sum, err)) != SL_OK)
        return st;
    sl_dataset *ds = NULL;
    sl_dataset_dirs dirs = {.dirs = data_dirs, .count = dir_count, .confine = 1};
    if ((st = sl_dataset_open(real, &dirs, &ds, err)) != SL_OK)
        return st;
    st = insert_dataset(db, base, sl_dataset_kind_name(ds->kind), ds, real, NULL, "", size, sum, err);
    sl_dataset_destroy(ds);
    return st;
}

sl_status sl_catalog_add_generator(sqlite3 *db, const char *name, const char *generator_json, sl_err *err)
{
    if (!name[0] || strlen(name) >= SL_PROTO_NAME_MAX)
        return sl_err_set(err, SL_ERR_INVALID, "catalog: a dataset name must have 1..%d bytes", SL_PROTO_NAME_MAX - 1);
    if (name_exists(db, name))
        return sl_err_set(err, SL_ERR_INVALID, "catalog: a dataset named \"%s\" already exists", name);
    sl_dataset *ds = NULL;
    sl_status st = sl_generate_json(generator_json, &ds, err);
    if (st)
        return st;
    cJSON *g = cJSON_Parse(generator_json);
    char *compact = g ? cJSON_PrintUnformatted(g) : NULL;
    cJSON_Delete(g);
    st = insert_dataset(db, name, sl_dataset_kind_name(ds->kind), ds, NULL, compact ? compact : generator_json,
                        "", -1, NULL, err);
    free(compact);
    sl_dataset_destroy(ds);
    return st;
}

static int known_extension(const char *name)
{
    static const char *const ext[] = {".trk", ".tck", ".vtk", ".obj", ".nrrd", ".nhdr", ".nii", ".nii.gz", ".json",
                                      ".lr", ".lr.gz"};
    size_t len = strlen(name);
    for (size_t i = 0; i < sizeof ext / sizeof ext[0]; i++) {
        size_t el = strlen(ext[i]);
        if (len > el && strcmp(name + len - el, ext[i]) == 0)
            return 1;
    }
    return 0;
}

sl_status sl_catalog_scan(sqlite3 *db, const char *dir, const char *const *data_dirs, int dir_count,
                          int *added, sl_err *err)
{
    return scan_dir(db, dir, data_dirs, dir_count, 1, added, err);
}

static sl_status scan_dir(sqlite3 *db, const char *dir, const char *const *data_dirs, int dir_count, int revive,
                          int *added, sl_err *err)
{
    *added = 0;
    char real[PATH_MAX];
    sl_status st = resolve_inside(dir, data_dirs, dir_count, real, err);
    if (st)
        return st;
    DIR *d = opendir(real);
    if (!d)
        return sl_err_set(err, SL_ERR_IO, "catalog: cannot list %s", dir);
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.' || !known_extension(e->d_name))
            continue;
        char path[PATH_MAX];
        struct stat sb;
        if (snprintf(path, sizeof path, "%s/%s", real, e->d_name) >= (int)sizeof path || stat(path, &sb) != 0 || !S_ISREG(sb.st_mode) || name_exists(db, e->d_name) ||
            (!revive && was_removed(db, e->d_name)))
            continue;
        sl_err one = {0};
        if (sl_catalog_add_file(db, path, data_dirs, dir_count, &one) == SL_OK)
            (*added)++;
        else
            fprintf(stderr, "sightline-server: skipped %s: %s\n", path, one.message);
    }
    closedir(d);
    return SL_OK;
}

sl_status sl_catalog_set_info(sqlite3 *db, const char *name, const char *bounds, const char *counts,
                               const char *attrs, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    /* Fills a row not described yet, and refreshes a volume described before
     * catalogs kept histograms (a catalog file from an older version). */
    if (sqlite3_prepare_v2(db, "UPDATE datasets SET bounds = ?2, counts = ?3, attributes = ?4"
                               " WHERE name = ?1 AND (bounds IS NULL OR (kind <> 'lines' AND"
                               " json_type(counts, '$.histogram') IS NULL))", -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare set_info");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 2, bounds, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 3, counts, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 4, attrs, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(q);
    sqlite3_finalize(q);
    return rc == SQLITE_DONE ? SL_OK : db_fail(db, err, "set_info");
}

sl_status sl_catalog_remove(sqlite3 *db, const char *name, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "DELETE FROM datasets WHERE name = ?1", -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare delete");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(q);
    sqlite3_finalize(q);
    if (rc != SQLITE_DONE)
        return db_fail(db, err, "delete");
    if (sqlite3_changes(db) == 0)
        return sl_err_set(err, SL_ERR_INVALID, "catalog: no dataset named \"%s\"", name);
    return exec_name(db, "INSERT OR REPLACE INTO removed(name) VALUES(?1)", name, err);
}

static cJSON *column_json(sqlite3_stmt *q, int col)
{
    const unsigned char *t = sqlite3_column_text(q, col);
    cJSON *j = t ? cJSON_Parse((const char *)t) : NULL;
    return j ? j : cJSON_CreateNull();
}

cJSON *sl_catalog_list_json(sqlite3 *db, int with_paths)
{
    cJSON *arr = cJSON_CreateArray();
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db,
                           "SELECT name, kind, source_path, generator_json, description, file_size, checksum,"
                           " bounds, counts, attributes, created FROM datasets ORDER BY id",
                           -1, &q, NULL) != SQLITE_OK)
        return arr;
    while (sqlite3_step(q) == SQLITE_ROW) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", (const char *)sqlite3_column_text(q, 0));
        cJSON_AddStringToObject(o, "kind", (const char *)sqlite3_column_text(q, 1));
        if (sqlite3_column_type(q, 2) != SQLITE_NULL) {
            if (with_paths)
                cJSON_AddStringToObject(o, "path", (const char *)sqlite3_column_text(q, 2));
            cJSON_AddStringToObject(o, "source", "file");
        } else {
            cJSON_AddStringToObject(o, "source", "generator");
        }
        if (sqlite3_column_type(q, 3) != SQLITE_NULL)
            cJSON_AddItemToObject(o, "generator", column_json(q, 3));
        cJSON_AddStringToObject(o, "description",
                                sqlite3_column_text(q, 4) ? (const char *)sqlite3_column_text(q, 4) : "");
        if (sqlite3_column_type(q, 5) != SQLITE_NULL)
            cJSON_AddNumberToObject(o, "file_size", (double)sqlite3_column_int64(q, 5));
        if (sqlite3_column_type(q, 6) != SQLITE_NULL)
            cJSON_AddStringToObject(o, "checksum", (const char *)sqlite3_column_text(q, 6));
        cJSON_AddItemToObject(o, "bounds", column_json(q, 7));
        cJSON_AddItemToObject(o, "counts", column_json(q, 8));
        cJSON_AddItemToObject(o, "attributes", column_json(q, 9));
        cJSON_AddStringToObject(o, "created", (const char *)sqlite3_column_text(q, 10));
        cJSON_AddItemToArray(arr, o);
    }
    sqlite3_finalize(q);
    return arr;
}

sl_status sl_catalog_lookup(sqlite3 *db, const char *name, char *source, size_t source_size, int *is_file,
                            int *kind, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "SELECT kind, source_path, generator_json FROM datasets WHERE name = ?1", -1, &q,
                           NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare lookup");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    sl_status st = SL_OK;
    if (sqlite3_step(q) != SQLITE_ROW) {
        st = sl_err_set(err, SL_ERR_INVALID, "no dataset named \"%s\" in the catalog", name);
    } else {
        const char *k = (const char *)sqlite3_column_text(q, 0);
        *kind = 0;
        for (int i = 0; i < SL_DATASET_KIND_COUNT; i++)
            if (k && strcmp(k, sl_dataset_kind_name(sl_dataset_kinds[i])) == 0)
                *kind = sl_dataset_kinds[i];
        const char *path = (const char *)sqlite3_column_text(q, 1);
        const char *gen = (const char *)sqlite3_column_text(q, 2);
        *is_file = path != NULL;
        const char *src = path ? path : gen;
        if (!src || strlen(src) >= source_size)
            st = sl_err_set(err, SL_ERR_LIMIT, "dataset \"%s\" has no usable source (or one over %zu bytes)", name,
                            source_size);
        else
            memcpy(source, src, strlen(src) + 1);
    }
    sqlite3_finalize(q);
    return st;
}

/* The rows of a named table (count_sql: "SELECT COUNT(*), SUM(name = ?1)
 * FROM t") and whether `name` is among them: the caps of saved views and
 * paths (a new name only below the cap, a replacement always). */
static sl_status count_named(sqlite3 *db, const char *count_sql, const char *name, long long *count,
                             int *exists, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    *count = 0;
    *exists = 0;
    if (sqlite3_prepare_v2(db, count_sql, -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare count");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    if (sqlite3_step(q) == SQLITE_ROW) {
        *count = sqlite3_column_int64(q, 0);
        *exists = sqlite3_column_int64(q, 1) > 0;
    }
    sqlite3_finalize(q);
    return SL_OK;
}

sl_status sl_catalog_save_view(sqlite3 *db, const char *name, const char *dataset, const char *technique,
                               const char *params_json, const char *camera_json, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    /* Replacing a view is always allowed; a new name only below the cap. */
    long long count = 0;
    int exists = 0;
    sl_status cst = count_named(db, "SELECT COUNT(*), SUM(name = ?1) FROM views", name, &count, &exists, err);
    if (cst != SL_OK)
        return cst;
    if (!exists && count >= SL_CATALOG_MAX_VIEWS)
        return sl_err_set(err, SL_ERR_LIMIT, "the catalog already holds %d saved views (the limit); reuse a name",
                          SL_CATALOG_MAX_VIEWS);
    if (sqlite3_prepare_v2(db,
                           "INSERT INTO views(name, dataset, technique, params, camera) VALUES(?1, ?2, ?3, ?4, ?5)"
                           " ON CONFLICT(name) DO UPDATE SET dataset = excluded.dataset,"
                           " technique = excluded.technique, params = excluded.params, camera = excluded.camera",
                           -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare save_view");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 2, dataset, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 3, technique, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 4, params_json, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 5, camera_json, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(q);
    sqlite3_finalize(q);
    return rc == SQLITE_DONE ? SL_OK : db_fail(db, err, "save_view");
}

sl_status sl_catalog_load_view(sqlite3 *db, const char *name, cJSON **view, sl_err *err)
{
    *view = NULL;
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "SELECT name, dataset, technique, params, camera FROM views WHERE name = ?1", -1, &q,
                           NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare load_view");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    if (sqlite3_step(q) == SQLITE_ROW) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", (const char *)sqlite3_column_text(q, 0));
        cJSON_AddStringToObject(o, "dataset", (const char *)sqlite3_column_text(q, 1));
        cJSON_AddStringToObject(o, "technique", (const char *)sqlite3_column_text(q, 2));
        cJSON_AddItemToObject(o, "params", column_json(q, 3));
        cJSON_AddItemToObject(o, "camera", column_json(q, 4));
        *view = o;
    }
    sqlite3_finalize(q);
    return SL_OK;
}

cJSON *sl_catalog_list_views_json(sqlite3 *db)
{
    cJSON *arr = cJSON_CreateArray();
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "SELECT name, dataset, technique, created FROM views ORDER BY name", -1, &q, NULL)
        != SQLITE_OK)
        return arr;
    while (sqlite3_step(q) == SQLITE_ROW) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", (const char *)sqlite3_column_text(q, 0));
        cJSON_AddStringToObject(o, "dataset", (const char *)sqlite3_column_text(q, 1));
        cJSON_AddStringToObject(o, "technique", (const char *)sqlite3_column_text(q, 2));
        cJSON_AddStringToObject(o, "created", (const char *)sqlite3_column_text(q, 3));
        cJSON_AddItemToArray(arr, o);
    }
    sqlite3_finalize(q);
    return arr;
}

sl_status sl_catalog_save_path(sqlite3 *db, const char *name, const char *technique, const char *path_json,
                               int keys, double duration, sl_err *err)
{
    size_t bytes = strlen(path_json);
    if (bytes > SL_CATALOG_MAX_PATH_BYTES)
        return sl_err_set(err, SL_ERR_LIMIT, "path: %zu bytes of JSON; a saved path holds at most %d", bytes,
                          SL_CATALOG_MAX_PATH_BYTES);
    sqlite3_stmt *q = NULL;
    long long count = 0;
    int exists = 0;
    sl_status cst = count_named(db, "SELECT COUNT(*), SUM(name = ?1) FROM paths", name, &count, &exists, err);
    if (cst != SL_OK)
        return cst;
    if (!exists && count >= SL_CATALOG_MAX_PATHS)
        return sl_err_set(err, SL_ERR_LIMIT, "the catalog already holds %d saved paths (the limit); reuse a name",
                          SL_CATALOG_MAX_PATHS);
    if (sqlite3_prepare_v2(db,
                           "INSERT INTO paths(name, technique, path, keys, duration) VALUES(?1, ?2, ?3, ?4, ?5)"
                           " ON CONFLICT(name) DO UPDATE SET technique = excluded.technique, path = excluded.path,"
                           " keys = excluded.keys, duration = excluded.duration",
                           -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare save_path");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 2, technique, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 3, path_json, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int(q, 4, keys);
    sqlite3_bind_double(q, 5, duration);
    int rc = sqlite3_step(q);
    sqlite3_finalize(q);
    return rc == SQLITE_DONE ? SL_OK : db_fail(db, err, "save_path");
}

sl_status sl_catalog_load_path(sqlite3 *db, const char *name, cJSON **path, sl_err *err)
{
    *path = NULL;
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "SELECT path FROM paths WHERE name = ?1", -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare load_path");
    sqlite3_bind_text(q, 1, name, -1, SQLITE_TRANSIENT);
    if (sqlite3_step(q) == SQLITE_ROW)
        *path = column_json(q, 0);
    sqlite3_finalize(q);
    return SL_OK;
}

cJSON *sl_catalog_list_paths_json(sqlite3 *db)
{
    cJSON *arr = cJSON_CreateArray();
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "SELECT name, technique, keys, duration, created FROM paths ORDER BY name", -1, &q,
                           NULL) != SQLITE_OK)
        return arr;
    while (sqlite3_step(q) == SQLITE_ROW) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", (const char *)sqlite3_column_text(q, 0));
        cJSON_AddStringToObject(o, "technique", (const char *)sqlite3_column_text(q, 1));
        cJSON_AddNumberToObject(o, "keys", sqlite3_column_int(q, 2));
        cJSON_AddNumberToObject(o, "duration", sqlite3_column_double(q, 3));
        cJSON_AddStringToObject(o, "created", (const char *)sqlite3_column_text(q, 4));
        cJSON_AddItemToArray(arr, o);
    }
    sqlite3_finalize(q);
    return arr;
}

sl_status sl_catalog_session_put(sqlite3 *db, const char *id, const char *node, const char *token_hash,
                                 const char *state_json, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db,
                           "INSERT INTO sessions(id, node, token_hash, state) VALUES(?1, ?2, ?3, ?4)"
                           " ON CONFLICT(id) DO UPDATE SET node = excluded.node, token_hash = excluded.token_hash,"
                           " state = excluded.state, updated = strftime('%Y-%m-%dT%H:%M:%SZ','now')",
                           -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare session_put");
    sqlite3_bind_text(q, 1, id, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 2, node, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 3, token_hash, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(q, 4, state_json, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(q);
    sqlite3_finalize(q);
    return rc == SQLITE_DONE ? SL_OK : db_fail(db, err, "session_put");
}

sl_status sl_catalog_session_get(sqlite3 *db, const char *id, char **state_json, char token_hash[65], char *node,
                                 size_t node_size, sl_err *err)
{
    *state_json = NULL;
    token_hash[0] = '\0';
    if (node_size)
        node[0] = '\0';
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "SELECT state, token_hash, node FROM sessions WHERE id = ?1", -1, &q, NULL) !=
        SQLITE_OK)
        return db_fail(db, err, "prepare session_get");
    sqlite3_bind_text(q, 1, id, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(q);
    sl_status st = SL_OK;
    if (rc == SQLITE_ROW) {
        const char *state = (const char *)sqlite3_column_text(q, 0);
        const char *hash = (const char *)sqlite3_column_text(q, 1);
        const char *owner = (const char *)sqlite3_column_text(q, 2);
        *state_json = strdup(state ? state : "");
        snprintf(token_hash, 65, "%s", hash ? hash : "");
        if (node_size)
            snprintf(node, node_size, "%s", owner ? owner : "");
        if (!*state_json)
            st = sl_err_set(err, SL_ERR_NOMEM, "catalog: out of memory reading the checkpoint of %s", id);
    } else if (rc == SQLITE_DONE) {
        st = sl_err_set(err, SL_ERR_INVALID, "catalog: no checkpoint of session %s", id);
    } else {
        st = db_fail(db, err, "session_get");
    }
    sqlite3_finalize(q);
    return st;
}

sl_status sl_catalog_sessions_clear_node(sqlite3 *db, const char *node, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "DELETE FROM sessions WHERE node = ?1", -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare sessions_clear_node");
    sqlite3_bind_text(q, 1, node, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(q);
    sqlite3_finalize(q);
    return rc == SQLITE_DONE ? SL_OK : db_fail(db, err, "sessions_clear_node");
}

sl_status sl_catalog_session_remove(sqlite3 *db, const char *id, sl_err *err)
{
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(db, "DELETE FROM sessions WHERE id = ?1", -1, &q, NULL) != SQLITE_OK)
        return db_fail(db, err, "prepare session_remove");
    sqlite3_bind_text(q, 1, id, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(q);
    sqlite3_finalize(q);
    return rc == SQLITE_DONE ? SL_OK : db_fail(db, err, "session_remove");
}
