/* db.c — the backend-independent half of sl_db.h: choosing the backend
 * from the target, transactions, and results (text cells read whole).
 * A URI's password never reaches a message: sl_db_name keeps the URI with
 * the userinfo's password cut out. Same thread rule as sl_db.h.
 */
#include "db_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int is_postgres_uri(const char *target)
{
    return strncmp(target, "postgresql://", 13) == 0 || strncmp(target, "postgres://", 11) == 0;
}

/* The URI with ":password" of "user:password@" removed. */
static void redact_uri(const char *uri, char *out, size_t size)
{
    const char *scheme_end = strstr(uri, "://");
    const char *at = scheme_end ? strchr(scheme_end + 3, '@') : NULL;
    const char *slash = scheme_end ? strchr(scheme_end + 3, '/') : NULL;
    const char *colon = scheme_end ? strchr(scheme_end + 3, ':') : NULL;
    if (at && (!slash || at < slash) && colon && colon < at)
        snprintf(out, size, "%.*s%s", (int)(colon - uri), uri, at);
    else
        snprintf(out, size, "%s", uri);
}

sl_status sl_db_open(const char *target, sl_db **out, sl_err *err)
{
    *out = NULL;
    if (!target || !target[0])
        return sl_err_set(err, SL_ERR_INVALID, "catalog: no database given (a file path or postgresql://…)");
    sl_db *db = calloc(1, sizeof *db);
    if (!db)
        return sl_err_set(err, SL_ERR_NOMEM, "catalog: out of memory opening %s", target);
    sl_status st;
    if (is_postgres_uri(target)) {
        redact_uri(target, db->name, sizeof db->name);
        st = sl_db_pg_open(db, target, err);
    } else {
        snprintf(db->name, sizeof db->name, "%s", target);
        st = sl_db_sqlite_open(db, target, err);
    }
    if (st != SL_OK) {
        free(db);
        return st;
    }
    *out = db;
    return SL_OK;
}

void sl_db_close(sl_db *db)
{
    if (!db)
        return;
    if (db->ops)
        db->ops->close(db);
    free(db);
}

sl_db_backend sl_db_backend_of(const sl_db *db)
{
    return db->backend;
}

const char *sl_db_name(const sl_db *db)
{
    return db->name;
}

sl_status sl_db_run(sl_db *db, const char *sql, const sl_db_arg *args, int nargs, long long *changed, sl_err *err)
{
    long long n = 0;
    sl_status st = db->ops->exec(db, sql, args, nargs, NULL, &n, err);
    if (changed)
        *changed = st == SL_OK ? n : 0;
    return st;
}

sl_status sl_db_query(sl_db *db, const char *sql, const sl_db_arg *args, int nargs, sl_db_result **out,
                      sl_err *err)
{
    *out = NULL;
    long long n = 0;
    return db->ops->exec(db, sql, args, nargs, out, &n, err);
}

sl_status sl_db_script(sl_db *db, const char *sql, sl_err *err)
{
    return db->ops->script(db, sql, err);
}

sl_status sl_db_begin(sl_db *db, int schema_lock, sl_err *err)
{
    const char *begin = db->backend == SL_DB_SQLITE ? "BEGIN IMMEDIATE" : "BEGIN";
    sl_status st = sl_db_run(db, begin, NULL, 0, NULL, err);
    if (st != SL_OK)
        return st;
    db->in_transaction = 1;
    /* Any 64-bit key works; this one is "sightlin" in ASCII. */
    if (schema_lock && db->backend == SL_DB_POSTGRESQL &&
        (st = sl_db_run(db, "SELECT pg_advisory_xact_lock(7526752851063286126)", NULL, 0, NULL, err)) != SL_OK)
        sl_db_rollback(db);
    return st;
}

sl_status sl_db_commit(sl_db *db, sl_err *err)
{
    sl_status st = sl_db_run(db, "COMMIT", NULL, 0, NULL, err);
    if (st != SL_OK)
        sl_db_rollback(db);
    db->in_transaction = 0;
    return st;
}

void sl_db_rollback(sl_db *db)
{
    sl_err ignored = {0};
    if (db->in_transaction)
        sl_db_run(db, "ROLLBACK", NULL, 0, NULL, &ignored);
    db->in_transaction = 0;
}

sl_db_result *sl_db_result_create(int cols)
{
    sl_db_result *r = calloc(1, sizeof *r);
    if (r)
        r->cols = cols;
    return r;
}

sl_status sl_db_result_append(sl_db_result *r, const char *const *cells, const int *lens, sl_err *err)
{
    if (r->rows == r->capacity) {
        int cap = r->capacity ? 2 * r->capacity : 16;
        char **grown = realloc(r->cells, (size_t)cap * (size_t)(r->cols ? r->cols : 1) * sizeof *grown);
        if (!grown)
            return sl_err_set(err, SL_ERR_NOMEM, "catalog: out of memory reading %d rows", r->rows + 1);
        r->cells = grown;
        r->capacity = cap;
    }
    char **row = r->cells + (size_t)r->rows * (size_t)r->cols;
    for (int c = 0; c < r->cols; c++) {
        row[c] = NULL;
        if (!cells[c])
            continue;
        size_t len = lens && lens[c] >= 0 ? (size_t)lens[c] : strlen(cells[c]);
        row[c] = malloc(len + 1);
        if (!row[c]) {
            for (int k = 0; k < c; k++)
                free(row[k]);
            return sl_err_set(err, SL_ERR_NOMEM, "catalog: out of memory reading a row");
        }
        memcpy(row[c], cells[c], len);
        row[c][len] = '\0';
    }
    r->rows++;
    return SL_OK;
}

int sl_db_result_rows(const sl_db_result *r)
{
    return r ? r->rows : 0;
}

int sl_db_result_columns(const sl_db_result *r)
{
    return r ? r->cols : 0;
}

const char *sl_db_text(const sl_db_result *r, int row, int col)
{
    if (!r || row < 0 || row >= r->rows || col < 0 || col >= r->cols)
        return NULL;
    return r->cells[(size_t)row * (size_t)r->cols + (size_t)col];
}

long long sl_db_int(const sl_db_result *r, int row, int col, long long fallback)
{
    const char *t = sl_db_text(r, row, col);
    if (!t || !t[0])
        return fallback;
    char *end = NULL;
    errno = 0;
    long long v = strtoll(t, &end, 10);
    return errno == 0 && *end == '\0' ? v : fallback;
}

double sl_db_real(const sl_db_result *r, int row, int col, double fallback)
{
    const char *t = sl_db_text(r, row, col);
    if (!t || !t[0])
        return fallback;
    char *end = NULL;
    double v = strtod(t, &end);
    return *end == '\0' ? v : fallback;
}

void sl_db_result_destroy(sl_db_result *r)
{
    if (!r)
        return;
    for (size_t i = 0; i < (size_t)r->rows * (size_t)r->cols; i++)
        free(r->cells[i]);
    free(r->cells);
    free(r);
}
