/* bench_cluster.c — render nodes behind HAProxy on one machine (issue 16): how fast sessions
 * open, how dragging sessions fare, what the CPU does, how fast a killed node's sessions return.
 *
 *   bench-cluster [--nodes-list 1,2,3] [--seconds S] [--size WxH] [--sessions 10,30]
 *                 [--openers K] [--opens M] [--dataset GENERATOR_JSON]
 *
 * Per N it starts scripts/cluster (tests/support/sl_cluster.h), registers the dataset `bench`
 * with the CLI and measures through the balancer: sessions opened per second (closed loop, K
 * openers, each hello -> welcome -> first still); S sessions dragging at once (open loop, 30 Hz
 * camera moves each, fixed interactive scale 1; latency = arrival - send time of the frame's
 * camera seq, as bench-server); per-process CPU over the drag (/proc); for N >= 2, SIGKILL of the
 * busiest node and each of its sessions' time to a frame on another node, rejoined as the page
 * does. At N = 1 opens and drags also run on the node directly (no HAProxy). Prints Markdown,
 * asserts nothing. Threads: main runs the phases, one thread per client while a phase runs.
 */
#include <dirent.h>
#include <pthread.h>
#include <stdatomic.h>

#include "harness/sl_bench.h"
#include "sl_cluster.h"

#define MAX_LIST 8
#define MAX_SESSIONS 60      /* HAProxy's template refuses a source's 65th open connection */
#define MAX_OPENS 250        /* ... and its 301st new connection within 10 s */
#define DRAG_HZ 30.0
#define DRAG_MAX_SEQ 4096    /* 30 Hz for up to 120 s */
#define STREAM_FIXED "{\"interactive_adaptive\":false,\"interactive_scale\":1}"
#define DEFAULT_DATASET "{\"generator\":\"tornado\",\"lines\":100,\"points\":100,\"seed\":1}"

typedef struct bench_opts {
    int nodes[MAX_LIST], n_nodes;
    int sessions[MAX_LIST], n_sessions;
    double seconds;          /* drag window */
    int w, h;
    int openers, opens;
    const char *dataset;     /* generator JSON registered as `bench` */
} bench_opts;

/* ---- CPU from /proc ---- */

typedef struct cpu_sample {
    double t_ms;
    long long node[SL_CLUSTER_MAX_NODES]; /* utime + stime in clock ticks; -1 when gone */
    long long service[SL_CLUSTER_MAX_NODES], raster[SL_CLUSTER_MAX_NODES]; /* of which: threads */
    long long haproxy, self;
    long long busy, total;                /* /proc/stat, all CPUs */
} cpu_sample;

/* utime + stime in clock ticks from a /proc stat file (a process' or a thread's), or -1 when gone. */
static long long stat_ticks(const char *path)
{
    char buf[1024];
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    const char *p = strrchr(buf, ')'); /* the command name may hold spaces */
    unsigned long long ut = 0, st = 0;
    if (!p || sscanf(p + 1, " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &ut, &st) != 2)
        return -1;
    return (long long)(ut + st);
}

static long long proc_ticks(pid_t pid)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    return stat_ticks(path);
}

/* A node's threads by kind: the service thread (the main one: sockets, protocol, catalog) and
 * Mesa's rasterizer workers (`llvmpipe-N`: fragment work). The rest of the process' time is
 * its render thread (GL calls, llvmpipe's vertex stage, readback, JPEG) plus loaders. */
static void node_thread_ticks(pid_t pid, long long *service, long long *raster)
{
    char dir[64], path[400], comm[64];
    *service = *raster = 0;
    snprintf(dir, sizeof dir, "/proc/%d/task", (int)pid);
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        snprintf(path, sizeof path, "%s/%.255s/comm", dir, e->d_name);
        FILE *f = fopen(path, "r");
        comm[0] = 0;
        if (f && !fgets(comm, sizeof comm, f))
            comm[0] = 0;
        if (f)
            fclose(f);
        snprintf(path, sizeof path, "%s/%.255s/stat", dir, e->d_name);
        long long t = stat_ticks(path);
        if (t < 0)
            continue;
        if (atoi(e->d_name) == (int)pid)
            *service += t;
        else if (strncmp(comm, "llvmpipe-", 9) == 0)
            *raster += t;
    }
    if (d)
        closedir(d);
}

static void cpu_take(const sl_cluster *cl, cpu_sample *s)
{
    memset(s, 0, sizeof *s);
    s->t_ms = sl_clock_ms();
    for (int i = 0; i < cl->nodes; i++) {
        s->node[i] = proc_ticks(cl->node_pid[i]);
        node_thread_ticks(cl->node_pid[i], &s->service[i], &s->raster[i]);
    }
    s->haproxy = cl->haproxy_pid > 0 ? proc_ticks(cl->haproxy_pid) : -1;
    s->self = proc_ticks(getpid());
    FILE *f = fopen("/proc/stat", "r");
    unsigned long long v[8] = {0};
    if (f && fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                    &v[6], &v[7]) == 8) {
        s->busy = (long long)(v[0] + v[1] + v[2] + v[5] + v[6] + v[7]);
        s->total = s->busy + (long long)(v[3] + v[4]);
    }
    if (f)
        fclose(f);
}

