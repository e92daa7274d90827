/* Image module: file round trips, alpha, resizing, cropping, EXIF orientation (the same with
 * OpenImageIO and OpenCV), denoising and error messages. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/fsutil.h"
#include "vf/image.h"
#include "vf/rgb8.h"
#include "vf/rng.h"

static float *pixel(const vf_image *img, int x, int y)
{
    return img->data + ((size_t)y * img->width + x) * img->channels;
}

static void fill_pattern(vf_image *img)
{
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            for (int c = 0; c < img->channels; c++)
                pixel(img, x, y)[c] = (float)((x * 37 + y * 11 + c * 71) % 256) / 255.0f;
}

static double max_difference(const vf_image *a, const vf_image *b)
{
    double worst = 0;
    size_t n = (size_t)a->width * a->height * a->channels;
    for (size_t i = 0; i < n; i++)
        worst = fmax(worst, fabs((double)a->data[i] - (double)b->data[i]));
    return worst;
}

static const char *scratch(const char *name)
{
    static char path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, vf_test_tmpdir(), name);
    return path;
}

static void test_png_round_trip(void)
{
    vf_image img, back = {0};
    CHECK(vf_image_alloc(&img, 7, 5, 3) == VF_OK, "alloc");
    fill_pattern(&img);
    const char *path = scratch("pattern.png");
    CHECK(vf_image_save(path, &img) == VF_OK, "save png: %s", vf_error_message());
    CHECK(vf_image_load(path, &back) == VF_OK, "load png: %s", vf_error_message());
    CHECK(back.width == 7 && back.height == 5 && back.channels == 3, "png size %dx%dx%d",
          back.width, back.height, back.channels);
    if (back.data)
        CHECK(max_difference(&img, &back) <= 1.0 / 255, "png values differ by %g",
              max_difference(&img, &back));
    int w = 0, h = 0, c = 0;
    CHECK(vf_image_info(path, &w, &h, &c) == VF_OK && w == 7 && h == 5 && c == 3,
          "info %dx%dx%d", w, h, c);
    vf_image_free(&back);
    vf_image_free(&img);
}

static void test_exr_round_trip(void)
{
    vf_image img, back = {0};
    CHECK(vf_image_alloc(&img, 6, 4, 4) == VF_OK, "alloc");
    fill_pattern(&img);
    img.data[0] = 3.75f; /* float formats keep values outside 0..1 */
    img.data[1] = -0.125f;
    img.data[2] = 1e-4f;
    const char *path = scratch("pattern.exr");
    CHECK(vf_image_save(path, &img) == VF_OK, "save exr: %s", vf_error_message());
    CHECK(vf_image_load(path, &back) == VF_OK, "load exr: %s", vf_error_message());
    CHECK(back.width == 6 && back.height == 4 && back.channels == 4, "exr size %dx%dx%d",
          back.width, back.height, back.channels);
    if (back.data)
        CHECK(max_difference(&img, &back) <= 1e-6, "exr values differ by %g",
              max_difference(&img, &back));
    vf_image_free(&back);
    vf_image_free(&img);
}

static void test_jpeg_drops_alpha(void)
{
    vf_image img, back = {0};
    CHECK(vf_image_alloc(&img, 16, 16, 4) == VF_OK, "alloc");
    for (int i = 0; i < 16 * 16; i++)
        memcpy(img.data + 4 * i, (float[4]){0.8f, 0.4f, 0.2f, 0.5f}, sizeof(float[4]));
    const char *path = scratch("flat.jpg");
    CHECK(vf_image_save(path, &img) == VF_OK, "save jpg: %s", vf_error_message());
    CHECK(vf_image_load(path, &back) == VF_OK, "load jpg: %s", vf_error_message());
    CHECK(back.channels == 3, "jpeg has %d channels", back.channels);
    if (back.data) {
        CHECK_NEAR(pixel(&back, 8, 8)[0], 0.8, 0.02);
        CHECK_NEAR(pixel(&back, 8, 8)[2], 0.2, 0.02);
    }
    vf_image_free(&back);
    vf_image_free(&img);
}

