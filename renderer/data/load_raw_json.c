/* load_raw_json.c — a headerless raw volume described by a JSON sidecar:
 *
 *   {"raw": "head.raw", "dims": [x, y, z], "type": "u8|u16|s16|f32",
 *    "spacing": [sx, sy, sz], "origin": [ox, oy, oz],
 *    "endian": "little|big", "components": 1|3}
 *
 * Keys (case-sensitive; these seven only):
 *   raw        required  file name, resolved beside the JSON (no "..", an
 *                        absolute name must lie in the JSON's folder);
 *                        a name ending in ".gz" is gunzipped
 *   dims       required  voxels along x, y, z (whole numbers >= 1), x fastest
 *   type       required  sample type: u8, u16, s16 or f32
 *   spacing    optional  world units between voxel centres, > 0 (default 1 1 1)
 *   origin     optional  world position of voxel (0,0,0) (default 0 0 0)
 *   endian     optional  "little" (default) or "big"
 *   components optional  1 (default) or 3 (interleaved vector field, f32)
 * Any other key is an error naming it, so a typo ("endianness") cannot
 * silently give the default. The raw file must hold exactly dims x
 * components x type bytes (inflated, for ".gz").
 * Does not read any other layout (planar components, padding, headers).
 * Any thread; no GL. Invariant: the raw file is never read past the size
 * the JSON describes (a ".gz" file past sl_load_gzip_input_bound of it).
 */
#include "load_common.h"

#include <cjson/cJSON.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Reads a 3-number array; 0 when absent (values untouched), -1 when malformed. */
static int get_vec3(const cJSON *root, const char *key, double v[3])
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(root, key);
    if (!a)
        return 0;
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != 3)
        return -1;
    for (int i = 0; i < 3; i++) {
        const cJSON *x = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble))
            return -1;
        v[i] = x->valuedouble;
    }
    return 1;
}