/* CPU % of one core between two samples of a process' ticks; NAN when it vanished. */
static double cpu_pct(long long a, long long b, double ms)
{
    if (a < 0 || b < 0 || ms <= 0)
        return NAN;
    return (double)(b - a) / (double)sysconf(_SC_CLK_TCK) / (ms / 1000.0) * 100.0;
}

typedef struct cpu_use {
    double node[SL_CLUSTER_MAX_NODES], nodes_sum, haproxy, self, machine; /* % of one core */
    double other;                   /* machine - nodes - HAProxy - this client: PostgreSQL, other users */
    double service, render, raster; /* all nodes' threads by kind (node_thread_ticks) */
} cpu_use;

static cpu_use cpu_between(const sl_cluster *cl, const cpu_sample *a, const cpu_sample *b)
{
    cpu_use u = {0};
    double ms = b->t_ms - a->t_ms;
    for (int i = 0; i < cl->nodes; i++) {
        u.node[i] = cpu_pct(a->node[i], b->node[i], ms);
        if (isnan(u.node[i]))
            continue;
        u.nodes_sum += u.node[i];
        double service = cpu_pct(a->service[i], b->service[i], ms), raster = cpu_pct(a->raster[i], b->raster[i], ms);
        u.service += service;
        u.raster += raster;
        u.render += u.node[i] - service - raster;
    }
    u.haproxy = cpu_pct(a->haproxy, b->haproxy, ms);
    u.self = cpu_pct(a->self, b->self, ms);
    long long dt = b->total - a->total;
    u.machine = dt > 0 ? 100.0 * (double)(b->busy - a->busy) / (double)dt * (double)sysconf(_SC_NPROCESSORS_ONLN)
                       : NAN;
    u.other = fmax(0.0, u.machine - u.nodes_sum - (isnan(u.haproxy) ? 0 : u.haproxy) - (isnan(u.self) ? 0 : u.self));
    return u;
}

/* "97 / 95" (one figure per node), into buf. */
static const char *cpu_nodes_cell(int nodes, const cpu_use *u, char *buf, size_t size)
{
    size_t n = 0;
    buf[0] = 0;
    for (int i = 0; i < nodes && n < size; i++)
        n += (size_t)snprintf(buf + n, size - n, "%s%.0f", i ? " / " : "", u->node[i]);
    return buf;
}

/* ---- opening sessions (closed loop) ---- */

typedef struct opener {
    const sl_cluster *cl;
    int port, w, h, total;
    atomic_int *next;
    sl_bench_stat times;     /* ms from connect to the first still frame; this thread's */
    int ok;
    int per_node[SL_CLUSTER_MAX_NODES];
} opener;

static void *run_opener(void *arg)
{
    opener *o = arg;
    while (atomic_fetch_add(o->next, 1) < o->total) {
        double t0 = sl_clock_ms();
        tclient c;
        int good = tclient_connect_page(&c, o->port, NULL) == 0 && tclient_hello(&c, NULL, NULL, o->w, o->h) == 0 &&
                   tclient_wait_frame(&c, 0, 1, 30000) == 0;
        if (good) {
            sl_bench_stat_add(&o->times, sl_clock_ms() - t0);
            o->ok++;
            int node = sl_cluster_node_index(o->cl, tclient_welcome_node(&c));
            if (node >= 0)
                o->per_node[node]++;
        }
        tclient_close(&c);
    }
    return NULL;
}

typedef struct open_result {
    int ok, failed, per_node[SL_CLUSTER_MAX_NODES];
    double per_s;
    sl_bench_stat times;
    cpu_use cpu;
} open_result;

/* Opens o->opens sessions through port with o->openers threads; a session that does not open
 * (or is never tried, when a thread cannot start) counts as failed. */
