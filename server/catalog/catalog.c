/* catalog.c — the catalog: datasets, saved views, named camera paths and
 * session checkpoints, over sl_db.h (SQLite or PostgreSQL, one SQL text
 * for both; the schema and its migrations are in catalog_schema.c).
 *
 * Every statement binds its arguments; no SQL is built from input text.
 * File datasets must lie inside one of the allowed data directories after
 * realpath(), so "../" or a symlink cannot reach outside. A dataset row
 * records what the catalog needs to list it without loading it: kind,
 * source (generator JSON or absolute path), file size and an FNV-1a 64
 * checksum (so a node whose copy of the file differs refuses it:
 * dataset_cache.c), bounds, counts and attribute names. Removal sticks:
 * `remove` leaves a row in `removed`, and the automatic registration at
 * start (built-ins, <data-dir>/samples) skips those names; only an explicit
 * add, add-generator, scan or add-builtins brings one back. Saved views and
 * named paths are capped (sl_catalog.h); a replacement is always allowed.
 * Statements that must see one state (a cap and its insert, a row and its
 * tombstone) run in one transaction. Time stamps are ISO 8601 UTC texts
 * made here. Does not render. Service thread or the `catalog` CLI.
 */
#include "sl_catalog.h"

#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "core/sl_hash.h"
#include "data/sl_generate.h"
#include "data/sl_dataset_open.h"
#include "data/sl_load.h"
#include "lrspline/sl_lr.h"
#include "volume/sl_volume.h"
#include "sl_protocol.h"

#define TEXT(s) sl_db_text_arg(s)

