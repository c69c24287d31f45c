/* sl_db.h — the catalog's data-access layer: one API over SQLite (the
 * embedded default, one machine) and PostgreSQL through libpq (one catalog
 * shared by many render nodes).
 *
 * SQL is written once, in the subset both accept: placeholders $1..$n,
 * upserts with ON CONFLICT, CASE instead of boolean arithmetic, no
 * dialect functions (time stamps come from the caller). Arguments are
 * always bound, never pasted into the text. A result is read whole into
 * memory as text cells (SQL NULL stays NULL), so the connection is free
 * again when a call returns. Not here: schema and migrations
 * (catalog_schema.c), connection pools, asynchronous queries — every call
 * blocks its thread for one round trip (a loopback or LAN database).
 * Threads: one sl_db belongs to one thread at a time (the server's service
 * thread, or the `catalog` CLI). A PostgreSQL connection that broke is
 * reset once and the statement retried, outside a transaction only.
 */
#ifndef SL_DB_H
#define SL_DB_H

#include "core/sl_status.h"

typedef struct sl_db sl_db;
typedef struct sl_db_result sl_db_result;

typedef enum { SL_DB_SQLITE = 1, SL_DB_POSTGRESQL = 2 } sl_db_backend;

typedef enum { SL_DB_ARG_NULL = 0, SL_DB_ARG_TEXT, SL_DB_ARG_INT, SL_DB_ARG_REAL } sl_db_arg_type;

/* One bound argument; zero is SQL NULL. The text is borrowed for the call. */
typedef struct {
    sl_db_arg_type type;
    const char *text;
    long long i;
    double d;
} sl_db_arg;

/* A text argument, NULL for SQL NULL. */
static inline sl_db_arg sl_db_text_arg(const char *s)
{
    return (sl_db_arg){.type = s ? SL_DB_ARG_TEXT : SL_DB_ARG_NULL, .text = s};
}
static inline sl_db_arg sl_db_int_arg(long long v) { return (sl_db_arg){.type = SL_DB_ARG_INT, .i = v}; }
static inline sl_db_arg sl_db_real_arg(double v) { return (sl_db_arg){.type = SL_DB_ARG_REAL, .d = v}; }

/* target: "postgresql://…" or "postgres://…" (a libpq URI; connect_timeout
 * 5 s unless it names one) opens PostgreSQL, anything else is an SQLite
 * file path (created when absent, WAL mode, 2 s busy timeout).
 * SL_ERR_IO naming the target (without its password) on failure; *out is
 * NULL then. */
sl_status sl_db_open(const char *target, sl_db **out, sl_err *err);
void sl_db_close(sl_db *db);                                   /* NULL is fine */
sl_db_backend sl_db_backend_of(const sl_db *db);
/* The target for messages: the path, or the URI without its password. */
const char *sl_db_name(const sl_db *db);

/* Runs one statement; *changed (may be NULL) gets the rows it inserted,
 * updated or deleted. SL_ERR_IO with the database's message. */
sl_status sl_db_run(sl_db *db, const char *sql, const sl_db_arg *args, int nargs, long long *changed, sl_err *err);
/* Runs one statement and reads its rows; *out is owned by the caller
 * (sl_db_result_destroy), NULL on failure. */
sl_status sl_db_query(sl_db *db, const char *sql, const sl_db_arg *args, int nargs, sl_db_result **out,
                      sl_err *err);
/* Runs statements separated by ';' with no arguments (schema scripts). */
sl_status sl_db_script(sl_db *db, const char *sql, sl_err *err);

/* Transactions. begin: SQLite BEGIN IMMEDIATE (takes the write lock at
 * once, so two writers never deadlock on an upgrade); PostgreSQL BEGIN,
 * and with schema_lock a transaction-scoped advisory lock that serializes
 * schema migrations of nodes starting together. rollback never fails
 * loudly (it is the cleanup path). */
sl_status sl_db_begin(sl_db *db, int schema_lock, sl_err *err);
sl_status sl_db_commit(sl_db *db, sl_err *err);
void sl_db_rollback(sl_db *db);

int sl_db_result_rows(const sl_db_result *r);
int sl_db_result_columns(const sl_db_result *r);
/* The cell's text, NULL for SQL NULL or out of range. Owned by r. */
const char *sl_db_text(const sl_db_result *r, int row, int col);
/* The cell as a number; fallback for NULL, out of range or not a number. */
long long sl_db_int(const sl_db_result *r, int row, int col, long long fallback);
double sl_db_real(const sl_db_result *r, int row, int col, double fallback);
void sl_db_result_destroy(sl_db_result *r);                    /* NULL is fine */

#endif