static void open_sessions(const sl_cluster *cl, int port, const bench_opts *o, open_result *r)
{
    memset(r, 0, sizeof *r);
    atomic_int next = 0;
    opener *op = calloc((size_t)o->openers, sizeof *op); /* 64 KiB of samples each */
    pthread_t th[32];
    int started = 0;
    cpu_sample a, b;
    cpu_take(cl, &a);
    double t0 = sl_clock_ms();
    for (int i = 0; op && i < o->openers; i++) {
        op[i] = (opener){.cl = cl, .port = port, .w = o->w, .h = o->h, .total = o->opens, .next = &next};
        if (pthread_create(&th[i], NULL, run_opener, &op[i]) != 0)
            break;
        started++;
    }
    for (int i = 0; i < started; i++)
        pthread_join(th[i], NULL);
    double wall = sl_clock_ms() - t0;
    cpu_take(cl, &b);
    for (int i = 0; i < started; i++) {
        r->ok += op[i].ok;
        for (int n = 0; n < cl->nodes; n++)
            r->per_node[n] += op[i].per_node[n];
        sl_bench_stat_merge(&r->times, &op[i].times);
    }
    free(op);
    r->failed = o->opens - r->ok;
    r->per_s = wall > 0 ? r->ok / (wall / 1000.0) : 0;
    r->cpu = cpu_between(cl, &a, &b);
}

/* ---- dragging sessions (open loop) ---- */

typedef struct bsession {
    tclient c;
    int ok;                  /* open, stream set, first still seen */
    int node;                /* index of the node serving it */
    uint32_t seq;
    double az;               /* the camera of its last `end`: what a restore must show */
    /* drag, filled by its thread */
    double start_ms, seconds;
    int frames;
    sl_bench_stat lat;
    double render_ms, encode_ms; /* sums over its interactive frames */
    double sent[DRAG_MAX_SEQ];
    int still_after;         /* the full-size still after `end` arrived (its checkpoint is written) */
    /* recovery */
    double closed_ms, back_ms, last_attempt_ms; /* from the kill; the successful attempt's own time */
    int attempts, back, same_camera, back_node;
} bsession;

static int send_camera(tclient *c, uint32_t seq, const char *phase, double az)
{
    return tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"phase\":\"%s\",\"camera\":{\"orbit\":"
                           "{\"azimuth\":%.4f,\"elevation\":20,\"distance\":2.5}}}", seq, phase, az);
}

/* A new session through `port` at w x h with the fixed interactive scale; 0 once its still is in. */
static int open_drag_session(const sl_cluster *cl, int port, int w, int h, bsession *s)
{
    memset(s, 0, sizeof *s);
    s->node = -1;
    if (tclient_connect_page(&s->c, port, NULL) != 0 || tclient_hello(&s->c, NULL, NULL, w, h) != 0)
        return -1;
    s->c.auto_ack = 1; /* as the page: ack on arrival, so the 2-frame window never throttles */
    s->node = sl_cluster_node_index(cl, tclient_welcome_node(&s->c));
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(s->c.welcome, "state"),
                                                      "version");
    uint32_t version = cJSON_IsNumber(v) ? (uint32_t)v->valuedouble : 0;
    if (tclient_send(&s->c, "{\"type\":\"set\",\"stream\":%s}", STREAM_FIXED) != 0 ||
        tclient_wait_version(&s->c, version + 1, 60000) != 0)
        return -1;
    s->ok = 1;
    return 0;
}

static void *run_drag(void *arg)
{
    bsession *s = arg;
    tclient *c = &s->c;
    while (sl_clock_ms() < s->start_ms)
        usleep(1000);
    uint32_t first = s->seq + 1;
    double next = sl_clock_ms(), t_end = s->start_ms + s->seconds * 1000.0;
    while (sl_clock_ms() < t_end) {
        double now = sl_clock_ms();
        if (now >= next) {
            send_camera(c, ++s->seq, "move", s->az += 1.5);
            if (s->seq - first < DRAG_MAX_SEQ)
                s->sent[s->seq - first] = now;
            next += 1000.0 / DRAG_HZ;
        }
        /* Round the wait up: a receive timeout under 1 ms returns at once and the loop would spin. */
        double until = fmin(next, t_end) - sl_clock_ms();
        if (until <= 0)
            continue;
        int r = tclient_next(c, (int)ceil(until) + 1, NULL);
        if (r == 0 || (r < 0 && c->closed))
            break;
        if (r != 2 || c->last.h.kind != SL_FRAME_JPEG || !(c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE) ||
            c->last.h.camera_seq < first)
            continue;
        uint32_t k = c->last.h.camera_seq - first;
        if (k < DRAG_MAX_SEQ)
            sl_bench_stat_add(&s->lat, c->last.arrival_ms - s->sent[k]);
        s->frames++;
        s->render_ms += c->last.h.render_ms;
        s->encode_ms += c->last.h.encode_ms;
    }
    send_camera(c, ++s->seq, "end", s->az);
    s->still_after = tclient_wait_frame(c, s->seq, 1, 60000) == 0;
    return NULL;
}

typedef struct drag_result {
    int opened, wanted, per_node[SL_CLUSTER_MAX_NODES];
    sl_bench_stat lat;
    double fps_mean, fps_min, fps_total;
    double render_ms, encode_ms;   /* mean per interactive frame (wall, as the node measured) */
    double cpu_ms_per_frame;       /* all nodes' CPU over the window / frames delivered */
    cpu_use cpu;
} drag_result;

