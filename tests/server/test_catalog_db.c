/* test_catalog_db.c — the catalog (sl_catalog.h over sl_db.h) against a real
 * database: `test_catalog_db sqlite` on a temporary file, `test_catalog_db
 * postgresql` on a PostgreSQL server it starts itself (scripts/pg-temp: initdb
 * in a temporary directory, loopback port, stopped at the end), or on
 * $SIGHTLINE_TEST_PG_URL when set. The same checks run on both; the few that
 * only one backend has (an old SQLite file's migration; an unreachable
 * server, a password kept out of messages, a killed connection) are marked.
 * Covers: migrations (new database, re-open, four processes migrating one new
 * database at once, a newer schema refused), datasets (built-ins, generators,
 * files with size and checksum, confinement, removal that sticks, refresh),
 * views and paths (round trips, caps, replacement), session checkpoints, SQL
 * text in every argument, and two connections seeing each other's writes
 * (what render nodes sharing one catalog rely on).
 */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/sl_clock.h"
#include "data/sl_dataset.h"
#include "data/sl_generate.h"
#include "catalog/sl_catalog.h"
#include "sl_test.h"

static char tmp_dir[64];      /* data directory and SQLite files */
static char pg_dir[64];       /* the pg-temp server's directory, "" when not started here */
static char pg_url[512];      /* base URL of the server (database `sightline`) */
static int use_pg;
static pid_t test_pid;
static int fresh_count;

/* A database nobody has used: a new SQLite file, or a new PostgreSQL database. */
static void fresh_target(char *out, size_t size)
{
    fresh_count++;
    if (!use_pg) {
        snprintf(out, size, "%s/catalog%d.db", tmp_dir, fresh_count);
        return;
    }
    char name[32];
    snprintf(name, sizeof name, "fresh%d_%d", (int)getpid(), fresh_count);
    sl_db *admin = NULL;
    sl_err err = {0};
    char sql[96];
    snprintf(sql, sizeof sql, "CREATE DATABASE %s", name); /* a name made here, not input */
    SL_CHECK_MSG(sl_db_open(pg_url, &admin, &err) == SL_OK && sl_db_script(admin, sql, &err) == SL_OK, "%s",
                 err.message);
    sl_db_close(admin);
    const char *slash = strrchr(pg_url, '/');
    snprintf(out, size, "%.*s/%s", (int)(slash - pg_url), pg_url, name);
}

static int start_postgres(void)
{
    const char *given = getenv("SIGHTLINE_TEST_PG_URL");
    if (given && given[0]) {
        snprintf(pg_url, sizeof pg_url, "%s", given);
        return 1;
    }
    snprintf(pg_dir, sizeof pg_dir, "/tmp/sl-pg-XXXXXX");
    if (!mkdtemp(pg_dir))
        return 0;
    char cmd[256];
    snprintf(cmd, sizeof cmd, "scripts/pg-temp start %s", pg_dir);
    FILE *p = popen(cmd, "r");
    if (!p)
        return 0;
    int ok = fgets(pg_url, sizeof pg_url, p) != NULL;
    ok = pclose(p) == 0 && ok;
    pg_url[strcspn(pg_url, "\n")] = '\0';
    return ok && strncmp(pg_url, "postgresql://", 13) == 0;
}

/* At exit, and on SIGTERM / SIGINT / SIGALRM, so a failing or stopped
 * test does not leave its server running. Not in the forked children
 * (they leave with _exit). */
static void stop_postgres(void)
{
    if (!pg_dir[0] || getpid() != test_pid)
        return;
    char cmd[256];
    snprintf(cmd, sizeof cmd, "scripts/pg-temp stop %s", pg_dir);
    pg_dir[0] = '\0';
    if (system(cmd) != 0)
        fprintf(stderr, "could not stop the test's PostgreSQL\n");
}

static void stop_on_signal(int sig)
{
    stop_postgres();
    _exit(128 + sig);
}

static sl_db *open_catalog(const char *target)
{
    sl_db *db = NULL;
    sl_err err = {0};
    sl_status st = sl_catalog_open(target, &db, &err);
    SL_CHECK_MSG(st == SL_OK, "open %s: %s", target, err.message);
    return db;
}

static int schema_version(sl_db *db)
{
    int v = -1;
    sl_err err = {0};
    SL_CHECK_MSG(sl_catalog_schema_version(db, &v, &err) == SL_OK, "%s", err.message);
    return v;
}

