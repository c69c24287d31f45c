/* sl_cluster.h — start scripts/cluster (a throwaway PostgreSQL, N render nodes, HAProxy) for a
 * test or a benchmark, read what it prints, and stop it. Loopback only; header-only.
 *
 * sl_cluster_start runs `scripts/cluster --nodes N` in its own process group with an empty
 * temporary data directory and free ports, and reads its lines (`cluster: node<i> pid P port N
 * agent A`, `cluster: catalog URL`, `cluster: haproxy pid P`) until `cluster: open` (120 s at
 * most). sl_cluster_stop sends the script SIGTERM (it stops nodes, HAProxy, PostgreSQL), kills
 * the group after 30 s and removes the directory. No path leaves processes behind: the script
 * gets SIGTERM from the kernel when the caller dies (PR_SET_PDEATHSIG), and
 * sl_cluster_stop_on_signal does the same on SIGINT/SIGTERM/SIGHUP and removes the directory.
 * Datasets are registered apart (sl_cluster_add_generator: the CLI on the catalog URL).
 * Threads: start and stop from one thread (the parent-death signal follows the forking thread).
 */
#ifndef SL_CLUSTER_H
#define SL_CLUSTER_H

#include <stdatomic.h>
#include <sys/prctl.h>

#include "sl_server_harness.h"

#define SL_CLUSTER_MAX_NODES 16

typedef struct sl_cluster {
    char dir[64];                          /* the nodes' empty --data-dir, /tmp/sl-cluster-XXXXXX */
    char db[256];                          /* the shared catalog: the URL the script printed */
    pid_t script;                          /* scripts/cluster (leader of its process group), -1 when none */
    FILE *out;                             /* its stdout, unbuffered */
    int port;                              /* HAProxy */
    int nodes;
    pid_t haproxy_pid;
    pid_t node_pid[SL_CLUSTER_MAX_NODES];  /* node i+1 */
    int node_port[SL_CLUSTER_MAX_NODES];
} sl_cluster;

static __attribute__((unused)) const char *sl_cluster_src_dir(void)
{
    const char *s = getenv("SIGHTLINE_SOURCE_DIR");
    return s ? s : ".";
}

static __attribute__((unused)) const char *sl_cluster_bin_dir(void)
{
    const char *b = getenv("SIGHTLINE_BINARY_DIR");
    return b ? b : "build";
}

/* Starts `nodes` (1..SL_CLUSTER_MAX_NODES) nodes with server_args
 * (NULL-terminated, may be NULL; passed after `--`, so they win over the
 * script's). Returns 0 once HAProxy answers, or -1 (the reason on stderr);
 * call sl_cluster_stop on both paths. The script's lines are echoed to stderr. */
/* 1 when a TCP socket can bind 127.0.0.1:port now. */
static __attribute__((unused)) int sl_cluster_port_free(int port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0)
        return 0;
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    int ok = bind(fd, (struct sockaddr *)&a, sizeof a) == 0;
    close(fd);
    return ok;
}

static __attribute__((unused)) int sl_cluster_start(sl_cluster *c, int nodes, const char *const *server_args)
{
    memset(c, 0, sizeof *c);
    c->script = -1;
    c->haproxy_pid = -1;
    if (nodes < 1 || nodes > SL_CLUSTER_MAX_NODES)
        return -1;
    c->nodes = nodes;
    snprintf(c->dir, sizeof c->dir, "/tmp/sl-cluster-XXXXXX");
    if (!mkdtemp(c->dir)) {
        c->dir[0] = 0;
        return -1;
    }
    c->port = harness_free_port();
    /* node ports base+i, agents base+100+i: a base whose ports are all free now (a port taken
     * by another process made a node fail to listen, and the test with it) */
    int base = -1;
    for (int attempt = 0; attempt < 20 && base < 0; attempt++) {
        int b = harness_free_port();
        if (b <= 0 || b > 60000)
            continue;
        b -= b % 100;
        int all_free = 1;
        for (int i = 1; i <= nodes && all_free; i++)
            all_free = sl_cluster_port_free(b + i) && sl_cluster_port_free(b + 100 + i);
        if (all_free)
            base = b;
    }
    if (c->port <= 0 || base <= 0)
        return -1;
    char script[512], portv[16], basev[16], nodesv[16];
    snprintf(script, sizeof script, "%s/scripts/cluster", sl_cluster_src_dir());
    snprintf(portv, sizeof portv, "%d", c->port);
    snprintf(basev, sizeof basev, "%d", base);
    snprintf(nodesv, sizeof nodesv, "%d", nodes);
    const char *argv[64] = {"bash", script, "--nodes", nodesv, "--port", portv, "--base-port", basev,
                            "--build", sl_cluster_bin_dir(), "--data-dir", c->dir, "--"};
    int argc = 13;
    for (int i = 0; server_args && server_args[i] && argc < 63; i++)
        argv[argc++] = server_args[i];
    argv[argc] = NULL;
    int fds[2];
    if (pipe(fds) != 0)
        return -1;
    pid_t parent = getpid();
    c->script = fork();
    if (c->script == 0) {
        dup2(fds[1], 1);
        close(fds[0]);
        close(fds[1]);
        setpgid(0, 0);
        /* The caller's death (a crash, Ctrl-C) stops the cluster as SIGTERM would. */
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() != parent)
            _exit(1);
        execvp("bash", (char *const *)argv);
        _exit(127);
    }
    close(fds[1]);
    if (c->script < 0) {
        close(fds[0]);
        return -1;
    }
    c->out = fdopen(fds[0], "r");
    if (!c->out) {
        close(fds[0]);
        return -1;
    }
    setvbuf(c->out, NULL, _IONBF, 0); /* poll() sees the descriptor, so no line may wait in a stdio buffer */
    char line[512];
    int nodes_seen = 0;
    double deadline = sl_clock_ms() + 120000;
    while (sl_clock_ms() < deadline) {
        struct pollfd pfd = {.fd = fds[0], .events = POLLIN};
        if (poll(&pfd, 1, 500) <= 0)
            continue;
        if (!fgets(line, sizeof line, c->out))
            break;
        fputs(line, stderr);
        int i, pid, port, agent;
        if (sscanf(line, "cluster: node%d pid %d port %d agent %d", &i, &pid, &port, &agent) == 4 && i >= 1 &&
            i <= nodes) {
            c->node_pid[i - 1] = pid;
            c->node_port[i - 1] = port;
            nodes_seen++;
        } else if (sscanf(line, "cluster: haproxy pid %d", &pid) == 1) {
            c->haproxy_pid = pid;
        } else if (sscanf(line, "cluster: catalog %255s", c->db) == 1) {
            continue;
        } else if (strncmp(line, "cluster: open", 13) == 0) {
            if (nodes_seen == nodes && c->db[0])
                return 0;
            break;
        }
    }
    fprintf(stderr, "sl_cluster: scripts/cluster did not come up (%d of %d nodes seen)\n", nodes_seen, nodes);
    return -1;
}

