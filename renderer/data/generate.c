/* generate.c — generator JSON parsing, key validation, dispatch and the built-in catalog.
 *
 * One table of families (gen_family.h); each declares its keys with type,
 * range and default. This file is the only place that reads generator JSON:
 * it rejects a missing/unknown "generator", an unknown or repeated key, a
 * wrong type and an out-of-range value with a message naming the key and its
 * range, then calls the family with one validated value per key. Does not
 * generate data itself (gen_<family>.c do). Any thread; no GL; the only
 * mutable state is the generator listing, built once under pthread_once.
 */
#include "sl_generate.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "gen_family.h"

static const sl_gen_family *const families[] = {
    &sl_gen_tornado, &sl_gen_abc, &sl_gen_bundle, &sl_gen_furball, &sl_gen_hotroom, &sl_gen_random_walk,
    &sl_gen_marschner_lobb, &sl_gen_torus, &sl_gen_head, &sl_gen_ellipsoid, &sl_gen_lr_field,
};
#define FAMILY_COUNT ((int)(sizeof families / sizeof families[0]))

static const sl_builtin_dataset builtins[] = {
    {"tornado", "{\"generator\":\"tornado\",\"lines\":1000,\"points\":200,\"seed\":1}",
     "1000 streamlines of the analytic tornado vortex, 200 points each"},
    {"abc", "{\"generator\":\"abc\",\"lines\":500,\"points\":300,\"seed\":1}",
     "500 streamlines of the chaotic ABC flow, 300 points each"},
    {"bundle", "{\"generator\":\"bundle\",\"lines\":2000,\"points\":100,\"seed\":1}",
     "2000 fibres twisting around a curved axis, 100 points each"},
    {"furball", "{\"generator\":\"furball\",\"segments\":100000,\"seed\":1}",
     "random curly curves in a ball, 100000 segments"},
    {"furball_787k", "{\"generator\":\"furball\",\"segments\":787000,\"seed\":1}",
     "random curly curves in a ball, 787000 segments (the benchmark size)"},
    {"hotroom", "{\"generator\":\"hotroom\",\"lines\":20000,\"seed\":1}",
     "20000 short thick streamline pieces of a convective room flow, radii in the data"},
    {"marschner_lobb", "{\"generator\":\"marschner_lobb\",\"size\":41}",
     "the Marschner-Lobb test signal, 41^3 f32"},
    {"torus", "{\"generator\":\"torus\",\"size\":64}",
     "signed distance to a torus and a sphere, 64^3 f32"},
    {"head", "{\"generator\":\"head\",\"size\":128}",
     "CT-like head phantom, 128^3 u16"},
};
#define BUILTIN_COUNT ((int)(sizeof builtins / sizeof builtins[0]))

static sl_generator_info info_list[FAMILY_COUNT];
static pthread_once_t info_once = PTHREAD_ONCE_INIT;

static void info_build(void)
{
    for (int i = 0; i < FAMILY_COUNT; i++)
        info_list[i] = (sl_generator_info){families[i]->name, families[i]->kind,
                                           families[i]->description, families[i]->keys_help};
}

const sl_generator_info *sl_generator_list(int *count)
{
    pthread_once(&info_once, info_build);
    if (count)
        *count = FAMILY_COUNT;
    return info_list;
}

const sl_builtin_dataset *sl_builtin_datasets(int *count)
{
    if (count)
        *count = BUILTIN_COUNT;
    return builtins;
}

const char *sl_builtin_lookup(const char *name)
{
    if (!name)
        return NULL;
    for (int i = 0; i < BUILTIN_COUNT; i++)
        if (strcmp(builtins[i].name, name) == 0)
            return builtins[i].generator_json;
    return NULL;
}

static const sl_gen_family *family_find(const char *name)
{
    for (int i = 0; i < FAMILY_COUNT; i++)
        if (strcmp(families[i]->name, name) == 0)
            return families[i];
    return NULL;
}

/* "lines, points, seed" into buf. */
static void key_names(const sl_gen_family *f, char *buf, size_t size)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < f->key_count && used < size; i++) {
        int n = snprintf(buf + used, size - used, "%s%s", i ? ", " : "", f->keys[i].name);
        if (n < 0)
            break;
        used += (size_t)n;
    }
}

static void family_names(char *buf, size_t size)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < FAMILY_COUNT && used < size; i++) {
        int n = snprintf(buf + used, size - used, "%s%s", i ? ", " : "", families[i]->name);
        if (n < 0)
            break;
        used += (size_t)n;
    }
}

/* "an integer in 1..1000000" / "one of \"u8\", \"u16\"". */
static void key_range(const sl_gen_key *k, char *buf, size_t size)
{
    if (k->type == SL_GEN_CHOICE) {
        size_t used = (size_t)snprintf(buf, size, "one of");
        for (int c = 0; c < SL_GEN_MAX_CHOICES && k->choices[c] && used < size; c++) {
            int n = snprintf(buf + used, size - used, "%s \"%s\"", c ? "," : "", k->choices[c]);
            if (n < 0)
                break;
            used += (size_t)n;
        }
    } else {
        snprintf(buf, size, "%s in %.16g..%.16g", k->type == SL_GEN_INT ? "an integer" : "a number",
                 k->min, k->max);
    }
}

