/* Report pictures (vf/plot.h): charts and contact sheets come out as PNGs of the expected
 * size with the content drawn, and bad input is refused. */
#include <stdio.h>

#include "check.h"
#include "vf/image.h"
#include "vf/plot.h"

static void test_lines(const char *dir)
{
    char path[512];
    snprintf(path, sizeof path, "%s/loss.png", dir);
    double x[5] = {1, 2, 3, 4, 5}, a[5] = {0.5, 1, 1.5, 1.7, 2.1}, b[5] = {1, 2, 2, 3, 3};
    vf_plot_series s[2] = {{"mean", x, a, 5}, {"max", x, b, 5}};
    vf_plot_axes axes = {"title", "step", "loss", 0, 0};
    CHECK(vf_plot_lines(path, &axes, s, 2) == VF_OK, "%s", vf_error_message());
    vf_image img = {0};
    CHECK(vf_image_load(path, &img) == VF_OK, "%s", vf_error_message());
    CHECK(img.width == 800 && img.height == 500, "chart is %dx%d", img.width, img.height);
    /* Something besides the white background and black ink: the coloured series. */
    int coloured = 0;
    for (int i = 0; img.data && i < img.width * img.height; i++) {
        const float *p = img.data + (size_t)i * img.channels;
        coloured += p[0] - p[2] > 0.3f || p[2] - p[0] > 0.3f;
    }
    CHECK(coloured > 500, "%d coloured pixels", coloured);
    vf_image_free(&img);
    vf_plot_series empty = {"none", x, a, 0};
    CHECK(vf_plot_lines(path, &axes, &empty, 1) == VF_EINPUT, "an empty chart is refused");
}

static void test_sheet(const char *dir)
{
    char path[512];
    snprintf(path, sizeof path, "%s/sheet.png", dir);
    vf_image tiles[3] = {{0}};
    for (int i = 0; i < 3; i++) {
        vf_image_alloc(&tiles[i], 40, 30, 3);
        for (int p = 0; p < 40 * 30 * 3; p++)
            tiles[i].data[p] = (float)i / 2.0f;
    }
    const char *captions[3] = {"one 50%\nsecond line", "two", NULL};
    int mark[3] = {1, 0, 1};
    CHECK(vf_contact_sheet(path, tiles, captions, mark, 3, 2) == VF_OK, "%s", vf_error_message());
    vf_image img = {0};
    CHECK(vf_image_load(path, &img) == VF_OK, "%s", vf_error_message());
    /* 2 columns, 2 rows of 40x30 tiles, a 36-pixel caption bar each, 4-pixel gaps. */
    CHECK(img.width == 4 + 2 * 44 && img.height == 4 + 2 * (30 + 36 + 4), "sheet is %dx%d",
          img.width, img.height);
    if (img.data) { /* the third tile (white) sits at the start of the second row */
        const float *p = img.data + ((size_t)(4 + 70 + 10) * img.width + 4 + 10) * img.channels;
        CHECK(p[0] > 0.99f && p[1] > 0.99f && p[2] > 0.99f, "tile pixel %g %g %g", p[0], p[1],
              p[2]);
    }
    vf_image_free(&img);
    for (int i = 0; i < 3; i++)
        vf_image_free(&tiles[i]);
    CHECK(vf_contact_sheet(path, tiles, captions, mark, 0, 2) == VF_EINPUT, "no images refused");
}

static void test_line_plot(void)
{
    test_lines(vf_test_tmpdir());
}

static void test_contact_sheet(void)
{
    test_sheet(vf_test_tmpdir());
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_line_plot);
    CHECK_CASE(test_contact_sheet);
    return check_finish();
}