/* The named entry of a JSON list, or NULL. */
static const cJSON *find_named(const cJSON *list, const char *name)
{
    const cJSON *e;
    cJSON_ArrayForEach(e, list) {
        const cJSON *n = cJSON_GetObjectItemCaseSensitive(e, "name");
        if (cJSON_IsString(n) && strcmp(n->valuestring, name) == 0)
            return e;
    }
    return NULL;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    SL_CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* Four nodes starting together on one new database: one migrates, all
 * open, all register the built-ins (each row once; none fails on a name
 * another node inserted between its check and its insert). Repeated,
 * because the race is rare: SQLite's switch of a new file to WAL answered
 * "database is locked" in about 1 of 9 starts before it was retried. */
static void check_nodes_starting_together(int rounds)
{
    for (int round = 0; round < rounds; round++) {
        char target[600];
        fresh_target(target, sizeof target);
        pid_t kids[4];
        for (int i = 0; i < 4; i++) {
            kids[i] = fork();
            if (kids[i] == 0) {
                sl_db *k = NULL;
                sl_err kerr = {0};
                sl_status st = sl_catalog_open(target, &k, &kerr);
                if (st == SL_OK)
                    st = sl_catalog_init_defaults(k, NULL, 0, &kerr);
                if (st != SL_OK)
                    fprintf(stderr, "node %d: %s\n", i, kerr.message);
                sl_catalog_close(k);
                _exit(st == SL_OK ? 0 : 1);
            }
        }
        int all_ok = 1;
        for (int i = 0; i < 4; i++) {
            int status = 0;
            all_ok &= kids[i] > 0 && waitpid(kids[i], &status, 0) == kids[i] && WIFEXITED(status) &&
                      WEXITSTATUS(status) == 0;
        }
        SL_CHECK(all_ok);
        sl_db *db = open_catalog(target);
        SL_CHECK(db && schema_version(db) == sl_catalog_schema_latest());
        int builtins = 0;
        sl_builtin_datasets(&builtins);
        cJSON *list = db ? sl_catalog_list_json(db, 0) : NULL;
        SL_CHECK(cJSON_GetArraySize(list) == builtins);
        cJSON_Delete(list);
        sl_catalog_close(db);
    }
}

static void check_migrations(void)
{
    char target[600];
    fresh_target(target, sizeof target);
    sl_db *db = NULL;
    sl_err err = {0};
    int from = -1;
    SL_CHECK_MSG(sl_db_open(target, &db, &err) == SL_OK, "%s", err.message);
    SL_CHECK(db && sl_db_backend_of(db) == (use_pg ? SL_DB_POSTGRESQL : SL_DB_SQLITE));
    SL_CHECK_MSG(db && sl_catalog_migrate(db, &from, &err) == SL_OK, "%s", err.message);
    SL_CHECK(from == 0);
    SL_CHECK(db && schema_version(db) == sl_catalog_schema_latest());
    from = -1;
    SL_CHECK_MSG(db && sl_catalog_migrate(db, &from, &err) == SL_OK, "%s", err.message);
    SL_CHECK(from == sl_catalog_schema_latest()); /* nothing to do the second time */

    /* A database a newer build migrated is refused, not written. */
    char newer[16];
    snprintf(newer, sizeof newer, "%d", sl_catalog_schema_latest() + 1);
    sl_db_arg arg = sl_db_text_arg(newer);
    SL_CHECK(db && sl_db_run(db, "UPDATE meta SET value = $1 WHERE key = 'schema_version'", &arg, 1, NULL, &err) ==
                       SL_OK);
    sl_db_close(db);
    db = NULL;
    SL_CHECK(sl_catalog_open(target, &db, &err) == SL_ERR_INVALID && db == NULL);
    SL_CHECK_MSG(strstr(err.message, "newer") != NULL, "%s", err.message);
}

static void check_datasets(sl_db *db, const char *data_dir)
{
    sl_err err = {0};
    const char *dirs[] = {data_dir};
    SL_CHECK_MSG(sl_catalog_init_defaults(db, dirs, 1, &err) == SL_OK, "%s", err.message);
    int builtins = 0;
    sl_builtin_datasets(&builtins);
    cJSON *list = sl_catalog_list_json(db, 1);
    SL_CHECK(cJSON_GetArraySize(list) == builtins);
    const cJSON *first = cJSON_GetArrayItem(list, 0);
    SL_CHECK(first && strcmp(cJSON_GetObjectItemCaseSensitive(first, "name")->valuestring,
                             sl_builtin_datasets(&builtins)[0].name) == 0); /* registration order */
    cJSON_Delete(list);

    char source[4096], sum[SL_CATALOG_CHECKSUM_SIZE] = "x";
    int is_file = -1, kind = 0;
    SL_CHECK(sl_catalog_lookup(db, "tornado", source, sizeof source, &is_file, &kind, sum, &err) == SL_OK);
    SL_CHECK(is_file == 0 && kind == SL_DATASET_LINES && sum[0] == '\0' && strstr(source, "\"tornado\""));
    SL_CHECK(sl_catalog_lookup(db, "nope", source, sizeof source, &is_file, &kind, NULL, &err) == SL_ERR_INVALID);

    /* Generators: validated, unique names, SQL text kept as text. */
    const char *hostile = "x'); DROP TABLE datasets; --";
    SL_CHECK_MSG(sl_catalog_add_generator(db, hostile, "{\"generator\":\"abc\",\"lines\":3,\"seed\":1}", &err) ==
                     SL_OK, "%s", err.message);
    SL_CHECK(sl_catalog_add_generator(db, hostile, "{\"generator\":\"abc\",\"lines\":3}", &err) == SL_ERR_INVALID);
    SL_CHECK(sl_catalog_add_generator(db, "bad", "{\"generator\":\"no_such\"}", &err) != SL_OK);
    SL_CHECK(sl_catalog_lookup(db, hostile, source, sizeof source, &is_file, &kind, NULL, &err) == SL_OK);
    list = sl_catalog_list_json(db, 0);
    const cJSON *h = find_named(list, hostile);
    SL_CHECK(cJSON_GetArraySize(list) == builtins + 1 && h);
    SL_CHECK(h && cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(h, "bounds")) &&
             cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(h, "counts"),
                                                                    "lines")) == 3);
    cJSON_Delete(list);

    /* Files: confined to the data directories, size and checksum recorded. */
    char path[600], outside[600];
    snprintf(path, sizeof path, "%s/two.obj", data_dir);
    write_text(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\n");
    snprintf(outside, sizeof outside, "%s/outside.obj", tmp_dir);
    write_text(outside, "v 0 0 0\nv 1 0 0\nl 1 2\n");
    SL_CHECK(sl_catalog_add_file(db, outside, dirs, 1, &err) == SL_ERR_INVALID);
    char sneaky[700];
    snprintf(sneaky, sizeof sneaky, "%s/../outside.obj", data_dir);
    SL_CHECK(sl_catalog_add_file(db, sneaky, dirs, 1, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(sl_catalog_add_file(db, path, dirs, 1, &err) == SL_OK, "%s", err.message);
    SL_CHECK(sl_catalog_add_file(db, path, dirs, 1, &err) == SL_ERR_INVALID); /* the name exists */
    char want[SL_CATALOG_CHECKSUM_SIZE];
    long long size = 0;
    SL_CHECK(sl_catalog_file_checksum(path, &size, want, &err) == SL_OK && size == 32);
    SL_CHECK(sl_catalog_lookup(db, "two.obj", source, sizeof source, &is_file, &kind, sum, &err) == SL_OK);
    SL_CHECK(is_file == 1 && kind == SL_DATASET_LINES && strcmp(sum, want) == 0 && strstr(source, "/two.obj"));
    list = sl_catalog_list_json(db, 0);
    const cJSON *two = find_named(list, "two.obj");
    SL_CHECK(two && !cJSON_GetObjectItemCaseSensitive(two, "path")); /* clients never see server paths */
    SL_CHECK(two && cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(two, "file_size")) == 32);
    cJSON_Delete(list);

    /* A deliberate change: refresh records the new checksum. */
    write_text(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 2 2 2\nl 1 2 3 4\n");
    char changed[SL_CATALOG_CHECKSUM_SIZE];
    SL_CHECK(sl_catalog_file_checksum(path, &size, changed, &err) == SL_OK && strcmp(changed, want) != 0);
    SL_CHECK_MSG(sl_catalog_refresh_file(db, "two.obj", dirs, 1, &err) == SL_OK, "%s", err.message);
    SL_CHECK(sl_catalog_lookup(db, "two.obj", source, sizeof source, &is_file, &kind, sum, &err) == SL_OK);
    SL_CHECK(strcmp(sum, changed) == 0);
    SL_CHECK(sl_catalog_refresh_file(db, "tornado", dirs, 1, &err) == SL_ERR_INVALID);

    /* Descriptions fill a built-in's empty row once. */
    SL_CHECK(sl_catalog_set_info(db, "tornado", "[[0,0,0],[1,1,1]]", "{\"lines\":7}", "[]", &err) == SL_OK);
    SL_CHECK(sl_catalog_set_info(db, "tornado", "[[0,0,0],[2,2,2]]", "{\"lines\":9}", "[]", &err) == SL_OK);
    list = sl_catalog_list_json(db, 0);
    const cJSON *t = find_named(list, "tornado");
    SL_CHECK(t && cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(t, "counts"),
                                                                       "lines")) == 7);
    cJSON_Delete(list);

    /* Removal sticks across starts until an explicit add. */
    SL_CHECK(sl_catalog_remove(db, "tornado", &err) == SL_OK);
    SL_CHECK(sl_catalog_remove(db, "tornado", &err) == SL_ERR_INVALID);
    SL_CHECK(sl_catalog_init_defaults(db, dirs, 1, &err) == SL_OK);
    SL_CHECK(sl_catalog_lookup(db, "tornado", source, sizeof source, &is_file, &kind, NULL, &err) == SL_ERR_INVALID);
    int added = 0;
    SL_CHECK(sl_catalog_add_builtins(db, &added, &err) == SL_OK && added == 1);
    SL_CHECK(sl_catalog_lookup(db, "tornado", source, sizeof source, &is_file, &kind, NULL, &err) == SL_OK);
}