/* Stops everything sl_cluster_start started (SIGTERM to the script, SIGKILL to
 * its process group after 30 s) and removes the data directory. Safe on a
 * half-started or stopped cluster. */
static __attribute__((unused)) void sl_cluster_stop(sl_cluster *c)
{
    if (c->script > 0) {
        kill(c->script, SIGTERM);
        double deadline = sl_clock_ms() + 30000;
        int status = 0;
        pid_t r = 0;
        while ((r = waitpid(c->script, &status, WNOHANG)) == 0 && sl_clock_ms() < deadline)
            usleep(100000);
        if (r == 0) {
            kill(-c->script, SIGKILL);
            waitpid(c->script, &status, 0);
        }
        c->script = -1;
    }
    if (c->out)
        fclose(c->out);
    c->out = NULL;
    if (strncmp(c->dir, "/tmp/sl-cluster-", 16) == 0) {
        char cmd[128];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", c->dir);
        if (system(cmd) != 0)
            fprintf(stderr, "sl_cluster: could not remove %s\n", c->dir);
    }
    c->dir[0] = 0;
}

/* Registers generator dataset `name` (a generator call, JSON) in the cluster's
 * catalog with the CLI (`sightline-server --db URL catalog add-generator`);
 * the nodes see it at their next lookup. 0, or -1 (the CLI's message is on
 * stderr). */
static __attribute__((unused)) int sl_cluster_add_generator(const sl_cluster *c, const char *name, const char *json)
{
    char exe[1024];
    snprintf(exe, sizeof exe, "%s/bin/sightline-server", sl_cluster_bin_dir());
    char *argv[] = {exe, "--db", (char *)c->db, "catalog", "add-generator", (char *)name, (char *)json, NULL};
    int rc = harness_run_wait(argv);
    if (rc != 0)
        fprintf(stderr, "sl_cluster: `catalog add-generator %s` exited %d\n", name, rc);
    return rc == 0 ? 0 : -1;
}

/* The cluster a fatal signal stops (sl_cluster_stop_on_signal); any thread may take the signal. */
static sl_cluster *_Atomic sl_cluster_signal_target;

static __attribute__((unused)) void sl_cluster_on_signal(int sig)
{
    sl_cluster *c = atomic_load(&sl_cluster_signal_target);
    if (c && c->script > 0)
        kill(c->script, SIGTERM); /* the script stops the nodes, HAProxy and PostgreSQL */
    if (c && c->dir[0])
        rmdir(c->dir);
    signal(sig, SIG_DFL);
    raise(sig);
}

/* Until called again with NULL, SIGINT, SIGTERM and SIGHUP (those not ignored) stop c's cluster
 * and remove its directory before the process dies of the signal (a crash is covered by the
 * script's parent-death signal). c must stay valid while armed; disarm before sl_cluster_stop. */
static __attribute__((unused)) void sl_cluster_stop_on_signal(sl_cluster *c)
{
    atomic_store(&sl_cluster_signal_target, c);
    const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    for (int i = 0; i < 3; i++) {
        struct sigaction old, sa = {.sa_handler = sl_cluster_on_signal};
        sigemptyset(&sa.sa_mask);
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler != SIG_IGN)
            sigaction(sigs[i], &sa, NULL);
    }
}

/* The index (0-based) of node id "node<i>" in c, or -1. */
static __attribute__((unused)) int sl_cluster_node_index(const sl_cluster *c, const char *node)
{
    int i = 0;
    return sscanf(node, "node%d", &i) == 1 && i >= 1 && i <= c->nodes ? i - 1 : -1;
}

#endif
