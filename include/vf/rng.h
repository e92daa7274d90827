/* vf/rng.h: a small, seeded, reproducible random number generator.
 *
 * xoshiro256** (Blackman and Vigna) seeded through splitmix64, with uniform doubles in [0, 1)
 * and standard normals by the Box-Muller transform. The whole state is four 64-bit words in a
 * plain struct, so it can be copied, saved and restored: the same seed (or the same saved
 * state) gives bit-identical sequences on every run and machine. Not for cryptography. No
 * memory is allocated; one vf_rng must not be shared between threads without a lock. */
#ifndef VF_RNG_H
#define VF_RNG_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_rng {
    uint64_t s[4];
} vf_rng;

/* Seed the generator; every seed (0 included) gives a valid, distinct stream. */
void vf_rng_seed(vf_rng *rng, uint64_t seed);

/* The next 64 random bits. */
uint64_t vf_rng_next(vf_rng *rng);

/* Uniform double in [0, 1) with 53 random bits. */
double vf_rng_uniform(vf_rng *rng);

/* Uniform integer in [0, n); n must be > 0 (0 is returned otherwise). Unbiased. */
uint64_t vf_rng_below(vf_rng *rng, uint64_t n);

/* Standard normal N(0, 1) by Box-Muller (consumes two uniforms per call; no cached spare,
 * so the state is only the four words above). */
double vf_rng_normal(vf_rng *rng);

#ifdef __cplusplus
}
#endif
#endif
