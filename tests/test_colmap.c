/* COLMAP plumbing without COLMAP: the text model reader on a small handwritten model, camera
 * conversion, progress parsing, and the runner against stand-in programs (a shell script that
 * prints like COLMAP, one that fails, one that crashes). */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "vf/colmap.h"
#include "vf/colmap_model.h"
#include "vf/log.h"
#include "vf/pose.h"

static void write_file(const char *dir, const char *name, const char *text)
{
    char path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, dir, name);
    CHECK(vf_write_file_atomic(path, text, strlen(text)) == VF_OK, "write %s", path);
}

static const char cameras_txt[] =
    "# Camera list with one line of data per camera:\n"
    "# Number of cameras: 2\n"
    "1 OPENCV 540 960 687.7 687.8 270 480 0.057 -0.079 -0.0022 -0.0023\n"
    "2 SIMPLE_RADIAL 1000 750 742.4 500 375 0.09\n";

/* Image 1: identity pose; image 2: rotated 90 degrees about y (q = cos45, 0, sin45, 0), with
 * a name containing a space, and no 2D points at all (an empty line). */
static const char images_txt[] =
    "# Image list with two lines of data per image:\n"
    "# Number of images: 2, mean observations per image: 1\n"
    "1 1 0 0 0 0 0 2 1 0001.jpg\n"
    "10.5 20.5 -1 30 40 7 50.25 60.75 -1\n"
    "2 0.70710678118654757 0 0.70710678118654757 0 1 2 3 2 landscape/my photo.png\n"
    "\n";

static const char points_txt[] =
    "# 3D point list with one line of data per point:\n"
    "7 0.5 -1.5 4 255 128 0 0.5 1 1 2 0\n"
    "8 1 2 3 10 20 30 1.25 1 0\n";

static void test_model(const char *dir)
{
    write_file(dir, "cameras.txt", cameras_txt);
    write_file(dir, "images.txt", images_txt);
    write_file(dir, "points3D.txt", points_txt);
    vf_colmap_model m;
    CHECK(vf_colmap_model_load(dir, &m) == VF_OK, "load: %s", vf_error_message());
    CHECK(m.camera_count == 2 && m.image_count == 2 && m.point_count == 2, "counts %d %d %d",
          m.camera_count, m.image_count, m.point_count);
    if (m.image_count != 2 || m.point_count != 2)
        return;
    const vf_colmap_image *a = vf_colmap_model_image(&m, 1), *b = vf_colmap_model_image(&m, 2);
    CHECK(a && a->keypoints == 3 && a->observations == 1, "image 1 points");
    CHECK(b && b->keypoints == 0 && !strcmp(b->name, "landscape/my photo.png"), "image 2: '%s'",
          b ? b->name : "");
    CHECK(m.points[0].track_length == 2 && m.points[0].track[2] == 2 && m.points[0].rgb[1] == 128,
          "point 7 track and colour");
    /* (0.5 * 2 + 1.25 * 1) / 3 observations */
    CHECK_NEAR(vf_colmap_model_reprojection_error(&m), 0.75, 1e-12);

    /* Image 1 at (0,0,-2) looking along +z (OpenCV), so its OpenGL back axis is -z. */
    double c[3], c2w[16];
    vf_colmap_image_center(a, c);
    CHECK_NEAR(c[2], -2.0, 1e-12);
    vf_colmap_image_c2w(a, c2w);
    CHECK_NEAR(c2w[4 * 2 + 2], -1.0, 1e-12);
    CHECK_NEAR(c2w[4 * 1 + 1], -1.0, 1e-12); /* camera up = world -y (OpenCV y is down) */
    /* Image 2: centre -R^T t. */
    double rot[9], rt[9], expected[3];
    vf_rot_from_quat(b->q, rot);
    vf_mat3_transpose(rot, rt);
    vf_mat3_apply(rt, b->t, expected);
    vf_colmap_image_center(b, c);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(c[k], -expected[k], 1e-12);

    vf_camera cam;
    CHECK(vf_colmap_camera_to_vf(vf_colmap_model_camera(&m, 1), &cam) == VF_OK, "OPENCV");
    CHECK(cam.fx == 687.7 && cam.fy == 687.8 && cam.cx == 270 && cam.cy == 480 &&
              cam.k1 == 0.057 && cam.p2 == -0.0023,
          "OPENCV params");
    CHECK(vf_colmap_camera_to_vf(vf_colmap_model_camera(&m, 2), &cam) == VF_OK, "SIMPLE_RADIAL");
    CHECK(cam.fx == 742.4 && cam.fy == 742.4 && cam.cx == 500 && cam.cy == 375 && cam.k1 == 0.09 &&
              cam.k2 == 0 && cam.width == 1000,
          "SIMPLE_RADIAL params");
    vf_colmap_camera fisheye = {.id = 3, .model = "OPENCV_FISHEYE", .param_count = 8};
    CHECK(vf_colmap_camera_to_vf(&fisheye, &cam) == VF_EINPUT, "unsupported model refused");
    vf_colmap_model_free(&m);

    /* Malformed files name the file and line. */
    write_file(dir, "points3D.txt", "7 0.5 -1.5 4 255 128 0 0.5 1\n");
    CHECK(vf_colmap_model_load(dir, &m) == VF_EINPUT, "odd track refused");
    CHECK(strstr(vf_error_message(), "points3D.txt line 1") != NULL, "message: %s",
          vf_error_message());
    write_file(dir, "images.txt", "1 1 0 0 0 0 0 2 9 a.jpg\n\n");
    write_file(dir, "points3D.txt", "");
    CHECK(vf_colmap_model_load(dir, &m) == VF_EINPUT, "unknown camera refused");
    CHECK(strstr(vf_error_message(), "camera 9") != NULL, "message: %s", vf_error_message());
}

