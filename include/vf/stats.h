/* vf/stats.h: order statistics of small arrays of doubles (medians, percentiles), for the
 * robust yardsticks the stages use: a frame's sharpness against its neighbours', the centre of
 * a point cloud, pose errors, render times.
 *
 *     vf_sort_doubles(v, n);                      // ascending, in place
 *     double p90 = vf_sorted_quantile(v, n, 0.9); // nearest rank of sorted values
 *     double m = vf_median(v, n);                 // sorts v; mean of the middle two when n is even
 *     double rho = vf_spearman(x, y, n);          // rank correlation
 *
 * Nothing is allocated. NaNs sort after every number. */
#ifndef VF_STATS_H
#define VF_STATS_H

#ifdef __cplusplus
extern "C" {
#endif

/* Sort n values ascending, in place. */
void vf_sort_doubles(double *v, int n);

/* The q-quantile (0 <= q <= 1) of n >= 1 values already sorted ascending, by nearest rank:
 * v[round(q (n - 1))]. q = 0.5 gives the upper of the middle two when n is even. */
double vf_sorted_quantile(const double *v, int n, double q);

/* The median of n values (the mean of the middle two when n is even); sorts them in place.
 * NAN when n is 0. */
double vf_median(double *v, int n);

/* Spearman's rank correlation of a[i] and b[i] (ties get their mean rank), in [-1, 1]; NAN
 * when n < 3, a constant has no rank order, or out of memory. */
double vf_spearman(const double *a, const double *b, int n);

#ifdef __cplusplus
}
#endif
#endif
