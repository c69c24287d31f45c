/* parallel.c — sl_parallel.h: a job counter shared by threads started per call. */
#define _GNU_SOURCE
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

#include "sl_parallel.h"

int sl_parallel_threads(void)
{
    const char *env = getenv("SIGHTLINE_THREADS");
    if (env && *env) {
        char *end;
        long v = strtol(env, &end, 10);
        if (!*end && v >= 1 && v <= SL_PARALLEL_MAX_THREADS)
            return (int)v;
    }
    cpu_set_t set;
    int n = 0;
    if (sched_getaffinity(0, sizeof set, &set) == 0)
        n = CPU_COUNT(&set);
    if (n <= 0)
        n = (int)sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (n > SL_PARALLEL_MAX_THREADS ? SL_PARALLEL_MAX_THREADS : n);
}

typedef struct run_shared {
    sl_parallel_fn fn;
    void *ctx;
    int job_count;
    atomic_int next;
    atomic_int active; /* workers that ran at least one job */
} run_shared;

typedef struct worker_arg {
    run_shared *shared;
    int index;
} worker_arg;

static void *worker_main(void *opaque)
{
    worker_arg *w = opaque;
    run_shared *s = w->shared;
    int ran = 0;
    for (;;) {
        int job = atomic_fetch_add(&s->next, 1);
        if (job >= s->job_count)
            break;
        s->fn(s->ctx, job, w->index);
        ran = 1;
    }
    if (ran)
        atomic_fetch_add(&s->active, 1);
    return NULL;
}

int sl_parallel_run(int job_count, int threads, sl_parallel_fn fn, void *ctx)
{
    if (job_count <= 0)
        return 0;
    if (threads <= 0)
        threads = sl_parallel_threads();
    if (threads > job_count)
        threads = job_count;
    if (threads > SL_PARALLEL_MAX_THREADS)
        threads = SL_PARALLEL_MAX_THREADS;
    run_shared shared = {.fn = fn, .ctx = ctx, .job_count = job_count};
    atomic_init(&shared.next, 0);
    atomic_init(&shared.active, 0);
    pthread_t tid[SL_PARALLEL_MAX_THREADS];
    worker_arg args[SL_PARALLEL_MAX_THREADS];
    int started[SL_PARALLEL_MAX_THREADS] = {0};
    for (int k = 1; k < threads; k++) {
        args[k] = (worker_arg){&shared, k};
        started[k] = pthread_create(&tid[k], NULL, worker_main, &args[k]) == 0;
    }
    args[0] = (worker_arg){&shared, 0};
    worker_main(&args[0]);
    for (int k = 1; k < threads; k++)
        if (started[k])
            pthread_join(tid[k], NULL);
    return atomic_load(&shared.active);
}
