/* db_sqlite.c — the SQLite backend of sl_db.h: one database file in WAL
 * mode (readers never block the writer; several processes on one host may
 * share the file), a 2 s busy timeout for a writer that finds the lock
 * taken. Switching a new file to WAL is retried for as long: SQLite
 * answers SQLITE_BUSY at once, without its busy handler, when nodes
 * starting together switch the same new file (1 of 9 four-node starts
 * failed so before). Placeholders $1..$n are bound by name, so a statement may use
 * them in any order and more than once; a statement naming a parameter the
 * caller did not give is refused (a programmer error caught by the tests,
 * never SQL NULL by accident). REAL cells are printed with 17 digits so a
 * double survives the text round trip. Same thread rule as sl_db.h.
 */
#include "db_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <time.h>

#include <sqlite3.h>

enum { BUSY_TIMEOUT_MS = 2000 };

static sl_status fail(sl_db *db, sl_err *err, const char *what)
{
    return sl_err_set(err, SL_ERR_IO, "catalog %s: %s: %s", db->name, what,
                      sqlite3_errmsg((sqlite3 *)db->handle));
}

static sl_status bind_args(sl_db *db, sqlite3_stmt *q, const sl_db_arg *args, int nargs, sl_err *err)
{
    int count = sqlite3_bind_parameter_count(q);
    for (int i = 1; i <= count; i++) {
        const char *name = sqlite3_bind_parameter_name(q, i);
        char *end = NULL;
        long k = name && name[0] == '$' ? strtol(name + 1, &end, 10) : 0;
        if (k < 1 || k > nargs || !end || *end)
            return sl_err_set(err, SL_ERR_INVALID, "catalog %s: statement parameter %s has no argument (%d given)",
                              db->name, name ? name : "?", nargs);
        const sl_db_arg *a = &args[k - 1];
        int rc = SQLITE_OK;
        switch (a->type) {
        case SL_DB_ARG_TEXT: rc = sqlite3_bind_text(q, i, a->text, -1, SQLITE_TRANSIENT); break;
        case SL_DB_ARG_INT: rc = sqlite3_bind_int64(q, i, a->i); break;
        case SL_DB_ARG_REAL: rc = sqlite3_bind_double(q, i, a->d); break;
        case SL_DB_ARG_NULL: rc = sqlite3_bind_null(q, i); break;
        }
        if (rc != SQLITE_OK)
            return fail(db, err, "bind");
    }
    return SL_OK;
}

static sl_status read_row(sqlite3_stmt *q, sl_db_result *r, sl_err *err)
{
    enum { MAX_COLUMNS = 32 };
    const char *cells[MAX_COLUMNS];
    int lens[MAX_COLUMNS];
    char reals[MAX_COLUMNS][32];
    if (r->cols > MAX_COLUMNS)
        return sl_err_set(err, SL_ERR_LIMIT, "catalog: a query of %d columns (at most %d)", r->cols, MAX_COLUMNS);
    for (int c = 0; c < r->cols; c++) {
        lens[c] = -1;
        switch (sqlite3_column_type(q, c)) {
        case SQLITE_NULL: cells[c] = NULL; break;
        case SQLITE_FLOAT:
            snprintf(reals[c], sizeof reals[c], "%.17g", sqlite3_column_double(q, c));
            cells[c] = reals[c];
            break;
        default:
            cells[c] = (const char *)sqlite3_column_text(q, c);
            lens[c] = sqlite3_column_bytes(q, c);
            if (!cells[c])
                return sl_err_set(err, SL_ERR_NOMEM, "catalog: out of memory reading a cell");
        }
    }
    return sl_db_result_append(r, cells, lens, err);
}

static sl_status sqlite_exec(sl_db *db, const char *sql, const sl_db_arg *args, int nargs, sl_db_result **out,
                             long long *changed, sl_err *err)
{
    sqlite3 *h = db->handle;
    sqlite3_stmt *q = NULL;
    if (sqlite3_prepare_v2(h, sql, -1, &q, NULL) != SQLITE_OK)
        return fail(db, err, "prepare");
    sl_status st = bind_args(db, q, args, nargs, err);
    sl_db_result *r = NULL;
    if (st == SL_OK && out && !(r = sl_db_result_create(sqlite3_column_count(q))))
        st = sl_err_set(err, SL_ERR_NOMEM, "catalog: out of memory");
    int rc = SQLITE_DONE;
    while (st == SL_OK && (rc = sqlite3_step(q)) == SQLITE_ROW)
        if (r)
            st = read_row(q, r, err);
    if (st == SL_OK && rc != SQLITE_DONE)
        st = fail(db, err, "step");
    sqlite3_finalize(q);
    if (st != SL_OK) {
        sl_db_result_destroy(r);
        return st;
    }
    *changed = sqlite3_changes64(h);
    if (out)
        *out = r;
    return SL_OK;
}

static sl_status sqlite_script(sl_db *db, const char *sql, sl_err *err)
{
    char *msg = NULL;
    if (sqlite3_exec(db->handle, sql, NULL, NULL, &msg) == SQLITE_OK)
        return SL_OK;
    sl_status st = sl_err_set(err, SL_ERR_IO, "catalog %s: %s", db->name, msg ? msg : "script failed");
    sqlite3_free(msg);
    return st;
}

/* PRAGMA journal_mode=WAL, retried while another connection holds the lock
 * the switch needs (the busy handler does not run for it). */
static sl_status sqlite_enter_wal(sl_db *db, sl_err *err)
{
    enum { RETRY_US = 5000, TRIES = BUSY_TIMEOUT_MS * 1000 / RETRY_US };
    for (int attempt = 1;; attempt++) {
        int rc = sqlite3_exec(db->handle, "PRAGMA journal_mode=WAL", NULL, NULL, NULL);
        if (rc == SQLITE_OK)
            return SL_OK;
        if ((rc & 0xff) != SQLITE_BUSY || attempt >= TRIES)
            return fail(db, err, "journal_mode=WAL");
        struct timespec pause = {0, RETRY_US * 1000L};
        nanosleep(&pause, NULL);
    }
}

static void sqlite_close(sl_db *db)
{
    sqlite3_close(db->handle);
    db->handle = NULL;
}

static const sl_db_ops sqlite_ops = {sqlite_exec, sqlite_script, sqlite_close};

sl_status sl_db_sqlite_open(sl_db *db, const char *path, sl_err *err)
{
    sqlite3 *h = NULL;
    if (sqlite3_open_v2(path, &h, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, NULL) !=
        SQLITE_OK) {
        sl_status st = sl_err_set(err, SL_ERR_IO, "catalog: cannot open %s: %s", path,
                                  h ? sqlite3_errmsg(h) : "out of memory");
        sqlite3_close(h);
        return st;
    }
    sqlite3_busy_timeout(h, BUSY_TIMEOUT_MS);
    db->backend = SL_DB_SQLITE;
    db->ops = &sqlite_ops;
    db->handle = h;
    sl_status st = sqlite_enter_wal(db, err);
    if (st != SL_OK) {
        sqlite_close(db);
        db->ops = NULL;
    }
    return st;
}
