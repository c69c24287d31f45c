/* test_server_cluster.c — three render nodes behind HAProxy on one shared
 * PostgreSQL catalog, all started by this test through scripts/cluster (which
 * starts a throwaway PostgreSQL with scripts/pg-temp), loopback only.
 *
 *  0. the catalog is PostgreSQL, and the dataset registered there through one
 *     CLI call is what every node serves;
 *  1. 30 new sessions through the balancer spread over all three nodes (each
 *     gets at least 5), and every session id starts with the node that says
 *     `welcome.node`;
 *  2. collaborators join through the balancer with a share link
 *     (/ws?session=ID, hello with id + token): each lands on the session's node
 *     and, after a camera move, gets the same frame id as the creator;
 *  3. a view saved on one node loads on another (the shared catalog);
 *  4. a wrong token, and a token of another session (replayed), are refused
 *     with bad_token through the balancer and on every node directly;
 *  5. a node killed with SIGKILL: every one of its sessions, rejoined through
 *     the balancer as the page does, comes back on another node with the same
 *     camera and a frame within 10 s of the kill;
 *  6. a node sent SIGTERM drains: its /healthz answers 503, new sessions go
 *     only to the others, its own client still gets frames, and it exits when
 *     that last client leaves.
 * Bounded: every wait has a deadline; the cluster is stopped
 * (and its directory removed) on every path out.
 */
#include <sys/types.h>

#include "sl_cluster.h"

#define NODES 3
#define NEW_SESSIONS 30
#define SIZE 64

static int failures;
#define CHECK(cond, ...)                                                   \
    do {                                                                   \
        if (!(cond)) {                                                     \
            failures++;                                                    \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);           \
            fprintf(stderr, __VA_ARGS__);                                  \
            fputc('\n', stderr);                                           \
        }                                                                  \
    } while (0)

/* 1 while pid runs (a zombie child of the cluster script counts as gone). */
static int process_alive(pid_t pid)
{
    char path[64], stat[256] = "";
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    size_t n = fread(stat, 1, sizeof stat - 1, f);
    fclose(f);
    stat[n] = 0;
    const char *paren = strrchr(stat, ')');
    return paren && paren[1] == ' ' && paren[2] != 'Z' && paren[2] != 'X';
}

/* The nodes the cluster's test runs, and the options that let 30 sessions and
 * their collaborators in from one address (the balancer's). */
static int cluster_start(sl_cluster *c)
{
    const char *args[] = {"--default-dataset", "tiny", "--max-pending", "64", "--max-clients", "128",
                          "--max-sessions", "64", "--grace", "20", NULL};
    if (sl_cluster_start(c, NODES, args) != 0)
        return -1;
    /* The sessions' dataset, registered once in the shared catalog by the CLI
     * (the nodes look the default dataset up at each hello). */
    return sl_cluster_add_generator(c, "tiny", HARNESS_TINY);
}

static double welcome_azimuth(const tclient *t)
{
    const cJSON *st = cJSON_GetObjectItemCaseSensitive(t->welcome, "state");
    const cJSON *orbit = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(st, "camera"), "orbit");
    const cJSON *az = cJSON_GetObjectItemCaseSensitive(orbit, "azimuth");
    return cJSON_IsNumber(az) ? az->valuedouble : NAN;
}

static int send_orbit(tclient *t, uint32_t seq, double azimuth)
{
    return tclient_send(t, "{\"type\":\"camera\",\"seq\":%u,\"camera\":{\"orbit\":{\"azimuth\":%.3f,"
                           "\"elevation\":20,\"distance\":2.5}}}", seq, azimuth);
}

/* The error code a hello gets (NULL on a welcome or no answer); code has 64 bytes. */
static const char *hello_error(int port, const char *session, const char *token, char code[64])
{
    tclient t;
    code[0] = 0;
    if (tclient_connect_page(&t, port, session) != 0)
        return NULL;
    tclient_send(&t, "{\"type\":\"hello\",\"version\":1,\"session\":\"%s\",\"token\":\"%s\",\"width\":%d,\"height\":%d}",
                 session, token, SIZE, SIZE);
    double deadline = sl_clock_ms() + 10000;
    while (!code[0] && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&t, 2000, &j);
        if (r == 1 && strcmp(json_type(j), "error") == 0) {
            const cJSON *cd = cJSON_GetObjectItemCaseSensitive(j, "code");
            snprintf(code, 64, "%s", cJSON_IsString(cd) ? cd->valuestring : "?");
        } else if (r == 1 && strcmp(json_type(j), "welcome") == 0) {
            snprintf(code, 64, "welcome");
        }
        cJSON_Delete(j);
        if (r < 0)
            break;
    }
    tclient_close(&t);
    return code[0] ? code : NULL;
}