/* Opens n sessions through port (kept open in ss[0..n) for the caller), drags them all at once. */
static void drag_sessions(const sl_cluster *cl, int port, const bench_opts *o, int n, bsession *ss, drag_result *r)
{
    memset(r, 0, sizeof *r);
    r->wanted = n;
    for (int i = 0; i < n; i++) {
        if (open_drag_session(cl, port, o->w, o->h, &ss[i]) == 0) {
            r->opened++;
            if (ss[i].node >= 0)
                r->per_node[ss[i].node]++;
        } else {
            fprintf(stderr, "bench-cluster: drag session %d did not open: %s\n", i, ss[i].c.err.message);
        }
    }
    pthread_t th[MAX_SESSIONS];
    int run[MAX_SESSIONS] = {0};
    double start = sl_clock_ms() + 300;
    for (int i = 0; i < n; i++) {
        if (!ss[i].ok)
            continue;
        ss[i].start_ms = start + i * (1000.0 / DRAG_HZ) / n; /* users do not move in step */
        ss[i].seconds = o->seconds;
        run[i] = pthread_create(&th[i], NULL, run_drag, &ss[i]) == 0;
    }
    while (sl_clock_ms() < start)
        usleep(1000);
    cpu_sample a, b;
    cpu_take(cl, &a);
    while (sl_clock_ms() < start + o->seconds * 1000.0)
        usleep(5000);
    cpu_take(cl, &b);
    int frames = 0, counted = 0;
    double fps_sum = 0;
    r->fps_min = NAN;
    for (int i = 0; i < n; i++) {
        if (!run[i])
            continue;
        pthread_join(th[i], NULL);
        double fps = ss[i].frames / o->seconds;
        fps_sum += fps;
        r->fps_min = isnan(r->fps_min) ? fps : fmin(r->fps_min, fps);
        frames += ss[i].frames;
        r->render_ms += ss[i].render_ms;
        r->encode_ms += ss[i].encode_ms;
        sl_bench_stat_merge(&r->lat, &ss[i].lat);
        counted++;
    }
    r->fps_mean = counted ? fps_sum / counted : 0;
    r->fps_total = frames / o->seconds;
    r->render_ms = frames ? r->render_ms / frames : NAN;
    r->encode_ms = frames ? r->encode_ms / frames : NAN;
    r->cpu = cpu_between(cl, &a, &b);
    r->cpu_ms_per_frame = frames ? r->cpu.nodes_sum / 100.0 * o->seconds * 1000.0 / frames : NAN;
}

static void close_sessions(bsession *ss, int n)
{
    for (int i = 0; i < n; i++)
        tclient_close(&ss[i].c);
}

/* ---- recovery after SIGKILL ---- */

typedef struct rejoin {
    bsession *s;
    const sl_cluster *cl;
    int port, w, h;
    double kill_ms;
} rejoin;

/* As web/protocol.js: the socket drops, the page waits 500 ms * 2^retry (at most 5 s) and
 * reconnects with /ws?session=ID and hello {session, token}; done at the first frame. 30 s at most. */
static void *run_rejoin(void *arg)
{
    rejoin *j = arg;
    bsession *s = j->s;
    while (!s->c.closed && sl_clock_ms() - j->kill_ms < 10000)
        tclient_next(&s->c, 100, NULL);
    s->closed_ms = sl_clock_ms() - j->kill_ms;
    char session[64], token[64];
    snprintf(session, sizeof session, "%s", s->c.session);
    snprintf(token, sizeof token, "%s", s->c.token);
    tclient_close(&s->c);
    for (int retry = 0; sl_clock_ms() - j->kill_ms < 30000; retry++) {
        double delay = fmin(5000.0, 500.0 * (1 << (retry < 4 ? retry : 4)));
        usleep((useconds_t)(delay * 1000.0));
        s->attempts++;
        tclient t;
        double t0 = sl_clock_ms();
        if (tclient_connect_page(&t, j->port, session) == 0 && tclient_hello(&t, session, token, j->w, j->h) == 0 &&
            tclient_wait_frame(&t, 0, 1, 10000) == 0) {
            s->back_ms = sl_clock_ms() - j->kill_ms;
            s->last_attempt_ms = sl_clock_ms() - t0;
            s->back = 1;
            s->back_node = sl_cluster_node_index(j->cl, tclient_welcome_node(&t));
            const cJSON *orbit = cJSON_GetObjectItemCaseSensitive(
                cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(t.welcome, "state"), "camera"),
                "orbit");
            const cJSON *az = cJSON_GetObjectItemCaseSensitive(orbit, "azimuth");
            s->same_camera = cJSON_IsNumber(az) && fabs(az->valuedouble - s->az) < 1e-3;
            t.auto_ack = 1;
            s->c = t; /* stays connected: a session of a live node now */
            return NULL;
        }
        fprintf(stderr, "bench-cluster: rejoin of %s, attempt %d at %.0f ms: %s\n", session, s->attempts,
                sl_clock_ms() - j->kill_ms, t.err.message[0] ? t.err.message : "no welcome or frame");
        tclient_close(&t);
    }
    return NULL;
}

