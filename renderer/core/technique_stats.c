/* technique_stats.c — the named extra numbers of sl_prepare_stats (see sl_technique.h).
 *
 * Bounded by construction: at most SL_STATS_EXTRA_MAX entries, each name cut
 * to fit its 32 bytes and always NUL-terminated, so readers (sightline-render
 * --stats) need no length checks of their own. Any thread; no GL.
 */
#include "sl_technique.h"

#include <string.h>

void sl_prepare_stats_add(sl_prepare_stats *s, const char *name, double value)
{
    if (!s || !name || s->extra_count < 0 || s->extra_count >= SL_STATS_EXTRA_MAX)
        return;
    sl_stat_value *e = &s->extra[s->extra_count++];
    size_t len = strnlen(name, sizeof e->name - 1);
    memcpy(e->name, name, len);
    memset(e->name + len, 0, sizeof e->name - len);
    e->value = value;
}
