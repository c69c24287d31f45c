/* sl_json_keys.h — the allowed keys of a JSON object (scene documents, cameras).
 *
 * sl_json_check_keys: SL_ERR_INVALID naming the first key of obj not in `allowed` (a NULL-ended
 * list) by its JSON path (path "" is the root) and listing the allowed ones. Any thread.
 */
#ifndef SL_JSON_KEYS_H
#define SL_JSON_KEYS_H

#include <cjson/cJSON.h>

#include "core/sl_status.h"

sl_status sl_json_check_keys(const cJSON *obj, const char *path, const char *const *allowed, sl_err *err);

#endif
