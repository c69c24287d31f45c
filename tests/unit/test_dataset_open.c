/* test_dataset_open.c — sl_dataset_open (renderer/data/sl_dataset_open.h):
 * built-in names, generator and Hermite JSON, relative paths looked up in
 * the directories in order, the mistyped-name message, and confinement
 * (a path outside the allowed directories, by "../" or through a symlink,
 * is refused; the same file inside is opened). Files in a temporary
 * directory; removed at the end. Single thread; no GL.
 */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "data/sl_dataset_open.h"
#include "sl_test.h"

static const char *hermite = "{\"nodes\":[{\"p\":[0,0,0],\"t\":[1,0,0],\"r\":0.1},"
                             "{\"p\":[1,0,0],\"t\":[1,0,0],\"r\":0.1}],\"segments\":[[0,1]]}";

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    SL_CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static sl_status open_in(const char *source, const char *const *dirs, int count, int confine, sl_dataset **ds,
                         sl_err *err)
{
    sl_dataset_dirs where = {.dirs = dirs, .count = count, .confine = confine};
    return sl_dataset_open(source, &where, ds, err);
}

int main(void)
{
    sl_err err;
    sl_dataset *ds = NULL;
    /* Built-in name and generator JSON. */
    SL_CHECK(sl_dataset_open("torus", NULL, &ds, &err) == SL_OK && ds && ds->kind == SL_DATASET_VOLUME);
    sl_dataset_destroy(ds);
    SL_CHECK(sl_dataset_open(" {\"generator\":\"tornado\",\"lines\":5,\"seed\":1}", NULL, &ds, &err) == SL_OK && ds &&
             ds->lines.line_count == 5);
    sl_dataset_destroy(ds);
    SL_CHECK(sl_dataset_open(hermite, NULL, &ds, &err) == SL_OK && ds && ds->kind == SL_DATASET_LINES);
    sl_dataset_destroy(ds);
    SL_CHECK(sl_dataset_open("{\"generator\":", NULL, &ds, &err) == SL_ERR_INVALID && !ds);
    SL_CHECK_MSG(strstr(err.message, "does not parse") != NULL, "%s", err.message);
    /* A mistyped name lists the built-ins. */
    SL_CHECK(sl_dataset_open("tornadoo", NULL, &ds, &err) == SL_ERR_INVALID && !ds);
    SL_CHECK_MSG(strstr(err.message, "neither a built-in dataset") && strstr(err.message, "tornado"), "%s",
                 err.message);

    /* root/a, root/b (holding seg.json), root/outside.json, root/a/link.json -> ../outside.json */
    char root[] = "/tmp/sl-dataset-open-XXXXXX";
    SL_CHECK(mkdtemp(root) != NULL);
    /* a and b are short (root is 27 bytes), so gcc can see that seg and link fit. */
    char a[256], b[256], seg[PATH_MAX], outside[PATH_MAX], link[PATH_MAX];
    snprintf(a, sizeof a, "%s/a", root);
    snprintf(b, sizeof b, "%s/b", root);
    snprintf(seg, sizeof seg, "%s/b/seg.json", root); /* from root (known length), not b: gcc -Wformat-truncation */
    snprintf(outside, sizeof outside, "%s/outside.json", root);
    snprintf(link, sizeof link, "%s/a/link.json", root);
    SL_CHECK(mkdir(a, 0700) == 0 && mkdir(b, 0700) == 0);
    write_text(seg, hermite);
    write_text(outside, hermite);
    SL_CHECK(symlink("../outside.json", link) == 0);
    const char *dirs[2] = {a, b};

    /* Relative: found in the second directory; confined or not. */
    SL_CHECK(open_in("seg.json", dirs, 2, 0, &ds, &err) == SL_OK && ds);
    sl_dataset_destroy(ds);
    SL_CHECK(open_in("seg.json", dirs, 2, 1, &ds, &err) == SL_OK && ds);
    sl_dataset_destroy(ds);
    /* Absolute inside: opened; outside by ../ or through a symlink: refused when confined. */
    SL_CHECK(open_in(seg, dirs, 2, 1, &ds, &err) == SL_OK && ds);
    sl_dataset_destroy(ds);
    SL_CHECK(open_in("../outside.json", dirs, 2, 1, &ds, &err) == SL_ERR_INVALID && !ds);
    SL_CHECK_MSG(strstr(err.message, "outside the allowed data directories") != NULL, "%s", err.message);
    SL_CHECK(open_in("link.json", dirs, 2, 1, &ds, &err) == SL_ERR_INVALID && !ds);
    SL_CHECK(open_in(outside, dirs, 2, 1, &ds, &err) == SL_ERR_INVALID && !ds);
    /* Not confined (the CLI): the same paths open. */
    SL_CHECK(open_in("link.json", dirs, 2, 0, &ds, &err) == SL_OK && ds);
    sl_dataset_destroy(ds);
    /* A missing file is named as looked up in the first directory. */
    SL_CHECK(open_in("missing.json", dirs, 2, 0, &ds, &err) != SL_OK && !ds);
    SL_CHECK_MSG(strstr(err.message, "missing.json") != NULL, "%s", err.message);
    SL_CHECK(open_in("missing.json", dirs, 2, 1, &ds, &err) == SL_ERR_IO && !ds);

    unlink(link);
    unlink(seg);
    unlink(outside);
    rmdir(a);
    rmdir(b);
    rmdir(root);
    SL_TEST_END();
}
