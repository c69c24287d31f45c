/* main.c — sightline-server: arguments, the `catalog` subcommand, start and orderly stop.
 *
 *   sightline-server [--port 8080] [--bind 127.0.0.1] [--db PATH|URL] [--data-dir DIR]...
 *                    [--web-dir DIR] [--allow-origin URL]... [--max-clients N]
 *                    [--max-pending N] [--max-pending-per-address N]
 *                    [--max-sessions N] [--grace S] [--idle-release S] [--egl-device D]
 *                    [--default-dataset NAME] [--hello-timeout S] [--node-id NAME] [--agent-port P]
 *                    [--trusted-proxy ADDR[/BITS]]...
 *                    [--test-frame-delay-ms MS] [--test-frame-fixed-ms MS] [--test-frame-time-ms MS]
 *                    [--test-frame-time-fixed-ms MS]
 *                    [--test-load-delay-ms MS]   (the --test-* options are for tests only)
 *   sightline-server [--db PATH|URL] [--data-dir DIR] catalog add PATH | add-generator NAME JSON | list
 *                    | remove NAME | refresh NAME | scan DIR | add-builtins
 * --db is an SQLite file (default ~/.local/share/sightline/catalog.db) or a
 * postgresql:// URL: one catalog that several render nodes share.
 * (options may also follow the subcommand).
 *
 * The work is elsewhere (see sl_server.h for the map): this file opens the
 * catalog, starts the render thread (render.c), creates the lws context
 * (ws.c) and runs the service loop on the main thread until SIGINT or a
 * second SIGTERM; the first SIGTERM drains (no new sessions; the node exits
 * 0 once no session has clients or --grace seconds passed, session.c).
 * Stop order matters: render thread first (it calls lws_cancel_service),
 * then the lws context (closing clients), then sessions, then the catalog.
 * --port 0 picks a free port; the chosen one is printed as
 * "listening on http://ADDR:PORT/" on stdout (tests read it).
 */
#include "net/sl_net.h"

#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/sl_technique.h"
#include "sl_params_json.h"

#ifndef SL_SOURCE_DIR
#define SL_SOURCE_DIR "."
#endif

static volatile sig_atomic_t interrupted, drain_requested;

/* SIGINT stops at once; the first SIGTERM asks for a drain, a second stops at once. */
static void on_signal(int sig)
{
    if (sig == SIGTERM && !drain_requested)
        drain_requested = 1;
    else
        interrupted = 1;
}

/* The host name as a node id: every character outside [A-Za-z0-9_-]
 * becomes '-', at most SL_NODE_ID_MAX of them; "node" when there is none. */
