/* sl_clock.c — monotonic milliseconds and deadlines (see sl_clock.h). Any thread. */
#include "sl_clock.h"

double sl_clock_ms(void)
{
    struct timespec ts;
    clock_gettime(SL_CLOCK_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

struct timespec sl_clock_deadline(double ms_from_now)
{
    struct timespec ts;
    clock_gettime(SL_CLOCK_ID, &ts);
    if (!(ms_from_now > 0.0))
        ms_from_now = 0.0;
    else if (ms_from_now > 1e12) /* ~30 years: keeps the nanoseconds below in range */
        ms_from_now = 1e12;
    long long ns = ts.tv_nsec + (long long)(ms_from_now * 1e6);
    ts.tv_sec += (time_t)(ns / 1000000000LL);
    ts.tv_nsec = (long)(ns % 1000000000LL);
    return ts;
}