/* Now as "YYYY-MM-DDTHH:MM:SSZ". */
static void utc_now(char out[32])
{
    time_t t = time(NULL);
    struct tm tm;
    gmtime_r(&t, &tm);
    strftime(out, 32, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

sl_status sl_catalog_open(const char *target, sl_db **out, sl_err *err)
{
    *out = NULL;
    sl_db *db = NULL;
    sl_status st = sl_db_open(target, &db, err);
    if (st == SL_OK && (st = sl_catalog_migrate(db, NULL, err)) != SL_OK) {
        sl_db_close(db);
        db = NULL;
    }
    *out = db;
    return st;
}

void sl_catalog_close(sl_db *db)
{
    sl_db_close(db);
}

/* 1 when a row of `sql` (one text argument) exists; a failed query counts as none. */
static int row_exists(sl_db *db, const char *sql, const char *name)
{
    sl_db_result *r = NULL;
    sl_err ignored = {0};
    sl_db_arg arg = TEXT(name);
    int found = sl_db_query(db, sql, &arg, 1, &r, &ignored) == SL_OK && sl_db_result_rows(r) > 0;
    sl_db_result_destroy(r);
    return found;
}

static int name_exists(sl_db *db, const char *name)
{
    return row_exists(db, "SELECT 1 FROM datasets WHERE name = $1", name);
}

static int was_removed(sl_db *db, const char *name)
{
    return row_exists(db, "SELECT 1 FROM removed WHERE name = $1", name);
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
        int n = sl_volume_tf_auto_opacity(&ds->volume, 1, ramp); /* the composite ramp: the default mode's */
        cJSON *a_ramp = cJSON_AddArrayToObject(c, "auto_opacity");
        for (int k = 0; a_ramp && k < n; k++)
            cJSON_AddItemToArray(a_ramp, cJSON_CreateDoubleArray(ramp[k], 2));
        double iso = sl_volume_auto_isovalue(&ds->volume);
        if (isfinite(iso))
            cJSON_AddNumberToObject(c, "auto_isovalue", iso);
    }
    *bounds = cJSON_PrintUnformatted(b);
    *counts = cJSON_PrintUnformatted(c);
    *attrs = cJSON_PrintUnformatted(a);
    cJSON_Delete(b);
    cJSON_Delete(c);
    cJSON_Delete(a);
}

/* ds may be NULL (a built-in not generated yet): bounds/counts/attributes stay NULL.
 * if_absent: an automatic registration (built-ins, samples at a node's start),
 * which another node starting at the same moment may have made first: a row
 * of that name is left as it is and *inserted is 0. Otherwise a duplicate
 * name is an error. inserted may be NULL. */
static sl_status insert_dataset(sl_db *db, const char *name, const char *kind, const sl_dataset *ds,
                                const char *path, const char *generator, const char *description,
                                long long file_size, const char *checksum, int if_absent, int *inserted,
                                sl_err *err)
{
    long long changed = 0;
    char *bounds = NULL, *counts = NULL, *attrs = NULL;
    if (ds)
        sl_catalog_describe(ds, &bounds, &counts, &attrs);
    char now[32];
    utc_now(now);
    sl_db_arg args[] = {TEXT(name), TEXT(kind), TEXT(path), TEXT(generator), TEXT(description ? description : ""),
                        file_size >= 0 ? sl_db_int_arg(file_size) : TEXT(NULL), TEXT(checksum), TEXT(bounds),
                        TEXT(counts), TEXT(attrs), TEXT(now)};
#define INSERT_DATASET                                                                                 \
    "INSERT INTO datasets(name, kind, source_path, generator_json, description, file_size, checksum, bounds," \
    " counts, attributes, created) VALUES($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11)"
    const char *sql = if_absent ? INSERT_DATASET " ON CONFLICT(name) DO NOTHING" : INSERT_DATASET;
#undef INSERT_DATASET
    sl_status st = sl_db_begin(db, 0, err);
    if (st == SL_OK && sl_db_run(db, sql, args, 11, &changed, err) != SL_OK) {
        sl_err why = *err;
        st = sl_err_set(err, SL_ERR_INVALID, "catalog: cannot add \"%s\": %s", name, why.message);
    }
    /* Every insert is deliberate (explicit, or automatic after checking
     * was_removed), so the name is no longer removed. */
    if (st == SL_OK && changed > 0)
        st = sl_db_run(db, "DELETE FROM removed WHERE name = $1", args, 1, NULL, err);
    if (st == SL_OK)
        st = sl_db_commit(db, err); /* rolls back itself when it fails */
    else
        sl_db_rollback(db);
    if (inserted)
        *inserted = st == SL_OK && changed > 0;
    free(bounds);
    free(counts);
    free(attrs);
    return st;
}

/* Registers the built-ins that are absent; revive=0 skips removed ones. */
static sl_status register_builtins(sl_db *db, int revive, int *added, sl_err *err)
{
    int n = 0;
    const sl_builtin_dataset *b = sl_builtin_datasets(&n);
    for (int i = 0; i < n; i++) {
        /* No check for an existing row: the insert leaves one alone (and a
         * check would race with another node's start anyway). */
        if (!revive && was_removed(db, b[i].name))
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
        int inserted = 0;
        sl_status st = insert_dataset(db, b[i].name, kind, NULL, NULL, b[i].generator_json, b[i].description, -1,
                                      NULL, 1, &inserted, err);
        if (st)
            return st;
        if (added)
            *added += inserted;
    }
    return SL_OK;
}

sl_status sl_catalog_add_builtins(sl_db *db, int *added, sl_err *err)
{
    *added = 0;
    return register_builtins(db, 1, added, err);
}

static sl_status scan_dir(sl_db *db, const char *dir, const char *const *data_dirs, int dir_count, int revive,
                          int *added, sl_err *err);

sl_status sl_catalog_init_defaults(sl_db *db, const char *const *data_dirs, int dir_count, sl_err *err)
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

sl_status sl_catalog_file_checksum(const char *path, long long *size, char hex[SL_CATALOG_CHECKSUM_SIZE], sl_err *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "catalog: cannot open %s", path);
    uint64_t h = SL_FNV1A_SEED;
    unsigned char buf[65536];
    size_t n;
    long long total = 0;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
        h = sl_fnv1a(h, buf, n);
        total += (long long)n;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad)
        return sl_err_set(err, SL_ERR_IO, "catalog: read error in %s", path);
    *size = total;
    snprintf(hex, SL_CATALOG_CHECKSUM_SIZE, "%016llx", (unsigned long long)h);
    return SL_OK;
}

