/* sl_clock.h — the one time source of Sightline: monotonic milliseconds.
 *
 * Every duration and deadline (load and prepare times, frame timing, server
 * grace periods and debounce, client timeouts, tests and benchmarks) reads
 * this clock, so any two readings compare. It is CLOCK_MONOTONIC: it never
 * jumps with the wall clock, and its origin is arbitrary, so it measures
 * intervals and deadlines, never dates. Any thread; no state.
 */
#ifndef SL_CLOCK_H
#define SL_CLOCK_H

#include <time.h>

/* The POSIX clock behind sl_clock_ms; a condition variable that waits for
 * sl_clock_deadline must be set to it (pthread_condattr_setclock). */
#define SL_CLOCK_ID CLOCK_MONOTONIC

/* Milliseconds on SL_CLOCK_ID, with sub-microsecond resolution. */
double sl_clock_ms(void);

/* The absolute SL_CLOCK_ID time `ms_from_now` milliseconds ahead (clamped
 * to [0, 1e12]; NaN counts as 0), for waits that take a deadline such as
 * pthread_cond_timedwait. */
struct timespec sl_clock_deadline(double ms_from_now);

#endif