typedef struct recovery_result {
    int victim, sessions, back, same_camera, elsewhere, attempts_max;
    sl_bench_stat back_ms, closed_ms, last_attempt_ms;
} recovery_result;

static void recover(sl_cluster *cl, const bench_opts *o, bsession *ss, int n, recovery_result *r)
{
    memset(r, 0, sizeof *r);
    int count[SL_CLUSTER_MAX_NODES] = {0};
    for (int i = 0; i < n; i++)
        if (ss[i].ok && ss[i].still_after && ss[i].node >= 0)
            count[ss[i].node]++;
    r->victim = 0;
    for (int k = 1; k < cl->nodes; k++)
        if (count[k] > count[r->victim])
            r->victim = k;
    usleep(1000000); /* the still frames' checkpoints reach the catalog (service thread, after the frame) */
    rejoin rj[MAX_SESSIONS];
    pthread_t th[MAX_SESSIONS];
    int run[MAX_SESSIONS] = {0};
    double kill_ms = sl_clock_ms();
    kill(cl->node_pid[r->victim], SIGKILL);
    for (int i = 0; i < n; i++) {
        if (!ss[i].ok || !ss[i].still_after || ss[i].node != r->victim)
            continue;
        r->sessions++;
        rj[i] = (rejoin){.s = &ss[i], .cl = cl, .port = cl->port, .w = o->w, .h = o->h, .kill_ms = kill_ms};
        run[i] = pthread_create(&th[i], NULL, run_rejoin, &rj[i]) == 0;
    }
    for (int i = 0; i < n; i++) {
        if (!run[i])
            continue;
        pthread_join(th[i], NULL);
        sl_bench_stat_add(&r->closed_ms, ss[i].closed_ms);
        r->attempts_max = ss[i].attempts > r->attempts_max ? ss[i].attempts : r->attempts_max;
        if (ss[i].back) {
            r->back++;
            r->same_camera += ss[i].same_camera;
            r->elsewhere += ss[i].back_node >= 0 && ss[i].back_node != r->victim;
            sl_bench_stat_add(&r->back_ms, ss[i].back_ms);
            sl_bench_stat_add(&r->last_attempt_ms, ss[i].last_attempt_ms);
        }
    }
}

/* ---- one cluster size ---- */

typedef struct node_run {
    int nodes;
    int ok;
    double cold_ms[SL_CLUSTER_MAX_NODES]; /* first session on each node: dataset load + prepare + still */
    open_result open[2];                  /* [0] through HAProxy, [1] node1 directly (N = 1 only) */
    drag_result drag[MAX_LIST][2];
    recovery_result rec;
    int have_rec;
} node_run;

static int paths_of(int nodes)
{
    return nodes == 1 ? 2 : 1;
}

static void run_nodes(const bench_opts *o, int nodes, node_run *nr)
{
    memset(nr, 0, sizeof *nr);
    nr->nodes = nodes;
    const char *args[] = {"--default-dataset", "bench", "--max-pending", "64", "--max-pending-per-address", "64",
                          "--max-clients", "128", "--max-sessions", "256", "--idle-release", "600", NULL};
    sl_cluster cl;
    if (sl_cluster_start(&cl, nodes, args) != 0 || sl_cluster_add_generator(&cl, "bench", o->dataset) != 0) {
        fprintf(stderr, "bench-cluster: the %d-node cluster did not start\n", nodes);
        sl_cluster_stop(&cl);
        return;
    }
    sl_cluster_stop_on_signal(&cl);
    /* Warm every node: its first session loads the dataset and prepares the scene, which every
     * later session on it shares (--idle-release 600 keeps it while sessions come and go). */
    for (int i = 0; i < nodes; i++) {
        tclient c;
        double t0 = sl_clock_ms();
        int good = tclient_connect_page(&c, cl.node_port[i], NULL) == 0 &&
                   tclient_hello(&c, NULL, NULL, o->w, o->h) == 0 && tclient_wait_frame(&c, 0, 1, 120000) == 0;
        nr->cold_ms[i] = good ? sl_clock_ms() - t0 : NAN;
        tclient_close(&c);
    }
    int ports[2] = {cl.port, cl.node_port[0]};
    for (int p = 0; p < paths_of(nodes); p++) {
        fprintf(stderr, "bench-cluster: %d node(s), %s: opening %d sessions\n", nodes, p ? "direct" : "HAProxy",
                o->opens);
        open_sessions(&cl, ports[p], o, &nr->open[p]);
    }
    bsession *ss = calloc(MAX_SESSIONS, sizeof *ss); /* ~100 KiB each: samples and send times */
    if (!ss) {
        sl_cluster_stop_on_signal(NULL);
        sl_cluster_stop(&cl);
        return;
    }
    int last_n = 0;
    for (int k = 0; k < o->n_sessions; k++) {
        for (int p = 0; p < paths_of(nodes); p++) {
            close_sessions(ss, last_n);
            last_n = o->sessions[k];
            fprintf(stderr, "bench-cluster: %d node(s), %s: %d sessions dragging\n", nodes, p ? "direct" : "HAProxy",
                    last_n);
            drag_sessions(&cl, ports[p], o, last_n, ss, &nr->drag[k][p]);
        }
    }
    /* Recovery needs another node to go to; with N >= 2 the last sessions came through HAProxy. */
    if (nodes >= 2 && last_n > 0) {
        fprintf(stderr, "bench-cluster: %d nodes: SIGKILL of the busiest node\n", nodes);
        recover(&cl, o, ss, last_n, &nr->rec);
        nr->have_rec = 1;
    }
    close_sessions(ss, last_n);
    free(ss);
    sl_cluster_stop_on_signal(NULL);
    sl_cluster_stop(&cl);
    nr->ok = 1;
}

