/* vf/stats.h: medians and nearest-rank quantiles, the conventions the stages rely on. */
#include <math.h>

#include "check.h"
#include "vf/stats.h"

static void test_median(void)
{
    double odd[] = {5, 1, 4, 2, 3};
    CHECK(vf_median(odd, 5) == 3 && odd[0] == 1 && odd[4] == 5, "odd count: the middle value, "
                                                               "sorted in place");
    double even[] = {10, 1, 4, 2};
    CHECK(vf_median(even, 4) == 3, "even count: the mean of the middle two (2 and 4)");
    double one[] = {-7};
    CHECK(vf_median(one, 1) == -7, "one value is its own median");
    CHECK(isnan(vf_median(NULL, 0)), "no values: NAN");
}

static void test_quantile(void)
{
    double v[11];
    for (int i = 0; i < 11; i++)
        v[i] = 10 - i; /* 10 .. 0 */
    vf_sort_doubles(v, 11);
    CHECK(v[0] == 0 && v[10] == 10, "sorted ascending");
    CHECK(vf_sorted_quantile(v, 11, 0) == 0 && vf_sorted_quantile(v, 11, 1) == 10, "ends");
    CHECK(vf_sorted_quantile(v, 11, 0.9) == 9 && vf_sorted_quantile(v, 11, 0.94) == 9 &&
              vf_sorted_quantile(v, 11, 0.96) == 10,
          "nearest rank: round(q (n - 1))");
    double pair[] = {1, 2};
    CHECK(vf_sorted_quantile(pair, 2, 0.5) == 2, "q 0.5 of an even count: the upper middle");
    double with_nan[] = {3, NAN, 1, 2};
    vf_sort_doubles(with_nan, 4);
    CHECK(with_nan[0] == 1 && with_nan[2] == 3 && isnan(with_nan[3]), "NaN sorts last");
}

/* Rank correlation: any increasing map is 1, a reversed one -1, ties take their mean rank
 * (sqrt(0.95) for this pair), a constant has none. */
static void test_spearman(void)
{
    double x[] = {1, 2, 3, 4, 5}, y[] = {2, 20, 21, 300, 1000}, down[] = {5, 4, 3, 2, 1};
    CHECK_NEAR(vf_spearman(x, y, 5), 1.0, 1e-12);
    CHECK_NEAR(vf_spearman(x, down, 5), -1.0, 1e-12);
    double tied[] = {1, 2, 2, 3, 5};
    double r_tied = vf_spearman(x, tied, 5);
    /* ranks 0, 1.5, 1.5, 3, 4 against 0..4: products 9.5 over sqrt(10 * 9.5) */
    CHECK_NEAR(r_tied, 9.5 / sqrt(10 * 9.5), 1e-12);
    double flat[] = {7, 7, 7, 7, 7};
    CHECK(isnan(vf_spearman(x, flat, 5)) && isnan(vf_spearman(x, y, 2)), "no order, no value");
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_median);
    CHECK_CASE(test_quantile);
    CHECK_CASE(test_spearman);
    return check_finish();
}
