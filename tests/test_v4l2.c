/* V4L2 capture against the in-process fake camera (tests/v4l2_fake.h): format negotiation,
 * streaming order and buffer re-queueing, YUYV and MJPEG conversion against the source
 * images, errors for missing and unsuitable devices, a whole webcam ingest, and the frame source
 * (vf/frames.h) and the calibration's board search reading the fake. */
#include "v4l2_fake.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/calib.h"
#include "vf/frames.h"
#include "vf/fsutil.h"
#include "vf/ingest.h"
#include "vf/log.h"
#include "vf/rgb8.h"
#include "vf/v4l2.h"

#define FRAMES 5
#define DEVICE "/dev/video-fake"

static vf_rgb8 sources[FRAMES];
static unsigned char *yuyv[FRAMES], *mjpeg[FRAMES];
static size_t mjpeg_size[FRAMES];

static unsigned char to_byte(double v)
{
    return (unsigned char)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
}

/* RGB to YUYV the way a camera would: BT.601 limited range, chroma averaged over pixel pairs. */
static void rgb_to_yuyv(const vf_rgb8 *img, unsigned char *out)
{
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x += 2) {
            const unsigned char *p = img->data + ((size_t)y * img->width + x) * 3;
            unsigned char *d = out + ((size_t)y * img->width + x) * 2;
            double u = 0, v = 0;
            for (int k = 0; k < 2; k++) {
                double r = p[3 * k], g = p[3 * k + 1], b = p[3 * k + 2];
                d[2 * k] = to_byte(16 + 0.257 * r + 0.504 * g + 0.098 * b);
                u += 0.5 * (128 - 0.148 * r - 0.291 * g + 0.439 * b);
                v += 0.5 * (128 + 0.439 * r - 0.368 * g - 0.071 * b);
            }
            d[1] = to_byte(u);
            d[3] = to_byte(v);
        }
}

/* Five frames of a camera panning over a colourful pattern (smooth enough for YUYV's shared
 * chroma and for JPEG, detailed enough to be sharp), as RGB, YUYV and MJPEG. */
static int load_recording(void)
{
    enum { W = 200, H = 160 };
    const double tau = 6.283185307179586;
    for (int i = 0; i < FRAMES; i++) {
        if (vf_rgb8_resize_buffer(&sources[i], W, H) != VF_OK)
            return -1;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                unsigned char *p = sources[i].data + ((size_t)y * W + x) * 3;
                double u = x + 7.0 * i; /* the pan */
                p[0] = to_byte(128 + 80 * sin(tau * u / 53) * cos(tau * y / 67));
                p[1] = to_byte(128 + 80 * sin(tau * (y + 0.3 * u) / 29));
                p[2] = to_byte(128 + 60 * cos(tau * (u + y) / 89));
            }
        yuyv[i] = malloc((size_t)W * H * 2);
        if (!yuyv[i])
            return -1;
        rgb_to_yuyv(&sources[i], yuyv[i]);
        if (vf_rgb8_encode_jpeg(&sources[i], 90, &mjpeg[i], &mjpeg_size[i]) != VF_OK)
            return -1;
    }
    return 0;
}

/* A fake offering `formats` at the recording's size, playing the recording. */
static void make_camera(fake_camera *cam, const uint32_t *formats, int count)
{
    fake_init(cam, DEVICE, formats, count, sources[0].width, sources[0].height);
    cam->frame_count = FRAMES;
    cam->yuyv = yuyv;
    cam->mjpeg = mjpeg;
    cam->mjpeg_size = mjpeg_size;
}

static const uint32_t both[] = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG};

