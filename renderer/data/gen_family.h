/* gen_family.h — the internal contract between generate.c and one generator family.
 *
 * A family declares its keys (name, type, range, default) and a generate
 * function. generate.c parses and validates the JSON against the key table and
 * hands the family one value per key, in table order, already checked; a
 * family therefore never sees an unknown key, a wrong type or an out-of-range
 * value. Families may still refuse a combination (e.g. lines * points above
 * SL_MAX_VERTICES) with an sl_err naming the keys.
 * Not part of the public API (see sl_generate.h). Any thread; no GL; no globals
 * written, so families are reentrant.
 */
#ifndef SL_GEN_FAMILY_H
#define SL_GEN_FAMILY_H

#include "sl_dataset.h"

#define SL_GEN_MAX_KEYS 8
#define SL_GEN_MAX_CHOICES 4

/* Largest seed, so every seed survives the trip through a JSON double. */
#define SL_GEN_SEED_MAX 9007199254740991.0 /* 2^53 - 1 */

typedef enum sl_gen_key_type {
    SL_GEN_INT = 1,    /* JSON number with no fractional part, in [min, max] */
    SL_GEN_NUMBER,     /* any finite JSON number in [min, max] */
    SL_GEN_CHOICE      /* JSON string, one of choices[]; value = its index */
} sl_gen_key_type;

typedef struct sl_gen_key {
    const char *name;
    sl_gen_key_type type;
    double min, max, def;                     /* SL_GEN_CHOICE: def is an index */
    const char *choices[SL_GEN_MAX_CHOICES];  /* SL_GEN_CHOICE only, NULL-terminated */
} sl_gen_key;

/* values[i] belongs to keys[i]; *out receives a finished dataset (owned by
 * the caller) on SL_OK and stays NULL otherwise. err is never NULL here
 * (generate.c passes its own when the caller gave none). */
typedef sl_status (*sl_gen_fn)(const double *values, sl_dataset **out, sl_err *err);

typedef struct sl_gen_family {
    const char *name;
    sl_dataset_kind kind;
    const char *description;
    const char *keys_help;   /* must mention every key; checked by test_generate */
    int key_count;
    sl_gen_key keys[SL_GEN_MAX_KEYS];
    sl_gen_fn generate;
} sl_gen_family;

extern const sl_gen_family sl_gen_tornado;
extern const sl_gen_family sl_gen_abc;
extern const sl_gen_family sl_gen_bundle;
extern const sl_gen_family sl_gen_furball;
extern const sl_gen_family sl_gen_hotroom;
extern const sl_gen_family sl_gen_random_walk;
extern const sl_gen_family sl_gen_marschner_lobb;
extern const sl_gen_family sl_gen_torus;
extern const sl_gen_family sl_gen_head;
extern const sl_gen_family sl_gen_ellipsoid;
extern const sl_gen_family sl_gen_lr_field;

#endif
