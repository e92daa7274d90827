/* Choosing well-spread views among many found boards (a video finds the same pose in dozens of
 * consecutive frames; a calibration wants the board everywhere in the frame, near and far,
 * tilted every way). */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "calib_internal.h"

enum { FEATURES = 5 };

static double dist2(const double *a, const double *b)
{
    return hypot(a[0] - b[0], a[1] - b[1]);
}

/* Centre (2), apparent size and tilt (2) of the board's outer quad, all about 0..1. */
static void view_features(const vf_calib_views *set, const double quad[8], double f[FEATURES])
{
    const double *q[4] = {quad, quad + 2, quad + 4, quad + 6};
    double area = 0;
    f[0] = f[1] = 0;
    for (int k = 0; k < 4; k++) {
        const double *a = q[k], *b = q[(k + 1) % 4];
        area += a[0] * b[1] - a[1] * b[0];
        f[0] += a[0] / (4.0 * set->width);
        f[1] += a[1] / (4.0 * set->height);
    }
    f[2] = sqrt(fabs(0.5 * area) / ((double)set->width * set->height));
    double top = dist2(q[0], q[1]), right = dist2(q[1], q[2]), bottom = dist2(q[2], q[3]),
           left = dist2(q[3], q[0]);
    /* foreshortening: opposite edges differ in length when the board is tilted; tilt is what
       pins the focal length down, so it weighs double */
    f[3] = 2.0 * (right - left) / (right + left + 1e-9);
    f[4] = 2.0 * (bottom - top) / (bottom + top + 1e-9);
}

int vf__calib_select_views(const vf_calib_views *set, int max, int *chosen)
{
    int n = set->count;
    if (n <= max) {
        for (int i = 0; i < n; i++)
            chosen[i] = i;
        return n;
    }
    double *f = malloc((size_t)n * FEATURES * sizeof *f);
    double *nearest = malloc((size_t)n * sizeof *nearest);
    if (!f || !nearest) {
        free(f);
        free(nearest);
        return 0;
    }
    double mean[FEATURES] = {0};
    for (int i = 0; i < n; i++) {
        view_features(set, set->views[i].quad, f + FEATURES * i);
        for (int k = 0; k < FEATURES; k++)
            mean[k] += f[FEATURES * i + k] / n;
    }
    for (int i = 0; i < n; i++) {
        double d = 0;
        for (int k = 0; k < FEATURES; k++)
            d += pow(f[FEATURES * i + k] - mean[k], 2);
        nearest[i] = d + DBL_MIN; /* the first pick: the view farthest from the average one */
    }
    int count = 0;
    while (count < max) {
        int best = -1;
        for (int i = 0; i < n; i++)
            if (nearest[i] > 0 && (best < 0 || nearest[i] > nearest[best]))
                best = i;
        if (best < 0)
            break; /* all remaining views duplicate chosen ones */
        chosen[count++] = best;
        for (int i = 0; i < n; i++) {
            double d = 0;
            for (int k = 0; k < FEATURES; k++)
                d += pow(f[FEATURES * i + k] - f[FEATURES * best + k], 2);
            if (d < nearest[i])
                nearest[i] = d;
        }
    }
    free(f);
    free(nearest);
    return count;
}