/* sl_catalog_add_file; if_absent and inserted as for insert_dataset (a scan). */
static sl_status add_file(sl_db *db, const char *path, const char *const *data_dirs, int dir_count, int if_absent,
                          int *inserted, sl_err *err)
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
    char sum[SL_CATALOG_CHECKSUM_SIZE];
    if ((st = sl_catalog_file_checksum(real, &size, sum, err)) != SL_OK)
        return st;
    sl_dataset *ds = NULL;
    sl_dataset_dirs dirs = {.dirs = data_dirs, .count = dir_count, .confine = 1};
    if ((st = sl_dataset_open(real, &dirs, &ds, err)) != SL_OK)
        return st;
    st = insert_dataset(db, base, sl_dataset_kind_name(ds->kind), ds, real, NULL, "", size, sum, if_absent, inserted,
                        err);
    sl_dataset_destroy(ds);
    return st;
}

sl_status sl_catalog_add_file(sl_db *db, const char *path, const char *const *data_dirs, int dir_count,
                              sl_err *err)
{
    return add_file(db, path, data_dirs, dir_count, 0, NULL, err);
}

sl_status sl_catalog_refresh_file(sl_db *db, const char *name, const char *const *data_dirs, int dir_count,
                                  sl_err *err)
{
    char source[PATH_MAX], real[PATH_MAX], sum[SL_CATALOG_CHECKSUM_SIZE];
    int is_file = 0, kind = 0;
    sl_status st = sl_catalog_lookup(db, name, source, sizeof source, &is_file, &kind, NULL, err);
    if (st != SL_OK)
        return st;
    if (!is_file)
        return sl_err_set(err, SL_ERR_INVALID, "catalog: \"%s\" is generated, not a file", name);
    long long size = 0;
    sl_dataset *ds = NULL;
    sl_dataset_dirs dirs = {.dirs = data_dirs, .count = dir_count, .confine = 1};
    if ((st = resolve_inside(source, data_dirs, dir_count, real, err)) != SL_OK ||
        (st = sl_catalog_file_checksum(real, &size, sum, err)) != SL_OK ||
        (st = sl_dataset_open(real, &dirs, &ds, err)) != SL_OK)
        return st;
    char *bounds = NULL, *counts = NULL, *attrs = NULL;
    sl_catalog_describe(ds, &bounds, &counts, &attrs);
    sl_db_arg args[] = {TEXT(name), sl_db_int_arg(size), TEXT(sum), TEXT(bounds), TEXT(counts), TEXT(attrs),
                        TEXT(sl_dataset_kind_name(ds->kind))};
    st = sl_db_run(db,
                   "UPDATE datasets SET file_size = $2, checksum = $3, bounds = $4, counts = $5, attributes = $6,"
                   " kind = $7 WHERE name = $1",
                   args, 7, NULL, err);
    free(bounds);
    free(counts);
    free(attrs);
    sl_dataset_destroy(ds);
    return st;
}

sl_status sl_catalog_add_generator(sl_db *db, const char *name, const char *generator_json, sl_err *err)
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
                        "", -1, NULL, 0, NULL, err);
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

sl_status sl_catalog_scan(sl_db *db, const char *dir, const char *const *data_dirs, int dir_count,
                          int *added, sl_err *err)
{
    return scan_dir(db, dir, data_dirs, dir_count, 1, added, err);
}

static sl_status scan_dir(sl_db *db, const char *dir, const char *const *data_dirs, int dir_count, int revive,
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
        int inserted = 0;
        if (add_file(db, path, data_dirs, dir_count, 1, &inserted, &one) == SL_OK)
            *added += inserted;
        else
            fprintf(stderr, "sightline-server: skipped %s: %s\n", path, one.message);
    }
    closedir(d);
    return SL_OK;
}

