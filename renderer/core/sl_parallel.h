/* sl_parallel.h — run N independent jobs (screen tiles) on all of the machine's cores.
 *
 * sl_parallel_threads() is the worker count: $SIGHTLINE_THREADS when it is an integer
 * in 1..SL_PARALLEL_MAX_THREADS, else the cores this process may run on. sl_parallel_run
 * starts that many threads (the caller's thread is one of them), each taking the next job
 * index from a shared counter until none is left, and returns when all jobs are done. Jobs
 * must write disjoint memory; fn gets the worker's index (0..threads-1) for per-worker
 * scratch. Threads are started per call: a few tens of microseconds against frames of
 * milliseconds. Call from one thread at a time per ctx; fn must not call sl_parallel_run.
 */
#ifndef SL_PARALLEL_H
#define SL_PARALLEL_H

#define SL_PARALLEL_MAX_THREADS 256

int sl_parallel_threads(void);

typedef void (*sl_parallel_fn)(void *ctx, int job, int worker);

/* Runs jobs 0..job_count-1 on min(threads, job_count) workers (threads <= 0: sl_parallel_threads());
 * returns the number of workers that ran at least one job. If a thread cannot be started,
 * the others (at least the caller's) do its share. */
int sl_parallel_run(int job_count, int threads, sl_parallel_fn fn, void *ctx);

#endif
