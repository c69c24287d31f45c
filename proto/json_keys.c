/* json_keys.c — sl_json_keys.h: the one rule for unknown fields in scene and camera objects. */
#include "sl_json_keys.h"

#include <string.h>

static int key_allowed(const char *key, const char *const *allowed)
{
    for (int i = 0; allowed[i]; i++)
        if (strcmp(key, allowed[i]) == 0)
            return 1;
    return 0;
}

sl_status sl_json_check_keys(const cJSON *obj, const char *path, const char *const *allowed, sl_err *err)
{
    for (const cJSON *c = obj->child; c; c = c->next)
        if (!c->string || !key_allowed(c->string, allowed)) {
            char list[256] = "";
            for (int i = 0; allowed[i]; i++) {
                strncat(list, allowed[i], sizeof list - strlen(list) - 1);
                if (allowed[i + 1])
                    strncat(list, ", ", sizeof list - strlen(list) - 1);
            }
            return sl_err_set(err, SL_ERR_INVALID, "%s%s%.64s: unknown field (allowed: %s)",
                              path, *path ? "." : "", c->string ? c->string : "?", list);
        }
    return SL_OK;
}
