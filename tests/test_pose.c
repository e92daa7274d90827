/* Tests of vf/pose.h against hand-worked matrices, round trips and the viewpoint conventions. */
#include "check.h"

#include <stdint.h>
#include <string.h>

#include "vf/pose.h"

static const double PI = 3.14159265358979323846;
static const double EPS = 1e-12;

static double rad(double deg) { return deg * PI / 180.0; }

/* A small deterministic generator, so the test does not depend on other modules. */
static uint64_t rng_state = 0x9e3779b97f4a7c15u;
static double uniform(double lo, double hi)
{
    rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
    return lo + (hi - lo) * (double)(rng_state >> 11) / 9007199254740992.0;
}
static double normal(void) /* crude but adequate: sum of 12 uniforms */
{
    double s = 0;
    for (int i = 0; i < 12; i++)
        s += uniform(0, 1);
    return s - 6.0;
}

static double max_abs_diff(const double *a, const double *b, int n)
{
    double m = 0;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

#define CHECK_VEC(a, b, n, tol)                                                              \
    CHECK(max_abs_diff(a, b, n) <= (tol), "%s vs %s: max difference %.3g > %g", #a, #b,     \
          max_abs_diff(a, b, n), (double)(tol))

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static double norm3(const double a[3]) { return sqrt(dot3(a, a)); }

static void random_rotation(double r[9])
{
    double v[3] = {uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
    double n = norm3(v), angle = uniform(0, PI);
    for (int i = 0; i < 3; i++)
        v[i] *= angle / n;
    vf_rot_from_axis_angle(v, r);
}

static void check_is_rotation(const double r[9], const char *what)
{
    double rt[9], rtr[9], id[9];
    vf_mat3_transpose(r, rt);
    vf_mat3_mul(rt, r, rtr);
    vf_mat3_identity(id);
    CHECK(max_abs_diff(rtr, id, 9) < 1e-12, "%s: R^T R differs from I by %.3g", what,
          max_abs_diff(rtr, id, 9));
    CHECK(fabs(vf_mat3_det(r) - 1.0) < 1e-12, "%s: det %.15g", what, vf_mat3_det(r));
}

static void test_basic_rotations(void)
{
    double r[9], out[3];
    double ex[3] = {1, 0, 0}, ey[3] = {0, 1, 0}, ez[3] = {0, 0, 1};
    vf_rot_z(rad(90), r);
    vf_mat3_apply(r, ex, out);
    CHECK_VEC(out, ey, 3, EPS); /* Rz(90) x = y */
    vf_rot_x(rad(90), r);
    vf_mat3_apply(r, ey, out);
    CHECK_VEC(out, ez, 3, EPS); /* Rx(90) y = z */
    vf_rot_y(rad(90), r);
    vf_mat3_apply(r, ez, out);
    CHECK_VEC(out, ex, 3, EPS); /* Ry(90) z = x */

    double rz30[9], want[9] = {cos(rad(30)), -0.5, 0, 0.5, cos(rad(30)), 0, 0, 0, 1};
    vf_rot_z(rad(30), rz30);
    CHECK_VEC(rz30, want, 9, EPS);

    /* multiply and transpose: Rz(30) Rz(60) = Rz(90); Rz(30)^T = Rz(-30) */
    double rz60[9], prod[9], rz90[9], t[9], rzm30[9];
    vf_rot_z(rad(60), rz60);
    vf_mat3_mul(rz30, rz60, prod);
    vf_rot_z(rad(90), rz90);
    CHECK_VEC(prod, rz90, 9, EPS);
    vf_mat3_transpose(rz30, t);
    vf_rot_z(rad(-30), rzm30);
    CHECK_VEC(t, rzm30, 9, EPS);
    double m[9] = {2, 0, 1, 1, 3, 0, 0, 1, 4};
    CHECK_NEAR(vf_mat3_det(m), 2 * 12 - 0 + 1 * 1, EPS); /* 25 */
}

static void test_axis_angle_and_quaternion(void)
{
    /* hand-worked: 90 degrees about z is the quaternion (cos 45, 0, 0, sin 45) */
    double v[3] = {0, 0, PI / 2}, r[9], rz[9], q[4];
    vf_rot_from_axis_angle(v, r);
    vf_rot_z(PI / 2, rz);
    CHECK_VEC(r, rz, 9, EPS);
    vf_rot_to_quat(rz, q);
    double want_q[4] = {sqrt(0.5), 0, 0, sqrt(0.5)};
    CHECK_VEC(q, want_q, 4, EPS);

    /* COLMAP quaternion order: (w, x, y, z) = (0, 1, 0, 0) is 180 degrees about x */
    double qx[4] = {0, 1, 0, 0}, rx180[9], want_rx[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1};
    vf_rot_from_quat(qx, rx180);
    CHECK_VEC(rx180, want_rx, 9, EPS);
    double back[3], want_v[3] = {PI, 0, 0};
    vf_rot_to_axis_angle(rx180, back);
    back[0] = fabs(back[0]); /* +pi and -pi about x are the same rotation */
    CHECK(max_abs_diff(back, want_v, 3) < 1e-12, "180 about x: %g %g %g", back[0], back[1],
          back[2]);

    /* unnormalized quaternion is normalized */
    double q2[4] = {2, 0, 0, 2}, r2[9];
    vf_rot_from_quat(q2, r2);
    CHECK_VEC(r2, rz, 9, EPS);

    /* round trips on random rotations, including near 0 and near 180 degrees */
    for (int i = 0; i < 200; i++) {
        double rr[9], qq[4], r_back[9], aa[3], aa_back[3];
        double angle = i < 20 ? 1e-9 * i : i < 40 ? PI - 1e-7 * (i - 20) : uniform(0, PI);
        double axis[3] = {normal(), normal(), normal()};
        double n = norm3(axis);
        for (int k = 0; k < 3; k++)
            aa[k] = axis[k] / n * angle;
        vf_rot_from_axis_angle(aa, rr);
        check_is_rotation(rr, "from axis-angle");
        vf_rot_to_axis_angle(rr, aa_back);
        CHECK(max_abs_diff(aa, aa_back, 3) < 1e-8, "axis-angle round trip, angle %.12g: %.3g",
              angle, max_abs_diff(aa, aa_back, 3));
        vf_rot_to_quat(rr, qq);
        CHECK_NEAR(qq[0] * qq[0] + qq[1] * qq[1] + qq[2] * qq[2] + qq[3] * qq[3], 1.0, EPS);
        CHECK(qq[0] >= 0, "w = %g", qq[0]);
        vf_rot_from_quat(qq, r_back);
        CHECK_VEC(rr, r_back, 9, 1e-14 * 10);
        CHECK_NEAR(vf_rot_angle_deg(rr, r_back), 0.0, 1e-6);
    }
}

static void test_angle_and_orthonormalize(void)
{
    double a[9], b[9], rz[9];
    random_rotation(a);
    vf_rot_z(rad(37), rz);
    vf_mat3_mul(a, rz, b);
    CHECK_NEAR(vf_rot_angle_deg(a, b), 37.0, 1e-10);
    CHECK_NEAR(vf_rot_angle_deg(b, a), 37.0, 1e-10);
    vf_rot_z(rad(180), rz);
    vf_mat3_mul(a, rz, b);
    CHECK_NEAR(vf_rot_angle_deg(a, b), 180.0, 1e-6);
    vf_rot_z(rad(1e-7), rz);
    vf_mat3_mul(a, rz, b);
    CHECK_NEAR(vf_rot_angle_deg(a, b), 1e-7, 1e-12);

    /* an exact rotation is left alone; a drifted one comes back orthonormal and close */
    double o[9];
    vf_rot_orthonormalize(a, o);
    CHECK_VEC(o, a, 9, 1e-12);
    double drift[9];
    for (int i = 0; i < 9; i++)
        drift[i] = a[i] + 1e-4 * normal();
    vf_rot_orthonormalize(drift, o);
    check_is_rotation(o, "orthonormalized");
    CHECK(vf_rot_angle_deg(o, a) < 0.05, "orthonormalized moved by %g deg",
          vf_rot_angle_deg(o, a));
    /* a pure scaling of a rotation orthonormalizes to that rotation */
    for (int i = 0; i < 9; i++)
        drift[i] = 3.0 * a[i];
    vf_rot_orthonormalize(drift, o);
    CHECK_VEC(o, a, 9, 1e-12);
    /* a symmetric stretch of R: nearest rotation is R itself (polar decomposition) */
    double stretch[9] = {1.2, 0.1, 0, 0.1, 0.9, 0.05, 0, 0.05, 1.1}, m[9];
    vf_mat3_mul(a, stretch, m);
    vf_rot_orthonormalize(m, o);
    CHECK_VEC(o, a, 9, 1e-10);
}

static void test_mat4(void)
{
    double r[9], t[3] = {1, -2, 3}, m[16], inv[16], gen[16], prod[16], id[16];
    random_rotation(r);
    vf_mat4_from_rt(r, t, m);
    vf_mat4_identity(id);
    vf_mat4_rigid_inverse(m, inv);
    CHECK(vf_mat4_inverse(m, gen) == VF_OK, "inverse failed");
    CHECK_VEC(inv, gen, 16, 1e-12);
    vf_mat4_mul(m, inv, prod);
    CHECK_VEC(prod, id, 16, 1e-12);

    /* hand-worked: T(1,-2,3) Rz(90) maps (1,0,0) to (1,-1,3), direction (1,0,0) to (0,1,0) */
    double rz[9], m2[16], p[3] = {1, 0, 0}, out[3];
    vf_rot_z(PI / 2, rz);
    vf_mat4_from_rt(rz, t, m2);
    vf_mat4_transform_point(m2, p, out);
    double want_p[3] = {1, -1, 3}, want_d[3] = {0, 1, 0};
    CHECK_VEC(out, want_p, 3, EPS);
    vf_mat4_transform_dir(m2, p, out);
    CHECK_VEC(out, want_d, 3, EPS);

    /* similarity inverse */
    double sr[9], sm[16], sinv[16], sgen[16];
    for (int i = 0; i < 9; i++)
        sr[i] = 2.5 * r[i];
    vf_mat4_from_rt(sr, t, sm);
    vf_mat4_similarity_inverse(sm, sinv);
    CHECK(vf_mat4_inverse(sm, sgen) == VF_OK, "inverse failed");
    CHECK_VEC(sinv, sgen, 16, 1e-12);

    /* general inverse of a non-rigid matrix, and a singular one */
    double g[16] = {2, 1, 0, 0, 0, 0, 3, 1, 1, 0, 0, 2, 0, 1, 1, 0}, ginv[16];
    CHECK(vf_mat4_inverse(g, ginv) == VF_OK, "inverse failed");
    vf_mat4_mul(g, ginv, prod);
    CHECK_VEC(prod, id, 16, 1e-12);
    double sing[16] = {1, 2, 3, 4, 2, 4, 6, 8, 0, 1, 0, 1, 1, 0, 0, 1};
    CHECK(vf_mat4_inverse(sing, ginv) == VF_EINPUT, "singular matrix inverted");
    CHECK(strstr(vf_error_message(), "singular") != NULL, "message: %s", vf_error_message());
}

static void test_camera_axes(void)
{
    /* a COLMAP camera at world (0, 0, -5) looking along +z, image y down: R = I, t = (0,0,5) */
    double r[9], t[3] = {0, 0, 5}, c2w[16];
    vf_mat3_identity(r);
    vf_w2c_cv_to_c2w_gl(r, t, c2w);
    double want[16] = {1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, -5, 0, 0, 0, 1};
    CHECK_VEC(c2w, want, 16, EPS);
    /* OpenGL: the camera looks along its -z, which must be world +z here */
    double fwd_cam[3] = {0, 0, -1}, fwd[3], want_fwd[3] = {0, 0, 1};
    vf_mat4_transform_dir(c2w, fwd_cam, fwd);
    CHECK_VEC(fwd, want_fwd, 3, EPS);

    for (int i = 0; i < 20; i++) {
        double rr[9], tt[3] = {uniform(-3, 3), uniform(-3, 3), uniform(-3, 3)}, rb[9], tb[3];
        double gl[16], cv[16], gl2[16];
        random_rotation(rr);
        vf_w2c_cv_to_c2w_gl(rr, tt, gl);
        vf_c2w_gl_to_w2c_cv(gl, rb, tb);
        CHECK_VEC(rr, rb, 9, 1e-12);
        CHECK_VEC(tt, tb, 3, 1e-12);
        vf_c2w_gl_to_cv(gl, cv);
        vf_c2w_cv_to_gl(cv, gl2);
        CHECK_VEC(gl, gl2, 16, 0);
        /* a world point in front of the OpenCV camera (z > 0) is in front of the GL one (z < 0) */
        double x_cam_cv[3] = {0.3, -0.2, 2.0}, x_world[3], x_cam_gl[3], w2c_gl[16];
        vf_mat4_transform_point(cv, x_cam_cv, x_world);
        vf_mat4_rigid_inverse(gl, w2c_gl);
        vf_mat4_transform_point(w2c_gl, x_world, x_cam_gl);
        double want_gl[3] = {0.3, 0.2, -2.0};
        CHECK_VEC(x_cam_gl, want_gl, 3, 1e-12);
    }
}

static vf_similarity random_similarity(void)
{
    vf_similarity s = {.scale = uniform(0.2, 5.0)};
    random_rotation(s.R);
    for (int k = 0; k < 3; k++)
        s.t[k] = uniform(-10, 10);
    return s;
}

static void test_similarity(void)
{
    /* hand-worked: scale 2, Rz(90), t = (1, 0, 0) maps (1, 0, 0) to (1, 2, 0) */
    vf_similarity s = {.scale = 2.0, .t = {1, 0, 0}};
    vf_rot_z(PI / 2, s.R);
    double p[3] = {1, 0, 0}, out[3], want[3] = {1, 2, 0};
    vf_similarity_apply(&s, p, out);
    CHECK_VEC(out, want, 3, EPS);

    vf_similarity id = vf_similarity_identity();
    vf_similarity_apply(&id, p, out);
    CHECK_VEC(out, p, 3, 0);

    for (int i = 0; i < 20; i++) {
        vf_similarity a = random_similarity(), b = random_similarity();
        vf_similarity inv = vf_similarity_inverse(&a), ab = vf_similarity_compose(&b, &a);
        vf_similarity round = vf_similarity_compose(&inv, &a);
        double x[3] = {uniform(-5, 5), uniform(-5, 5), uniform(-5, 5)}, y[3], z[3], w[3];
        vf_similarity_apply(&a, x, y);
        vf_similarity_apply(&inv, y, z);
        CHECK_VEC(z, x, 3, 1e-12);
        vf_similarity_apply(&round, x, z);
        CHECK_VEC(z, x, 3, 1e-12);
        vf_similarity_apply(&b, y, z);
        vf_similarity_apply(&ab, x, w);
        CHECK_VEC(z, w, 3, 1e-11);
        /* the 4x4 form agrees */
        double m[16];
        vf_similarity_to_mat4(&a, m);
        vf_mat4_transform_point(m, x, z);
        CHECK_VEC(z, y, 3, 1e-12);

        /* moving a camera: the rotation stays orthonormal, a point seen at depth d in the
         * camera is seen at depth scale * d afterwards, along the same camera direction */
        double c2w[16], moved[16], rot[9], rc[9], pos[3] = {1, 2, 3};
        random_rotation(rc);
        vf_mat4_from_rt(rc, pos, c2w);
        vf_similarity_apply_c2w(&a, c2w, moved);
        vf_mat4_rotation(moved, rot);
        check_is_rotation(rot, "moved camera");
        double in_cam[3] = {0.1, 0.2, -1.5}, world[3], world_moved[3], in_moved[3], w2c[16];
        vf_mat4_transform_point(c2w, in_cam, world);
        vf_similarity_apply(&a, world, world_moved);
        vf_mat4_rigid_inverse(moved, w2c);
        vf_mat4_transform_point(w2c, world_moved, in_moved);
        double want_cam[3] = {a.scale * 0.1, a.scale * 0.2, a.scale * -1.5};
        CHECK_VEC(in_moved, want_cam, 3, 1e-10);
    }
}

static void test_umeyama(void)
{
    enum { N = 200 };
    static double src[3 * N], dst[3 * N];
    vf_similarity truth = random_similarity(), fit;
    for (int i = 0; i < N; i++) {
        for (int k = 0; k < 3; k++)
            src[3 * i + k] = uniform(-2, 2);
        vf_similarity_apply(&truth, &src[3 * i], &dst[3 * i]);
    }
    /* exact data: recovered to rounding */
    CHECK(vf_similarity_umeyama(src, dst, N, &fit) == VF_OK, "%s", vf_error_message());
    CHECK_NEAR(fit.scale, truth.scale, 1e-10);
    CHECK(vf_rot_angle_deg(fit.R, truth.R) < 1e-8, "rotation off by %g deg",
          vf_rot_angle_deg(fit.R, truth.R));
    CHECK_VEC(fit.t, truth.t, 3, 1e-9);

    /* noisy data: recovered to about the noise over sqrt(N) */
    for (int i = 0; i < 3 * N; i++)
        dst[i] += 0.01 * truth.scale * normal();
    CHECK(vf_similarity_umeyama(src, dst, N, &fit) == VF_OK, "%s", vf_error_message());
    CHECK(fabs(fit.scale / truth.scale - 1.0) < 2e-3, "scale %g vs %g", fit.scale, truth.scale);
    CHECK(vf_rot_angle_deg(fit.R, truth.R) < 0.1, "rotation off by %g deg",
          vf_rot_angle_deg(fit.R, truth.R));
    CHECK(max_abs_diff(fit.t, truth.t, 3) < 0.01 * truth.scale, "t off by %g",
          max_abs_diff(fit.t, truth.t, 3));
    check_is_rotation(fit.R, "umeyama");

    /* a 180-degree rotation and a planar (coplanar) point set are fine */
    vf_similarity flip = {.scale = 0.5, .t = {0, 0, 1}};
    vf_rot_x(PI, flip.R);
    double plane[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, plane_dst[12];
    for (int i = 0; i < 4; i++)
        vf_similarity_apply(&flip, &plane[3 * i], &plane_dst[3 * i]);
    CHECK(vf_similarity_umeyama(plane, plane_dst, 4, &fit) == VF_OK, "%s", vf_error_message());
    CHECK(vf_rot_angle_deg(fit.R, flip.R) < 1e-8, "planar: off by %g deg",
          vf_rot_angle_deg(fit.R, flip.R));
    CHECK_NEAR(fit.scale, 0.5, 1e-12);

    /* a reflected target must still give a proper rotation */
    double mirrored[3 * N];
    for (int i = 0; i < N; i++)
        mirrored[3 * i] = -src[3 * i], mirrored[3 * i + 1] = src[3 * i + 1],
        mirrored[3 * i + 2] = src[3 * i + 2];
    CHECK(vf_similarity_umeyama(src, mirrored, N, &fit) == VF_OK, "%s", vf_error_message());
    check_is_rotation(fit.R, "umeyama on a mirror image");

    /* degenerate inputs */
    double line[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
    CHECK(vf_similarity_umeyama(line, line, 3, &fit) == VF_EINPUT, "collinear accepted");
    CHECK(vf_similarity_umeyama(src, dst, 2, &fit) == VF_EINPUT, "2 points accepted");
}

/* Twenty cameras seen in another frame (a similarity away) agree exactly; turning two of them
 * by 10 degrees shows as a max of 10, two over 5 degrees and an unchanged median. */
static void test_pose_compare(void)
{
    enum { N = 20 };
    double ours[N][16], ref[N][16];
    const double *a[N], *b[N];
    vf_similarity frame = random_similarity();
    for (int i = 0; i < N; i++) {
        vf_viewpoint v = {.psi = 18.0 * i, .theta = uniform(10, 60), .phi = uniform(-5, 5)};
        vf_viewpoint_to_c2w(&v, ref[i]);
        vf_similarity_apply_c2w(&frame, ref[i], ours[i]);
        a[i] = ours[i];
        b[i] = ref[i];
    }
    vf_pose_agreement g;
    CHECK(vf_pose_compare(a, b, N, 0, &g) == VF_OK, "%s", vf_error_message());
    CHECK(g.count == N && g.rot_max < 1e-6 && g.pos_p90 < 1e-9 && g.rot_over_5deg == 0,
          "exact: max %g deg, position p90 %g", g.rot_max, g.pos_p90);
    for (int i = 3; i < N; i += 10) { /* turn cameras 3 and 13 by 10 degrees about their x */
        double turn[9], rot[9], pos[3], turned[9];
        vf_rot_x(rad(10), turn);
        vf_mat4_rotation(ours[i], rot);
        vf_mat4_translation(ours[i], pos);
        vf_mat3_mul(rot, turn, turned);
        vf_mat4_from_rt(turned, pos, ours[i]);
    }
    CHECK(vf_pose_compare(a, b, N, 0, &g) == VF_OK, "%s", vf_error_message());
    CHECK(fabs(g.rot_max - 10) < 1e-6 && g.rot_over_5deg == 2 && g.rot_median < 1e-6,
          "two turned: max %g deg, %d over 5, median %g", g.rot_max, g.rot_over_5deg,
          g.rot_median);
    CHECK(vf_pose_compare(a, b, 2, 0, &g) == VF_EINPUT, "2 cameras accepted");
}

/* ---- viewpoint ---- */

static void c2w_parts(const vf_viewpoint *v, double pos[3], double view[3], double up[3])
{
    double c2w[16], back[3] = {0, 0, -1}, yup[3] = {0, 1, 0};
    vf_viewpoint_to_c2w(v, c2w);
    vf_mat4_translation(c2w, pos);
    vf_mat4_transform_dir(c2w, back, view);
    vf_mat4_transform_dir(c2w, yup, up);
}

static void test_viewpoint_hand_worked(void)
{
    /* phi = 90: overhead, looking straight down, image up = world +y */
    vf_viewpoint top = {0, 0, 90, 0, 0, 0};
    double c2w[16], want_top[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 4, 0, 0, 0, 1};
    vf_viewpoint_to_c2w(&top, c2w);
    CHECK_VEC(c2w, want_top, 16, EPS);
    double pos[3], view[3], up[3];
    c2w_parts(&top, pos, view, up);
    double down[3] = {0, 0, -1};
    CHECK_VEC(view, down, 3, EPS);

    /* psi = 90, phi = 30, offsets (dx, dy, dz) = (0.2, 1, -0.4): R = Rz(90) Rx(-60),
     * position R (0.2, -0.4, 5); worked by hand */
    vf_viewpoint v = {90, 0, 30, 0.2, 1.0, -0.4};
    double h = sqrt(3.0) / 2;
    double want[16] = {0, -0.5, -h, 0.2 - 5 * h,  /* row 0 */
                       1, 0,    0,  0.2,          /* row 1 */
                       0, -h,   0.5, 0.4 * h + 2.5, 0, 0, 0, 1};
    vf_viewpoint_to_c2w(&v, c2w);
    CHECK_VEC(c2w, want, 16, 1e-12);

    /* theta = 30 at phi = 90: Ry(-30), the camera tilts toward -x, position (-2, 0, 2 sqrt 3) */
    vf_viewpoint tilt = {0, 30, 90, 0, 0, 0};
    double want_tilt[16] = {h, 0, -0.5, -2, 0, 1, 0, 0, 0.5, 0, h, 4 * h, 0, 0, 0, 1};
    vf_viewpoint_to_c2w(&tilt, c2w);
    CHECK_VEC(c2w, want_tilt, 16, 1e-12);
}

static void test_viewpoint_phi(void)
{
    /* phi = 20: camera at (0, 4 cos 20, 4 sin 20), 20 degrees above the ground, looking at the
     * origin, but rolled 180 degrees: its up vector (0, sin 20, -cos 20) points below the
     * horizon, so world up is down in the image. */
    vf_viewpoint low = {0, 0, 20, 0, 0, 0};
    double pos[3], view[3], up[3];
    c2w_parts(&low, pos, view, up);
    double want_pos[3] = {0, 4 * cos(rad(20)), 4 * sin(rad(20))};
    CHECK_VEC(pos, want_pos, 3, 1e-12);
    CHECK_NEAR(pos[2], 1.368080573, 1e-9);
    double to_origin[3] = {-pos[0] / 4, -pos[1] / 4, -pos[2] / 4};
    CHECK_VEC(view, to_origin, 3, 1e-12);
    double want_up[3] = {0, sin(rad(20)), -cos(rad(20))};
    CHECK_VEC(up, want_up, 3, 1e-12);
    CHECK(up[2] < -0.9, "phi = 20 is upside down: up z = %g", up[2]);

    /* phi = 160: the mirror position on the -y side, and upright */
    vf_viewpoint high = {0, 0, 160, 0, 0, 0};
    c2w_parts(&high, pos, view, up);
    double want_pos160[3] = {0, -4 * cos(rad(20)), 4 * sin(rad(20))};
    CHECK_VEC(pos, want_pos160, 3, 1e-12);
    CHECK(up[2] > 0.9, "phi = 160 is upright: up z = %g", up[2]);

    /* phi' = 180 - phi with psi + 180 is the same camera position and gaze, rolled 180 */
    for (double phi = 20; phi <= 160; phi += 10) {
        vf_viewpoint a = {25, 0, phi, 0, 0, 0}, b = {205, 0, 180 - phi, 0, 0, 0};
        double pa[3], va[3], ua[3], pb[3], vb[3], ub[3];
        c2w_parts(&a, pa, va, ua);
        c2w_parts(&b, pb, vb, ub);
        CHECK_VEC(pa, pb, 3, 1e-12);
        CHECK_VEC(va, vb, 3, 1e-12);
        CHECK_NEAR(dot3(ua, ub), -1.0, 1e-12);
        CHECK_NEAR(pa[2], 4 * sin(rad(phi)), 1e-12); /* height above the ground */
    }
}

static void test_viewpoint_properties(void)
{
    for (int i = 0; i < 200; i++) {
        vf_viewpoint v = {uniform(-180, 180), uniform(-30, 30), uniform(20, 160), 0,
                          uniform(-1, 1), 0};
        double pos[3], view[3], up[3];
        c2w_parts(&v, pos, view, up);
        /* dx = dz = 0: distance 4 + dy and the optical axis through the origin */
        CHECK_NEAR(norm3(pos), VF_CAMERA_DISTANCE + v.dy, 1e-12);
        double cross[3] = {pos[1] * view[2] - pos[2] * view[1],
                           pos[2] * view[0] - pos[0] * view[2],
                           pos[0] * view[1] - pos[1] * view[0]};
        CHECK(norm3(cross) < 1e-12, "axis misses the origin by %g", norm3(cross));
        CHECK(dot3(pos, view) < 0, "camera looks away from the origin");

        /* psi rotates the camera (position and axes) about world z */
        vf_viewpoint v0 = v;
        v0.psi = 0;
        v0.dx = uniform(-0.5, 0.5), v0.dz = uniform(-0.5, 0.5);
        vf_viewpoint vp = v0;
        vp.psi = v.psi;
        double c0[16], cp[16], rz[16], rz3[9], zero[3] = {0, 0, 0}, expected[16];
        vf_viewpoint_to_c2w(&v0, c0);
        vf_viewpoint_to_c2w(&vp, cp);
        vf_rot_z(rad(v.psi), rz3);
        vf_mat4_from_rt(rz3, zero, rz);
        vf_mat4_mul(rz, c0, expected);
        CHECK_VEC(cp, expected, 16, 1e-12);

        /* dx moves the camera along its own x (right), dz along its own y (up) */
        double c_off[16], right[3] = {1, 0, 0}, r_world[3], u_world[3], yup[3] = {0, 1, 0};
        vf_viewpoint with_off = v;
        with_off.dx = 0.3, with_off.dz = -0.2;
        vf_viewpoint_to_c2w(&with_off, c_off);
        vf_mat4_transform_dir(c_off, right, r_world);
        vf_mat4_transform_dir(c_off, yup, u_world);
        double moved[3];
        vf_mat4_translation(c_off, moved);
        for (int k = 0; k < 3; k++)
            moved[k] -= pos[k];
        double want_move[3];
        for (int k = 0; k < 3; k++)
            want_move[k] = 0.3 * r_world[k] - 0.2 * u_world[k];
        CHECK_VEC(moved, want_move, 3, 1e-12);
    }
}

static int psi_matches(double a, double b)
{
    double d = fmod(fabs(a - b), 360.0);
    return fmin(d, 360.0 - d) < 1e-9;
}

static void check_round_trip(const vf_viewpoint *v)
{
    double c2w[16], rot[9];
    vf_viewpoint back;
    vf_viewpoint_to_c2w(v, c2w);
    vf_mat4_rotation(c2w, rot);
    check_is_rotation(rot, "viewpoint rotation");
    vf_c2w_to_viewpoint(c2w, &back);
    CHECK(psi_matches(back.psi, v->psi), "psi %.12g -> %.12g", v->psi, back.psi);
    CHECK_NEAR(back.theta, v->theta, 1e-9);
    CHECK_NEAR(back.phi, v->phi, 1e-9);
    CHECK_NEAR(back.dx, v->dx, 1e-12);
    CHECK_NEAR(back.dy, v->dy, 1e-12);
    CHECK_NEAR(back.dz, v->dz, 1e-12);
}

static void test_viewpoint_round_trip_and_bounds(void)
{
    /* the default box of vf/viewfool.h */
    double lo[6] = {-180, -30, 20, -0.5, -1, -0.5}, hi[6] = {180, 30, 160, 0.5, 1, 0.5};

    /* every corner of the box (2^6): orthonormal, det +1, and round-trips */
    for (int corner = 0; corner < 64; corner++) {
        double a[6];
        for (int k = 0; k < 6; k++)
            a[k] = corner & (1 << k) ? hi[k] : lo[k];
        vf_viewpoint v = vf_viewpoint_from_array(a);
        check_round_trip(&v);
    }
    for (int i = 0; i < 500; i++) {
        double a[6];
        for (int k = 0; k < 6; k++)
            a[k] = uniform(lo[k], hi[k]);
        vf_viewpoint v = vf_viewpoint_from_array(a);
        check_round_trip(&v);
    }
    vf_viewpoint v = {1, 2, 3, 4, 5, 6};
    double a[6], want[6] = {1, 2, 3, 4, 5, 6};
    vf_viewpoint_to_array(&v, a);
    CHECK_VEC(a, want, 6, 0);
    vf_viewpoint w = vf_viewpoint_from_array(want);
    CHECK(memcmp(&v, &w, sizeof v) == 0, "array -> viewpoint changed the order");
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_basic_rotations);
    CHECK_CASE(test_axis_angle_and_quaternion);
    CHECK_CASE(test_angle_and_orthonormalize);
    CHECK_CASE(test_mat4);
    CHECK_CASE(test_camera_axes);
    CHECK_CASE(test_similarity);
    CHECK_CASE(test_umeyama);
    CHECK_CASE(test_pose_compare);
    CHECK_CASE(test_viewpoint_hand_worked);
    CHECK_CASE(test_viewpoint_phi);
    CHECK_CASE(test_viewpoint_properties);
    CHECK_CASE(test_viewpoint_round_trip_and_bounds);
    return check_finish();
}
