/* src/field/fast_math.h: exp, log and the field's activations in plain float arithmetic that
 * the compiler inlines (libm's expf and log1pf are calls and dominated the ray marcher).
 * Relative error about 2e-7, on the order of float rounding: renders match libm's to within
 * a few 1e-7. */
#ifndef VF_FIELD_FAST_MATH_H
#define VF_FIELD_FAST_MATH_H

#include <stdint.h>
#include <string.h>

/* 2^x: split x = n + f with n an integer and |f| <= 0.5; 2^f by its Taylor series to the
 * 6th power (remainder below 1.2e-7), 2^n by building the float's exponent. */
static inline float fast_exp2(float x)
{
    x = x < -125.0f ? -125.0f : x > 125.0f ? 125.0f : x;
    float n = x >= 0 ? (float)(int)(x + 0.5f) : -(float)(int)(0.5f - x);
    float f = x - n;
    float p = 1.5403530e-4f;
    p = p * f + 1.3333558e-3f;
    p = p * f + 9.6181291e-3f;
    p = p * f + 5.5504109e-2f;
    p = p * f + 2.4022651e-1f;
    p = p * f + 6.9314718e-1f;
    p = p * f + 1.0f;
    int32_t bits = ((int32_t)n + 127) << 23;
    float scale;
    memcpy(&scale, &bits, sizeof scale);
    return p * scale;
}

static inline float fast_exp(float x)
{
    return fast_exp2(x * 1.44269504f);
}

/* ln(y) for normal y > 0: y = m 2^e with m in [sqrt(1/2), sqrt(2)), and
 * ln(m) = 2 atanh(z), z = (m - 1) / (m + 1), |z| < 0.172, by its series to z^9. */
static inline float fast_log(float y)
{
    int32_t bits;
    memcpy(&bits, &y, sizeof bits);
    int32_t e = ((bits >> 23) & 0xff) - 127;
    bits = (bits & 0x007fffff) | 0x3f800000; /* m in [1, 2) */
    float m;
    memcpy(&m, &bits, sizeof m);
    if (m > 1.41421356f) {
        m *= 0.5f;
        e++;
    }
    float z = (m - 1.0f) / (m + 1.0f), z2 = z * z;
    float s = 1.0f / 9.0f;
    s = s * z2 + 1.0f / 7.0f;
    s = s * z2 + 1.0f / 5.0f;
    s = s * z2 + 1.0f / 3.0f;
    s = s * z2 + 1.0f;
    return 2.0f * z * s + (float)e * 0.69314718f;
}

/* softplus(x) = ln(1 + e^x). ln(1 + e) is rescaled by e / ((1 + e) - 1), which cancels the
 * rounding of 1 + e when e is small. */
static inline float fast_softplus(float x)
{
    if (x > 20.0f)
        return x;
    float e = fast_exp(x), y = 1.0f + e, d = y - 1.0f;
    return d == 0.0f ? e : fast_log(y) * (e / d);
}

static inline float fast_sigmoid(float x)
{
    return 1.0f / (1.0f + fast_exp(-x));
}

#endif