/* Pixels: opaque red, half-transparent red, fully transparent green. */
static void test_alpha_compositing(void)
{
    vf_image rgba, straight = {0}, on_white = {0}, on_black = {0};
    CHECK(vf_image_alloc(&rgba, 3, 1, 4) == VF_OK, "alloc");
    const float px[3][4] = {{1, 0, 0, 1}, {1, 0, 0, 128 / 255.0f}, {0, 1, 0, 0}};
    memcpy(rgba.data, px, sizeof px);
    const char *path = scratch("alpha.png");
    CHECK(vf_image_save(path, &rgba) == VF_OK, "save: %s", vf_error_message());

    /* Colour is stored and read back straight, not premultiplied. */
    CHECK(vf_image_load(path, &straight) == VF_OK && straight.channels == 4, "load rgba");
    if (straight.data)
        CHECK_NEAR(pixel(&straight, 1, 0)[0], 1.0, 1e-6);

    const float white[3] = {1, 1, 1}, black[3] = {0, 0, 0};
    CHECK(vf_image_load_rgb(path, white, &on_white) == VF_OK, "load on white");
    CHECK(vf_image_load_rgb(path, black, &on_black) == VF_OK, "load on black");
    if (on_white.data && on_black.data) {
        double a = 128 / 255.0;
        CHECK(on_white.channels == 3, "rgb has %d channels", on_white.channels);
        CHECK_NEAR(pixel(&on_white, 0, 0)[1], 0.0, 1e-6);
        CHECK_NEAR(pixel(&on_white, 1, 0)[0], 1.0, 1e-6);
        CHECK_NEAR(pixel(&on_white, 1, 0)[1], 1.0 - a, 1e-6);
        CHECK_NEAR(pixel(&on_white, 2, 0)[0], 1.0, 1e-6);
        CHECK_NEAR(pixel(&on_black, 1, 0)[0], a, 1e-6);
        CHECK_NEAR(pixel(&on_black, 1, 0)[1], 0.0, 1e-6);
        CHECK_NEAR(pixel(&on_black, 2, 0)[1], 0.0, 1e-6);
    }
    vf_image_free(&on_black);
    vf_image_free(&on_white);
    vf_image_free(&straight);
    vf_image_free(&rgba);
}

static void test_grey_expands(void)
{
    vf_image grey, rgb = {0};
    CHECK(vf_image_alloc(&grey, 2, 2, 1) == VF_OK, "alloc");
    grey.data[3] = 0.6f;
    const char *path = scratch("grey.png");
    CHECK(vf_image_save(path, &grey) == VF_OK, "save grey: %s", vf_error_message());
    CHECK(vf_image_load_rgb(path, (float[3]){1, 1, 1}, &rgb) == VF_OK, "load grey as rgb");
    if (rgb.data) {
        CHECK(rgb.channels == 3, "channels %d", rgb.channels);
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(pixel(&rgb, 1, 1)[c], 0.6, 1.0 / 255);
    }
    vf_image_free(&rgb);
    vf_image_free(&grey);
}

static void test_resize_constant(void)
{
    const int sizes[][2] = {{13, 7}, {80, 61}}; /* down and up */
    vf_image img;
    CHECK(vf_image_alloc(&img, 40, 30, 3) == VF_OK, "alloc");
    for (size_t i = 0; i < 40 * 30 * 3; i++)
        img.data[i] = 0.3f;
    for (int s = 0; s < 2; s++) {
        vf_image out = {0};
        CHECK(vf_image_resize(&img, sizes[s][0], sizes[s][1], &out) == VF_OK, "resize: %s",
              vf_error_message());
        CHECK(out.width == sizes[s][0] && out.height == sizes[s][1] && out.channels == 3,
              "resized to %dx%dx%d", out.width, out.height, out.channels);
        double worst = 0;
        for (size_t i = 0; out.data && i < (size_t)out.width * out.height * 3; i++)
            worst = fmax(worst, fabs(out.data[i] - 0.3));
        CHECK(worst < 1e-5, "constant image changed by %g after resize", worst);
        vf_image_free(&out);
    }
    vf_image_free(&img);
}

