/* Tests of vf/camera.h: intrinsics, OPENCV distortion and its inverse, projection, pixel rays. */
#include <string.h>

#include "check.h"

#include "vf/calib.h"
#include "vf/camera.h"
#include "vf/fsutil.h"

static const double PI = 3.14159265358979323846;

static vf_camera lens(double k1, double k2, double p1, double p2)
{
    vf_camera cam = {.width = 640, .height = 480, .fx = 500, .fy = 400, .cx = 320, .cy = 240,
                     .k1 = k1, .k2 = k2, .p1 = p1, .p2 = p2};
    return cam;
}

static void test_intrinsics(void)
{
    /* 90 degrees across 640 pixels: f = 320 / tan 45 = 320 */
    vf_camera cam = vf_camera_from_fov(640, 480, PI / 2);
    CHECK_NEAR(cam.fx, 320.0, 1e-9);
    CHECK_NEAR(cam.fy, 320.0, 1e-9);
    CHECK_NEAR(cam.cx, 320.0, 0);
    CHECK_NEAR(cam.cy, 240.0, 0);
    CHECK(cam.width == 640 && cam.height == 480, "%dx%d", cam.width, cam.height);
    CHECK(!vf_camera_has_distortion(&cam), "fov camera has distortion");

    /* the NeRF-synthetic camera_angle_x 0.6911112070083618 at 800 px gives f = 1111.111 */
    vf_camera nerf = vf_camera_from_fov(800, 800, 0.6911112070083618);
    CHECK_NEAR(nerf.fx, 1111.1110311937682, 1e-6);

    /* halving the image halves every intrinsic; the same ray leaves the same pixel centre */
    vf_camera half = vf_camera_scaled(&cam, 320, 240);
    CHECK_NEAR(half.fx, 160.0, 1e-9);
    CHECK_NEAR(half.cx, 160.0, 0);
    CHECK_NEAR(half.cy, 120.0, 0);
    CHECK(half.width == 320 && half.height == 240, "%dx%d", half.width, half.height);
    vf_camera distorted = lens(0.1, 0, 0, 0);
    vf_camera small = vf_camera_scaled(&distorted, 320, 120);
    CHECK_NEAR(small.fy, 100.0, 1e-12);
    CHECK_NEAR(small.cy, 60.0, 1e-12);
    CHECK_NEAR(small.k1, 0.1, 0);
    double p[3] = {0.3, -0.2, 1.7}, u, v, us, vs;
    vf_camera_project(&distorted, p, &u, &v);
    vf_camera_project(&small, p, &us, &vs);
    CHECK_NEAR(us, u * 0.5, 1e-12);
    CHECK_NEAR(vs, v * 0.25, 1e-12);

    CHECK(vf_camera_has_distortion(&distorted), "k1 not seen");
    vf_camera tangential = lens(0, 0, 0, 1e-4);
    CHECK(vf_camera_has_distortion(&tangential), "p2 not seen");
}

static void test_distort_hand_worked(void)
{
    /* x = 1/4, y = -1/8: r^2 = 5/64, radial = 1 + 0.1 r^2 + 0.01 r^4 = 1.00787353515625
     * x_d = x radial + 2 p1 x y + p2 (r^2 + 2 x^2) = 0.2519683837890625 - 0.0000625 - 0.00040625
     * y_d = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y = -0.12598419189453125 + 0.000109375
     *       + 0.000125 */
    vf_camera cam = lens(0.1, 0.01, 0.001, -0.002);
    double xd, yd;
    vf_camera_distort(&cam, 0.25, -0.125, &xd, &yd);
    CHECK_NEAR(xd, 0.2514996337890625, 1e-15);
    CHECK_NEAR(yd, -0.12574981689453125, 1e-15);

    /* the same point projected: u = 500 x_d + 320, v = 400 y_d + 240 */
    double p[3] = {0.5, -0.25, 2.0}, u, v;
    CHECK(vf_camera_project(&cam, p, &u, &v), "point in front rejected");
    CHECK_NEAR(u, 445.74981689453125, 1e-10);
    CHECK_NEAR(v, 189.7000732421875, 1e-10);

    /* without distortion: u = 500 * 0.25 + 320 = 445, v = 400 * -0.125 + 240 = 190 */
    vf_camera pin = lens(0, 0, 0, 0);
    CHECK(vf_camera_project(&pin, p, &u, &v), "point in front rejected");
    CHECK_NEAR(u, 445.0, 1e-12);
    CHECK_NEAR(v, 190.0, 1e-12);

    /* behind the camera, or on its plane */
    double behind[3] = {0.1, 0.1, -1.0}, on_plane[3] = {1, 1, 0};
    CHECK(!vf_camera_project(&pin, behind, &u, &v), "point behind accepted");
    CHECK(!vf_camera_project(&pin, on_plane, &u, &v), "point on the camera plane accepted");
}

static void check_undistort_round_trip(const vf_camera *cam, double extent, const char *what)
{
    double worst = 0.0;
    for (int i = 0; i <= 20; i++)
        for (int j = 0; j <= 20; j++) {
            double x = extent * (i / 10.0 - 1.0), y = extent * (j / 10.0 - 1.0), xd, yd, bx, by;
            vf_camera_distort(cam, x, y, &xd, &yd);
            vf_camera_undistort(cam, xd, yd, &bx, &by);
            worst = fmax(worst, fmax(fabs(bx - x), fabs(by - y)));
        }
    CHECK(worst < 1e-12, "%s: undistort round trip error %.3g", what, worst);
}