static void check_views_and_paths(sl_db *db)
{
    sl_err err = {0};
    const char *params = "{\"radius\":0.01,\"note\":\"it's \\\"quoted\\\"\"}";
    SL_CHECK_MSG(sl_catalog_save_view(db, "front", "tornado", "tubes", params, "{\"orbit\":{\"azimuth\":30}}", &err) ==
                     SL_OK, "%s", err.message);
    cJSON *v = NULL;
    SL_CHECK(sl_catalog_load_view(db, "front", &v, &err) == SL_OK && v);
    cJSON *want = cJSON_Parse(params);
    SL_CHECK(v && cJSON_Compare(cJSON_GetObjectItemCaseSensitive(v, "params"), want, 1));
    cJSON_Delete(want);
    cJSON_Delete(v);
    v = NULL;
    SL_CHECK(sl_catalog_load_view(db, "absent", &v, &err) == SL_OK && v == NULL);

    /* The cap: new names up to SL_CATALOG_MAX_VIEWS, a replacement always. */
    int ok = 1;
    for (int i = 1; i < SL_CATALOG_MAX_VIEWS; i++) {
        char name[32];
        snprintf(name, sizeof name, "view%03d", i);
        ok &= sl_catalog_save_view(db, name, "tornado", "tubes", "{}", "{}", &err) == SL_OK;
    }
    SL_CHECK_MSG(ok, "%s", err.message);
    SL_CHECK(sl_catalog_save_view(db, "one too many", "tornado", "tubes", "{}", "{}", &err) == SL_ERR_LIMIT);
    SL_CHECK(sl_catalog_save_view(db, "front", "abc", "tubes", "{}", "{\"a\":1}", &err) == SL_OK);
    cJSON *views = sl_catalog_list_views_json(db);
    SL_CHECK(cJSON_GetArraySize(views) == SL_CATALOG_MAX_VIEWS);
    const cJSON *front = find_named(views, "front");
    SL_CHECK(front && strcmp(cJSON_GetObjectItemCaseSensitive(front, "dataset")->valuestring, "abc") == 0);
    SL_CHECK(strcmp(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(views, 0), "name")->valuestring,
                    "front") == 0); /* by name */
    cJSON_Delete(views);

    /* Paths: the duration survives as the same double; oversized text is refused. */
    const char *path = "{\"keys\":[{\"t\":0},{\"t\":4.1}]}";
    SL_CHECK(sl_catalog_save_path(db, "spin", "tubes", path, 2, 4.1, &err) == SL_OK);
    cJSON *p = NULL;
    SL_CHECK(sl_catalog_load_path(db, "spin", &p, &err) == SL_OK && cJSON_GetArraySize(cJSON_GetObjectItem(p, "keys"))
                                                                         == 2);
    cJSON_Delete(p);
    cJSON *paths = sl_catalog_list_paths_json(db);
    const cJSON *spin = find_named(paths, "spin");
    SL_CHECK(spin && cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(spin, "duration")) == 4.1 &&
             cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(spin, "keys")) == 2);
    cJSON_Delete(paths);
    char *big = malloc(SL_CATALOG_MAX_PATH_BYTES + 2);
    memset(big, ' ', SL_CATALOG_MAX_PATH_BYTES + 1);
    big[SL_CATALOG_MAX_PATH_BYTES + 1] = '\0';
    SL_CHECK(sl_catalog_save_path(db, "big", "tubes", big, 2, 1, &err) == SL_ERR_LIMIT);
    free(big);
}