/* A horizontal ramp (value = x centre / width) shrinks 4x to the same ramp. */
static void test_resize_gradient(void)
{
    vf_image img, out = {0};
    CHECK(vf_image_alloc(&img, 64, 8, 1) == VF_OK, "alloc");
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 64; x++)
            pixel(&img, x, y)[0] = (x + 0.5f) / 64;
    CHECK(vf_image_resize(&img, 16, 2, &out) == VF_OK, "resize: %s", vf_error_message());
    for (int x = 2; out.data && x < 14; x++)
        CHECK_NEAR(pixel(&out, x, 1)[0], (x + 0.5) / 16, 0.005);
    for (int x = 1; out.data && x < 16; x++)
        CHECK(pixel(&out, x, 0)[0] > pixel(&out, x - 1, 0)[0], "not increasing at x=%d", x);
    vf_image_free(&out);
    vf_image_free(&img);
}

static void test_center_crop(void)
{
    vf_image img, crop = {0};
    CHECK(vf_image_alloc(&img, 6, 5, 2) == VF_OK, "alloc");
    for (int y = 0; y < 5; y++)
        for (int x = 0; x < 6; x++)
            pixel(&img, x, y)[1] = (float)(10 * y + x);
    CHECK(vf_image_center_crop(&img, 3, 2, &crop) == VF_OK, "crop: %s", vf_error_message());
    /* Margins 3 and 3: the window starts at (1, 1). */
    CHECK(crop.width == 3 && crop.height == 2 && crop.channels == 2, "crop size");
    for (int y = 0; crop.data && y < 2; y++)
        for (int x = 0; x < 3; x++)
            CHECK(pixel(&crop, x, y)[1] == 10 * (y + 1) + x + 1, "crop (%d,%d) = %g", x, y,
                  pixel(&crop, x, y)[1]);
    vf_image_free(&crop);
    CHECK(vf_image_center_crop(&img, 7, 2, &crop) == VF_EINPUT, "crop larger than the image");
    vf_image_free(&img);
}

static void test_errors(void)
{
    vf_image img = {0};
    const char *missing = scratch("missing.png");
    CHECK(vf_image_load(missing, &img) == VF_EINPUT, "missing file");
    CHECK(strstr(vf_error_message(), missing) && strstr(vf_error_message(), "does not exist"),
          "message: %s", vf_error_message());

    char text_file[VF_PATH_MAX];
    snprintf(text_file, sizeof text_file, "%s", scratch("notes.png"));
    CHECK(vf_write_file_atomic(text_file, "hello\n", 6) == VF_OK, "write text");
    CHECK(vf_image_load(text_file, &img) == VF_EINPUT, "text file");
    CHECK(strstr(vf_error_message(), text_file) && strstr(vf_error_message(), "not an image"),
          "message: %s", vf_error_message());
    int w, h, c;
    CHECK(vf_image_info(text_file, &w, &h, &c) == VF_EINPUT, "info of a text file");
    CHECK(img.data == NULL, "output untouched on failure");

    vf_image small;
    CHECK(vf_image_alloc(&small, 2, 2, 3) == VF_OK, "alloc");
    CHECK(vf_image_save(scratch("x.bmpx"), &small) == VF_EINPUT, "unknown extension");
    const char *nowhere = scratch("no/such/folder/x.png");
    CHECK(vf_image_save(nowhere, &small) != VF_OK, "save into a missing folder");
    CHECK(strstr(vf_error_message(), nowhere) != NULL, "message: %s", vf_error_message());
    vf_image_free(&small);
}

