/* gen_random.c — splitmix64-seeded xoshiro256** (see gen_random.h).
 *
 * Integer state only; uniform draws are exact conversions of 53-bit integers,
 * so the stream is bit-identical across platforms. sl_rng_normal uses sqrt
 * (exact in IEEE 754) and log (libm; identical wherever libm is). Rejection
 * loops consume a data-dependent number of draws, which is deterministic.
 * Does not share state: each caller owns its sl_rng. Any thread.
 */
#include "gen_random.h"

#include <math.h>

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

void sl_rng_seed(sl_rng *rng, uint64_t seed, uint64_t stream)
{
    uint64_t x = seed ^ (stream * 0xd1b54a32d192ed03ull);
    /* Mix the stream in twice so (seed, stream) and (seed', stream') with
     * equal xor still diverge. */
    x = splitmix64(&x) + stream;
    for (int i = 0; i < 4; i++)
        rng->s[i] = splitmix64(&x);
    if (!(rng->s[0] | rng->s[1] | rng->s[2] | rng->s[3]))
        rng->s[0] = 1; /* the all-zero state is the one fixed point */
}

uint64_t sl_rng_next(sl_rng *rng)
{
    uint64_t *s = rng->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double sl_rng_uniform(sl_rng *rng)
{
    return (double)(sl_rng_next(rng) >> 11) * (1.0 / 9007199254740992.0);
}

double sl_rng_range(sl_rng *rng, double lo, double hi)
{
    return lo + (hi - lo) * sl_rng_uniform(rng);
}

int64_t sl_rng_int(sl_rng *rng, int64_t lo, int64_t hi)
{
    uint64_t span = (uint64_t)hi - (uint64_t)lo + 1u;
    if (span == 0) /* the full 64-bit range */
        return (int64_t)sl_rng_next(rng);
    uint64_t limit = UINT64_MAX - UINT64_MAX % span;
    uint64_t r;
    do
        r = sl_rng_next(rng);
    while (r >= limit);
    return (int64_t)((uint64_t)lo + r % span);
}

double sl_rng_normal(sl_rng *rng)
{
    double u, v, s;
    do {
        u = 2.0 * sl_rng_uniform(rng) - 1.0;
        v = 2.0 * sl_rng_uniform(rng) - 1.0;
        s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    return u * sqrt(-2.0 * log(s) / s);
}

void sl_rng_in_ball(sl_rng *rng, double p[3])
{
    double r2;
    do {
        for (int c = 0; c < 3; c++)
            p[c] = 2.0 * sl_rng_uniform(rng) - 1.0;
        r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    } while (r2 > 1.0);
}

void sl_rng_on_sphere(sl_rng *rng, double d[3])
{
    double r2;
    do {
        for (int c = 0; c < 3; c++)
            d[c] = 2.0 * sl_rng_uniform(rng) - 1.0;
        r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    } while (r2 > 1.0 || r2 < 1e-6);
    double inv = 1.0 / sqrt(r2);
    for (int c = 0; c < 3; c++)
        d[c] *= inv;
}