sl_status sl_catalog_set_info(sl_db *db, const char *name, const char *bounds, const char *counts,
                              const char *attrs, sl_err *err)
{
    /* Fills a row not described yet, and refreshes a volume described before
     * catalogs kept histograms (a catalog from an older version). */
    sl_db_result *r = NULL;
    sl_db_arg args[] = {TEXT(name), TEXT(bounds), TEXT(counts), TEXT(attrs)};
    sl_status st = sl_db_query(db, "SELECT kind, bounds, counts FROM datasets WHERE name = $1", args, 1, &r, err);
    if (st != SL_OK || sl_db_result_rows(r) == 0) {
        sl_db_result_destroy(r);
        return st;
    }
    const char *kind = sl_db_text(r, 0, 0), *old_counts = sl_db_text(r, 0, 2);
    cJSON *c = old_counts ? cJSON_Parse(old_counts) : NULL;
    int stale = !sl_db_text(r, 0, 1) ||
                (kind && strcmp(kind, "lines") != 0 && !cJSON_GetObjectItemCaseSensitive(c, "histogram"));
    cJSON_Delete(c);
    sl_db_result_destroy(r);
    if (!stale)
        return SL_OK;
    return sl_db_run(db, "UPDATE datasets SET bounds = $2, counts = $3, attributes = $4 WHERE name = $1", args, 4,
                     NULL, err);
}

sl_status sl_catalog_remove(sl_db *db, const char *name, sl_err *err)
{
    char now[32];
    utc_now(now);
    sl_db_arg args[] = {TEXT(name), TEXT(now)};
    long long changed = 0;
    sl_status st = sl_db_begin(db, 0, err);
    if (st == SL_OK)
        st = sl_db_run(db, "DELETE FROM datasets WHERE name = $1", args, 1, &changed, err);
    if (st == SL_OK && changed == 0)
        st = sl_err_set(err, SL_ERR_INVALID, "catalog: no dataset named \"%s\"", name);
    if (st == SL_OK)
        st = sl_db_run(db,
                       "INSERT INTO removed(name, removed) VALUES($1, $2)"
                       " ON CONFLICT(name) DO UPDATE SET removed = excluded.removed",
                       args, 2, NULL, err);
    if (st == SL_OK)
        return sl_db_commit(db, err);
    sl_db_rollback(db);
    return st;
}

/* The cell parsed as JSON, or JSON null. */
static cJSON *cell_json(const sl_db_result *r, int row, int col)
{
    const char *t = sl_db_text(r, row, col);
    cJSON *j = t ? cJSON_Parse(t) : NULL;
    return j ? j : cJSON_CreateNull();
}

/* Adds the cell as a string member; NULL cells are left out unless fallback is given. */
static void add_text(cJSON *o, const char *key, const sl_db_result *r, int row, int col, const char *fallback)
{
    const char *t = sl_db_text(r, row, col);
    if (t || fallback)
        cJSON_AddStringToObject(o, key, t ? t : fallback);
}

cJSON *sl_catalog_list_json(sl_db *db, int with_paths)
{
    cJSON *arr = cJSON_CreateArray();
    sl_db_result *r = NULL;
    sl_err err = {0};
    if (sl_db_query(db,
                    "SELECT name, kind, source_path, generator_json, description, file_size, checksum,"
                    " bounds, counts, attributes, created FROM datasets ORDER BY id",
                    NULL, 0, &r, &err) != SL_OK) {
        fprintf(stderr, "sightline-server: %s\n", err.message);
        return arr;
    }
    for (int i = 0; i < sl_db_result_rows(r); i++) {
        cJSON *o = cJSON_CreateObject();
        add_text(o, "name", r, i, 0, "");
        add_text(o, "kind", r, i, 1, "");
        if (sl_db_text(r, i, 2)) {
            if (with_paths)
                add_text(o, "path", r, i, 2, NULL);
            cJSON_AddStringToObject(o, "source", "file");
        } else {
            cJSON_AddStringToObject(o, "source", "generator");
        }
        if (sl_db_text(r, i, 3))
            cJSON_AddItemToObject(o, "generator", cell_json(r, i, 3));
        add_text(o, "description", r, i, 4, "");
        if (sl_db_text(r, i, 5))
            cJSON_AddNumberToObject(o, "file_size", (double)sl_db_int(r, i, 5, 0));
        add_text(o, "checksum", r, i, 6, NULL);
        cJSON_AddItemToObject(o, "bounds", cell_json(r, i, 7));
        cJSON_AddItemToObject(o, "counts", cell_json(r, i, 8));
        cJSON_AddItemToObject(o, "attributes", cell_json(r, i, 9));
        add_text(o, "created", r, i, 10, "");
        cJSON_AddItemToArray(arr, o);
    }
    sl_db_result_destroy(r);
    return arr;
}

