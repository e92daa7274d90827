/* The viewpoint box a set of cameras covers (vf/view_coverage.h): cameras placed at known
 * viewpoints must come back inside the box, with the documented margins, yaw arcs that
 * cross +-180 unwrapped, and a full circle when the cameras surround the object; and the gap
 * of a viewpoint to the nearest photo (the field's trust there) from known angles and
 * distances. */
#include <math.h>

#include "check.h"
#include "vf/pose.h"
#include "vf/view_coverage.h"

/* n cameras with yaw from psi0 in steps of dpsi, phi alternating 110/140, small offsets. */
static void cameras(double *c2w, int n, double psi0, double dpsi)
{
    for (int i = 0; i < n; i++) {
        vf_viewpoint v = {psi0 + i * dpsi, (i % 3) - 1.0,        i % 2 ? 110.0 : 140.0,
                          0.05 * (i % 2),  -0.2 + 0.1 * (i % 5), 0.0};
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

/* The angle between two cameras' centres seen from the origin, in degrees. */
static double centre_angle(const double *a, const double *b)
{
    double d = 0, na = 0, nb = 0;
    for (int k = 0; k < 3; k++) {
        d += a[4 * k + 3] * b[4 * k + 3];
        na += a[4 * k + 3] * a[4 * k + 3];
        nb += b[4 * k + 3] * b[4 * k + 3];
    }
    return acos(d / sqrt(na * nb)) * 180 / M_PI;
}

static void test_trust_gap(void)
{
    double photos[16 * 3], view[16];
    for (int i = 0; i < 3; i++) {
        vf_viewpoint v = {30.0 * i, 0, 120, 0, 0, 0}; /* yaw 0, 30, 60 */
        vf_viewpoint_to_c2w(&v, photos + 16 * i);
    }
    /* between the first two photos: the gap is the angle to the nearer one */
    vf_viewpoint between = {12, 0, 120, 0, 0, 0};
    vf_viewpoint_to_c2w(&between, view);
    vf_view_trust t = vf_view_trust_of_pose(photos, 3, view);
    CHECK(t.nearest == 0, "nearest photo %d, want 0", t.nearest);
    CHECK_NEAR(t.gap_deg, centre_angle(view, photos), 1e-6);
    CHECK_NEAR(t.angle_deg, t.gap_deg, 1e-9);
    CHECK_NEAR(t.distance_ratio, 1.0, 1e-9);
    CHECK(t.gap_deg > 5 && t.gap_deg < 12, "a 12 deg turn of yaw, high up: %g", t.gap_deg);
    CHECK(vf_view_trusted(&t), "%g deg is within the limit", t.gap_deg);
    /* the viewpoint form gives the same */
    double array[6] = {12, 0, 120, 0, 0, 0};
    CHECK_NEAR(vf_view_trust_of(photos, 3, array).gap_deg, t.gap_deg, 1e-9);
    /* on the third photo's line of sight, 10% farther: ln(1.1) radians, 5.46 degrees */
    for (int i = 0; i < 16; i++)
        view[i] = photos[32 + i] * (i == 3 || i == 7 || i == 11 ? 1.1 : 1.0);
    t = vf_view_trust_of_pose(photos, 3, view);
    CHECK(t.nearest == 2, "nearest photo %d, want 2", t.nearest);
    CHECK_NEAR(t.angle_deg, 0, 1e-6);
    CHECK_NEAR(t.distance_ratio, 1.1, 1e-9);
    CHECK_NEAR(t.gap_deg, log(1.1) * 180 / M_PI, 1e-6);
    /* behind the object, 120 deg of yaw from every photo (at a high elevation): beyond */
    vf_viewpoint behind = {180, 0, 120, 0, 0, 0};
    vf_viewpoint_to_c2w(&behind, view);
    t = vf_view_trust_of_pose(photos, 3, view);
    CHECK(t.nearest == 2 && t.gap_deg > 45, "behind: photo %d at %g deg", t.nearest, t.gap_deg);
    CHECK(!vf_view_trusted(&t), "%g deg is beyond the limit", t.gap_deg);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_frontal_arc);
    CHECK_CASE(test_arc_across_180);
    CHECK_CASE(test_full_circle);
    CHECK_CASE(test_too_few);
    CHECK_CASE(test_trust_gap);
    return check_finish();
}
