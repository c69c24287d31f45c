/* sl_params_json.h — technique parameters to and from JSON.
 *
 * Values: numbers (float, int, attribute: an index, -1 = none), true/false
 * (bool), a choice name (enum), [x, y, z] (vec3), [v, ...] of 0 to 4 numbers
 * (values; [] = auto), a transfer function as [[value, r, g, b, a], ...] or
 * {"colormap", "opacity", "range"}, a 2D one as {"range", "widgets": [[k1,
 * k2, radius, r, g, b, a], ...]} (see core/sl_params.h and PROTOCOL.md). A
 * patch is applied all-or-nothing: on the first unknown
 * name, wrong type, out-of-range value or NaN, nothing changes and err names
 * the parameter and its allowed range. Any thread.
 */
#ifndef SL_PARAMS_JSON_H
#define SL_PARAMS_JSON_H

#include <cjson/cJSON.h>

#include "core/sl_params.h"
#include "core/sl_technique.h"

sl_status sl_params_apply_json(sl_params *params, const cJSON *patch, sl_err *err);
/* {"name": value, ...} of every parameter. */
cJSON *sl_params_to_json(const sl_params *params);
/* The schema as a JSON array of {name, type, min, max, default, choices, unit, description, invalidates};
 * min/max for float, int, vec3, attribute (min -1: -1 = none) and values (per value, with max_count),
 * choices for enum, colormaps for transfer_function, max_widgets for transfer_2d. */
cJSON *sl_params_schema_json(const sl_param_def *schema, int count);
/* {name, description, dataset_kinds: [...], params: schema} */
cJSON *sl_technique_json(const sl_technique *t);

#endif
