/* The guided-capture overlay (vf/overlay.h): text on a darkened band, a green border on
 * target and a grey one off it; no window is offered without a reachable display. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/overlay.h"

static const unsigned char *pixel(const vf_rgb8 *img, int x, int y)
{
    return img->data + 3 * ((size_t)y * img->width + x);
}

static void test_overlay_draw(void)
{
    vf_rgb8 frame = {0}, out = {0};
    CHECK(vf_rgb8_resize_buffer(&frame, 320, 240) == VF_OK, "alloc");
    memset(frame.data, 128, 320 * 240 * 3);
    const char *lines[2] = {"target 0 - frame 12", "orbit 12 deg left, raise 5 cm"};

    CHECK(vf_overlay_draw(&frame, lines, 2, 1, &out) == VF_OK, "%s", vf_error_message());
    CHECK(out.width == 320 && out.height == 240, "same size");
    const unsigned char *edge = pixel(&out, 160, 239), *band = pixel(&out, 315, 20);
    CHECK(edge[0] < 30 && edge[1] > 200 && edge[2] < 30, "green border on target (%d,%d,%d)",
          edge[0], edge[1], edge[2]);
    CHECK(band[0] < 60, "the band behind the text is darkened (%d)", band[0]);
    int bright = 0;
    for (int y = 0; y < 40; y++)
        for (int x = 0; x < 300; x++)
            bright += pixel(&out, x, y)[0] > 200;
    CHECK(bright > 100, "text drawn (%d bright pixels)", bright);
    CHECK(pixel(&out, 160, 160)[0] == 128, "the frame below the band untouched");

    CHECK(vf_overlay_draw(&frame, lines, 2, 0, &out) == VF_OK, "%s", vf_error_message());
    edge = pixel(&out, 160, 239);
    CHECK(edge[0] == edge[1] && edge[1] == edge[2], "grey border off target");

    unsetenv("DISPLAY");
    CHECK(!vf_overlay_available(), "no $DISPLAY: no window");
    setenv("DISPLAY", ":987", 1);
    CHECK(!vf_overlay_available(), "a display without its X socket: no window");
    vf_overlay *window = NULL;
    CHECK(vf_overlay_open("test", &window) == VF_EINPUT && window == NULL, "open refused");

    vf_rgb8_free(&frame);
    vf_rgb8_free(&out);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_overlay_draw);
    return check_finish();
}
