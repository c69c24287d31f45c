/* test_clock.c — the one monotonic clock (core/sl_clock.h).
 *
 * Readings never go backwards over 100000 calls; a 20 ms sleep measures at
 * least 20 ms and not wildly more; sl_clock_deadline lands `ms` ahead on the
 * same clock, clamps negative, NaN and huge arguments, always gives a
 * normalized timespec, and a condition variable set to SL_CLOCK_ID waits
 * until it.
 */
#include <math.h>
#include <pthread.h>
#include <time.h>

#include "core/sl_clock.h"
#include "sl_test.h"

static double ts_ms(struct timespec ts)
{
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static void test_monotonic(void)
{
    double prev = sl_clock_ms();
    int backwards = 0;
    for (int i = 0; i < 100000; i++) {
        double t = sl_clock_ms();
        backwards += t < prev;
        prev = t;
    }
    SL_CHECK(backwards == 0);
    SL_CHECK(prev > 0.0 && isfinite(prev));
}

static void test_interval(void)
{
    double t0 = sl_clock_ms();
    struct timespec d = {.tv_sec = 0, .tv_nsec = 20 * 1000 * 1000};
    while (nanosleep(&d, &d) != 0)
        ;
    double ms = sl_clock_ms() - t0;
    SL_CHECK_MSG(ms >= 20.0 && ms < 2000.0, "a 20 ms sleep measured %.3f ms", ms);
}

static void test_deadline(void)
{
    double now = sl_clock_ms();
    struct timespec ts = sl_clock_deadline(1500.25);
    double ahead = ts_ms(ts) - now;
    SL_CHECK_MSG(ahead >= 1500.0 && ahead < 1600.0, "deadline 1500.25 ms ahead landed %.3f ms ahead", ahead);
    SL_CHECK(ts.tv_nsec >= 0 && ts.tv_nsec < 1000000000L);
    const double odd[] = {-5.0, NAN, 0.0, 999.9999, 1e300};
    for (int i = 0; i < 5; i++) {
        now = sl_clock_ms();
        ts = sl_clock_deadline(odd[i]);
        ahead = ts_ms(ts) - now;
        SL_CHECK(ts.tv_nsec >= 0 && ts.tv_nsec < 1000000000L);
        if (i < 3)
            SL_CHECK_MSG(ahead >= -0.001 && ahead < 100.0, "deadline(%g) landed %.3f ms ahead", odd[i], ahead);
        else if (i == 3)
            SL_CHECK_MSG(ahead >= 999.0 && ahead < 1100.0, "deadline(%g) landed %.3f ms ahead", odd[i], ahead);
        else
            SL_CHECK_MSG(ahead > 0.99e12 && ahead < 1.01e12, "deadline(1e300) is clamped to 1e12 ms, got %.6g", ahead);
    }
}

/* A timed wait on a condition variable of SL_CLOCK_ID returns at the deadline. */
static void test_timed_wait(void)
{
    pthread_mutex_t m = PTHREAD_MUTEX_INITIALIZER;
    pthread_cond_t c;
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    SL_CHECK(pthread_condattr_setclock(&ca, SL_CLOCK_ID) == 0);
    pthread_cond_init(&c, &ca);
    pthread_condattr_destroy(&ca);
    pthread_mutex_lock(&m);
    double t0 = sl_clock_ms();
    struct timespec ts = sl_clock_deadline(30.0);
    int rc = 0;
    while (rc == 0)
        rc = pthread_cond_timedwait(&c, &m, &ts);
    double waited = sl_clock_ms() - t0;
    pthread_mutex_unlock(&m);
    pthread_cond_destroy(&c);
    SL_CHECK_MSG(waited >= 29.9 && waited < 2000.0, "a 30 ms timed wait took %.3f ms", waited);
}

int main(void)
{
    test_monotonic();
    test_interval();
    test_deadline();
    test_timed_wait();
    SL_TEST_END();
}