/* The format asked for when offered, the other one when not, MJPEG by default. */
static void test_negotiation(void)
{
    static const struct {
        uint32_t offered[2];
        int count;
        uint32_t asked, expected;
    } cases[] = {
        {{V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG}, 2, V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_YUYV},
        {{V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG}, 2, V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_MJPEG},
        {{V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG}, 2, 0, V4L2_PIX_FMT_MJPEG},
        {{V4L2_PIX_FMT_YUYV, 0}, 1, V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_YUYV},
        {{V4L2_PIX_FMT_MJPEG, 0}, 1, V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        fake_camera cam;
        make_camera(&cam, cases[k].offered, cases[k].count);
        vf_v4l2_ops ops = fake_ops(&cam);
        vf_v4l2_request request = {1280, 720, cases[k].asked, 0};
        vf_v4l2 *camera = NULL;
        vf_status status = vf_v4l2_open(DEVICE, &ops, &request, &camera);
        CHECK(status == VF_OK, "case %zu: %s", k, vf_error_message());
        if (status != VF_OK)
            continue;
        const vf_v4l2_info *info = vf_v4l2_get_info(camera);
        char got[5], want[5];
        CHECK(info->pixel_format == cases[k].expected, "case %zu: got %s, wanted %s", k,
              vf_fourcc_text(info->pixel_format, got), vf_fourcc_text(cases[k].expected, want));
        CHECK(cam.asked_fourcc == cases[k].expected, "case %zu: S_FMT asked for the chosen one", k);
        CHECK(info->width == cam.width && info->height == cam.height,
              "the size the driver answered (%dx%d)", info->width, info->height);
        CHECK_NEAR(info->fps, 30, 1e-9);
        CHECK(!strcmp(info->card, "Fake Camera"), "card '%s'", info->card);
        vf_v4l2_close(camera);
        CHECK(cam.closes == 1, "closed once");
    }
}

/* Open, start, read n frames; check order, content against the sources, and clean-up. */
static void stream_and_check(uint32_t format, int buffers, int n, double tolerance)
{
    char name[5];
    vf_fourcc_text(format, name);
    fake_camera cam;
    make_camera(&cam, both, 2);
    cam.corrupt_sequence = 7;
    vf_v4l2_ops ops = fake_ops(&cam);
    vf_v4l2_request request = {0, 0, format, buffers};
    vf_v4l2 *camera = NULL;
    vf_status status = vf_v4l2_open(DEVICE, &ops, &request, &camera);
    if (status == VF_OK)
        status = vf_v4l2_start(camera);
    CHECK(status == VF_OK, "%s: %s", name, vf_error_message());
    if (status != VF_OK) {
        vf_v4l2_close(camera);
        return;
    }
    CHECK(vf_v4l2_get_info(camera)->buffer_count == buffers, "%s: %d buffers", name, buffers);
    vf_rgb8 frame = {0, 0, NULL};
    uint32_t expected = 0;
    double worst = 0;
    for (int i = 0; i < n; i++) {
        uint32_t sequence = 0;
        status = vf_v4l2_read(camera, 100, &frame, &sequence);
        CHECK(status == VF_OK, "%s frame %d: %s", name, i, vf_error_message());
        if (status != VF_OK)
            break;
        if (expected == (uint32_t)cam.corrupt_sequence)
            expected++; /* the corrupt frame is skipped */
        CHECK(sequence == expected, "%s: frame %d has number %u, wanted %u", name, i, sequence,
              expected);
        double diff = vf_rgb8_mean_abs_diff(&frame, &sources[sequence % FRAMES]);
        worst = diff > worst ? diff : worst;
        CHECK(diff >= 0 && diff < tolerance, "%s frame %u differs from its source by %.2f", name,
              sequence, diff);
        expected = sequence + 1;
    }
    printf("%s: %d frames through %d buffers, worst mean difference %.2f grey levels\n", name, n,
           buffers, worst);
    /* Every buffer went back: the initial queueing plus one per frame taken. */
    CHECK(cam.qbufs == buffers + cam.dqbufs, "%s: %d QBUF for %d DQBUF", name, cam.qbufs,
          cam.dqbufs);
    CHECK(cam.queued == buffers, "%s: all %d buffers queued again", name, buffers);
    vf_v4l2_close(camera);
    vf_rgb8_free(&frame);
    CHECK(!cam.streaming, "%s: streaming stopped", name);
    CHECK(cam.maps == buffers && cam.unmaps == buffers, "%s: %d maps, %d unmaps", name, cam.maps,
          cam.unmaps);
    CHECK(cam.opens == 1 && cam.closes == 1, "%s: opened and closed once", name);
}

/* Known colours through the converter. */
static void test_yuyv_colours(void)
{
    /* Two pixels a sample: black, white, then a red pair and a blue pair (studio range). */
    static const unsigned char yuyv_px[] = {16, 128, 16, 128, 235, 128, 235, 128,
                                            81, 90, 81, 240, 41, 240, 41, 110};
    unsigned char rgb[8 * 3];
    vf_yuyv_to_rgb8(yuyv_px, sizeof yuyv_px, 8, 1, rgb);
    static const int expected[8][3] = {{0, 0, 0},   {0, 0, 0},   {255, 255, 255}, {255, 255, 255},
                                       {255, 0, 0}, {255, 0, 0}, {0, 0, 255},     {0, 0, 255}};
    int worst = 0;
    for (int i = 0; i < 8; i++)
        for (int c = 0; c < 3; c++) {
            int d = abs(rgb[3 * i + c] - expected[i][c]);
            worst = d > worst ? d : worst;
        }
    CHECK(worst <= 3, "known YUYV colours off by up to %d", worst);
}

static void expect_error(vf_status status, const char *needle)
{
    const char *message = vf_error_message();
    CHECK(status == VF_EINPUT, "wanted a failure naming '%s'", needle);
    CHECK(strstr(message, needle) && !strchr(message, '\n'), "one line naming '%s': %s", needle,
          message);
}

static void test_errors(void)
{
    fake_camera cam;
    make_camera(&cam, both, 2);
    vf_v4l2_ops ops = fake_ops(&cam);
    vf_v4l2 *camera = NULL;
    expect_error(vf_v4l2_open("/dev/video-missing", &ops, NULL, &camera), "/dev/video-missing");
    CHECK(strstr(vf_error_message(), "does not exist"), "%s", vf_error_message());

    cam.not_capture = 1;
    expect_error(vf_v4l2_open(DEVICE, &ops, NULL, &camera), "is not a video capture device");
    CHECK(cam.closes == cam.opens, "closed again after refusing it");

    static const uint32_t rgb_only[] = {V4L2_PIX_FMT_RGB24};
    make_camera(&cam, rgb_only, 1);
    ops = fake_ops(&cam);
    expect_error(vf_v4l2_open(DEVICE, &ops, NULL, &camera), "neither YUYV nor MJPEG");
    CHECK(strstr(vf_error_message(), "RGB3"), "names what it offers: %s", vf_error_message());

    /* The real system calls: a missing node, and a character device that is no camera. */
    expect_error(vf_v4l2_open("/dev/video-none-99", NULL, NULL, &camera), "does not exist");
    expect_error(vf_v4l2_open("/dev/null", NULL, NULL, &camera), "/dev/null is not a V4L2 camera");

    /* A camera that stops delivering: buffers never come back (nothing recorded). */
    make_camera(&cam, both, 2);
    cam.frame_count = 0;
    ops = fake_ops(&cam);
    vf_rgb8 frame = {0, 0, NULL};
    vf_status status = vf_v4l2_open(DEVICE, &ops, NULL, &camera);
    if (status == VF_OK)
        status = vf_v4l2_start(camera);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status == VF_OK) {
        cam.queued = 0; /* the driver holds no buffer: poll times out */
        expect_error(vf_v4l2_read(camera, 10, &frame, NULL), "sent no frame");
        vf_v4l2_close(camera);
    }
}

