/* The point nearest to a bundle of rays (vf/calib.h). */
#include <math.h>

#include "vf/calib.h"

/* Solve the 3x3 system a x = b by Cramer's rule; returns 0 when a is (nearly) singular
 * relative to its scale. */
static int solve3(const double a[9], const double b[3], double x[3])
{
    double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                 a[2] * (a[3] * a[7] - a[4] * a[6]);
    double scale = fabs(a[0]) + fabs(a[4]) + fabs(a[8]);
    if (!(fabs(det) > 1e-10 * scale * scale * scale))
        return 0;
    for (int c = 0; c < 3; c++) {
        double m[9];
        for (int k = 0; k < 9; k++)
            m[k] = k % 3 == c ? b[k / 3] : a[k];
        x[c] = (m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                m[2] * (m[3] * m[7] - m[4] * m[6])) /
               det;
    }
    return 1;
}

vf_status vf_triangulate_rays(const double *origin, const double *dir, int n, double out[3])
{
    /* minimize sum |(I - d d^T)(x - o)|^2:  sum (I - d d^T) x = sum (I - d d^T) o */
    double a[9] = {0}, b[3] = {0};
    for (int i = 0; i < n; i++) {
        const double *d = dir + 3 * i, *o = origin + 3 * i;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                double p = (r == c) - d[r] * d[c];
                a[3 * r + c] += p;
                b[r] += p * o[c];
            }
    }
    if (n < 2 || !solve3(a, b, out))
        return vf_fail(VF_EINPUT, "the rays to triangulate are (nearly) parallel: pick the "
                                  "point in frames taken from clearly different directions");
    return VF_OK;
}