sl_status sl_load_raw_json(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *name = sl_load_display_name(path);
    cJSON *root = cJSON_ParseWithLength((const char *)data, size);
    sl_dataset *ds = NULL;
    uint8_t *raw = NULL, *inflated = NULL;
    sl_status st = SL_OK;
    if (!root || !cJSON_IsObject(root)) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: not a JSON object", name);
        goto fail;
    }
    static const char *const keys[] = {"raw", "dims", "type", "spacing", "origin", "endian", "components"};
    for (const cJSON *item = root->child; item; item = item->next) {
        size_t k = 0;
        while (k < sizeof keys / sizeof keys[0] && strcmp(item->string, keys[k]) != 0)
            k++;
        if (k == sizeof keys / sizeof keys[0]) {
            st = sl_err_set(err, SL_ERR_FORMAT,
                            "%s: unknown key '%.64s' (the keys are raw, dims, type, spacing, origin, endian, "
                            "components)",
                            name, item->string);
            goto fail;
        }
        for (const cJSON *other = root->child; other != item; other = other->next)
            if (strcmp(other->string, item->string) == 0) {
                st = sl_err_set(err, SL_ERR_FORMAT, "%s: key '%s' appears twice", name, item->string);
                goto fail;
            }
    }
    const cJSON *raw_item = cJSON_GetObjectItemCaseSensitive(root, "raw");
    if (!cJSON_IsString(raw_item) || !raw_item->valuestring[0]) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'raw' (the raw file's name) is missing or not a string", name);
        goto fail;
    }
    double dimd[3];
    if (get_vec3(root, "dims", dimd) != 1) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'dims' must be an array of 3 numbers", name);
        goto fail;
    }
    int dims[3];
    for (int c = 0; c < 3; c++) {
        if (dimd[c] != floor(dimd[c]) || dimd[c] < 1) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'dims': axis %d is %g, must be a whole number >= 1", name, c,
                            dimd[c]);
            goto fail;
        }
        if (dimd[c] > INT_MAX) {
            st = sl_err_set(err, SL_ERR_LIMIT, "%s: field 'dims': axis %d is %.0f, above the limit of %d", name, c,
                            dimd[c], INT_MAX);
            goto fail;
        }
        dims[c] = (int)dimd[c];
    }
    static const struct { const char *name; sl_src_type type; } types[] = {
        {"u8", SL_SRC_U8}, {"u16", SL_SRC_U16}, {"s16", SL_SRC_S16}, {"f32", SL_SRC_F32}};
    const cJSON *type_item = cJSON_GetObjectItemCaseSensitive(root, "type");
    int ti = -1;
    for (int i = 0; i < 4 && cJSON_IsString(type_item); i++)
        if (strcmp(type_item->valuestring, types[i].name) == 0)
            ti = i;
    if (ti < 0) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'type' is missing or not one of u8, u16, s16, f32", name);
        goto fail;
    }
    sl_src_type type = types[ti].type;
    double spacing[3] = {1.0, 1.0, 1.0}, origin[3] = {0.0, 0.0, 0.0};
    if (get_vec3(root, "spacing", spacing) < 0 || !(spacing[0] > 0 && spacing[1] > 0 && spacing[2] > 0)) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'spacing' must be an array of 3 finite numbers > 0", name);
        goto fail;
    }
    if (get_vec3(root, "origin", origin) < 0) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'origin' must be an array of 3 finite numbers", name);
        goto fail;
    }
    int big = 0;
    const cJSON *endian = cJSON_GetObjectItemCaseSensitive(root, "endian");
    if (endian) {
        if (cJSON_IsString(endian) && strcmp(endian->valuestring, "little") == 0)
            big = 0;
        else if (cJSON_IsString(endian) && strcmp(endian->valuestring, "big") == 0)
            big = 1;
        else {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'endian' must be \"little\" or \"big\"", name);
            goto fail;
        }
    }
    int comps = 1;
    const cJSON *comp_item = cJSON_GetObjectItemCaseSensitive(root, "components");
    if (comp_item) {
        if (!cJSON_IsNumber(comp_item) || (comp_item->valuedouble != 1 && comp_item->valuedouble != 3)) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: field 'components' must be 1 or 3", name);
            goto fail;
        }
        comps = (int)comp_item->valuedouble;
    }
    unsigned long long values = (unsigned long long)comps;
    for (int c = 0; c < 3; c++) {
        values *= (unsigned long long)dims[c];
        if (values > SL_MAX_VOXELS) {
            st = sl_err_set(err, SL_ERR_LIMIT, "%s: field 'dims' is %dx%dx%d x%d, above the limit of %llu values", name,
                            dims[0], dims[1], dims[2], comps, SL_MAX_VOXELS);
            goto fail;
        }
    }
    size_t n = (size_t)values;
    size_t needed = n * sl_src_type_size(type);

    char resolved[PATH_MAX];
    st = sl_load_resolve_sibling(path, raw_item->valuestring, "raw", resolved, sizeof resolved, err);
    if (st != SL_OK)
        goto fail;
    size_t len = strlen(resolved), raw_size = 0;
    int gz = len > 3 && strcmp(resolved + len - 3, ".gz") == 0;
    uint64_t limit = gz ? sl_load_gzip_input_bound(needed) : needed;
    st = sl_load_read_raw(resolved, limit, &raw, &raw_size, err);
    if (st == SL_ERR_LIMIT) {
        st = sl_err_set(err, SL_ERR_FORMAT,
                        gz ? "%s: field 'raw': %s is larger than a gzip stream of the %zu bytes fields 'dims', 'type' "
                             "and 'components' give can be"
                           : "%s: field 'raw': %s is larger than the %zu bytes fields 'dims', 'type' and "
                             "'components' give",
                        name, resolved, needed);
        goto fail;
    }
    if (st != SL_OK) {
        sl_err_prefix(err, "%s: field 'raw'", name);
        goto fail;
    }
    const uint8_t *src = raw;
    size_t src_size = raw_size;
    if (gz) {
        st = sl_gunzip(raw, raw_size, needed, &inflated, &src_size, err);
        if (st != SL_OK) {
            sl_err_prefix(err, "%s: field 'raw': %s (%zu bytes expected)", name, resolved, needed);
            goto fail;
        }
        src = inflated;
    }
    if (src_size != needed) {
        st = sl_err_set(err, SL_ERR_FORMAT,
                        "%s: field 'raw': %s has %zu bytes, fields 'dims', 'type' and 'components' need exactly %zu",
                        name, resolved, src_size, needed);
        goto fail;
    }

    char ds_name[SL_NAME_MAX];
    sl_load_base_name(path, "raw", ds_name, sizeof ds_name);
    ds = sl_dataset_create(comps == 3 ? SL_DATASET_VECTORS : SL_DATASET_VOLUME, ds_name);
    if (!ds) {
        st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", name);
        goto fail;
    }
    sl_voxel_type target = comps == 3 ? SL_VOXEL_F32 : sl_src_type_target(type);
    st = sl_volume_alloc(&ds->volume, dims, comps, target, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s", name);
        goto fail;
    }
    sl_load_convert(ds->volume.data, target, src, type, sl_src_type_size(type) > 1 && big != sl_load_host_big_endian(),
                    n, 0, 1.0, 0.0);
    for (int c = 0; c < 3; c++)
        ds->volume.spacing[c] = spacing[c];
    ds->origin = sl_v3(origin[0], origin[1], origin[2]);
    st = sl_dataset_finish_volume(ds, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s", name);
        goto fail;
    }
    cJSON_Delete(root);
    free(raw);
    free(inflated);
    *out = ds;
    return SL_OK;
fail:
    cJSON_Delete(root);
    free(raw);
    free(inflated);
    sl_dataset_destroy(ds);
    return st;
}