/* A whole webcam ingest through the fake: frames written, report filled, scratch removed. */
static void test_camera_ingest(void)
{
    fake_camera cam;
    make_camera(&cam, both, 2);
    vf_ingest_options options;
    vf_ingest_defaults(&options);
    vf_v4l2_ops ops = fake_ops(&cam);
    options.ops = &ops;
    options.seconds = 60;
    options.frame_limit = 20;
    options.select.max_frames = 8;
    char out[VF_PATH_MAX - 64];
    snprintf(out, sizeof out, "%s/camera", vf_test_tmpdir());
    json_t *report = NULL;
    vf_status status = vf_ingest_camera(DEVICE, &options, out, &report);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status != VF_OK)
        return;
    CHECK(json_integer_value(json_object_get(report, "frame_count")) == 20, "20 frames captured");
    CHECK(json_integer_value(json_object_get(report, "kept")) == 8, "8 kept (one a stretch)");
    CHECK(!strcmp(json_string_value(json_object_get(report, "pixel_format")), "MJPG"), "MJPEG");
    CHECK(json_integer_value(json_object_get(report, "dropped")) == 0, "none dropped");
    CHECK(json_array_size(json_object_get(report, "sharpness")) == 20, "every frame scored");
    char path[VF_PATH_MAX + 64];
    const char *first = json_string_value(json_array_get(json_object_get(report, "files"), 0));
    snprintf(path, sizeof path, "%s/images/%s", out, first ? first : "?");
    vf_rgb8 img = {0, 0, NULL};
    CHECK(vf_rgb8_load(path, &img) == VF_OK, "%s", vf_error_message());
    int index = (int)json_integer_value(json_array_get(json_object_get(report, "chosen"), 0));
    double diff = vf_rgb8_mean_abs_diff(&img, &sources[index % FRAMES]);
    CHECK(diff >= 0 && diff < 3, "the kept frame is the captured one (difference %.2f)", diff);
    snprintf(path, sizeof path, "%s/.capture", out);
    CHECK(!vf_is_dir(path), "scratch folder removed");
    snprintf(path, sizeof path, "%s/report.json", out);
    CHECK(vf_is_file(path), "report written");
    vf_rgb8_free(&img);
    json_decref(report);

    /* A camera pointed at a still scene: one frame kept, the rest repeat it. */
    make_camera(&cam, both, 2);
    cam.frame_count = 1;
    ops = fake_ops(&cam);
    snprintf(out, sizeof out, "%s/still", vf_test_tmpdir());
    status = vf_ingest_camera(DEVICE, &options, out, &report);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status == VF_OK) {
        CHECK(json_integer_value(json_object_get(report, "kept")) == 1, "one frame of a still scene");
        CHECK(json_integer_value(json_object_get(report, "duplicates")) >= 7, "the others repeat it");
        json_decref(report);
    }
}

