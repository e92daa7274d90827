/* The frame folder COLMAP reads (vf/sfm_images.h): COLMAP's single camera would silently drop
 * frames of another size, so a set mixing portrait and landscape frames is split into one
 * subfolder (one camera) per size; RGBA frames are composited onto the background as PNG;
 * other frames are linked unchanged; the share of plain background is measured. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/image.h"
#include "vf/sfm_images.h"

/* A width x height image: a grey gradient, with the left half transparent when alpha. */
static void write_image(const char *dir, const char *name, int width, int height, int alpha)
{
    char path[VF_PATH_MAX];
    vf_image img;
    vf_path_join(path, sizeof path, dir, name);
    CHECK(vf_image_alloc(&img, width, height, alpha ? 4 : 3) == VF_OK, "alloc");
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            float *p = img.data + ((size_t)y * width + x) * img.channels;
            p[0] = p[1] = p[2] = 0.2f + 0.5f * x / width;
            if (alpha)
                p[3] = x < width / 2 ? 0.0f : 1.0f;
        }
    CHECK(vf_image_save(path, &img) == VF_OK, "save %s: %s", name, vf_error_message());
    vf_image_free(&img);
}

static const vf_sfm_frame *find(const vf_sfm_images *set, const char *name)
{
    for (int i = 0; i < set->count; i++)
        if (!strcmp(set->frames[i].name, name))
            return &set->frames[i];
    return NULL;
}

static void test_one_size(const char *src, const char *dst)
{
    static const float white[3] = {1, 1, 1};
    write_image(src, "a.png", 40, 30, 0);
    write_image(src, "b.png", 40, 30, 0);
    vf_sfm_images set;
    CHECK(vf_sfm_images_prepare(src, dst, white, &set) == VF_OK, "%s", vf_error_message());
    CHECK(set.count == 2 && set.size_groups == 1 && set.with_alpha == 0, "two frames, one size");
    CHECK(find(&set, "a.png") && find(&set, "b.png"), "one size: no subfolders");
    CHECK(set.background_fraction < 0.01, "no plain background (%.3f)", set.background_fraction);
    vf_sfm_images_free(&set);
}

static void test_mixed(const char *src, const char *dst)
{
    static const float white[3] = {1, 1, 1};
    write_image(src, "1_landscape.png", 40, 30, 0);
    write_image(src, "2_portrait.png", 30, 40, 0);
    write_image(src, "3_cutout.png", 40, 30, 1);
    char notes[VF_PATH_MAX];
    vf_path_join(notes, sizeof notes, src, "notes.txt"); /* not an image: skipped */
    FILE *f = fopen(notes, "w");
    if (f) {
        fputs("not a frame\n", f);
        fclose(f);
    }
    vf_sfm_images set;
    CHECK(vf_sfm_images_prepare(src, dst, white, &set) == VF_OK, "%s", vf_error_message());
    CHECK(set.count == 3, "three frames (%d)", set.count);
    CHECK(set.size_groups == 2, "two sizes, so two cameras (%d)", set.size_groups);
    CHECK(set.with_alpha == 1, "one cut-out frame (%d)", set.with_alpha);
    const vf_sfm_frame *land = find(&set, "40x30/1_landscape.png");
    const vf_sfm_frame *port = find(&set, "30x40/2_portrait.png");
    const vf_sfm_frame *cut = find(&set, "40x30/3_cutout.png");
    CHECK(land && port && cut, "frames grouped by size into WxH/ folders");
    /* The cut-out frame's transparent half is white, and counted as background. */
    CHECK_NEAR(set.background_fraction, 0.5 / 3, 0.02);
    char path[VF_PATH_MAX];
    vf_image img;
    vf_path_join(path, sizeof path, dst, "40x30/3_cutout.png");
    CHECK(vf_image_load(path, &img) == VF_OK, "composited frame written");
    if (img.data) {
        CHECK(img.channels == 3, "composited frame is RGB (%d channels)", img.channels);
        CHECK(img.data[0] > 0.99f && img.data[(size_t)(img.width - 1) * 3] < 0.8f,
              "transparent part white, the rest kept");
        vf_image_free(&img);
    }
    vf_path_join(path, sizeof path, dst, "30x40/2_portrait.png");
    CHECK(vf_is_file(path), "portrait frame placed");
    vf_sfm_images_free(&set);
}

/* A frame whose background was removed to opaque white: the white around a dark square is
 * keyed out, the white hole inside the square is not (it does not touch the edge). */
