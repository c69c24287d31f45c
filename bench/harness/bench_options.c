/* bench_options.c — the options every benchmark takes (sl_bench.h): --small, --size, --frames.
 * Strict: a malformed or out-of-range value is an error naming the option. Any thread.
 */
#include "sl_bench.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sl_bench_options_init(sl_bench_options *o, int frames)
{
    *o = (sl_bench_options){.width = 1280, .height = 720, .frames = frames > 0 ? frames : 1};
}

int sl_bench_parse_int(const char *s, long lo, long hi, int *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno != 0)
        return -1;
    if (end == s || *end || v < lo || v > hi)
        return -1;
    *out = (int)v;
    return 0;
}

int sl_bench_option(sl_bench_options *o, int argc, char **argv, int *i, const char *program)
{
    const char *a = argv[*i];
    const char *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    if (strcmp(a, "--small") == 0) {
        o->width = 256;
        o->height = 144;
        return 1;
    }
    if (strcmp(a, "--size") == 0) {
        char w[16], h[16], extra;
        if (!v || sscanf(v, "%15[0-9]x%15[0-9]%c", w, h, &extra) != 2 || sl_bench_parse_int(w, 16, 8192, &o->width) != 0 ||
            sl_bench_parse_int(h, 16, 8192, &o->height) != 0) {
            fprintf(stderr, "%s: --size wants WxH with each side in [16, 8192]\n", program);
            return -1;
        }
        *i += 1;
        return 1;
    }
    if (strcmp(a, "--frames") == 0) {
        if (!v || sl_bench_parse_int(v, 1, 100000, &o->frames) != 0) {
            fprintf(stderr, "%s: --frames wants a count in [1, 100000]\n", program);
            return -1;
        }
        *i += 1;
        return 1;
    }
    return 0;
}