/* The frame source on a webcam: the fake's frames in order, named DEVICE#N, device closed. */
static void test_frames_source(void)
{
    fake_camera cam;
    make_camera(&cam, both, 2);
    vf_v4l2_ops ops = fake_ops(&cam);
    vf_frames in;
    vf_status status = vf_frames_open_v4l2(DEVICE, &ops, NULL, &in);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status != VF_OK)
        return;
    CHECK(cam.streaming, "streaming once open");
    vf_rgb8 frame = {0, 0, NULL};
    vf_frame_info info;
    for (int i = 0; i < 3; i++) {
        int got = 0;
        char name[64];
        status = vf_frames_next(&in, &frame, &info, &got);
        CHECK(status == VF_OK && got, "frame %d: %s", i, vf_error_message());
        if (status != VF_OK || !got)
            break;
        snprintf(name, sizeof name, "%s#%d", DEVICE, i);
        CHECK(!strcmp(info.name, name) && info.index == i, "frame %d named %s", i, info.name);
        double diff = vf_rgb8_mean_abs_diff(&frame, &sources[i]);
        CHECK(diff >= 0 && diff < 3, "frame %d is the fake's (difference %.2f)", i, diff);
    }
    vf_frames_close(&in);
    vf_rgb8_free(&frame);
    CHECK(!cam.streaming && cam.closes == 1, "device stopped and closed");
    fake_camera none;
    make_camera(&none, both, 2);
    none.path = "/dev/video-other";
    ops = fake_ops(&none);
    expect_error(vf_frames_open_v4l2(DEVICE, &ops, NULL, &in), "does not exist");
}

/* calib intrinsics --v4l2 on the fake filming a flat board: every frame searched is a view,
 * named after the driver's frame number. */
static void test_calib_camera(void)
{
    vf_calib_board board = {9, 6, 0.03, 0, 0};
    vf_rgb8 image = {0, 0, NULL};
    unsigned char *jpeg = NULL;
    size_t size = 0;
    vf_status status = vf_calib_board_image(&board, 16, &image);
    if (status == VF_OK)
        status = vf_rgb8_encode_jpeg(&image, 95, &jpeg, &size);
    CHECK(status == VF_OK, "%s", vf_error_message());
    fake_camera cam;
    const uint32_t mjpeg_only[] = {V4L2_PIX_FMT_MJPEG};
    fake_init(&cam, DEVICE, mjpeg_only, 1, image.width, image.height);
    cam.frame_count = 1;
    cam.mjpeg = &jpeg;
    cam.mjpeg_size = &size;
    vf_v4l2_ops ops = fake_ops(&cam);
    vf_calib_views views = {0};
    if (status == VF_OK)
        status = vf_calib_collect_camera(DEVICE, &ops, &board, 0.2, &views);
    CHECK(status == VF_OK, "%s", vf_error_message());
    CHECK(views.frames_seen > 0 && views.count == views.frames_seen, "board in %d of %d frames",
          views.count, views.frames_seen);
    CHECK(views.count == 0 || !strcmp(views.views[0].name, "frame 0"), "first view named %s",
          views.count ? views.views[0].name : "");
    CHECK(views.width == image.width && views.height == image.height, "frame size %dx%d",
          views.width, views.height);
    CHECK(cam.opens == 1 && cam.closes == 1, "device opened and closed once");
    vf_calib_views_free(&views);
    vf_rgb8_free(&image);
    free(jpeg);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    vf_log_set_quiet(1);
    if (load_recording() != 0) {
        fprintf(stderr, "cannot load the recording: %s\n", vf_error_message());
        return 1;
    }
    CHECK_CASE(test_negotiation);
    stream_and_check(V4L2_PIX_FMT_YUYV, 2, 12, 2.0);
    stream_and_check(V4L2_PIX_FMT_MJPEG, 3, 12, 3.0);
    CHECK_CASE(test_yuyv_colours);
    CHECK_CASE(test_errors);
    CHECK_CASE(test_camera_ingest);
    CHECK_CASE(test_frames_source);
    CHECK_CASE(test_calib_camera);
    for (int i = 0; i < FRAMES; i++) {
        vf_rgb8_free(&sources[i]);
        free(yuyv[i]);
        free(mjpeg[i]);
    }
    return check_finish();
}