static void default_node_id(char out[SL_NODE_ID_MAX + 1])
{
    char host[256] = "";
    if (gethostname(host, sizeof host - 1) != 0)
        host[0] = '\0';
    size_t n = 0;
    for (; host[n] && n < SL_NODE_ID_MAX; n++) {
        char ch = host[n];
        int ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_';
        out[n] = ok ? ch : '-';
    }
    out[n] = '\0';
    if (n == 0)
        snprintf(out, SL_NODE_ID_MAX + 1, "node");
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sightline-server [--port N] [--bind ADDR] [--db PATH|URL] [--data-dir DIR]... [--web-dir DIR]\n"
            "                        [--allow-origin URL]... [--max-clients N] [--max-pending N]\n"
            "                        [--max-pending-per-address N] [--max-sessions N] [--grace SECONDS]\n"
            "                        [--idle-release SECONDS] [--egl-device software|INDEX] [--default-dataset NAME]\n"
            "                        [--hello-timeout S] [--node-id NAME] [--agent-port P] [--trusted-proxy ADDR[/BITS]]...\n"
            "                        [--test-frame-delay-ms MS] [--test-frame-fixed-ms MS] [--test-frame-time-ms MS]\n"
            "                        [--test-frame-time-fixed-ms MS] [--test-load-delay-ms MS]\n"
            "                        (tests only: sleep MS x frame pixels / session pixels, and MS, in every\n"
            "                        frame's render, and MS before every dataset load, so a scene is slow in a\n"
            "                        known way)\n"
            "       sightline-server [--db PATH|URL] [--data-dir DIR] catalog add PATH | add-generator NAME JSON\n"
            "                        | list | remove NAME | refresh NAME | scan DIR | add-builtins\n"
            "       (a removed dataset stays removed; `add`, `scan` or `add-builtins` brings it back;\n"
            "       `refresh` records a deliberately changed file's new checksum)\n"
            "  --db PATH|URL     the catalog: an SQLite file (one machine; default\n"
            "                    ~/.local/share/sightline/catalog.db) or postgresql://USER@HOST:PORT/DB, one\n"
            "                    catalog for every render node (datasets, views, paths, session checkpoints)\n"
            "  --node-id NAME    this node in session ids (NAME.<hex>), welcome, /healthz, /metrics and\n"
            "                    the catalog's checkpoints: 1-32 of [A-Za-z0-9_-] (default: the host name so\n"
            "                    sanitized); nodes sharing one catalog need distinct ids\n"
            "  --agent-port P    HAProxy agent-check on TCP port P (0, the default: off): \"up ready W%%\"\n"
            "                    (W falls with the sessions), \"drain\" while draining\n"
            "  --trusted-proxy ADDR[/BITS]  a balancer (IPv4 or IPv6, up to 16): an upgrade from it is\n"
            "                    counted against the client X-Forwarded-For names (the rightmost entry\n"
            "                    that is not a trusted proxy); from any other peer the header is ignored\n"
            "  SIGTERM drains: no new sessions (`draining`), existing ones are served until their clients\n"
            "  leave or --grace seconds pass, then exit 0; a second SIGTERM or SIGINT stops at once\n");
}

static int dir_exists(const char *p)
{
    struct stat sb;
    return stat(p, &sb) == 0 && S_ISDIR(sb.st_mode);
}

/* mkdir -p for the directory part of path. */
static void make_parent_dirs(const char *path)
{
    char tmp[PATH_MAX];
    snprintf(tmp, sizeof tmp, "%s", path);
    for (char *p = tmp + 1; *p; p++) {
        if (*p == '/') {
            *p = '\0';
            mkdir(tmp, 0755);
            *p = '/';
        }
    }
}

static int parse_int(const char *s, int lo, int hi, int *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || !end || *end || v < lo || v > hi)
        return 0;
    *out = (int)v;
    return 1;
}

