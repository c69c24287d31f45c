/* sl_generate.h — deterministic, seeded dataset generators and the built-in catalog.
 *
 * A generator call is a JSON object {"generator": NAME, ...keys}; each family
 * declares its keys (a size key so benchmarks can sweep data size, and
 * "seed" where it has randomness); an unknown key, a wrong type or an out-of-range value is an error
 * naming it. Same call, same bytes, on every run of a build (own PRNG, no
 * libc rand, no time). Across machines the counts and line structure are
 * identical and the values agree up to libm's last-bit rounding (sin, cos,
 * exp may differ by an ulp between libm versions or with FMA); test_generate
 * pins both per family.
 * Families — lines: tornado, abc, bundle, furball, hotroom, random_walk;
 *            volumes: marschner_lobb, torus, head, ellipsoid; LR-spline volumes: lr_field.
 * Any thread; no GL.
 */
#ifndef SL_GENERATE_H
#define SL_GENERATE_H

#include "sl_dataset.h"

/* Generates from a JSON text such as {"generator":"tornado","lines":1000,"seed":1}. */
sl_status sl_generate_json(const char *json_text, sl_dataset **out, sl_err *err);

typedef struct sl_generator_info {
    const char *name;
    sl_dataset_kind kind;
    const char *description;   /* one line */
    const char *keys_help;     /* e.g. "lines (1..100000, default 1000), points, seed" */
} sl_generator_info;

/* The families, for listings; *count receives their number. */
const sl_generator_info *sl_generator_list(int *count);

/* Built-in named datasets (a name and a generator call), registered by the
 * server's catalog and usable as "dataset": NAME in a scene. */
typedef struct sl_builtin_dataset {
    const char *name;
    const char *generator_json;
    const char *description;
} sl_builtin_dataset;

const sl_builtin_dataset *sl_builtin_datasets(int *count);

/* Generator JSON of a built-in name, or NULL. */
const char *sl_builtin_lookup(const char *name);

#endif
