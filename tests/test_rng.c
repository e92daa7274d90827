/* vf_rng: reproducible streams, correct ranges and moments. */
#include <string.h>

#include "check.h"
#include "vf/rng.h"

static void test_reproducible(void)
{
    vf_rng a, b, c;
    vf_rng_seed(&a, 42);
    vf_rng_seed(&b, 42);
    vf_rng_seed(&c, 43);
    int same = 1, differ = 0;
    for (int i = 0; i < 1000; i++) {
        uint64_t x = vf_rng_next(&a), y = vf_rng_next(&b), z = vf_rng_next(&c);
        same &= x == y;
        differ += x != z;
    }
    CHECK(same, "the same seed gives the same stream");
    CHECK(differ > 990, "seeds 42 and 43 give different streams (%d of 1000 differ)", differ);

    /* A copied state continues identically (what saving and restoring relies on). */
    vf_rng saved = a;
    double n1 = vf_rng_normal(&a), n2 = vf_rng_normal(&saved);
    CHECK(memcmp(&n1, &n2, sizeof n1) == 0, "a copied state gives bit-identical normals");

    vf_rng zero;
    vf_rng_seed(&zero, 0);
    CHECK(zero.s[0] | zero.s[1] | zero.s[2] | zero.s[3], "seed 0 gives a usable state");
}

static void test_uniform(void)
{
    vf_rng rng;
    vf_rng_seed(&rng, 1);
    int n = 200000, in_range = 1;
    double sum = 0.0, sum_sq = 0.0;
    for (int i = 0; i < n; i++) {
        double u = vf_rng_uniform(&rng);
        in_range &= u >= 0.0 && u < 1.0;
        sum += u;
        sum_sq += u * u;
    }
    CHECK(in_range, "uniform values lie in [0, 1)");
    CHECK_NEAR(sum / n, 0.5, 0.005);
    CHECK_NEAR(sum_sq / n - (sum / n) * (sum / n), 1.0 / 12.0, 0.002);

    int counts[7] = {0}, below_ok = 1;
    for (int i = 0; i < 70000; i++) {
        uint64_t k = vf_rng_below(&rng, 7);
        below_ok &= k < 7;
        if (k < 7)
            counts[k]++;
    }
    CHECK(below_ok, "vf_rng_below(7) stays below 7");
    for (int k = 0; k < 7; k++)
        CHECK(counts[k] > 9500 && counts[k] < 10500, "bucket %d has %d of 70000", k, counts[k]);
    CHECK(vf_rng_below(&rng, 0) == 0, "below(0) is 0");
}

static void test_normal(void)
{
    vf_rng rng;
    vf_rng_seed(&rng, 2);
    int n = 200000, tail = 0, finite = 1;
    double m1 = 0, m2 = 0, m3 = 0, m4 = 0;
    for (int i = 0; i < n; i++) {
        double x = vf_rng_normal(&rng);
        finite &= isfinite(x);
        m1 += x / n;
        m2 += x * x / n;
        m3 += x * x * x / n;
        m4 += x * x * x * x / n;
        tail += fabs(x) > 1.959964;
    }
    CHECK(finite, "normals are finite");
    CHECK_NEAR(m1, 0.0, 0.01);
    CHECK_NEAR(m2, 1.0, 0.015);
    CHECK_NEAR(m3, 0.0, 0.04);
    CHECK_NEAR(m4, 3.0, 0.08);
    CHECK_NEAR((double)tail / n, 0.05, 0.003);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_reproducible);
    CHECK_CASE(test_uniform);
    CHECK_CASE(test_normal);
    return check_finish();
}