sl_status sl_catalog_lookup(sl_db *db, const char *name, char *source, size_t source_size, int *is_file,
                            int *kind, char checksum[SL_CATALOG_CHECKSUM_SIZE], sl_err *err)
{
    sl_db_result *r = NULL;
    sl_db_arg arg = TEXT(name);
    sl_status st = sl_db_query(db, "SELECT kind, source_path, generator_json, checksum FROM datasets WHERE name = $1",
                               &arg, 1, &r, err);
    if (st != SL_OK)
        return st;
    if (sl_db_result_rows(r) == 0) {
        sl_db_result_destroy(r);
        return sl_err_set(err, SL_ERR_INVALID, "no dataset named \"%s\" in the catalog", name);
    }
    const char *k = sl_db_text(r, 0, 0), *path = sl_db_text(r, 0, 1), *gen = sl_db_text(r, 0, 2);
    const char *sum = sl_db_text(r, 0, 3);
    *kind = 0;
    for (int i = 0; i < SL_DATASET_KIND_COUNT; i++)
        if (k && strcmp(k, sl_dataset_kind_name(sl_dataset_kinds[i])) == 0)
            *kind = sl_dataset_kinds[i];
    *is_file = path != NULL;
    if (checksum)
        snprintf(checksum, SL_CATALOG_CHECKSUM_SIZE, "%s", path && sum ? sum : "");
    const char *src = path ? path : gen;
    if (!src || strlen(src) >= source_size)
        st = sl_err_set(err, SL_ERR_LIMIT, "dataset \"%s\" has no usable source (or one over %zu bytes)", name,
                        source_size);
    else
        memcpy(source, src, strlen(src) + 1);
    sl_db_result_destroy(r);
    return st;
}

/* Inside the caller's transaction: SL_ERR_LIMIT when `name` is new and the
 * table (views or paths) already holds `cap` rows. */
static sl_status check_cap(sl_db *db, const char *table, const char *name, int cap, const char *what, sl_err *err)
{
    char sql[160];
    snprintf(sql, sizeof sql, "SELECT COUNT(*), SUM(CASE WHEN name = $1 THEN 1 ELSE 0 END) FROM %s", table);
    sl_db_result *r = NULL;
    sl_db_arg arg = TEXT(name);
    sl_status st = sl_db_query(db, sql, &arg, 1, &r, err);
    if (st == SL_OK && sl_db_int(r, 0, 1, 0) == 0 && sl_db_int(r, 0, 0, 0) >= cap)
        st = sl_err_set(err, SL_ERR_LIMIT, "the catalog already holds %d saved %s (the limit); reuse a name", cap,
                        what);
    sl_db_result_destroy(r);
    return st;
}

/* Runs a capped upsert (check_cap, then sql over args) in one transaction. */
static sl_status capped_upsert(sl_db *db, const char *table, int cap, const char *what, const char *sql,
                               const sl_db_arg *args, int nargs, sl_err *err)
{
    sl_status st = sl_db_begin(db, 0, err);
    if (st != SL_OK)
        return st;
    if ((st = check_cap(db, table, args[0].text, cap, what, err)) == SL_OK &&
        (st = sl_db_run(db, sql, args, nargs, NULL, err)) == SL_OK)
        return sl_db_commit(db, err);
    sl_db_rollback(db);
    return st;
}