/* ---- tables ---- */

static void per_node_cell(const int *per_node, int nodes, char *buf, size_t size)
{
    size_t n = 0;
    buf[0] = 0;
    for (int i = 0; i < nodes && n < size; i++)
        n += (size_t)snprintf(buf + n, size - n, "%s%d", i ? "/" : "", per_node[i]);
}

static const char *path_name(int p)
{
    return p ? "node1 directly" : "HAProxy";
}

static void print_tables(const bench_opts *o, node_run *runs, int n_runs)
{
    char a[128], b[128];
    printf("\n### Opening sessions\n\nClosed loop: %d openers, each opening one session after another (connect, "
           "`hello`, `welcome`, first full-size still), %d sessions per row, %dx%d. sessions/s = sessions opened "
           "/ wall time of the row. CPU in %% of one core over the row; client = this program; other = the "
           "machine's busy time less nodes, HAProxy and client (PostgreSQL, the kernel, other users' work).\n\n",
           o->openers, o->opens, o->w, o->h);
    printf("| nodes | path | sessions/s | open ms median / p95 | failed | sessions per node | first session on a "
           "cold node ms | CPU %% per node | nodes' CPU %% service / render / raster | CPU %% HAProxy | CPU %% client | "
           "CPU %% other | CPU %% machine (of %ld) |\n",
           sysconf(_SC_NPROCESSORS_ONLN) * 100);
    printf("| ---: | --- | ---: | ---: | ---: | --- | --- | --- | --- | ---: | ---: | ---: | ---: |\n");
    for (int r = 0; r < n_runs; r++) {
        node_run *nr = &runs[r];
        if (!nr->ok) {
            printf("| %d | - | the cluster did not start | | | | | | | |\n", nr->nodes);
            continue;
        }
        size_t n = 0;
        for (int i = 0; i < nr->nodes; i++)
            n += (size_t)snprintf(b + n, sizeof b - n, "%s%.0f", i ? " / " : "", nr->cold_ms[i]);
        for (int p = 0; p < paths_of(nr->nodes); p++) {
            open_result *op = &nr->open[p];
            char per[64], cpu[96];
            per_node_cell(op->per_node, nr->nodes, per, sizeof per);
            printf("| %d | %s | %.1f | %.0f / %.0f | %d | %s | %s | %s | %.0f / %.0f / %.0f | %.0f | %.0f | %.0f | "
                   "%.0f |\n",
                   nr->nodes, path_name(p), op->per_s, sl_bench_stat_pct(&op->times, 50),
                   sl_bench_stat_pct(&op->times, 95), op->failed, per, b,
                   cpu_nodes_cell(nr->nodes, &op->cpu, cpu, sizeof cpu), op->cpu.service, op->cpu.render,
                   op->cpu.raster, op->cpu.haproxy, op->cpu.self, op->cpu.other, op->cpu.machine);
        }
    }

    printf("\n### Dragging sessions\n\nEach session drags on its own: camera `move` at %.0f Hz for %.0f s (open "
           "loop), interactive frames at the full %dx%d (fixed scale 1, JPEG q60 4:2:0), acked on arrival. latency "
           "= frame arrival - send time of its camera seq (all sessions' frames pooled); fps = interactive frames "
           "per session per second; render / encode = the node's wall ms per frame (frame header); node CPU ms per "
           "frame = all nodes' CPU time over the window / frames delivered. CPU in %% of one core; the nodes' "
           "threads: service (sockets, protocol, catalog), render (GL calls with llvmpipe's vertex stage, "
           "readback, JPEG), raster (llvmpipe's fragment workers).\n\n",
           DRAG_HZ, o->seconds, o->w, o->h);
    printf("| nodes | path | sessions (per node) | latency median / p95 ms | fps per session mean / min | frames/s "
           "total | render / encode ms | CPU %% per node | nodes' CPU %% service / render / raster | CPU %% HAProxy | "
           "CPU %% client | CPU %% other | CPU %% machine (of %ld) | node CPU ms per frame |\n",
           sysconf(_SC_NPROCESSORS_ONLN) * 100);
    printf("| ---: | --- | --- | ---: | ---: | ---: | ---: | --- | --- | ---: | ---: | ---: | ---: | ---: |\n");
    for (int r = 0; r < n_runs; r++) {
        node_run *nr = &runs[r];
        if (!nr->ok)
            continue;
        for (int k = 0; k < o->n_sessions; k++)
            for (int p = 0; p < paths_of(nr->nodes); p++) {
                drag_result *d = &nr->drag[k][p];
                char per[64], cpu[96];
                per_node_cell(d->per_node, nr->nodes, per, sizeof per);
                snprintf(a, sizeof a, "%d%s (%s)", d->opened, d->opened < d->wanted ? " opened" : "", per);
                printf("| %d | %s | %s | %.0f / %.0f | %.1f / %.1f | %.0f | %.1f / %.1f | %s | %.0f / %.0f / %.0f | "
                       "%.0f | %.0f | %.0f | %.0f | %.1f |\n",
                       nr->nodes, path_name(p), a, sl_bench_stat_pct(&d->lat, 50), sl_bench_stat_pct(&d->lat, 95),
                       d->fps_mean, d->fps_min, d->fps_total, d->render_ms, d->encode_ms,
                       cpu_nodes_cell(nr->nodes, &d->cpu, cpu, sizeof cpu), d->cpu.service, d->cpu.render,
                       d->cpu.raster, d->cpu.haproxy, d->cpu.self, d->cpu.other, d->cpu.machine,
                       d->cpu_ms_per_frame);
            }
    }

    printf("\n### A node killed\n\nAfter the last drag (its sessions idle, their stills checkpointed), SIGKILL of "
           "the node holding the most sessions. Each of its clients rejoins as the page does "
           "(web/protocol.js: 500 ms after the drop, then 1, 2, 4, 5 s; /ws?session=ID through HAProxy, `hello` "
           "with id and token). back = kill -> first frame from another node; successful attempt = its own connect "
           "-> `welcome` -> first frame (the restore on the new node).\n\n");
    printf("| nodes | killed | its sessions | back (same camera, on another node) | kill -> drop seen ms median | "
           "back ms median / max | successful attempt ms median / max | attempts max |\n");
    printf("| ---: | --- | ---: | --- | ---: | ---: | ---: | ---: |\n");
    for (int r = 0; r < n_runs; r++) {
        node_run *nr = &runs[r];
        if (!nr->ok)
            continue;
        if (!nr->have_rec) {
            printf("| %d | - | - | no other node to restore on | | | | |\n", nr->nodes);
            continue;
        }
        recovery_result *rc = &nr->rec;
        printf("| %d | node%d | %d | %d (%d, %d) | %.0f | %.0f / %.0f | %.0f / %.0f | %d |\n", nr->nodes,
               rc->victim + 1, rc->sessions, rc->back, rc->same_camera, rc->elsewhere,
               sl_bench_stat_pct(&rc->closed_ms, 50), sl_bench_stat_pct(&rc->back_ms, 50),
               sl_bench_stat_pct(&rc->back_ms, 100), sl_bench_stat_pct(&rc->last_attempt_ms, 50),
               sl_bench_stat_pct(&rc->last_attempt_ms, 100), rc->attempts_max);
    }

    for (int r = 0; r < n_runs; r++) {
        node_run *nr = &runs[r];
        if (!nr->ok || nr->nodes != 1)
            continue;
        printf("\n### The balancer's own cost (1 node: through HAProxy / directly)\n\n");
        printf("| metric | through HAProxy | node1 directly | ratio |\n| --- | ---: | ---: | ---: |\n");
        printf("| sessions/s | %.1f | %.1f | %.2f |\n", nr->open[0].per_s, nr->open[1].per_s,
               nr->open[0].per_s / nr->open[1].per_s);
        double m0 = sl_bench_stat_pct(&nr->open[0].times, 50), m1 = sl_bench_stat_pct(&nr->open[1].times, 50);
        printf("| open ms median | %.0f | %.0f | %.2f |\n", m0, m1, m0 / m1);
        for (int k = 0; k < o->n_sessions; k++) {
            drag_result *d0 = &nr->drag[k][0], *d1 = &nr->drag[k][1];
            double l0 = sl_bench_stat_pct(&d0->lat, 50), l1 = sl_bench_stat_pct(&d1->lat, 50);
            printf("| %d dragging: latency median ms | %.0f | %.0f | %.2f |\n", o->sessions[k], l0, l1, l0 / l1);
            printf("| %d dragging: frames/s total | %.0f | %.0f | %.2f |\n", o->sessions[k], d0->fps_total,
                   d1->fps_total, d0->fps_total / d1->fps_total);
        }
        break;
    }
}

