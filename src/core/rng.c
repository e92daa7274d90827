/* xoshiro256** with splitmix64 seeding, plus uniform and normal variates (see vf/rng.h). */
#include "vf/rng.h"

#include <math.h>

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

/* splitmix64: spreads a 64-bit seed over the state so that nearby seeds give unrelated
 * streams and the state is never all zero. */
static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

void vf_rng_seed(vf_rng *rng, uint64_t seed)
{
    uint64_t x = seed;
    for (int i = 0; i < 4; i++)
        rng->s[i] = splitmix64(&x);
}

uint64_t vf_rng_next(vf_rng *rng)
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

double vf_rng_uniform(vf_rng *rng)
{
    return (double)(vf_rng_next(rng) >> 11) * 0x1.0p-53;
}

uint64_t vf_rng_below(vf_rng *rng, uint64_t n)
{
    if (n == 0)
        return 0;
    /* Reject the top partial block of 2^64 so every residue is equally likely. */
    uint64_t limit = UINT64_MAX - UINT64_MAX % n;
    uint64_t x;
    do
        x = vf_rng_next(rng);
    while (x >= limit);
    return x % n;
}

double vf_rng_normal(vf_rng *rng)
{
    /* 1 - U lies in (0, 1], so the log is finite. */
    double u1 = 1.0 - vf_rng_uniform(rng);
    double u2 = vf_rng_uniform(rng);
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}