sl_status sl_catalog_save_view(sl_db *db, const char *name, const char *dataset, const char *technique,
                               const char *params_json, const char *camera_json, sl_err *err)
{
    char now[32];
    utc_now(now);
    sl_db_arg args[] = {TEXT(name), TEXT(dataset), TEXT(technique), TEXT(params_json), TEXT(camera_json), TEXT(now)};
    return capped_upsert(db, "views", SL_CATALOG_MAX_VIEWS, "views",
                         "INSERT INTO views(name, dataset, technique, params, camera, created)"
                         " VALUES($1, $2, $3, $4, $5, $6)"
                         " ON CONFLICT(name) DO UPDATE SET dataset = excluded.dataset,"
                         " technique = excluded.technique, params = excluded.params, camera = excluded.camera",
                         args, 6, err);
}

sl_status sl_catalog_load_view(sl_db *db, const char *name, cJSON **view, sl_err *err)
{
    *view = NULL;
    sl_db_result *r = NULL;
    sl_db_arg arg = TEXT(name);
    sl_status st = sl_db_query(db, "SELECT name, dataset, technique, params, camera FROM views WHERE name = $1",
                               &arg, 1, &r, err);
    if (st == SL_OK && sl_db_result_rows(r) > 0) {
        cJSON *o = cJSON_CreateObject();
        add_text(o, "name", r, 0, 0, "");
        add_text(o, "dataset", r, 0, 1, "");
        add_text(o, "technique", r, 0, 2, "");
        cJSON_AddItemToObject(o, "params", cell_json(r, 0, 3));
        cJSON_AddItemToObject(o, "camera", cell_json(r, 0, 4));
        *view = o;
    }
    sl_db_result_destroy(r);
    return st;
}

cJSON *sl_catalog_list_views_json(sl_db *db)
{
    cJSON *arr = cJSON_CreateArray();
    sl_db_result *r = NULL;
    sl_err err = {0};
    if (sl_db_query(db, "SELECT name, dataset, technique, created FROM views ORDER BY name", NULL, 0, &r, &err) !=
        SL_OK)
        fprintf(stderr, "sightline-server: %s\n", err.message);
    for (int i = 0; i < sl_db_result_rows(r); i++) {
        cJSON *o = cJSON_CreateObject();
        add_text(o, "name", r, i, 0, "");
        add_text(o, "dataset", r, i, 1, "");
        add_text(o, "technique", r, i, 2, "");
        add_text(o, "created", r, i, 3, "");
        cJSON_AddItemToArray(arr, o);
    }
    sl_db_result_destroy(r);
    return arr;
}

sl_status sl_catalog_save_path(sl_db *db, const char *name, const char *technique, const char *path_json,
                               int keys, double duration, sl_err *err)
{
    size_t bytes = strlen(path_json);
    if (bytes > SL_CATALOG_MAX_PATH_BYTES)
        return sl_err_set(err, SL_ERR_LIMIT, "path: %zu bytes of JSON; a saved path holds at most %d", bytes,
                          SL_CATALOG_MAX_PATH_BYTES);
    char now[32];
    utc_now(now);
    sl_db_arg args[] = {TEXT(name), TEXT(technique), TEXT(path_json), sl_db_int_arg(keys), sl_db_real_arg(duration),
                        TEXT(now)};
    return capped_upsert(db, "paths", SL_CATALOG_MAX_PATHS, "paths",
                         "INSERT INTO paths(name, technique, path, keys, duration, created)"
                         " VALUES($1, $2, $3, $4, $5, $6)"
                         " ON CONFLICT(name) DO UPDATE SET technique = excluded.technique, path = excluded.path,"
                         " keys = excluded.keys, duration = excluded.duration",
                         args, 6, err);
}