/* The inverse of each EXIF orientation, and what 6 and 5 mean on a 3 x 2 image. */
static void test_reorient(void)
{
    static const int inverse[9] = {0, 1, 2, 3, 4, 5, 8, 7, 6};
    vf_image img, turned, back;
    vf_image_alloc(&img, 3, 2, 1);
    for (int i = 0; i < 6; i++)
        img.data[i] = (float)i; /* rows 0 1 2 / 3 4 5 */
    for (int o = 1; o <= 8; o++) {
        CHECK(vf_image_reorient(&img, o, &turned) == VF_OK, "reorient %d", o);
        CHECK(turned.width == (o >= 5 ? 2 : 3), "orientation %d: width %d", o, turned.width);
        CHECK(vf_image_reorient(&turned, inverse[o], &back) == VF_OK, "back from %d", o);
        CHECK(max_difference(&img, &back) == 0, "orientation %d then %d is not the identity", o,
              inverse[o]);
        if (o == 6) /* 90 clockwise: rows 3 0 / 4 1 / 5 2 */
            CHECK(turned.data[0] == 3 && turned.data[1] == 0 && turned.data[5] == 2,
                  "orientation 6: %g %g ... %g", turned.data[0], turned.data[1], turned.data[5]);
        if (o == 5) /* transpose: rows 0 3 / 1 4 / 2 5 */
            CHECK(turned.data[1] == 3 && turned.data[2] == 1, "orientation 5");
        vf_image_free(&turned);
        vf_image_free(&back);
    }
    vf_image_free(&img);
}

/* Write `jpeg` (a JPEG file) again as `out` with an EXIF block saying `orientation`: an APP1
 * segment right after the SOI marker holding a big-endian TIFF header and one IFD entry
 * (tag 0x0112, SHORT, count 1), as a phone writes it. */
static int write_with_orientation(const char *jpeg, int orientation, const char *out)
{
    char *data;
    size_t size;
    if (vf_read_file(jpeg, &data, &size) != VF_OK || size < 4)
        return 0;
    const unsigned char app1[36] = {
        0xFF, 0xE1, 0, 34, 'E', 'x', 'i', 'f', 0, 0,           /* marker, length, id */
        'M', 'M', 0, 42, 0, 0, 0, 8,                           /* TIFF header, IFD at 8 */
        0, 1,                                                  /* one entry */
        0x01, 0x12, 0, 3, 0, 0, 0, 1, 0, (unsigned char)orientation, 0, 0, /* Orientation */
        0, 0, 0, 0};                                           /* no next IFD */
    FILE *f = fopen(out, "wb");
    int ok = f && fwrite(data, 1, 2, f) == 2 && fwrite(app1, 1, sizeof app1, f) == sizeof app1 &&
             fwrite(data + 2, 1, size - 2, f) == size - 2;
    if (f)
        ok = fclose(f) == 0 && ok;
    free(data);
    return ok;
}

/* A phone JPEG stored sideways with EXIF orientation 6 (or 8, 3) reads upright, the same size
 * and pixels through OpenImageIO (classify, train) and OpenCV (ingest, localize, score), also
 * when its name does not say JPEG (one rule, by content: OpenCV's own went by the name). */