static const char *json_type_name(const cJSON *item)
{
    if (cJSON_IsNumber(item)) return "a number";
    if (cJSON_IsString(item)) return "a string";
    if (cJSON_IsBool(item)) return "a boolean";
    if (cJSON_IsNull(item)) return "null";
    if (cJSON_IsArray(item)) return "an array";
    if (cJSON_IsObject(item)) return "an object";
    return "an invalid value";
}

static sl_status key_parse(const sl_gen_family *f, const sl_gen_key *k, const cJSON *item,
                           double *value, sl_err *err)
{
    char range[256];
    key_range(k, range, sizeof range);
    if (k->type == SL_GEN_CHOICE) {
        if (cJSON_IsString(item))
            for (int c = 0; c < SL_GEN_MAX_CHOICES && k->choices[c]; c++)
                if (strcmp(item->valuestring, k->choices[c]) == 0) {
                    *value = c;
                    return SL_OK;
                }
        if (cJSON_IsString(item))
            return sl_err_set(err, SL_ERR_INVALID, "%s: key '%s' is \"%.64s\", must be %s",
                              f->name, k->name, item->valuestring, range);
        return sl_err_set(err, SL_ERR_INVALID, "%s: key '%s' is %s, must be %s",
                          f->name, k->name, json_type_name(item), range);
    }
    if (!cJSON_IsNumber(item))
        return sl_err_set(err, SL_ERR_INVALID, "%s: key '%s' is %s, must be %s",
                          f->name, k->name, json_type_name(item), range);
    double v = item->valuedouble;
    if (!isfinite(v) || (k->type == SL_GEN_INT && v != floor(v)))
        return sl_err_set(err, SL_ERR_INVALID, "%s: key '%s' is %.16g, must be %s", f->name, k->name, v, range);
    if (v < k->min || v > k->max)
        return sl_err_set(err, SL_ERR_INVALID, "%s: key '%s' = %.16g is out of range, must be %s",
                          f->name, k->name, v, range);
    *value = v;
    return SL_OK;
}

static sl_status parse_and_generate(const cJSON *root, sl_dataset **out, sl_err *err)
{
    if (!cJSON_IsObject(root))
        return sl_err_set(err, SL_ERR_INVALID, "generator call must be a JSON object, got %s", json_type_name(root));
    const cJSON *gen = cJSON_GetObjectItemCaseSensitive(root, "generator");
    char names[512];
    family_names(names, sizeof names);
    if (!gen)
        return sl_err_set(err, SL_ERR_INVALID, "generator call has no key 'generator' (one of %s)", names);
    if (!cJSON_IsString(gen))
        return sl_err_set(err, SL_ERR_INVALID, "key 'generator' is %s, must be a string (one of %s)",
                          json_type_name(gen), names);
    const sl_gen_family *f = family_find(gen->valuestring);
    if (!f)
        return sl_err_set(err, SL_ERR_INVALID, "key 'generator': unknown generator \"%.64s\" (known: %s)",
                          gen->valuestring, names);
    double values[SL_GEN_MAX_KEYS];
    int seen[SL_GEN_MAX_KEYS] = {0};
    for (int i = 0; i < f->key_count; i++)
        values[i] = f->keys[i].def;
    int generator_seen = 0;
    for (const cJSON *item = root->child; item; item = item->next) {
        const char *key = item->string ? item->string : "";
        if (strcmp(key, "generator") == 0) {
            if (generator_seen++)
                return sl_err_set(err, SL_ERR_INVALID, "%s: key 'generator' appears twice", f->name);
            continue;
        }
        int idx = -1;
        for (int i = 0; i < f->key_count; i++)
            if (strcmp(f->keys[i].name, key) == 0)
                idx = i;
        if (idx < 0) {
            char keys[256];
            key_names(f, keys, sizeof keys);
            return sl_err_set(err, SL_ERR_INVALID, "%s: unknown key '%.64s' (keys: %s)", f->name, key, keys);
        }
        if (seen[idx]++)
            return sl_err_set(err, SL_ERR_INVALID, "%s: key '%s' appears twice", f->name, key);
        sl_status st = key_parse(f, &f->keys[idx], item, &values[idx], err);
        if (st != SL_OK)
            return st;
    }
    return f->generate(values, out, err);
}

sl_status sl_generate_json(const char *json_text, sl_dataset **out, sl_err *err)
{
    sl_err local;
    if (!err)
        err = &local;
    sl_err_clear(err);
    if (!out)
        return sl_err_set(err, SL_ERR_INVALID, "sl_generate_json: out is NULL");
    *out = NULL;
    if (!json_text)
        return sl_err_set(err, SL_ERR_INVALID, "generator call is NULL");
    double t0 = sl_clock_ms();
    const char *at = NULL; /* cJSON's per-call error position (its global one is not thread-safe) */
    cJSON *root = cJSON_ParseWithOpts(json_text, &at, 1);
    if (!root) {
        long offset = at && at >= json_text ? (long)(at - json_text) : -1;
        return sl_err_set(err, SL_ERR_INVALID, "generator call is not valid JSON (error near byte %ld)", offset);
    }
    sl_status st = parse_and_generate(root, out, err);
    cJSON_Delete(root);
    if (st != SL_OK) {
        *out = NULL;
        return st;
    }
    (*out)->load_ms = sl_clock_ms() - t0;
    return SL_OK;
}
