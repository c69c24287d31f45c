/* server_metrics.c — the metrics' histograms and the names of the executions a frame
 * can come from (sl_server.h). Written under sl_server.lock by whichever thread
 * measured (render, loader callbacks); read by net/http.c's /metrics.
 */
#include "sl_server.h"

#include <string.h>

const double sl_histogram_bucket_ms[SL_HIST_BUCKETS - 1] = {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 5000};

const char *const sl_metric_backend_names[SL_METRIC_BACKENDS] = {"gl", "embree", "cpu", "single"};

int sl_metric_backend_index(const char *backend)
{
    for (int i = 0; backend && i < SL_METRIC_BACKENDS - 1; i++)
        if (!strcmp(backend, sl_metric_backend_names[i]))
            return i;
    return SL_METRIC_BACKENDS - 1;
}

void sl_histogram_add(sl_histogram *h, double ms)
{
    for (int i = 0; i < SL_HIST_BUCKETS - 1; i++)
        if (ms <= sl_histogram_bucket_ms[i])
            h->counts[i]++;
    h->counts[SL_HIST_BUCKETS - 1]++;
    h->sum += ms;
    h->total++;
}
