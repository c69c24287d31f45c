/* lr_lookup_shared.c — what the look-up builders share (lr_lookup_internal.h): the sorted
 * distinct element faces of a direction and the per-tree depth statistics. Below the builders
 * and lr_lookup.c, knowing neither. Any thread; no GL. */
#include "lr_lookup_internal.h"

#include <stdlib.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double *sl_lr_lookup_distinct_faces(const sl_lr_volume *lr, int d, size_t *n)
{
    double *v = malloc(2 * lr->element_count * sizeof *v + sizeof *v);
    if (!v)
        return NULL;
    for (size_t i = 0; i < lr->element_count; i++) {
        v[2 * i] = lr->elements[i].lo[d];
        v[2 * i + 1] = lr->elements[i].hi[d];
    }
    qsort(v, 2 * lr->element_count, sizeof *v, cmp_double);
    size_t m = 0;
    for (size_t i = 0; i < 2 * lr->element_count; i++)
        if (m == 0 || v[i] != v[m - 1])
            v[m++] = v[i];
    *n = m;
    return v;
}

void sl_lr_lookup_depth_stats(sl_lr_lookup_stats *s, const int *depth, size_t trees)
{
    s->trees = trees;
    s->depth_min = trees ? depth[0] : 0;
    s->depth_max = s->depth_min;
    double sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < trees; i++) {
        if (depth[i] < s->depth_min)
            s->depth_min = depth[i];
        if (depth[i] > s->depth_max)
            s->depth_max = depth[i];
        sum += depth[i];
    }
    s->depth_mean = trees ? sum / (double)trees : 0.0;
    for (size_t i = 0; i < trees; i++)
        sum2 += (depth[i] - s->depth_mean) * (depth[i] - s->depth_mean);
    s->depth_var = trees ? sum2 / (double)trees : 0.0;
}