static void check_sessions(sl_db *db, const char *target)
{
    sl_err err = {0};
    char hash[65], node[40];
    char *state = NULL;
    const char *h1 = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
    SL_CHECK(sl_catalog_session_put(db, "n1.aa", "n1", h1, "{\"v\":1}", &err) == SL_OK);
    SL_CHECK(sl_catalog_session_put(db, "n1.bb", "n1", h1, "{\"v\":2}", &err) == SL_OK);
    SL_CHECK(sl_catalog_session_put(db, "n2.cc", "n2", h1, "{\"v\":3}", &err) == SL_OK);
    /* A restore on another node takes the row over (upsert). */
    SL_CHECK(sl_catalog_session_put(db, "n1.bb", "n3", h1, "{\"v\":4}", &err) == SL_OK);
    SL_CHECK(sl_catalog_session_get(db, "n1.bb", &state, hash, node, sizeof node, &err) == SL_OK);
    SL_CHECK(state && strcmp(state, "{\"v\":4}") == 0 && strcmp(node, "n3") == 0 && strcmp(hash, h1) == 0);
    free(state);
    state = NULL;

    /* A second connection (another node) sees these rows and writes its own. */
    sl_db *other = open_catalog(target);
    SL_CHECK(other && sl_catalog_session_get(other, "n2.cc", &state, hash, node, sizeof node, &err) == SL_OK &&
             strcmp(node, "n2") == 0);
    free(state);
    state = NULL;
    SL_CHECK(other && sl_catalog_save_view(other, "view001", "from another node", "tubes", "{}", "{}", &err) == SL_OK);
    cJSON *v = NULL;
    SL_CHECK(sl_catalog_load_view(db, "view001", &v, &err) == SL_OK && v &&
             strcmp(cJSON_GetObjectItemCaseSensitive(v, "dataset")->valuestring, "from another node") == 0);
    cJSON_Delete(v);
    /* Node n1 restarts: only its own rows go. */
    SL_CHECK(other && sl_catalog_sessions_clear_node(other, "n1", &err) == SL_OK);
    sl_catalog_close(other);
    SL_CHECK(sl_catalog_session_get(db, "n1.aa", &state, hash, node, sizeof node, &err) == SL_ERR_INVALID && !state);
    SL_CHECK(sl_catalog_session_get(db, "n1.bb", &state, hash, node, sizeof node, &err) == SL_OK);
    free(state);
    state = NULL;
    SL_CHECK(sl_catalog_session_remove(db, "n1.bb", &err) == SL_OK);
    SL_CHECK(sl_catalog_session_get(db, "n1.bb", &state, hash, node, sizeof node, &err) == SL_ERR_INVALID);
}

