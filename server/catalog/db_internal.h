/* db_internal.h — what db.c shares with its two backends (db_sqlite.c,
 * db_pg.c): the connection record, the backend table and the result
 * builder. Not part of the server's contract (that is sl_db.h). Same
 * thread rule as sl_db.h.
 */
#ifndef SL_DB_INTERNAL_H
#define SL_DB_INTERNAL_H

#include "sl_db.h"

typedef struct {
    /* One statement; out (may be NULL: rows are dropped) gets the rows, changed the rows it changed. */
    sl_status (*exec)(sl_db *db, const char *sql, const sl_db_arg *args, int nargs, sl_db_result **out,
                      long long *changed, sl_err *err);
    sl_status (*script)(sl_db *db, const char *sql, sl_err *err);
    void (*close)(sl_db *db);
} sl_db_ops;

struct sl_db {
    sl_db_backend backend;
    const sl_db_ops *ops;
    void *handle;          /* sqlite3 * or PGconn * */
    int in_transaction;    /* between sl_db_begin and commit/rollback */
    char name[512];        /* the path, or the URI without its password */
};

struct sl_db_result {
    int rows, cols, capacity;  /* capacity: rows allocated */
    char **cells;              /* rows x cols, row-major; NULL is SQL NULL */
};

/* An empty result of cols columns; NULL when out of memory. */
sl_db_result *sl_db_result_create(int cols);
/* Appends a row of cols cells (NULL entries are SQL NULL; len < 0: strlen). SL_ERR_NOMEM. */
sl_status sl_db_result_append(sl_db_result *r, const char *const *cells, const int *lens, sl_err *err);

sl_status sl_db_sqlite_open(sl_db *db, const char *path, sl_err *err);
sl_status sl_db_pg_open(sl_db *db, const char *uri, sl_err *err);

#endif
