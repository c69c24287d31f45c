/* dataset_open.c — built-in names, JSON and paths to datasets (see sl_dataset_open.h). */
#include "sl_dataset_open.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "sl_generate.h"
#include "sl_load.h"

/* JSON text: inline Hermite data or a generator call. */
static sl_status open_json(const char *text, sl_dataset **out, sl_err *err)
{
    cJSON *root = cJSON_Parse(text);
    if (!root)
        return sl_err_set(err, SL_ERR_INVALID, "dataset JSON does not parse near '%.40s'",
                          cJSON_GetErrorPtr() ? cJSON_GetErrorPtr() : text);
    sl_status st = sl_hermite_json_detect(root) ? sl_hermite_dataset_from_json(root, "inline", out, err)
                                                : sl_generate_json(text, out, err);
    cJSON_Delete(root);
    return st;
}

/* 1 when real (a realpath) lies inside directory dir (compared by realpath). */
static int inside(const char *real, const char *dir)
{
    char rdir[PATH_MAX];
    if (!realpath(dir, rdir))
        return 0;
    size_t n = strlen(rdir);
    return strncmp(real, rdir, n) == 0 && (real[n] == '/' || real[n] == '\0' || (n == 1 && rdir[0] == '/'));
}

static sl_status not_a_name(const char *name, sl_err *err)
{
    int n;
    const sl_builtin_dataset *list = sl_builtin_datasets(&n);
    char names[512] = "";
    for (int i = 0; i < n; i++) {
        strncat(names, list[i].name, sizeof names - strlen(names) - 1);
        if (i + 1 < n)
            strncat(names, ", ", sizeof names - strlen(names) - 1);
    }
    return sl_err_set(err, SL_ERR_INVALID, "dataset '%.128s' is neither a built-in dataset (%s) nor a file", name,
                      names);
}

sl_status sl_dataset_open(const char *source, const sl_dataset_dirs *dirs, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    if (!source || !source[0])
        return sl_err_set(err, SL_ERR_INVALID, "dataset: empty source");
    const char *builtin = sl_builtin_lookup(source);
    if (builtin)
        return sl_generate_json(builtin, out, err);
    if (source[strspn(source, " \t\r\n")] == '{')
        return open_json(source, out, err);
    int count = dirs ? dirs->count : 0;
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s", source);
    /* Relative: the first directory holding it; when none does, the first's (for the error). */
    int found = 0;
    for (int i = 0; source[0] != '/' && i < count && !found; i++) {
        char candidate[PATH_MAX];
        if (snprintf(candidate, sizeof candidate, "%s/%s", dirs->dirs[i], source) >= (int)sizeof candidate)
            continue;
        found = access(candidate, F_OK) == 0;
        if (found || i == 0)
            memcpy(path, candidate, sizeof path);
    }
    if (!strchr(source, '/') && !strchr(source, '.') && access(path, F_OK) != 0)
        return not_a_name(source, err); /* no path, no extension, no such file: a mistyped name */
    if (dirs && dirs->confine) {
        char real[PATH_MAX];
        if (!realpath(path, real))
            return sl_err_set(err, SL_ERR_IO, "dataset %.200s: no such file", source);
        int ok = 0;
        for (int i = 0; i < count && !ok; i++)
            ok = inside(real, dirs->dirs[i]);
        if (!ok)
            return sl_err_set(err, SL_ERR_INVALID, "dataset %.200s is outside the allowed data directories", source);
        return sl_load_file(real, out, err);
    }
    return sl_load_file(path, out, err);
}