sl_status sl_catalog_load_path(sl_db *db, const char *name, cJSON **path, sl_err *err)
{
    *path = NULL;
    sl_db_result *r = NULL;
    sl_db_arg arg = TEXT(name);
    sl_status st = sl_db_query(db, "SELECT path FROM paths WHERE name = $1", &arg, 1, &r, err);
    if (st == SL_OK && sl_db_result_rows(r) > 0)
        *path = cell_json(r, 0, 0);
    sl_db_result_destroy(r);
    return st;
}

cJSON *sl_catalog_list_paths_json(sl_db *db)
{
    cJSON *arr = cJSON_CreateArray();
    sl_db_result *r = NULL;
    sl_err err = {0};
    if (sl_db_query(db, "SELECT name, technique, keys, duration, created FROM paths ORDER BY name", NULL, 0, &r,
                    &err) != SL_OK)
        fprintf(stderr, "sightline-server: %s\n", err.message);
    for (int i = 0; i < sl_db_result_rows(r); i++) {
        cJSON *o = cJSON_CreateObject();
        add_text(o, "name", r, i, 0, "");
        add_text(o, "technique", r, i, 1, "");
        cJSON_AddNumberToObject(o, "keys", (double)sl_db_int(r, i, 2, 0));
        cJSON_AddNumberToObject(o, "duration", sl_db_real(r, i, 3, 0));
        add_text(o, "created", r, i, 4, "");
        cJSON_AddItemToArray(arr, o);
    }
    sl_db_result_destroy(r);
    return arr;
}

sl_status sl_catalog_session_put(sl_db *db, const char *id, const char *node, const char *token_hash,
                                 const char *state_json, sl_err *err)
{
    char now[32];
    utc_now(now);
    sl_db_arg args[] = {TEXT(id), TEXT(node), TEXT(token_hash), TEXT(state_json), TEXT(now)};
    return sl_db_run(db,
                     "INSERT INTO sessions(id, node, token_hash, state, created, updated) VALUES($1, $2, $3, $4, $5, $5)"
                     " ON CONFLICT(id) DO UPDATE SET node = excluded.node, token_hash = excluded.token_hash,"
                     " state = excluded.state, updated = excluded.updated",
                     args, 5, NULL, err);
}

sl_status sl_catalog_session_get(sl_db *db, const char *id, char **state_json, char token_hash[65], char *node,
                                 size_t node_size, sl_err *err)
{
    *state_json = NULL;
    token_hash[0] = '\0';
    if (node_size)
        node[0] = '\0';
    sl_db_result *r = NULL;
    sl_db_arg arg = TEXT(id);
    sl_status st = sl_db_query(db, "SELECT state, token_hash, node FROM sessions WHERE id = $1", &arg, 1, &r, err);
    if (st == SL_OK && sl_db_result_rows(r) == 0)
        st = sl_err_set(err, SL_ERR_INVALID, "catalog: no checkpoint of session %s", id);
    if (st == SL_OK) {
        const char *state = sl_db_text(r, 0, 0), *hash = sl_db_text(r, 0, 1), *owner = sl_db_text(r, 0, 2);
        *state_json = strdup(state ? state : "");
        snprintf(token_hash, 65, "%s", hash ? hash : "");
        if (node_size)
            snprintf(node, node_size, "%s", owner ? owner : "");
        if (!*state_json)
            st = sl_err_set(err, SL_ERR_NOMEM, "catalog: out of memory reading the checkpoint of %s", id);
    }
    sl_db_result_destroy(r);
    return st;
}

sl_status sl_catalog_sessions_clear_node(sl_db *db, const char *node, sl_err *err)
{
    sl_db_arg arg = TEXT(node);
    return sl_db_run(db, "DELETE FROM sessions WHERE node = $1", &arg, 1, NULL, err);
}

sl_status sl_catalog_session_remove(sl_db *db, const char *id, sl_err *err)
{
    sl_db_arg arg = TEXT(id);
    return sl_db_run(db, "DELETE FROM sessions WHERE id = $1", &arg, 1, NULL, err);
}