static void test_undistort(void)
{
    /* a typical phone lens, a strong barrel lens and pincushion, over +-0.6 (about 62 deg) */
    vf_camera phone = lens(0.08, -0.03, 0.0005, -0.0007);
    vf_camera barrel = lens(-0.3, 0.08, 0.001, 0.002);
    vf_camera pincushion = lens(0.25, 0.05, -0.002, 0.001);
    check_undistort_round_trip(&phone, 0.6, "phone");
    check_undistort_round_trip(&barrel, 0.6, "barrel");
    check_undistort_round_trip(&pincushion, 0.6, "pincushion");

    /* no distortion: undistort is the identity */
    vf_camera pin = lens(0, 0, 0, 0);
    double x, y;
    vf_camera_undistort(&pin, 0.3, -0.7, &x, &y);
    CHECK_NEAR(x, 0.3, 0);
    CHECK_NEAR(y, -0.7, 0);
}

static void test_pixel_ray(void)
{
    vf_camera cam = lens(-0.2, 0.05, 0.001, -0.001);
    double dir[3];
    vf_camera_pixel_ray(&cam, cam.cx, cam.cy, dir); /* the principal point: straight ahead */
    CHECK_NEAR(dir[0], 0.0, 1e-15);
    CHECK_NEAR(dir[1], 0.0, 1e-15);
    CHECK_NEAR(dir[2], 1.0, 1e-15);

    /* pinhole, hand-worked: pixel (820, 240) is x = 500/500 = 1, so the ray is (1, 0, 1)/sqrt 2 */
    vf_camera pin = lens(0, 0, 0, 0);
    vf_camera_pixel_ray(&pin, 820, 240, dir);
    CHECK_NEAR(dir[0], sqrt(0.5), 1e-15);
    CHECK_NEAR(dir[1], 0.0, 1e-15);
    CHECK_NEAR(dir[2], sqrt(0.5), 1e-15);

    /* centred camera: the centres of the first and last pixels are mirror images */
    vf_camera fov = vf_camera_from_fov(64, 48, PI / 3);
    double first[3], last[3];
    vf_camera_pixel_ray(&fov, 0.5, 0.5, first);
    vf_camera_pixel_ray(&fov, 63.5, 47.5, last);
    CHECK_NEAR(first[0], -last[0], 1e-15);
    CHECK_NEAR(first[1], -last[1], 1e-15);
    /* the left edge of the image is at half the field of view */
    vf_camera_pixel_ray(&fov, 0.0, 24.0, first);
    CHECK_NEAR(atan2(-first[0], first[2]), PI / 6, 1e-12);

    /* ray -> project returns to the pixel, and the ray is unit length */
    for (int i = 0; i < 10; i++)
        for (int j = 0; j < 10; j++) {
            double u = 10 + 62.0 * i, v = 10 + 46.0 * j, pu, pv;
            vf_camera_pixel_ray(&cam, u, v, dir);
            CHECK_NEAR(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2], 1.0, 1e-14);
            double p[3] = {3 * dir[0], 3 * dir[1], 3 * dir[2]};
            CHECK(vf_camera_project(&cam, p, &pu, &pv), "ray goes behind the camera");
            CHECK(fabs(pu - u) < 1e-9 && fabs(pv - v) < 1e-9,
                  "pixel (%g, %g) -> ray -> (%.12g, %.12g)", u, v, pu, pv);
        }
}

/* The camera file (calib/camera_file.c): both spellings of the keys, and every hostile value
 * refused with a message naming the key. */
static void test_camera_file(void)
{
    char path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, vf_test_tmpdir(), "camera.json");
    const char *good = "{\"fx\": 500, \"fy\": 501, \"cx\": 320, \"cy\": 240, \"width\": 640, "
                       "\"height\": 480, \"k1\": 0.1}";
    vf_camera cam;
    vf_write_file_atomic(path, good, strlen(good));
    CHECK(vf_calib_load_camera(path, &cam) == VF_OK && cam.width == 640 && cam.fy == 501 &&
              cam.k1 == 0.1 && cam.p2 == 0,
          "fx/width spelling: %s", vf_error_message());
    static const char *const bad[][2] = {
        {"{\"fl_x\": 500, \"fl_y\": 500, \"cx\": 320, \"cy\": 240, \"w\": 1e300, \"h\": 480}", "\"w\""},
        {"{\"fl_x\": 500, \"fl_y\": 500, \"cx\": 320, \"cy\": 240, \"w\": 640.5, \"h\": 480}", "\"w\""},
        {"{\"fl_x\": -1, \"fl_y\": 500, \"cx\": 320, \"cy\": 240, \"w\": 640, \"h\": 480}", "fl_x"},
        {"{\"fl_x\": 500, \"fl_y\": 500, \"cx\": 320, \"w\": 640, \"h\": 480}", "cy"},
        {"{\"fl_x\": 500, \"fl_y\": 500, \"cx\": 320, \"cy\": 240, \"w\": 640, \"h\": 480, "
         "\"k2\": 1e50}", "k2"},
        {"[1, 2, 3]", "not a camera"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        vf_write_file_atomic(path, bad[i][0], strlen(bad[i][0]));
        CHECK(vf_calib_load_camera(path, &cam) == VF_EINPUT &&
                  strstr(vf_error_message(), bad[i][1]),
              "case %zu refused naming %s: %s", i, bad[i][1], vf_error_message());
    }
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_camera_file);
    CHECK_CASE(test_intrinsics);
    CHECK_CASE(test_distort_hand_worked);
    CHECK_CASE(test_undistort);
    CHECK_CASE(test_pixel_ray);
    return check_finish();
}