static int run_catalog(sl_server_config *cfg, int argc, char **argv)
{
    if (argc < 1) {
        usage(stderr);
        return 2;
    }
    sl_db *db = NULL;
    sl_err err = {0};
    if (sl_catalog_open(cfg->db_path, &db, &err) != SL_OK) {
        fprintf(stderr, "sightline-server: %s\n", err.message);
        return 1;
    }
    int rc = 0;
    const char *cmd = argv[0];
    if (strcmp(cmd, "list") == 0 && argc == 1) {
        if (sl_catalog_init_defaults(db, cfg->data_dirs, cfg->data_dir_count, &err) != SL_OK) {
            fprintf(stderr, "sightline-server: %s\n", err.message);
            rc = 1;
        }
        cJSON *list = sl_catalog_list_json(db, 1);
        const cJSON *d;
        cJSON_ArrayForEach(d, list) {
            const cJSON *name = cJSON_GetObjectItemCaseSensitive(d, "name");
            const cJSON *kind = cJSON_GetObjectItemCaseSensitive(d, "kind");
            char *counts = cJSON_PrintUnformatted(cJSON_GetObjectItemCaseSensitive(d, "counts"));
            const cJSON *path = cJSON_GetObjectItemCaseSensitive(d, "path");
            printf("%-20s %-8s %-40s %s\n", name->valuestring, kind->valuestring, counts ? counts : "",
                   cJSON_IsString(path) ? path->valuestring : "(generator)");
            free(counts);
        }
        cJSON_Delete(list);
    } else if (strcmp(cmd, "add") == 0 && argc == 2) {
        if (sl_catalog_add_file(db, argv[1], cfg->data_dirs, cfg->data_dir_count, &err) != SL_OK) {
            fprintf(stderr, "sightline-server: %s\n", err.message);
            rc = 1;
        }
    } else if (strcmp(cmd, "add-generator") == 0 && argc == 3) {
        if (sl_catalog_add_generator(db, argv[1], argv[2], &err) != SL_OK) {
            fprintf(stderr, "sightline-server: %s\n", err.message);
            rc = 1;
        }
    } else if (strcmp(cmd, "remove") == 0 && argc == 2) {
        if (sl_catalog_remove(db, argv[1], &err) != SL_OK) {
            fprintf(stderr, "sightline-server: %s\n", err.message);
            rc = 1;
        }
    } else if (strcmp(cmd, "refresh") == 0 && argc == 2) {
        if (sl_catalog_refresh_file(db, argv[1], cfg->data_dirs, cfg->data_dir_count, &err) != SL_OK) {
            fprintf(stderr, "sightline-server: %s\n", err.message);
            rc = 1;
        }
    } else if (strcmp(cmd, "add-builtins") == 0 && argc == 1) {
        int added = 0;
        if (sl_catalog_add_builtins(db, &added, &err) != SL_OK) {
            fprintf(stderr, "sightline-server: %s\n", err.message);
            rc = 1;
        } else {
            printf("added %d built-in dataset(s)\n", added);
        }
    } else if (strcmp(cmd, "scan") == 0 && argc == 2) {
        int added = 0;
        if (sl_catalog_scan(db, argv[1], cfg->data_dirs, cfg->data_dir_count, &added, &err) != SL_OK) {
            fprintf(stderr, "sightline-server: %s\n", err.message);
            rc = 1;
        } else {
            printf("added %d dataset(s)\n", added);
        }
    } else {
        usage(stderr);
        rc = 2;
    }
    sl_catalog_close(db);
    return rc;
}

