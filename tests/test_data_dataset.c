/* Posed-dataset import: the real NeRF-synthetic chair and the instant-ngp fox load with the
 * right cameras; a save/load round trip keeps everything; malformed files fail clearly. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "vf/dataset.h"

static vf_status load_text(const char *name, const char *json, vf_dataset *ds)
{
    char path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, vf_test_tmpdir(), name);
    vf_write_file_atomic(path, json, strlen(json));
    return vf_dataset_load(path, ds);
}

static void test_datasets(void)
{
    vf_dataset ds;
    CHECK(vf_dataset_load(vf_test_shared("data/nerf_synthetic/chair/transforms_train.json"), &ds) ==
              VF_OK,
          "chair: %s", vf_error_message());
    CHECK(ds.count == 100, "chair has 100 training frames, got %d", ds.count);
    if (ds.count == 100) {
        /* focal = 0.5 * 200 / tan(0.5 * 0.6911112070083618) */
        CHECK_NEAR(ds.frames[0].camera.fx, 277.7777, 1e-3);
        CHECK_NEAR(ds.frames[0].camera.cx, 100.0, 1e-9);
        CHECK(ds.frames[0].camera.width == 200 && ds.frames[0].camera.height == 200, "size");
        CHECK(strstr(ds.frames[5].image_path, "train/r_5.png") != NULL, "path %s",
              ds.frames[5].image_path);
        double *m = ds.frames[0].c2w;
        CHECK_NEAR(sqrt(m[3] * m[3] + m[7] * m[7] + m[11] * m[11]), 4.031, 0.01);
    }

    /* Save and load again: the same cameras and matrices. */
    char saved[VF_PATH_MAX];
    vf_path_join(saved, sizeof saved, vf_test_tmpdir(), "chair.json");
    CHECK(vf_dataset_save(saved, &ds) == VF_OK, "save: %s", vf_error_message());
    vf_dataset again;
    CHECK(vf_dataset_load(saved, &again) == VF_OK, "reload: %s", vf_error_message());
    CHECK(again.count == ds.count, "same count");
    if (again.count == ds.count && ds.count > 42) {
        CHECK_NEAR(again.frames[42].camera.fx, ds.frames[42].camera.fx, 1e-9);
        CHECK_NEAR(again.frames[42].c2w[7], ds.frames[42].c2w[7], 1e-9);
        CHECK(!strcmp(again.frames[42].image_path, ds.frames[42].image_path), "same image");
    }
    vf_dataset_free(&again);
    vf_dataset_free(&ds);

    /* The fox: explicit intrinsics with OPENCV distortion, JPEG images, portrait. */
    CHECK(vf_dataset_load(vf_test_shared("data/real_captures/instant_ngp_fox/transforms.json"),
                          &ds) == VF_OK,
          "fox: %s", vf_error_message());
    CHECK(ds.count == 50, "fox has 50 frames, got %d", ds.count);
    if (ds.count == 50) {
        const vf_camera *c = &ds.frames[0].camera;
        CHECK(c->width == 540 && c->height == 960, "fox size %dx%d", c->width, c->height);
        CHECK_NEAR(c->fx, 687.76, 1e-6);
        CHECK_NEAR(c->fy, 687.245, 1e-6);
        CHECK_NEAR(c->cy, 482.634, 1e-6);
        CHECK_NEAR(c->k1, 0.0578421, 1e-9);
        CHECK_NEAR(c->p2, 0.00015575, 1e-12);
    }
    vf_dataset_free(&ds);

    /* Full-resolution intrinsics with half-size images are scaled to the images. */
    CHECK(vf_dataset_load(vf_test_shared(
                              "data/real_captures/instant_ngp_fox/transforms_original_1080x1920.json"),
                          &ds) == VF_EINPUT,
          "original fox file lists images that do not exist");
    CHECK(strstr(vf_error_message(), "does not exist") != NULL, "message: %s", vf_error_message());

    /* Malformed files: each names the file and the problem. */
    char json[VF_PATH_MAX * 2];
    CHECK(load_text("empty.json", "{}", &ds) == VF_EINPUT, "no frames");
    CHECK(strstr(vf_error_message(), "frames") != NULL, "message: %s", vf_error_message());
    CHECK(load_text("bad.json", "{\"frames\": [", &ds) == VF_EINPUT, "invalid JSON");
    CHECK(strstr(vf_error_message(), "bad.json") != NULL, "message: %s", vf_error_message());
    snprintf(json, sizeof json,
             "{\"camera_angle_x\": 0.69, \"frames\": [{\"file_path\": \"%s\"}]}",
             vf_test_shared("data/nerf_synthetic/chair/train/r_0"));
    CHECK(load_text("nomatrix.json", json, &ds) == VF_EINPUT, "missing transform_matrix");
    CHECK(strstr(vf_error_message(), "transform_matrix") != NULL, "message: %s",
          vf_error_message());
    snprintf(json, sizeof json,
             "{\"frames\": [{\"file_path\": \"%s\", \"transform_matrix\": "
             "[[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]}",
             vf_test_shared("data/nerf_synthetic/chair/train/r_0"));
    CHECK(load_text("nofocal.json", json, &ds) == VF_EINPUT, "missing focal length");
    CHECK(strstr(vf_error_message(), "focal") != NULL, "message: %s", vf_error_message());
    CHECK(load_text("missing.json",
                    "{\"camera_angle_x\": 0.69, \"frames\": [{\"file_path\": \"nope/r_0\", "
                    "\"transform_matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]}",
                    &ds) == VF_EINPUT,
          "missing image");
    CHECK(strstr(vf_error_message(), "nope/r_0") != NULL, "message: %s", vf_error_message());

    /* Numbers out of range are refused, never cast (fuzzing: "w": 1e300 was undefined
     * behaviour in the int conversion; a huge matrix entry renders from infinity). */
    static const char *const hostile[][2] = {
        {"\"w\": 1e300, \"h\": 200", "w and h"},
        {"\"w\": -5, \"h\": 200", "w and h"},
        {"\"w\": 200.5, \"h\": 200", "w and h"},
        {"\"fl_x\": 1e200", "out of range"},
        {"\"k1\": 1e9", "out of range"},
    };
    for (size_t i = 0; i < sizeof hostile / sizeof hostile[0]; i++) {
        snprintf(json, sizeof json,
                 "{\"camera_angle_x\": 0.69, %s, \"frames\": [{\"file_path\": \"%s\", "
                 "\"transform_matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]}",
                 hostile[i][0], vf_test_shared("data/nerf_synthetic/chair/train/r_0"));
        CHECK(load_text("hostile.json", json, &ds) == VF_EINPUT &&
                  strstr(vf_error_message(), hostile[i][1]),
              "%s refused: %s", hostile[i][0], vf_error_message());
    }
    snprintf(json, sizeof json,
             "{\"camera_angle_x\": 0.69, \"frames\": [{\"file_path\": \"%s\", "
             "\"transform_matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,1e300],[0,0,0,1]]}]}",
             vf_test_shared("data/nerf_synthetic/chair/train/r_0"));
    CHECK(load_text("hostile.json", json, &ds) == VF_EINPUT &&
              strstr(vf_error_message(), "transform_matrix[2][3]"),
          "a huge matrix entry refused: %s", vf_error_message());
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_datasets);
    return check_finish();
}
