/* src/field/fast_math.h: the renderer's sigmoid, four lanes at a time, in plain float
 * arithmetic the compiler inlines (libm's expf is a call per lane and dominated the ray
 * marcher). GCC/Clang vector extensions: SSE/AVX on x86-64, NEON on ARM.
 * Relative error of the exponential about 2e-7, on the order of float rounding. Also the
 * half-precision conversions of builds without the F16C instructions. */
#ifndef VF_FIELD_FAST_MATH_H
#define VF_FIELD_FAST_MATH_H

#include <stdint.h>
#include <string.h>

typedef float fast_f4 __attribute__((vector_size(16)));
typedef int32_t fast_i4 __attribute__((vector_size(16)));

static inline fast_f4 fast_select4(fast_i4 mask, fast_f4 a, fast_f4 b)
{
    return (fast_f4)(((fast_i4)a & mask) | ((fast_i4)b & ~mask));
}

/* 2^x per lane: split x = n + f with n an integer (rounded by adding and subtracting
 * 1.5 * 2^23) and |f| <= 0.5; 2^f by its Taylor series to the 6th power (remainder below
 * 1.2e-7), 2^n by building the float's exponent. x is clamped to [-125, 125]. */
static inline fast_f4 fast_exp2_4(fast_f4 x)
{
    const fast_f4 lo = {-125.0f, -125.0f, -125.0f, -125.0f}, hi = -lo;
    x = fast_select4(x < lo, lo, x);
    x = fast_select4(x > hi, hi, x);
    const fast_f4 magic = {12582912.0f, 12582912.0f, 12582912.0f, 12582912.0f};
    fast_f4 n = (x + magic) - magic, f = x - n;
    fast_f4 p = f * 1.5403530e-4f + 1.3333558e-3f;
    p = p * f + 9.6181291e-3f;
    p = p * f + 5.5504109e-2f;
    p = p * f + 2.4022651e-1f;
    p = p * f + 6.9314718e-1f;
    p = p * f + 1.0f;
    fast_i4 bits = (__builtin_convertvector(n, fast_i4) + 127) << 23;
    return p * (fast_f4)bits;
}

static inline fast_f4 fast_sigmoid4(fast_f4 x)
{
    return 1.0f / (1.0f + fast_exp2_4(x * -1.44269504f));
}

/* IEEE half precision (binary16: 1 sign, 5 exponent, 10 fraction bits) to float and back, in
 * integer arithmetic, for builds without the F16C/AVX-512 conversion instructions (the
 * renderer's half copy of the grids, render_march.c). Rounding to nearest, ties to even, as the
 * instructions do; test_field checks both against them. */
static inline float fast_half_to_float(uint16_t h)
{
    const uint32_t sign = (uint32_t)(h & 0x8000u) << 16, exponent = (h >> 10) & 0x1fu;
    const uint32_t fraction = h & 0x3ffu;
    uint32_t bits;
    if (exponent == 0x1f) /* infinity, NaN */
        bits = sign | 0x7f800000u | fraction << 13;
    else if (exponent == 0) { /* zero, subnormal: fraction * 2^-24 is exact in float */
        float f = (float)fraction * 0x1p-24f;
        memcpy(&bits, &f, sizeof bits);
        bits |= sign;
    } else /* rebias the exponent from 15 to 127 */
        bits = sign | (exponent + 112) << 23 | fraction << 13;
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static inline uint16_t fast_float_to_half(float f)
{
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    const uint16_t sign = (uint16_t)((bits >> 16) & 0x8000u);
    const uint32_t magnitude = bits & 0x7fffffffu;
    if (magnitude >= 0x7f800000u) /* infinity stays, NaN stays a (quiet) NaN */
        return sign | 0x7c00u | (magnitude > 0x7f800000u ? 0x200u : 0);
    if (magnitude >= 0x477ff000u) /* 65520 and up round past the largest half, 65504 */
        return sign | 0x7c00u;
    if (magnitude < 0x38800000u) { /* under 2^-14: a subnormal half. In |f| + 0.5 the float's
                                      last place is 2^-24, the subnormal's step, so the float
                                      addition rounds to nearest even for us */
        float a, biased;
        memcpy(&a, &magnitude, sizeof a);
        biased = a + 0.5f;
        uint32_t b;
        memcpy(&b, &biased, sizeof b);
        return sign | (uint16_t)(b - 0x3f000000u);
    }
    /* normal: rebias the exponent from 127 to 15 and drop 13 fraction bits, rounding to
     * nearest even (add just under half of the last kept place, plus that place's bit); a
     * carry out of the fraction correctly raises the exponent */
    const uint32_t odd = (magnitude >> 13) & 1u;
    return sign | (uint16_t)((magnitude - (112u << 23) + 0xfffu + odd) >> 13);
}

#endif
