/* test_technique.c — the technique table's optional parts (core/sl_technique.h).
 *
 * sl_prepare_stats_add: entries in order, the count capped at
 * SL_STATS_EXTRA_MAX (the 49th is dropped, nothing past the array is
 * written), names cut to 31 bytes and always terminated, NULL guarded.
 * Export: every registered technique offers both export_ext (".xyz") and
 * export_geometry or neither, and sl_technique_exporters lists exactly those
 * that do ("none yet" when none), cut safely to a small buffer. No GL.
 */
#include <string.h>

#include "core/sl_technique.h"
#include "sl_test.h"

static void test_stats_add(void)
{
    sl_prepare_stats s;
    memset(&s, 0xab, sizeof s);
    s.extra_count = 0;
    sl_prepare_stats_add(&s, "set0.particles", 41234.0);
    sl_prepare_stats_add(&s, "", -1.5);
    SL_CHECK(s.extra_count == 2);
    SL_CHECK(strcmp(s.extra[0].name, "set0.particles") == 0 && s.extra[0].value == 41234.0);
    SL_CHECK(s.extra[1].name[0] == '\0' && s.extra[1].value == -1.5);
    /* The rest of a name's bytes are zero, so two equal stats compare equal bytewise. */
    int zero_tail = 1;
    for (size_t k = strlen("set0.particles"); k < sizeof s.extra[0].name; k++)
        zero_tail &= s.extra[0].name[k] == '\0';
    SL_CHECK(zero_tail);

    /* A name of 40 bytes keeps its first 31 and is terminated. */
    const char *long_name = "abcdefghijklmnopqrstuvwxyz0123456789ABCD";
    sl_prepare_stats_add(&s, long_name, 3.0);
    SL_CHECK(s.extra_count == 3);
    SL_CHECK(strlen(s.extra[2].name) == sizeof s.extra[2].name - 1);
    SL_CHECK(strncmp(s.extra[2].name, long_name, sizeof s.extra[2].name - 1) == 0);

    /* Up to the cap, then silently nothing. */
    for (int k = s.extra_count; k < SL_STATS_EXTRA_MAX + 5; k++)
        sl_prepare_stats_add(&s, "n", (double)k);
    SL_CHECK_MSG(s.extra_count == SL_STATS_EXTRA_MAX, "extra_count %d", s.extra_count);
    SL_CHECK(s.extra[SL_STATS_EXTRA_MAX - 1].value == SL_STATS_EXTRA_MAX - 1);
    /* A bad count (a technique's own bug) or NULLs change nothing. */
    s.extra_count = -3;
    sl_prepare_stats_add(&s, "x", 1.0);
    SL_CHECK(s.extra_count == -3);
    s.extra_count = 0;
    sl_prepare_stats_add(&s, NULL, 1.0);
    sl_prepare_stats_add(NULL, "x", 1.0);
    SL_CHECK(s.extra_count == 0);

    /* Zero-initialised stats (what every technique without extras reports) hold none. */
    sl_prepare_stats z = {0};
    SL_CHECK(z.extra_count == 0);
    sl_prepare_stats_add(&z, "one", 1.0);
    SL_CHECK(z.extra_count == 1 && strcmp(z.extra[0].name, "one") == 0);
}

static void test_exporters(void)
{
    int n = 0, exporting = 0;
    const sl_technique *const *list = sl_technique_list(&n);
    char names[1024];
    sl_technique_exporters(names, sizeof names);
    for (int i = 0; i < n; i++) {
        const sl_technique *t = list[i];
        int has_ext = t->export_ext != NULL, has_writer = t->export_geometry != NULL;
        SL_CHECK_MSG(has_ext == has_writer, "%s: export_ext and export_geometry go together", t->name);
        SL_CHECK(sl_technique_exports(t) == (has_ext && has_writer));
        if (has_ext)
            SL_CHECK_MSG(t->export_ext[0] == '.' && strlen(t->export_ext) >= 2 && !strchr(t->export_ext + 1, '.'),
                         "%s: export_ext '%s' is not one extension like \".csv\"", t->name, t->export_ext);
        if (sl_technique_exports(t)) {
            exporting++;
            SL_CHECK_MSG(strstr(names, t->name) != NULL, "exporters '%s' lack %s", names, t->name);
        }
    }
    if (!exporting)
        SL_CHECK_MSG(strcmp(names, "none yet") == 0, "exporters '%s'", names);
    SL_CHECK(sl_technique_exports(NULL) == 0);
    /* A buffer too small is cut, never overrun. */
    char tiny[4] = "zzz";
    sl_technique_exporters(tiny, sizeof tiny);
    SL_CHECK(strlen(tiny) <= 3 && strncmp(tiny, names, strlen(tiny)) == 0);
}

int main(void)
{
    test_stats_add();
    test_exporters();
    SL_TEST_END();
}