static void test_key_white(void)
{
    vf_image img;
    CHECK(vf_image_alloc(&img, 40, 30, 4) == VF_OK, "alloc");
    for (int y = 0; y < 30; y++)
        for (int x = 0; x < 40; x++) {
            float *p = img.data + ((size_t)y * 40 + x) * 4;
            int square = x >= 10 && x < 30 && y >= 8 && y < 22, hole = x >= 18 && x < 22 &&
                                                                      y >= 13 && y < 17;
            p[0] = p[1] = p[2] = square && !hole ? 0.1f : 1.0f;
            p[3] = 1.0f;
        }
    int keyed = 0;
    CHECK(vf_sfm_key_white_background(&img, &keyed) == VF_OK && keyed, "white background keyed");
    CHECK(img.data[3] == 0.0f && img.data[(29 * 40 + 39) * 4 + 3] == 0.0f, "corners transparent");
    CHECK(img.data[(10 * 40 + 12) * 4 + 3] == 1.0f, "the object stays opaque");
    CHECK(img.data[(15 * 40 + 20) * 4 + 3] == 1.0f, "a white hole inside the object stays opaque");
    /* a real alpha channel is left alone */
    img.data[(10 * 40 + 12) * 4 + 3] = 0.5f;
    CHECK(vf_sfm_key_white_background(&img, &keyed) == VF_OK && !keyed, "real alpha kept");
    vf_image_free(&img);
}

/* Undistorting with all channels: a lens without distortion gives the frame back exactly;
 * a wider pinhole sees past the frame's edge, which comes out transparent; a distorted
 * lens moves pixels where the camera model says. */
static void test_undistort(void)
{
    vf_image src, out = {0};
    CHECK(vf_image_alloc(&src, 32, 24, 4) == VF_OK, "alloc");
    for (size_t i = 0; i < 32 * 24; i++) {
        src.data[4 * i] = (float)(i % 32) / 32, src.data[4 * i + 1] = (float)(i / 32) / 24;
        src.data[4 * i + 2] = 0.5f, src.data[4 * i + 3] = 1.0f;
    }
    vf_camera lens = {.width = 32, .height = 24, .fx = 30, .fy = 30, .cx = 16, .cy = 12};
    CHECK(vf_sfm_undistort_frame(&src, &lens, &lens, &out) == VF_OK, "%s", vf_error_message());
    CHECK(out.width == 32 && out.channels == 4 &&
              !memcmp(out.data, src.data, 32 * 24 * 4 * sizeof(float)),
          "no distortion: the same frame");
    vf_image_free(&out);
    vf_camera wide = lens;
    wide.width = 40, wide.cx = 20;
    CHECK(vf_sfm_undistort_frame(&src, &lens, &wide, &out) == VF_OK, "%s", vf_error_message());
    CHECK(out.data[3] == 0.0f && out.data[(12 * 40 + 20) * 4 + 3] == 1.0f,
          "outside the frame transparent, inside opaque");
    vf_image_free(&out);
    vf_camera barrel = lens;
    barrel.k1 = -0.2;
    CHECK(vf_sfm_undistort_frame(&src, &barrel, &lens, &out) == VF_OK, "%s", vf_error_message());
    double p[3] = {(28.5 - 16) / 30, (20.5 - 12) / 30, 1}, u, v;
    vf_camera_project(&barrel, p, &u, &v);
    CHECK_NEAR(out.data[(20 * 32 + 28) * 4], (u - 0.5) / 32, 1e-5); /* red ramps with x */
    vf_image_free(&src);
    vf_image_free(&out);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    static const float white[3] = {1, 1, 1};
    char src[VF_PATH_MAX], dst[VF_PATH_MAX], src2[VF_PATH_MAX], dst2[VF_PATH_MAX];
    vf_path_join(src, sizeof src, vf_test_tmpdir(), "one");
    vf_path_join(dst, sizeof dst, vf_test_tmpdir(), "one_out");
    vf_path_join(src2, sizeof src2, vf_test_tmpdir(), "mixed");
    vf_path_join(dst2, sizeof dst2, vf_test_tmpdir(), "mixed_out");
    vf_mkdirs(src);
    vf_mkdirs(src2);
    test_one_size(src, dst);
    test_mixed(src2, dst2);
    CHECK_CASE(test_key_white);
    CHECK_CASE(test_undistort);

    vf_sfm_images set;
    CHECK(vf_sfm_images_prepare(dst2 /* only subfolders */, dst, white, &set) == VF_EINPUT,
          "a folder without images is bad input");
    CHECK(strstr(vf_error_message(), "holds no JPEG or PNG") != NULL, "message: %s",
          vf_error_message());
    return check_finish();
}
