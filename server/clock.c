/* clock.c — the server's one time source: monotonic milliseconds (sl_server.h).
 *
 * Every timestamp the server keeps (session grace, camera debounce, uptime,
 * frame latency) comes from here, so all of them compare. Any thread.
 */
#include "sl_server.h"

#include <time.h>

double sl_server_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}
