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

static int by_pointee(const void *a, const void *b)
{
    double x = **(const double *const *)a, y = **(const double *const *)b;
    return (x > y) - (x < y);
}

/* The ranks (0-based, ties averaged) of n values. */
static int rank(const double *v, int n, double *out)
{
    const double **order = malloc(sizeof *order * (size_t)n);
    if (!order)
        return 0;
    for (int i = 0; i < n; i++)
        order[i] = &v[i];
    qsort(order, (size_t)n, sizeof *order, by_pointee);
    for (int i = 0; i < n;) {
        int j = i;
        while (j + 1 < n && *order[j + 1] == *order[i])
            j++;
        for (int k = i; k <= j; k++)
            out[order[k] - v] = 0.5 * (i + j);
        i = j + 1;
    }
    free(order);
    return 1;
}

double vf_spearman(const double *a, const double *b, int n)
{
    if (n < 3)
        return NAN;
    double *ra = malloc(sizeof(double) * 2 * (size_t)n), *rb = ra ? ra + n : NULL;
    if (!ra || !rank(a, n, ra) || !rank(b, n, rb)) {
        free(ra);
        return NAN;
    }
    double mean = 0.5 * (n - 1), sab = 0, saa = 0, sbb = 0;
    for (int i = 0; i < n; i++) {
        sab += (ra[i] - mean) * (rb[i] - mean);
        saa += (ra[i] - mean) * (ra[i] - mean);
        sbb += (rb[i] - mean) * (rb[i] - mean);
    }
    free(ra);
    return saa > 0 && sbb > 0 ? sab / sqrt(saa * sbb) : NAN;
}