/* SQLite only: a version-2 file (tables of that build, sessions of one
 * process) opens, keeps its rows and gains today's tables. */
static void check_sqlite_old_file(void)
{
    char target[600];
    fresh_target(target, sizeof target);
    sl_db *raw = NULL;
    sl_err err = {0};
    SL_CHECK(sl_db_open(target, &raw, &err) == SL_OK);
    SL_CHECK_MSG(raw && sl_db_script(raw,
                     "CREATE TABLE datasets(id INTEGER PRIMARY KEY, name TEXT UNIQUE NOT NULL, kind TEXT NOT NULL,"
                     " source_path TEXT, generator_json TEXT, description TEXT, file_size INTEGER, checksum TEXT,"
                     " bounds TEXT, counts TEXT, attributes TEXT,"
                     " created TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ','now')));"
                     "CREATE TABLE views(id INTEGER PRIMARY KEY, name TEXT UNIQUE NOT NULL, dataset TEXT NOT NULL,"
                     " technique TEXT NOT NULL, params TEXT NOT NULL, camera TEXT NOT NULL,"
                     " created TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ','now')));"
                     "CREATE TABLE sessions(id TEXT PRIMARY KEY, state TEXT NOT NULL);"
                     "CREATE TABLE removed(name TEXT PRIMARY KEY, removed TEXT NOT NULL DEFAULT 'then');"
                     "CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);"
                     "INSERT INTO meta VALUES('schema_version', '2');"
                     "INSERT INTO datasets(name, kind, generator_json) VALUES('old', 'lines',"
                     " '{\"generator\":\"abc\",\"lines\":2}');"
                     "INSERT INTO views(name, dataset, technique, params, camera) VALUES('v', 'old', 'tubes', '{}', '{}');"
                     "INSERT INTO sessions VALUES('s', '{}');",
                     &err) == SL_OK, "%s", err.message);
    sl_db_close(raw);
    sl_db *db = open_catalog(target);
    SL_CHECK(db && schema_version(db) == sl_catalog_schema_latest());
    char source[1024];
    int is_file = 0, kind = 0;
    cJSON *v = NULL;
    SL_CHECK(db && sl_catalog_lookup(db, "old", source, sizeof source, &is_file, &kind, NULL, &err) == SL_OK);
    SL_CHECK(db && sl_catalog_load_view(db, "v", &v, &err) == SL_OK && v);
    cJSON_Delete(v);
    SL_CHECK(db && sl_catalog_session_put(db, "n.1", "n", "ab", "{}", &err) == SL_OK);
    SL_CHECK(db && sl_catalog_save_path(db, "p", "tubes", "{}", 0, 0, &err) == SL_OK);
    sl_catalog_close(db);
}