int main(int argc, char **argv)
{
    sl_server_config cfg = {.port = 8080, .bind = "127.0.0.1", .max_clients = 64, .max_pending = 16,
                            .max_pending_per_address = 4, .max_sessions = 32, .grace_s = 300,
                            .idle_release_s = 30, .hello_timeout_s = 10};
    char db_default[PATH_MAX], web_default[PATH_MAX], data_default[PATH_MAX];
    const char *xdg = getenv("XDG_DATA_HOME"), *home = getenv("HOME");
    if (xdg && xdg[0])
        snprintf(db_default, sizeof db_default, "%s/sightline/catalog.db", xdg);
    else
        snprintf(db_default, sizeof db_default, "%s/.local/share/sightline/catalog.db", home ? home : ".");
    cfg.db_path = db_default;
    snprintf(web_default, sizeof web_default, "%s", dir_exists("web") ? "web" : SL_SOURCE_DIR "/web");
    cfg.web_dir = web_default;
    default_node_id(cfg.node_id);
    int catalog_at = 0;
    char *positional[4];
    int npos = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        int ok = 1;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--port") == 0 && v) {
            ok = parse_int(v, 0, 65535, &cfg.port), i++;
        } else if (strcmp(a, "--bind") == 0 && v) {
            cfg.bind = v, i++;
        } else if (strcmp(a, "--db") == 0 && v) {
            cfg.db_path = v, i++;
        } else if (strcmp(a, "--web-dir") == 0 && v) {
            cfg.web_dir = v, i++;
        } else if (strcmp(a, "--data-dir") == 0 && v) {
            ok = cfg.data_dir_count < SL_SERVER_MAX_DATA_DIRS;
            if (ok)
                cfg.data_dirs[cfg.data_dir_count++] = v;
            i++;
        } else if (strcmp(a, "--allow-origin") == 0 && v) {
            ok = cfg.origin_count < SL_SERVER_MAX_ORIGINS;
            if (ok)
                cfg.origins[cfg.origin_count++] = v;
            i++;
        } else if (strcmp(a, "--max-clients") == 0 && v) {
            ok = parse_int(v, 1, 10000, &cfg.max_clients), i++;
        } else if (strcmp(a, "--max-pending") == 0 && v) {
            ok = parse_int(v, 1, 10000, &cfg.max_pending), i++;
        } else if (strcmp(a, "--max-pending-per-address") == 0 && v) {
            ok = parse_int(v, 1, 10000, &cfg.max_pending_per_address), i++;
        } else if (strcmp(a, "--max-sessions") == 0 && v) {
            ok = parse_int(v, 1, 10000, &cfg.max_sessions), i++;
        } else if (strcmp(a, "--grace") == 0 && v) {
            ok = parse_int(v, 0, 86400, &cfg.grace_s), i++;
        } else if (strcmp(a, "--idle-release") == 0 && v) {
            ok = parse_int(v, 0, 86400, &cfg.idle_release_s), i++;
        } else if (strcmp(a, "--hello-timeout") == 0 && v) {
            ok = parse_int(v, 1, 3600, &cfg.hello_timeout_s), i++;
        } else if (strcmp(a, "--test-frame-delay-ms") == 0 && v) {
            int ms = 0;
            ok = parse_int(v, 0, 10000, &ms), i++;
            cfg.test_frame_delay_ms = ms;
        } else if (strcmp(a, "--test-frame-fixed-ms") == 0 && v) {
            int ms = 0;
            ok = parse_int(v, 0, 10000, &ms), i++;
            cfg.test_frame_fixed_ms = ms;
        } else if (strcmp(a, "--test-frame-time-ms") == 0 && v) {
            int ms = 0;
            ok = parse_int(v, 0, 10000, &ms), i++;
            cfg.test_frame_time_ms = ms;
        } else if (strcmp(a, "--test-frame-time-fixed-ms") == 0 && v) {
            int ms = 0;
            ok = parse_int(v, 0, 10000, &ms), i++;
            cfg.test_frame_time_fixed_ms = ms;
        } else if (strcmp(a, "--test-load-delay-ms") == 0 && v) {
            int ms = 0;
            ok = parse_int(v, 0, 60000, &ms), i++;
            cfg.test_load_delay_ms = ms;
        } else if (strcmp(a, "--node-id") == 0 && v) {
            if (!sl_node_id_valid(v)) {
                fprintf(stderr, "sightline-server: --node-id \"%s\": a node id is 1-%d characters of "
                        "[A-Za-z0-9_-]\n", v, SL_NODE_ID_MAX);
                return 2;
            }
            snprintf(cfg.node_id, sizeof cfg.node_id, "%s", v), i++;
        } else if (strcmp(a, "--trusted-proxy") == 0 && v) {
            sl_err perr = {0};
            if (cfg.trusted_proxy_count >= SL_TRUSTED_PROXY_MAX) {
                fprintf(stderr, "sightline-server: at most %d --trusted-proxy options\n", SL_TRUSTED_PROXY_MAX);
                return 2;
            }
            if (sl_net_prefix_parse(v, &cfg.trusted_proxies[cfg.trusted_proxy_count], &perr) != SL_OK) {
                fprintf(stderr, "sightline-server: %s\n", perr.message);
                return 2;
            }
            cfg.trusted_proxy_count++, i++;
        } else if (strcmp(a, "--agent-port") == 0 && v) {
            ok = parse_int(v, 0, 65535, &cfg.agent_port), i++;
        } else if (strcmp(a, "--default-dataset") == 0 && v) {
            cfg.default_dataset = v, i++;
        } else if (strcmp(a, "--egl-device") == 0 && v) {
            cfg.egl_device = v, i++;
        } else if (a[0] != '-' && (catalog_at || strcmp(a, "catalog") == 0)) {
            /* The first word that is not an option value must be `catalog`;
             * options may come before and after it. */
            if (!catalog_at)
                catalog_at = i;
            else if (npos < 4)
                positional[npos++] = argv[i];
            else
                ok = 0;
        } else {
            ok = 0;
        }
        if (!ok) {
            fprintf(stderr, "sightline-server: bad or incomplete argument \"%s\"\n", a);
            usage(stderr);
            return 2;
        }
    }
    if (cfg.data_dir_count == 0) {
        snprintf(data_default, sizeof data_default, "%s", dir_exists("data") ? "data" : SL_SOURCE_DIR "/data");
        cfg.data_dirs[cfg.data_dir_count++] = data_default;
    }
    if (cfg.db_path == db_default) /* a URL given with --db has no parent directory to make */
        make_parent_dirs(db_default);
    if (catalog_at)
        return run_catalog(&cfg, npos, positional);

    sl_server *srv = calloc(1, sizeof *srv);
    if (!srv)
        return 1;
    srv->cfg = cfg;
    srv->start_ms = sl_clock_ms();
    pthread_mutex_init(&srv->lock, NULL);
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, SL_CLOCK_ID); /* sl_clock_deadline's clock (render.c) */
    pthread_cond_init(&srv->wake, &ca);
    pthread_condattr_destroy(&ca);
    sl_err err = {0};
    int rc = 1, port = 0;
    if (sl_catalog_open(cfg.db_path, &srv->db, &err) != SL_OK ||
        sl_catalog_init_defaults(srv->db, cfg.data_dirs, cfg.data_dir_count, &err) != SL_OK ||
        sl_catalog_sessions_clear_node(srv->db, cfg.node_id, &err) != SL_OK) {
        fprintf(stderr, "sightline-server: %s\n", err.message);
        goto done;
    }
    srv->techniques_json = cJSON_CreateArray();
    int tc = 0;
    const sl_technique *const *techs = sl_technique_list(&tc);
    for (int i = 0; i < tc; i++)
        cJSON_AddItemToArray(srv->techniques_json, sl_technique_json(techs[i]));
    /* Recording files (record.c) live here until fetched or their job ends. */
    snprintf(srv->record_dir, sizeof srv->record_dir, "/tmp/sightline-recordings-XXXXXX");
    if (!mkdtemp(srv->record_dir)) {
        fprintf(stderr, "sightline-server: warning: no folder for recordings (%s): record is refused\n",
                strerror(errno));
        srv->record_dir[0] = '\0';
    }
    if (sl_render_start(srv, &err) != SL_OK) {
        fprintf(stderr, "sightline-server: %s\n", err.message);
        goto done;
    }
    if (sl_ws_create(srv, &port, &err) != SL_OK) {
        fprintf(stderr, "sightline-server: %s\n", err.message);
        goto done;
    }
    if (sl_agent_start(srv, &err) != SL_OK) {
        fprintf(stderr, "sightline-server: %s\n", err.message);
        goto done;
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    signal(SIGPIPE, SIG_IGN);
    printf("sightline-server: node %s, renderer %s\n", cfg.node_id, srv->gpu_renderer);
    if (cfg.agent_port > 0)
        printf("sightline-server: agent-check on %s:%d\n", cfg.bind, cfg.agent_port);
    printf("sightline-server: listening on http://%s:%d/\n", cfg.bind, port);
    fflush(stdout);
    sl_ws_run(srv, &interrupted, &drain_requested);
    rc = 0;
done:
    sl_agent_stop(srv);
    sl_render_stop(srv);
    sl_ws_destroy(srv);
    sl_sessions_destroy_all(srv); /* removes every recording file */
    if (srv->record_dir[0] && rmdir(srv->record_dir) != 0)
        fprintf(stderr, "sightline-server: warning: %s not removed: %s\n", srv->record_dir, strerror(errno));
    sl_catalog_close(srv->db);
    cJSON_Delete(srv->techniques_json);
    pthread_cond_destroy(&srv->wake);
    pthread_mutex_destroy(&srv->lock);
    free(srv);
    sl_checkpoint_crypto_cleanup();
    return rc;
}
