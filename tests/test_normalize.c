/* The object frame: cameras made in the object frame (ViewFool viewpoints), moved into an
 * arbitrary "COLMAP" frame by a similarity, must come back exactly where they were: a full
 * ring (up from the cameras' x axes, azimuth from the first camera), an arc looking down on
 * the object (where the mean camera up would lean), and cameras whose axes are parallel (the
 * centre then comes from the sparse points). */
#include <string.h>

#include "check.h"
#include "vf/normalize.h"
#include "vf/pose.h"

#define MAX_CAMERAS 64

/* A similarity with rotation, scale 0.37 and an offset: the "COLMAP" frame. */
static vf_similarity some_world(void)
{
    double axis_angle[3] = {0.3, -1.1, 2.0};
    vf_similarity s = {.scale = 0.37, .t = {5.0, -2.0, 11.0}};
    vf_rot_from_axis_angle(axis_angle, s.R);
    return s;
}

/* Cameras at viewpoints (psi[i], 0, phi, 0, 0, 0), moved into the world by `w`. */
static int make_cameras(const double *psi, int n, double phi, const vf_similarity *w,
                        double *c2w)
{
    for (int i = 0; i < n; i++) {
        vf_viewpoint v = {.psi = psi[i], .phi = phi};
        double obj[16];
        vf_viewpoint_to_c2w(&v, obj);
        vf_similarity_apply_c2w(w, obj, c2w + 16 * i);
    }
    return n;
}

/* normalization o world should be the identity. */
static void check_round_trip(const vf_normalization *norm, const vf_similarity *w,
                             const char *what)
{
    vf_similarity back = vf_similarity_compose(&norm->object_from_world, w);
    vf_similarity id = vf_similarity_identity();
    CHECK(fabs(back.scale - 1) < 1e-9, "%s: scale %.12f", what, back.scale);
    CHECK(vf_rot_angle_deg(back.R, id.R) < 1e-6, "%s: rotation off by %g deg", what,
          vf_rot_angle_deg(back.R, id.R));
    for (int k = 0; k < 3; k++)
        CHECK(fabs(back.t[k]) < 1e-9, "%s: offset %g", what, back.t[k]);
}

static void test_full_ring(void)
{
    double psi[24], c2w[16 * 24];
    for (int i = 0; i < 24; i++)
        psi[i] = i * 15.0 - 170.0 + 170.0 * (i == 0); /* the first camera at psi = 0 */
    vf_similarity w = some_world();
    int n = make_cameras(psi, 24, 140.0, &w, c2w);
    vf_normalization norm;
    CHECK(vf_normalize_scene(c2w, n, NULL, 0, &norm) == VF_OK, "ring: %s", vf_error_message());
    CHECK(!strcmp(norm.up_method, "level camera x axes"), "ring up from x axes");
    CHECK(!strcmp(norm.center_method, "optical axes"), "ring centre from axes");
    CHECK_NEAR(norm.world_distance, 4 * 0.37, 1e-9);
    check_round_trip(&norm, &w, "full ring");
}

static void test_arc_looking_down(void)
{
    double psi[9], c2w[16 * 9];
    for (int i = 0; i < 9; i++)
        psi[i] = -60.0 + 15.0 * i; /* symmetric about psi = 0 */
    vf_similarity w = some_world();
    int n = make_cameras(psi, 9, 130.0, &w, c2w); /* 50 degrees above the horizon */
    vf_normalization norm;
    CHECK(vf_normalize_scene(c2w, n, NULL, 0, &norm) == VF_OK, "arc: %s", vf_error_message());
    CHECK(!strcmp(norm.up_method, "level camera x axes"), "arc up from x axes");
    check_round_trip(&norm, &w, "arc");
}

static void test_parallel_axes(void)
{
    /* Three cameras side by side, all looking along the same direction: axes never meet. */
    vf_similarity w = some_world();
    double c2w[16 * 3], points[3 * 6];
    for (int i = 0; i < 3; i++) {
        vf_viewpoint v = {.phi = 100, .dx = 0.3 * (i - 1)};
        double obj[16];
        vf_viewpoint_to_c2w(&v, obj);
        vf_similarity_apply_c2w(&w, obj, c2w + 16 * i);
    }
    /* Sparse points around the origin (median: the origin), one behind the cameras. */
    const double object_points[6][3] = {{0, 0, 0},        {0.1, -0.1, 0.2},  {-0.1, 0.1, -0.2},
                                        {0.2, 0.2, -0.1}, {-0.2, -0.2, 0.1}, {0, -20, 30}};
    for (int i = 0; i < 6; i++)
        vf_similarity_apply(&w, object_points[i], points + 3 * i);
    vf_normalization norm;
    CHECK(vf_normalize_scene(c2w, 3, points, 6, &norm) == VF_OK, "parallel: %s",
          vf_error_message());
    CHECK(!strcmp(norm.center_method, "sparse points"), "centre from points: %s",
          norm.center_method);
    CHECK(!strcmp(norm.up_method, "mean camera up"), "up from the mean: %s", norm.up_method);
    double c[3];
    vf_similarity_apply(&norm.object_from_world, norm.center_world, c);
    CHECK(fabs(c[0]) + fabs(c[1]) + fabs(c[2]) < 1e-9, "centre maps to the origin");
    double origin[3] = {0, 0, 0}, expected[3];
    vf_similarity_apply(&w, origin, expected);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(norm.center_world[k], expected[k], 1e-9);

    CHECK(vf_normalize_scene(c2w, 3, NULL, 0, &norm) == VF_EINPUT, "no axes, no points");
    CHECK(vf_normalize_scene(c2w, 1, NULL, 0, &norm) == VF_EINPUT, "one camera");
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_full_ring);
    CHECK_CASE(test_arc_looking_down);
    CHECK_CASE(test_parallel_axes);
    return check_finish();
}