int main(void)
{
    harness_small_asan_quarantine();
    signal(SIGPIPE, SIG_IGN);
    sl_cluster cl;
    if (cluster_start(&cl) != 0) {
        sl_cluster_stop(&cl);
        fprintf(stderr, "FAIL: the cluster did not start\n");
        return 1;
    }
    /* 0. The nodes share one PostgreSQL catalog. */
    CHECK(strncmp(cl.db, "postgresql://", 13) == 0, "the cluster's catalog is %s, not PostgreSQL", cl.db);

    /* 1. New sessions spread over the nodes. */
    static tclient s[NEW_SESSIONS];
    int owner[NEW_SESSIONS], per_node[NODES] = {0};
    uint32_t seq[NEW_SESSIONS];
    double az_now[NEW_SESSIONS]; /* the camera each session shows (what a restore must bring back) */
    for (int i = 0; i < NEW_SESSIONS; i++) {
        owner[i] = -1;
        seq[i] = 0;
        az_now[i] = NAN;
        if (tclient_connect_page(&s[i], cl.port, NULL) != 0 || tclient_hello(&s[i], NULL, NULL, SIZE, SIZE) != 0) {
            CHECK(0, "session %d: no welcome through the balancer (%s)", i, s[i].err.message);
            continue;
        }
        s[i].auto_ack = 1;
        owner[i] = sl_cluster_node_index(&cl, tclient_welcome_node(&s[i]));
        char prefix[48];
        snprintf(prefix, sizeof prefix, "%s.", tclient_welcome_node(&s[i]));
        CHECK(owner[i] >= 0, "session %d: welcome.node '%s' is not one of the cluster's", i, tclient_welcome_node(&s[i]));
        CHECK(strncmp(s[i].session, prefix, strlen(prefix)) == 0, "session id %s does not start with %s", s[i].session,
              prefix);
        if (owner[i] >= 0)
            per_node[owner[i]]++;
    }
    fprintf(stderr, "sessions per node: %d %d %d\n", per_node[0], per_node[1], per_node[2]);
    for (int n = 0; n < NODES; n++)
        CHECK(per_node[n] >= 5, "node%d got %d of %d new sessions", n + 1, per_node[n], NEW_SESSIONS);
    /* Every session shows a distinct camera, checkpointed at its still frame. */
    for (int i = 0; i < NEW_SESSIONS; i++)
        if (owner[i] >= 0) {
            send_orbit(&s[i], ++seq[i], az_now[i] = 5.0 + 7.0 * i);
            CHECK(tclient_wait_frame(&s[i], seq[i], 1, 60000) == 0, "session %d: no still frame for its camera", i);
        }

    /* 2. Collaborators land on the session's node and see the same frames. */
    for (int n = 0; n < NODES; n++) {
        int joined = 0;
        for (int i = 0; i < NEW_SESSIONS && joined < 2; i++) {
            if (owner[i] != n)
                continue;
            joined++;
            tclient b;
            if (tclient_connect_page(&b, cl.port, s[i].session) != 0 || tclient_hello(&b, s[i].session, s[i].token, SIZE, SIZE)) {
                CHECK(0, "collaborator of %s: no welcome", s[i].session);
                tclient_close(&b);
                continue;
            }
            b.auto_ack = 1;
            CHECK(strcmp(tclient_welcome_node(&b), tclient_welcome_node(&s[i])) == 0, "collaborator of %s landed on %s", s[i].session,
                  tclient_welcome_node(&b));
            send_orbit(&s[i], ++seq[i], az_now[i] = 11.0 + 7.0 * i);
            int ok_a = tclient_wait_frame(&s[i], seq[i], 1, 30000) == 0;
            int ok_b = tclient_wait_frame(&b, seq[i], 1, 30000) == 0;
            CHECK(ok_a && ok_b, "collaborator of %s: the still frame of camera %u did not reach both", s[i].session,
                  seq[i]);
            if (ok_a && ok_b)
                CHECK(s[i].last.h.frame_id == b.last.h.frame_id, "%s: creator frame %u, collaborator frame %u",
                      s[i].session, s[i].last.h.frame_id, b.last.h.frame_id);
            tclient_close(&b);
        }
    }

    /* 3. A view saved on one node loads on another. */
    int a = -1, bidx = -1;
    for (int i = 0; i < NEW_SESSIONS; i++) {
        if (owner[i] == 0 && a < 0)
            a = i;
        if (owner[i] == 1 && bidx < 0)
            bidx = i;
    }
    if (a >= 0 && bidx >= 0) {
        send_orbit(&s[a], ++seq[a], az_now[a] = 123.0);
        tclient_wait_frame(&s[a], seq[a], 1, 30000);
        tclient_send(&s[a], "{\"type\":\"save_view\",\"name\":\"cluster-view\"}");
        cJSON *saved = tclient_wait_type(&s[a], "view_saved", 10000);
        CHECK(saved != NULL, "save_view on node1 got no view_saved");
        cJSON_Delete(saved);
        tclient_send(&s[bidx], "{\"type\":\"load_view\",\"name\":\"cluster-view\"}");
        double az = NAN, deadline = sl_clock_ms() + 10000;
        while (isnan(az) && sl_clock_ms() < deadline) {
            cJSON *j = NULL;
            if (tclient_next(&s[bidx], 1000, &j) == 1 && strcmp(json_type(j), "state") == 0) {
                const cJSON *orbit = cJSON_GetObjectItemCaseSensitive(
                    cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(j, "patch"), "camera"), "orbit");
                const cJSON *v = cJSON_GetObjectItemCaseSensitive(orbit, "azimuth");
                if (cJSON_IsNumber(v))
                    az = v->valuedouble;
            }
            cJSON_Delete(j);
        }
        CHECK(fabs(az - 123.0) < 1e-6, "the view saved on node1 loaded on node2 with azimuth %g, not 123", az);
        az_now[bidx] = 123.0;
        tclient_wait_frame(&s[bidx], 0, 1, 30000); /* its still frame (and checkpoint) */
    } else {
        CHECK(0, "no sessions on node1 and node2 to test saved views");
    }

    /* 4. Wrong and replayed tokens, through the balancer and on every node. */
    char code[64];
    for (int n = 0; n < NODES; n++) {
        int i = -1, other = -1;
        for (int k = 0; k < NEW_SESSIONS; k++) {
            if (owner[k] == n && i < 0)
                i = k;
            else if (owner[k] >= 0 && owner[k] != n && other < 0)
                other = k;
        }
        if (i < 0 || other < 0)
            continue;
        const char *e = hello_error(cl.port, s[i].session, "00000000000000000000000000000000", code);
        CHECK(e && strcmp(e, "bad_token") == 0, "wrong token for %s through the balancer: %s", s[i].session, e ? e : "none");
        e = hello_error(cl.port, s[i].session, s[other].token, code);
        CHECK(e && strcmp(e, "bad_token") == 0, "replayed token for %s through the balancer: %s", s[i].session,
              e ? e : "none");
        for (int m = 0; m < NODES; m++) {
            e = hello_error(cl.node_port[m], s[i].session, s[other].token, code);
            CHECK(e && strcmp(e, "bad_token") == 0, "replayed token for %s on node%d directly: %s", s[i].session, m + 1,
                  e ? e : "none");
        }
    }

    /* 5. Kill node2: its sessions come back elsewhere with their cameras. */
    const int dead = 1;
    double kill_ms = sl_clock_ms();
    kill(cl.node_pid[dead], SIGKILL);
    double worst_ms = 0;
    int restored = 0;
    for (int i = 0; i < NEW_SESSIONS; i++) {
        if (owner[i] != dead)
            continue;
        double expect = az_now[i];
        tclient_close(&s[i]);
        char session[64], token[64];
        snprintf(session, sizeof session, "%s", s[i].session);
        snprintf(token, sizeof token, "%s", s[i].token);
        int back = 0;
        while (!back && sl_clock_ms() - kill_ms < 15000) {
            tclient t;
            if (tclient_connect_page(&t, cl.port, session) == 0 && tclient_hello(&t, session, token, SIZE, SIZE) == 0) {
                t.auto_ack = 1;
                CHECK(sl_cluster_node_index(&cl, tclient_welcome_node(&t)) != dead && sl_cluster_node_index(&cl, tclient_welcome_node(&t)) >= 0,
                      "%s came back on '%s'", session, tclient_welcome_node(&t));
                double az = welcome_azimuth(&t);
                CHECK(fabs(az - expect) < 1e-6, "%s came back with azimuth %g, not %g", session, az, expect);
                CHECK(strcmp(t.session, session) == 0, "%s came back as %s", session, t.session);
                if (tclient_wait_frame(&t, 0, 1, 10000) == 0) {
                    back = 1;
                    double ms = sl_clock_ms() - kill_ms;
                    worst_ms = ms > worst_ms ? ms : worst_ms;
                    restored++;
                }
                owner[i] = sl_cluster_node_index(&cl, tclient_welcome_node(&t));
                s[i] = t; /* keep it connected: it is a session of a live node now */
                snprintf(s[i].session, sizeof s[i].session, "%s", session);
                snprintf(s[i].token, sizeof s[i].token, "%s", token);
            } else {
                tclient_close(&t);
                usleep(200000);
            }
        }
        CHECK(back, "%s did not come back within 15 s of its node's death", session);
    }
    fprintf(stderr, "node2 killed: %d sessions back, the last after %.0f ms\n", restored, worst_ms);
    CHECK(restored == per_node[dead], "%d of node2's %d sessions came back", restored, per_node[dead]);
    CHECK(worst_ms <= 10000, "the last session came back after %.0f ms (limit 10 s)", worst_ms);

    /* 6. Drain node3. */
    const int drain = 2;
    kill(cl.node_pid[drain], SIGTERM);
    char body[2048];
    int status = -1;
    double deadline = sl_clock_ms() + 5000;
    while ((status = harness_http_get(cl.node_port[drain], NULL, "/healthz", body, sizeof body)) != 503 &&
           sl_clock_ms() < deadline)
        usleep(100000);
    CHECK(status == 503, "a draining node's /healthz answered %d, not 503", status);
    usleep(2500000); /* HAProxy's agent asks every second */
    int on_drain = 0, opened = 0;
    tclient fresh[6];
    for (int i = 0; i < 6; i++) {
        if (tclient_connect_page(&fresh[i], cl.port, NULL) == 0 && tclient_hello(&fresh[i], NULL, NULL, SIZE, SIZE) == 0) {
            opened++;
            on_drain += sl_cluster_node_index(&cl, tclient_welcome_node(&fresh[i])) == drain;
        }
    }
    CHECK(opened == 6 && on_drain == 0, "while node3 drains: %d of 6 new sessions opened, %d on node3", opened, on_drain);
    for (int i = 0; i < 6; i++)
        tclient_close(&fresh[i]);
    int drain_clients = 0;
    for (int i = 0; i < NEW_SESSIONS; i++)
        if (owner[i] == drain && s[i].ws) {
            drain_clients++;
            send_orbit(&s[i], ++seq[i], az_now[i] = 200.0 + i);
            CHECK(tclient_wait_frame(&s[i], seq[i], 1, 30000) == 0, "%s on the draining node got no frame",
                  s[i].session);
        }
    CHECK(drain_clients > 0, "node3 had no session to drain");
    CHECK(process_alive(cl.node_pid[drain]), "node3 exited while it still had clients");
    for (int i = 0; i < NEW_SESSIONS; i++)
        if (owner[i] == drain)
            tclient_close(&s[i]);
    deadline = sl_clock_ms() + 20000;
    while (process_alive(cl.node_pid[drain]) && sl_clock_ms() < deadline)
        usleep(100000);
    CHECK(!process_alive(cl.node_pid[drain]), "node3 did not exit within 20 s of its last client leaving");

    for (int i = 0; i < NEW_SESSIONS; i++)
        if (s[i].ws)
            tclient_close(&s[i]);
    sl_cluster_stop(&cl);
    if (failures)
        fprintf(stderr, "%d check(s) failed\n", failures);
    else
        fprintf(stderr, "all checks passed\n");
    return failures ? 1 : 0;
}
