/* The viewpoint box a set of cameras covers (vf/view_coverage.h): cameras placed at known
 * viewpoints must come back inside the box, with the documented margins, yaw arcs that
 * cross +-180 unwrapped, and a full circle when the cameras surround the object. */
#include <math.h>

#include "check.h"
#include "vf/pose.h"
#include "vf/view_coverage.h"

/* n cameras with yaw from psi0 in steps of dpsi, phi alternating 110/140, small offsets. */
static void cameras(double *c2w, int n, double psi0, double dpsi)
{
    for (int i = 0; i < n; i++) {
        vf_viewpoint v = {psi0 + i * dpsi, (i % 3) - 1.0, i % 2 ? 110.0 : 140.0, 0.05 * (i % 2),
                          -0.2 + 0.1 * (i % 5), 0.0};
        vf_viewpoint_to_c2w(&v, c2w + 16 * i);
    }
}

static void test_frontal_arc(void)
{
    double c2w[16 * 10];
    vf_view_bounds b;
    cameras(c2w, 10, -40, 10); /* yaw -40 .. 50 */
    CHECK(vf_view_coverage(c2w, 10, &b) == VF_OK, "%s", vf_error_message());
    CHECK_NEAR(b.lo[0], -40 - 5, 1e-6); /* margin max(5% of 90, 5) = 5 degrees */
    CHECK_NEAR(b.hi[0], 50 + 5, 1e-6);
    CHECK_NEAR(b.lo[1], -1 - 5, 1e-6);
    CHECK_NEAR(b.hi[1], 1 + 5, 1e-6);
    CHECK_NEAR(b.lo[2], 110 - 5, 1e-6);
    CHECK_NEAR(b.hi[2], 140 + 5, 1e-6);
    CHECK_NEAR(b.lo[3], 0 - 0.1, 1e-6);
    CHECK_NEAR(b.hi[3], 0.05 + 0.1, 1e-6);
    CHECK_NEAR(b.lo[4], -0.2 - 0.1, 1e-6);
    CHECK_NEAR(b.hi[4], 0.2 + 0.1, 1e-6);
    CHECK(vf_view_bounds_check(&b) == VF_OK, "the box is usable: %s", vf_error_message());
}

static void test_arc_across_180(void)
{
    double c2w[16 * 7];
    vf_view_bounds b;
    cameras(c2w, 7, 150, 10); /* yaw 150 .. 210, i.e. up to -150 */
    CHECK(vf_view_coverage(c2w, 7, &b) == VF_OK, "%s", vf_error_message());
    CHECK_NEAR(b.lo[0], 145, 1e-6);
    CHECK_NEAR(b.hi[0], 215, 1e-6);
}

static void test_full_circle(void)
{
    double c2w[16 * 12];
    vf_view_bounds b;
    cameras(c2w, 12, -180, 30); /* every 30 degrees: no gap over 60 */
    CHECK(vf_view_coverage(c2w, 12, &b) == VF_OK, "%s", vf_error_message());
    CHECK_NEAR(b.lo[0], -180, 1e-9);
    CHECK_NEAR(b.hi[0], 180, 1e-9);
}

static void test_too_few(void)
{
    double c2w[16];
    vf_view_bounds b;
    cameras(c2w, 1, 0, 0);
    CHECK(vf_view_coverage(c2w, 1, &b) == VF_EINPUT, "one camera covers no range");
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_frontal_arc);
    CHECK_CASE(test_arc_across_180);
    CHECK_CASE(test_full_circle);
    CHECK_CASE(test_too_few);
    return check_finish();
}