/* ---- options ---- */

/* "1,2,3" into list (each in [lo, hi], at most MAX_LIST); the count, or -1. */
static int parse_list(const char *text, int lo, int hi, int *list)
{
    int n = 0;
    const char *p = text;
    while (*p) {
        char *end = NULL;
        long v = strtol(p, &end, 10);
        if (end == p || v < lo || v > hi || n == MAX_LIST || (*end && *end != ','))
            return -1;
        list[n++] = (int)v;
        p = *end ? end + 1 : end;
    }
    return n > 0 ? n : -1;
}

static int usage(void)
{
    fprintf(stderr, "usage: bench-cluster [--nodes-list 1,2,3] [--seconds S (1..120)] [--size WxH]\n"
                    "                     [--sessions 10,30 (each 1..%d)] [--openers K (1..32)] [--opens M (1..%d)]\n"
                    "                     [--dataset GENERATOR_JSON]\n",
            MAX_SESSIONS, MAX_OPENS);
    return 2;
}

int main(int argc, char **argv)
{
    bench_opts o = {.nodes = {1, 2, 3}, .n_nodes = 3, .sessions = {10, 30}, .n_sessions = 2, .seconds = 8,
                    .w = 640, .h = 360, .openers = 8, .opens = 60, .dataset = DEFAULT_DATASET};
    for (int i = 1; i < argc; i += 2) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        char *end = NULL;
        int ok = v != NULL;
        if (ok && strcmp(a, "--nodes-list") == 0)
            ok = (o.n_nodes = parse_list(v, 1, 8, o.nodes)) > 0;
        else if (ok && strcmp(a, "--sessions") == 0)
            ok = (o.n_sessions = parse_list(v, 1, MAX_SESSIONS, o.sessions)) > 0;
        else if (ok && strcmp(a, "--seconds") == 0)
            ok = (o.seconds = strtod(v, &end)) >= 1 && o.seconds <= 120 && end != v && !*end;
        else if (ok && strcmp(a, "--size") == 0)
            ok = sscanf(v, "%dx%d", &o.w, &o.h) == 2 && o.w >= 1 && o.w <= 4096 && o.h >= 1 && o.h <= 4096;
        else if (ok && strcmp(a, "--openers") == 0)
            ok = sl_bench_parse_int(v, 1, 32, &o.openers) == 0;
        else if (ok && strcmp(a, "--opens") == 0)
            ok = sl_bench_parse_int(v, 1, MAX_OPENS, &o.opens) == 0;
        else if (ok && strcmp(a, "--dataset") == 0)
            o.dataset = v;
        else
            ok = 0;
        if (!ok)
            return usage();
    }
    signal(SIGPIPE, SIG_IGN);
    harness_default_binary_dir();
    if (!getenv("SIGHTLINE_SOURCE_DIR"))
        setenv("SIGHTLINE_SOURCE_DIR", SIGHTLINE_SOURCE_DIR, 1);

    char load0[64] = "", load1[64] = "";
    FILE *f = fopen("/proc/loadavg", "r");
    if (f && !fgets(load0, sizeof load0, f))
        load0[0] = 0;
    if (f)
        fclose(f);
    double t0 = sl_clock_ms();
    node_run *runs = calloc((size_t)o.n_nodes, sizeof *runs);
    if (!runs)
        return 1;
    for (int r = 0; r < o.n_nodes; r++)
        run_nodes(&o, o.nodes[r], &runs[r]);
    f = fopen("/proc/loadavg", "r");
    if (f && !fgets(load1, sizeof load1, f))
        load1[0] = 0;
    if (f)
        fclose(f);
    load0[strcspn(load0, "\n")] = 0;
    load1[strcspn(load1, "\n")] = 0;
    printf("sightline-server nodes behind HAProxy (scripts/cluster: PostgreSQL catalog, loopback) on %ld cores, "
           "llvmpipe. Dataset `bench` = %s with the default technique (tubes_mesh) at %dx%d. Load average before: "
           "%s; after: %s; %.0f s in all.\n",
           sysconf(_SC_NPROCESSORS_ONLN), o.dataset, o.w, o.h, load0, load1, (sl_clock_ms() - t0) / 1000.0);
    print_tables(&o, runs, o.n_nodes);
    free(runs);
    return 0;
}
