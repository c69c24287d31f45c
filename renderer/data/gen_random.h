/* gen_random.h — the seeded pseudo-random generator every generator family uses.
 *
 * xoshiro256** (Blackman & Vigna 2018) seeded through splitmix64, written here
 * from the published recurrences. Integer-only state update, so a seed gives
 * the same stream on every machine and compiler; no libc rand, no time.
 * `stream` lets one seed feed independent sub-streams (e.g. one per line), so
 * the data does not change when an unrelated draw is added elsewhere.
 * Caller-owned state; any thread; not cryptographic.
 */
#ifndef SL_GEN_RANDOM_H
#define SL_GEN_RANDOM_H

#include <stdint.h>

typedef struct sl_rng { uint64_t s[4]; } sl_rng;

/* Seeds from (seed, stream); distinct pairs give unrelated streams. */
void sl_rng_seed(sl_rng *rng, uint64_t seed, uint64_t stream);

uint64_t sl_rng_next(sl_rng *rng);

/* Uniform double in [0, 1) with 53 random bits. */
double sl_rng_uniform(sl_rng *rng);

/* Uniform double in [lo, hi). */
double sl_rng_range(sl_rng *rng, double lo, double hi);

/* Uniform integer in [lo, hi] (hi >= lo), without modulo bias. */
int64_t sl_rng_int(sl_rng *rng, int64_t lo, int64_t hi);

/* Standard normal deviate (Marsaglia polar method; uses sqrt and log only). */
double sl_rng_normal(sl_rng *rng);

/* Uniform point inside the unit ball (rejection) and unit vector on the sphere. */
void sl_rng_in_ball(sl_rng *rng, double p[3]);
void sl_rng_on_sphere(sl_rng *rng, double d[3]);

#endif