static void test_progress_lines(void)
{
    size_t done = 0, total = 0;
    CHECK(vf_colmap_parse_progress("Processed file [3/50]", &done, &total) && done == 3 &&
              total == 50,
          "feature extraction");
    CHECK(vf_colmap_parse_progress("Matching image [7/40] in 1.2s", &done, &total) && done == 7,
          "sequential matching");
    CHECK(vf_colmap_parse_progress("Matching block [2/3, 1/3] in 4.0s", &done, &total) &&
              done == 4 && total == 9,
          "exhaustive matching");
    total = 50;
    CHECK(vf_colmap_parse_progress("Registering image #17 (12)", &done, &total) && done == 12 &&
              total == 50,
          "mapping");
    CHECK(!vf_colmap_parse_progress("  Features:        6712", &done, &total), "other lines");
}

/* A stand-in program: prints two progress lines and an error, then runs `tail`. */
static void make_script(const char *path, const char *tail)
{
    char text[512];
    snprintf(text, sizeof text,
             "#!/bin/sh\necho \"Processed file [1/2]\"\necho \"Processed file [2/2]\"\n"
             "echo \"args: $*\"\necho \"E0101 ERROR: the disk is on fire\" >&2\n%s\n",
             tail);
    CHECK(vf_write_file_atomic(path, text, strlen(text)) == VF_OK, "script");
    chmod(path, 0755);
}

static void test_runner(const char *dir)
{
    char script[VF_PATH_MAX], log[VF_PATH_MAX];
    vf_path_join(script, sizeof script, dir, "fake-colmap");
    vf_path_join(log, sizeof log, dir, "colmap.log");
    vf_args args = {0};
    vf_args_add(&args, "feature_extractor");
    vf_args_opt(&args, "--SiftExtraction.max_num_features", "%d", 2048);
    vf_colmap colmap;

    setenv("VF_COLMAP", script, 1);
    make_script(script, "exit 0");
    CHECK(vf_colmap_open(&colmap, log) == VF_OK, "open: %s", vf_error_message());
    double seconds = -1;
    CHECK(vf_colmap_run(&colmap, "test", 2, &args, &seconds) == VF_OK, "ok run: %s",
          vf_error_message());
    CHECK(seconds >= 0, "wall time");
    CHECK(colmap.last_exit == 0, "exit code 0 kept");

    make_script(script, "exit 3");
    CHECK(vf_colmap_run(&colmap, "test", 2, &args, NULL) == VF_EINTERNAL, "failing program");
    CHECK(strstr(vf_error_message(), "feature_extractor failed (exit 3)") &&
              strstr(vf_error_message(), "the disk is on fire"),
          "message: %s", vf_error_message());
    CHECK(colmap.last_exit == 3, "exit code kept (%d)", colmap.last_exit);

    make_script(script, "kill -SEGV $$");
    CHECK(vf_colmap_run(&colmap, "test", 2, &args, NULL) == VF_EINTERNAL, "crashing program");
    CHECK(colmap.last_exit == -1, "a crash has no exit code (%d)", colmap.last_exit);
    CHECK(strstr(vf_error_message(), "crashed") != NULL, "message: %s", vf_error_message());
    vf_colmap_close(&colmap);

    char *text = NULL;
    CHECK(vf_read_file(log, &text, NULL) == VF_OK, "log written");
    CHECK(text && strstr(text, "args: feature_extractor --SiftExtraction.max_num_features 2048"),
          "arguments passed one by one, output logged");
    free(text);

    setenv("VF_COLMAP", "/nonexistent/colmap", 1);
    CHECK(vf_colmap_open(&colmap, log) == VF_EINTERNAL, "missing program");
    unsetenv("VF_COLMAP");
    setenv("PATH", "/nonexistent", 1);
    CHECK(vf_colmap_open(&colmap, log) == VF_EINTERNAL, "colmap not on PATH");
    CHECK(strstr(vf_error_message(), "apt-get install colmap") != NULL, "message: %s",
          vf_error_message());
    vf_args_free(&args);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    const char *dir = vf_test_tmpdir();
    vf_log_set_quiet(1);
    test_model(dir);
    CHECK_CASE(test_progress_lines);
    test_runner(dir);
    return check_finish();
}
