/* vf/wilson.h: a confidence interval for a success rate measured on few trials.
 *
 * The Wilson score interval (Wilson 1927) for k successes in n trials: unlike the normal
 * approximation p +- z sqrt(p(1-p)/n), it stays inside [0, 1] and is sensible for k = 0 or
 * k = n, which is the usual case for attack success rates on a few dozen frames:
 *     centre = (p + z^2 / 2n) / (1 + z^2 / n)
 *     half   = z / (1 + z^2 / n) * sqrt(p (1 - p) / n + z^2 / 4n^2)
 * Pure math, nothing allocated. */
#ifndef VF_WILSON_H
#define VF_WILSON_H

#ifdef __cplusplus
extern "C" {
#endif

#define VF_Z95 1.959963984540054 /* two-sided 95% normal quantile */

/* The interval [*lo, *hi] for k of n (0 <= k <= n); n = 0 gives [0, 1]. */
void vf_wilson_interval(int k, int n, double z, double *lo, double *hi);

#ifdef __cplusplus
}
#endif
#endif
