/* db_pg.c — the PostgreSQL backend of sl_db.h (libpq): one connection per
 * sl_db, parameters sent as text with their types left to the server (it
 * infers them from the columns they meet), results read as text.
 * Defaults a URI may override: connect_timeout 5 s, statement_timeout
 * 10 s and lock_timeout 5 s (a stuck database costs a node one bounded
 * wait, never its service thread for good), application_name
 * "sightline". NOTICEs (e.g. "already exists, skipping") are not printed.
 * A statement that fails because the connection broke is retried once
 * after PQreset, unless a transaction is open (its work is lost with the
 * connection, so the caller must see the failure). A connection left in a
 * failed transaction that sl_db does not know of is rolled back before the
 * next statement, so one missed rollback cannot block every later one. Same
 * thread rule as sl_db.h.
 */
#include "db_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libpq-fe.h>

static void quiet_notices(void *arg, const char *message)
{
    (void)arg;
    (void)message;
}

/* libpq's message without its trailing newline. */
static sl_status fail_text(sl_db *db, sl_err *err, const char *what, const char *message)
{
    size_t len = message ? strlen(message) : 0;
    while (len && (message[len - 1] == '\n' || message[len - 1] == ' '))
        len--;
    return sl_err_set(err, SL_ERR_IO, "catalog %s: %s: %.*s", db->name, what, (int)len, message ? message : "");
}

static PGresult *exec_once(PGconn *conn, const char *sql, const char *const *values, int nargs)
{
    return PQexecParams(conn, sql, nargs, NULL, values, NULL, NULL, 0);
}

static int succeeded(const PGresult *res)
{
    ExecStatusType s = PQresultStatus(res);
    return s == PGRES_COMMAND_OK || s == PGRES_TUPLES_OK;
}

static sl_status pg_exec(sl_db *db, const char *sql, const sl_db_arg *args, int nargs, sl_db_result **out,
                         long long *changed, sl_err *err)
{
    enum { MAX_ARGS = 16 };
    if (nargs > MAX_ARGS)
        return sl_err_set(err, SL_ERR_LIMIT, "catalog: a statement of %d arguments (at most %d)", nargs, MAX_ARGS);
    char numbers[MAX_ARGS][32];
    const char *values[MAX_ARGS];
    for (int i = 0; i < nargs; i++) {
        values[i] = NULL;
        if (args[i].type == SL_DB_ARG_TEXT) {
            values[i] = args[i].text;
        } else if (args[i].type == SL_DB_ARG_INT) {
            snprintf(numbers[i], sizeof numbers[i], "%lld", args[i].i);
            values[i] = numbers[i];
        } else if (args[i].type == SL_DB_ARG_REAL) {
            snprintf(numbers[i], sizeof numbers[i], "%.17g", args[i].d);
            values[i] = numbers[i];
        }
    }
    PGconn *conn = db->handle;
    if (!db->in_transaction && PQtransactionStatus(conn) == PQTRANS_INERROR)
        PQclear(PQexec(conn, "ROLLBACK"));
    PGresult *res = exec_once(conn, sql, values, nargs);
    if (!succeeded(res) && PQstatus(conn) == CONNECTION_BAD && !db->in_transaction) {
        PQclear(res);
        PQreset(conn);
        res = PQstatus(conn) == CONNECTION_OK ? exec_once(conn, sql, values, nargs) : NULL;
    }
    if (!succeeded(res)) {
        sl_status st = fail_text(db, err, "statement failed", res ? PQresultErrorMessage(res) : PQerrorMessage(conn));
        PQclear(res);
        return st;
    }
    const char *tuples = PQcmdTuples(res);
    *changed = tuples && tuples[0] ? strtoll(tuples, NULL, 10) : 0;
    sl_status st = SL_OK;
    if (out) {
        int cols = PQnfields(res), rows = PQntuples(res);
        enum { MAX_COLUMNS = 32 };
        sl_db_result *r = cols <= MAX_COLUMNS ? sl_db_result_create(cols) : NULL;
        if (!r)
            st = sl_err_set(err, SL_ERR_NOMEM, "catalog: cannot hold a result of %d columns", cols);
        for (int row = 0; st == SL_OK && row < rows; row++) {
            const char *cells[MAX_COLUMNS];
            int lens[MAX_COLUMNS];
            for (int c = 0; c < cols; c++) {
                cells[c] = PQgetisnull(res, row, c) ? NULL : PQgetvalue(res, row, c);
                lens[c] = PQgetlength(res, row, c);
            }
            st = sl_db_result_append(r, cells, lens, err);
        }
        if (st == SL_OK)
            *out = r;
        else
            sl_db_result_destroy(r);
    }
    PQclear(res);
    return st;
}

static sl_status pg_script(sl_db *db, const char *sql, sl_err *err)
{
    PGresult *res = PQexec(db->handle, sql);
    sl_status st = succeeded(res) ? SL_OK
                                  : fail_text(db, err, "script failed",
                                              res ? PQresultErrorMessage(res) : PQerrorMessage(db->handle));
    PQclear(res);
    return st;
}

static void pg_close(sl_db *db)
{
    PQfinish(db->handle);
    db->handle = NULL;
}

static const sl_db_ops pg_ops = {pg_exec, pg_script, pg_close};

sl_status sl_db_pg_open(sl_db *db, const char *uri, sl_err *err)
{
    /* Key words before dbname are defaults the URI may override (libpq
     * keeps the last value it processes). */
    const char *const keys[] = {"connect_timeout", "options", "application_name", "dbname", NULL};
    const char *const values[] = {"5", "-c statement_timeout=10000 -c lock_timeout=5000", "sightline", uri, NULL};
    PGconn *conn = PQconnectdbParams(keys, values, 1);
    if (!conn)
        return sl_err_set(err, SL_ERR_NOMEM, "catalog: out of memory connecting to %s", db->name);
    if (PQstatus(conn) != CONNECTION_OK) {
        sl_status st = fail_text(db, err, "cannot connect", PQerrorMessage(conn));
        PQfinish(conn);
        return st;
    }
    PQsetNoticeProcessor(conn, quiet_notices, NULL);
    db->backend = SL_DB_POSTGRESQL;
    db->ops = &pg_ops;
    db->handle = conn;
    return SL_OK;
}
