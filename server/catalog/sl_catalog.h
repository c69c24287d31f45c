/* sl_catalog.h — the catalog: datasets, saved views, named camera paths
 * and the session checkpoints of every node, in SQLite (one machine) or
 * PostgreSQL (many render nodes) through one data-access layer (sl_db.h).
 *
 * Every query uses bound parameters; every text the catalog returns as
 * JSON was checked before it was stored. Service thread and the `catalog`
 * CLI only (one sl_db per thread), never the render thread, except
 * sl_catalog_describe and sl_catalog_file_checksum, which touch no
 * database. The schema and its migrations: catalog_schema.c.
 */
#ifndef SL_CATALOG_H
#define SL_CATALOG_H

#include <stddef.h>

#include <cjson/cJSON.h>

#include "core/sl_status.h"
#include "sl_db.h"

typedef struct sl_dataset sl_dataset;

#define SL_CATALOG_MAX_VIEWS 256       /* saved views; save_view of a new name fails above */
#define SL_CATALOG_MAX_PATHS 256       /* saved paths; save_path of a new name fails above */
#define SL_CATALOG_MAX_PATH_BYTES 32768 /* JSON text of one saved path */
#define SL_CATALOG_CHECKSUM_SIZE 17     /* FNV-1a 64 of a file in lowercase hex, plus NUL */

/* catalog_schema.c */
/* The schema version this build writes. */
int sl_catalog_schema_latest(void);
/* The version the database holds (0: new); creates `meta` when absent. */
sl_status sl_catalog_schema_version(sl_db *db, int *version, sl_err *err);
/* Applies every migration after the stored version, in one transaction
 * under the schema lock; *from (may be NULL) gets the version found. */
sl_status sl_catalog_migrate(sl_db *db, int *from, sl_err *err);

/* catalog.c */
/* FNV-1a 64 of a file's bytes in lowercase hex, and its size. SL_ERR_IO. */
sl_status sl_catalog_file_checksum(const char *path, long long *size, char hex[SL_CATALOG_CHECKSUM_SIZE],
                                   sl_err *err);
/* Opens the database (sl_db_open: a file path or postgresql://…) and
 * migrates it to this build's schema (catalog_schema.c). SL_ERR_IO when it
 * cannot be reached, SL_ERR_INVALID when its schema is newer than this build. */
sl_status sl_catalog_open(const char *target, sl_db **out, sl_err *err);
void sl_catalog_close(sl_db *db);                   /* NULL is fine */
/* At every start: registers the built-in generator datasets and the files
 * in <dir>/samples that are absent, except names that were removed. */
sl_status sl_catalog_init_defaults(sl_db *db, const char *const *data_dirs, int dir_count, sl_err *err);
/* Registers every absent built-in, removed or not (`catalog add-builtins`). */
sl_status sl_catalog_add_builtins(sl_db *db, int *added, sl_err *err);
/* Adds a file; refused when outside every data_dir (after realpath). */
sl_status sl_catalog_add_file(sl_db *db, const char *path, const char *const *data_dirs, int dir_count,
                              sl_err *err);
sl_status sl_catalog_scan(sl_db *db, const char *dir, const char *const *data_dirs, int dir_count,
                          int *added, sl_err *err);
/* A file dataset changed on purpose: checks that it still loads and
 * stores its new size, checksum, bounds and counts. SL_ERR_INVALID for a
 * name that is not a file dataset. */
sl_status sl_catalog_refresh_file(sl_db *db, const char *name, const char *const *data_dirs, int dir_count,
                                  sl_err *err);
/* Deletes the row and records the name as removed (see init_defaults). */
sl_status sl_catalog_remove(sl_db *db, const char *name, sl_err *err);
/* Registers a named generator call (validated by generating it once). */
sl_status sl_catalog_add_generator(sl_db *db, const char *name, const char *generator_json, sl_err *err);
/* Bounds, counts and attribute names of a dataset as malloc'd JSON texts (no
 * database: callable from the render thread). */
void sl_catalog_describe(const sl_dataset *ds, char **bounds, char **counts, char **attrs);
/* Fills bounds/counts/attributes of a row that has none yet (built-ins). */
sl_status sl_catalog_set_info(sl_db *db, const char *name, const char *bounds, const char *counts,
                              const char *attrs, sl_err *err);
/* JSON array of {name, kind, source ("file"|"generator"), generator?, bounds,
 * counts, attributes, ...}; the absolute file `path` only with with_paths
 * (the CLI; clients never see server paths). */
cJSON *sl_catalog_list_json(sl_db *db, int with_paths);
/* Fills source (generator JSON or path), is_file, kind and (when not NULL)
 * checksum: the file's FNV-1a 64 in hex when it was registered, "" for a
 * generator. SL_ERR_INVALID when unknown. */
sl_status sl_catalog_lookup(sl_db *db, const char *name, char *source, size_t source_size, int *is_file,
                            int *kind, char checksum[SL_CATALOG_CHECKSUM_SIZE], sl_err *err);
/* Stores or replaces a named view; SL_ERR_LIMIT for a new name when
 * SL_CATALOG_MAX_VIEWS views exist. */
sl_status sl_catalog_save_view(sl_db *db, const char *name, const char *dataset, const char *technique,
                               const char *params_json, const char *camera_json, sl_err *err);
/* *view receives {name, dataset, technique, params, camera} or NULL when absent. */
sl_status sl_catalog_load_view(sl_db *db, const char *name, cJSON **view, sl_err *err);
cJSON *sl_catalog_list_views_json(sl_db *db);
/* Stores or replaces a named path (path_json already checked by the
 * caller, with its key count and last key time); SL_ERR_LIMIT when the
 * text is over SL_CATALOG_MAX_PATH_BYTES or, for a new name,
 * SL_CATALOG_MAX_PATHS paths exist. */
sl_status sl_catalog_save_path(sl_db *db, const char *name, const char *technique, const char *path_json,
                               int keys, double duration, sl_err *err);
/* *path receives the stored path object, or NULL when no path has that name. */
sl_status sl_catalog_load_path(sl_db *db, const char *name, cJSON **path, sl_err *err);
/* [{name, technique, keys, duration, created}] by name. */
cJSON *sl_catalog_list_paths_json(sl_db *db);
/* Session checkpoints (issue 16): one row per live session of any node. state_json is the
 * sl_msg_state_json text plus whatever the server needs to restore (see session.c);
 * token_hash is the lowercase hex SHA-256 of the join token (64 chars + NUL), never the token;
 * node is the owning node id. put is an upsert that also sets `updated`. */
sl_status sl_catalog_session_put(sl_db *db, const char *id, const char *node, const char *token_hash,
                                 const char *state_json, sl_err *err);
/* SL_OK and *state_json (malloc'd, caller frees) when found; SL_ERR_INVALID with a
 * "no checkpoint" message when not. token_hash gets 65 bytes; node gets node_size bytes. */
sl_status sl_catalog_session_get(sl_db *db, const char *id, char **state_json, char token_hash[65],
                                 char *node, size_t node_size, sl_err *err);
sl_status sl_catalog_session_remove(sl_db *db, const char *id, sl_err *err);
/* At a node's start: removes only the rows of that node (other nodes' sessions survive). */
sl_status sl_catalog_sessions_clear_node(sl_db *db, const char *node, sl_err *err);

#endif