/* PostgreSQL only: a server that is not there fails in bounded time without
 * printing the password; a connection the server killed is re-made. */
static void check_pg_failures(const char *target)
{
    sl_db *db = NULL;
    sl_err err = {0};
    /* Port 1 on loopback: nothing listens there. */
    double t0 = sl_clock_ms();
    SL_CHECK(sl_catalog_open("postgresql://sightline:hunter2@127.0.0.1:1/sightline", &db, &err) == SL_ERR_IO);
    SL_CHECK(db == NULL && sl_clock_ms() - t0 < 6000);
    SL_CHECK_MSG(!strstr(err.message, "hunter2") && strstr(err.message, "127.0.0.1:1"), "%s", err.message);

    db = open_catalog(target);
    sl_db *killer = open_catalog(target);
    sl_db_result *r = NULL;
    SL_CHECK(db && sl_db_query(db, "SELECT pg_backend_pid()", NULL, 0, &r, &err) == SL_OK);
    sl_db_arg pid = sl_db_int_arg(sl_db_int(r, 0, 0, 0));
    sl_db_result_destroy(r);
    SL_CHECK(killer && sl_db_run(killer, "SELECT pg_terminate_backend(CAST($1 AS INTEGER))", &pid, 1, NULL, &err) ==
                           SL_OK);
    sl_catalog_close(killer);
    usleep(200 * 1000);
    cJSON *views = db ? sl_catalog_list_views_json(db) : NULL;
    SL_CHECK_MSG(cJSON_GetArraySize(views) > 0, "the statement after a killed connection failed");
    cJSON_Delete(views);
    sl_catalog_close(db);
}

int main(int argc, char **argv)
{
    if (argc != 2 || (strcmp(argv[1], "sqlite") && strcmp(argv[1], "postgresql"))) {
        fprintf(stderr, "usage: test_catalog_db sqlite|postgresql\n");
        return 2;
    }
    use_pg = strcmp(argv[1], "postgresql") == 0;
    snprintf(tmp_dir, sizeof tmp_dir, "/tmp/sl-catalog-XXXXXX");
    if (!mkdtemp(tmp_dir))
        return 1;
    char data_dir[128];
    snprintf(data_dir, sizeof data_dir, "%s/data", tmp_dir);
    mkdir(data_dir, 0755);
    test_pid = getpid();
    atexit(stop_postgres);
    signal(SIGTERM, stop_on_signal);
    signal(SIGINT, stop_on_signal);
    signal(SIGALRM, stop_on_signal);
    alarm(110); /* under ctest's TIMEOUT, so the server is stopped by us */
    if (use_pg && !start_postgres()) {
        fprintf(stderr, "test_catalog_db: could not start PostgreSQL (scripts/pg-temp)\n");
        stop_postgres();
        return 1;
    }
    check_migrations();
    check_nodes_starting_together(use_pg ? 3 : 30);
    char target[600];
    fresh_target(target, sizeof target);
    sl_db *db = open_catalog(target);
    if (db) {
        check_datasets(db, data_dir);
        check_views_and_paths(db);
        check_sessions(db, target);
        sl_catalog_close(db);
    }
    if (use_pg)
        check_pg_failures(target);
    else
        check_sqlite_old_file();
    stop_postgres();
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", tmp_dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmp_dir);
    SL_TEST_END();
}
