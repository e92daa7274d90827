/* Order statistics (vf/stats.h). */
#include "vf/stats.h"

#include <math.h>
#include <stdlib.h>

static int compare_doubles(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    if (isnan(x) || isnan(y))
        return isnan(x) - isnan(y);
    return (x > y) - (x < y);
}

void vf_sort_doubles(double *v, int n)
{
    if (n > 1)
        qsort(v, (size_t)n, sizeof *v, compare_doubles);
}

double vf_sorted_quantile(const double *v, int n, double q)
{
    return v[(int)(q * (n - 1) + 0.5)];
}

double vf_median(double *v, int n)
{
    if (n <= 0)
        return NAN;
    vf_sort_doubles(v, n);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
