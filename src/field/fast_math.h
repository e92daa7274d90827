/* src/field/fast_math.h: the renderer's sigmoid, four lanes at a time, in plain float
 * arithmetic the compiler inlines (libm's expf is a call per lane and dominated the ray
 * marcher). GCC/Clang vector extensions: SSE/AVX on x86-64, NEON on ARM.
 * Relative error of the exponential about 2e-7, on the order of float rounding. */
#ifndef VF_FIELD_FAST_MATH_H
#define VF_FIELD_FAST_MATH_H

#include <stdint.h>

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

#endif