static void test_exif_orientation(void)
{
    /* Quadrants: red top left, green top right, blue bottom left, white bottom right. */
    vf_image img;
    vf_image_alloc(&img, 40, 24, 3);
    for (int y = 0; y < 24; y++)
        for (int x = 0; x < 40; x++) {
            float *p = pixel(&img, x, y);
            int right = x >= 20, bottom = y >= 12;
            p[0] = (!right && !bottom) || (right && bottom);
            p[1] = right;
            p[2] = bottom;
        }
    char stored[VF_PATH_MAX];
    snprintf(stored, sizeof stored, "%s", scratch("stored.jpg"));
    CHECK(vf_image_save(stored, &img) == VF_OK, "save: %s", vf_error_message());
    const int orientations[3] = {6, 8, 3};
    /* The quadrant colour (r, g, b as 0/1) expected at the top left of the upright image. */
    const int top_left[3][3] = {{0, 0, 1}, {0, 1, 0}, {1, 1, 1}};
    for (int k = 0; k < 6; k++) {
        int o = orientations[k % 3];
        char jpg[VF_PATH_MAX];
        snprintf(jpg, sizeof jpg, "%s/o%d.%s", vf_test_tmpdir(), o, k < 3 ? "jpg" : "photo");
        CHECK(write_with_orientation(stored, o, jpg), "write %s", jpg);
        vf_image up = {0};
        vf_rgb8 cv = {0};
        int w = 0, h = 0, ch = 0;
        CHECK(vf_image_info(jpg, &w, &h, &ch) == VF_OK && vf_image_load(jpg, &up) == VF_OK &&
                  vf_rgb8_load(jpg, &cv) == VF_OK,
              "%s: %s", jpg, vf_error_message());
        int want_w = o == 3 ? 40 : 24, want_h = o == 3 ? 24 : 40;
        CHECK(w == want_w && h == want_h && up.width == want_w && up.height == want_h &&
                  cv.width == want_w && cv.height == want_h,
              "%s: header %dx%d, OpenImageIO %dx%d, OpenCV %dx%d", jpg, w, h, up.width,
              up.height, cv.width, cv.height);
        if (up.width == cv.width && up.height == cv.height && up.data && cv.data) {
            double worst = 0;
            for (int i = 0; i < up.width * up.height * 3; i++)
                worst = fmax(worst, fabs(up.data[i] - cv.data[i] / 255.0));
            CHECK(worst < 0.02, "%s: the decoders differ by %.3f", jpg, worst);
            const float *p = pixel(&up, 2, 2);
            CHECK(fabs(p[0] - top_left[k % 3][0]) < 0.1 && fabs(p[1] - top_left[k % 3][1]) < 0.1 &&
                      fabs(p[2] - top_left[k % 3][2]) < 0.1,
                  "%s: top left is %.2f %.2f %.2f", jpg, p[0], p[1], p[2]);
        }
        vf_image_free(&up);
        vf_rgb8_free(&cv);
    }
    vf_image_free(&img);
}

/* The phone's denoising (the studio's): grain on two flat halves goes, the edge between them
 * stays where it was and as steep. */
static void test_denoise(void)
{
    vf_rgb8 img = {0};
    CHECK(vf_rgb8_resize_buffer(&img, 64, 64) == VF_OK, "frame allocated");
    vf_rng rng;
    vf_rng_seed(&rng, 3);
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++)
            for (int c = 0; c < 3; c++) {
                double v = (x < 32 ? 60 : 190) + 8 * vf_rng_normal(&rng);
                img.data[(y * 64 + x) * 3 + c] = (unsigned char)(v < 0 ? 0 : v > 255 ? 255 : v);
            }
    CHECK(vf_rgb8_denoise(&img, 6) == VF_OK, "denoised");
    double sum = 0, sq = 0, n = 0, edge = 0;
    for (int y = 0; y < 64; y++) {
        for (int x = 4; x < 28; x++) {
            double v = img.data[(y * 64 + x) * 3 + 1];
            sum += v, sq += v * v, n++;
        }
        edge += img.data[(y * 64 + 33) * 3] - img.data[(y * 64 + 30) * 3];
    }
    double mean = sum / n, sd = sqrt(sq / n - mean * mean);
    CHECK(fabs(mean - 60) < 2 && sd < 3, "flat half after denoising: mean %.1f (60), spread %.2f "
          "(8 before)", mean, sd);
    CHECK(edge / 64 > 120, "the edge stays: a step of %.0f across 3 pixels (130)", edge / 64);
    vf_rgb8 same = {0};
    CHECK(vf_rgb8_fit(&img, 64, &same) == VF_OK && vf_rgb8_denoise(&same, 0) == VF_OK &&
              vf_rgb8_mean_abs_diff(&same, &img) == 0,
          "strength 0 leaves the frame as it is");
    vf_rgb8_free(&same);
    vf_rgb8_free(&img);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_png_round_trip);
    CHECK_CASE(test_exr_round_trip);
    CHECK_CASE(test_jpeg_drops_alpha);
    CHECK_CASE(test_alpha_compositing);
    CHECK_CASE(test_grey_expands);
    CHECK_CASE(test_resize_constant);
    CHECK_CASE(test_resize_gradient);
    CHECK_CASE(test_center_crop);
    CHECK_CASE(test_reorient);
    CHECK_CASE(test_exif_orientation);
    CHECK_CASE(test_denoise);
    CHECK_CASE(test_errors);
    return check_finish();
}
