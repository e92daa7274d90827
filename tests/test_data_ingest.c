/* Ingest on real captures: the 50 fox photos made into a sideways phone video with a rotation
 * flag (frames must come out upright and match the photos), a video with known blurred and
 * repeated frames (exactly those are rejected), and photo folders (the spray can's RGBA
 * photos on white; a folder mixing portrait and landscape), and a real RGBA frame decoded. The
 * videos are made with the
 * ffmpeg command line inside the test. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "vf/fsutil.h"
#include "vf/image.h"
#include "vf/ingest.h"
#include "vf/log.h"
#include "vf/rgb8.h"

#define FOX "data/real_captures/instant_ngp_fox/images"
#define SPRAY "data/real_captures/spray_can_photoroom/images"

static char tmp[VF_PATH_MAX - 256];

/* The fox photos in name order (the video's frame order). */
static char photos[64][32];
static int photo_count;

static void list_fox_photos(void)
{
    char cmd[VF_PATH_MAX + 64];
    snprintf(cmd, sizeof cmd, "ls %s", vf_test_shared(FOX));
    FILE *p = popen(cmd, "r");
    while (p && photo_count < 64 && fscanf(p, "%31s", photos[photo_count]) == 1)
        photo_count++;
    if (p)
        pclose(p);
}

static int load_fox(int index, vf_rgb8 *out)
{
    char path[VF_PATH_MAX];
    snprintf(path, sizeof path, "%s/%s", vf_test_shared(FOX), photos[index]);
    return vf_rgb8_load(path, out) == VF_OK ? 0 : -1;
}

/* Load OUT/images/<files[k]>. */
static int load_output(const char *out, const json_t *report, int k, vf_rgb8 *img)
{
    const char *name = json_string_value(json_array_get(json_object_get(report, "files"), k));
    char path[VF_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/images/%s", out, name ? name : "?");
    return vf_rgb8_load(path, img) == VF_OK ? 0 : -1;
}

static long report_int(const json_t *report, const char *key)
{
    return (long)json_integer_value(json_object_get(report, key));
}

/* (a) A portrait capture stored sideways (turned counter-clockwise, as a phone's sensor
 * records it) with a display matrix saying "turn 90 degrees clockwise to show". */
static void test_rotated_video(void)
{
    char video[VF_PATH_MAX], out[VF_PATH_MAX], ref[VF_PATH_MAX];
    snprintf(video, sizeof video, "%s/phone.mp4", tmp);
    snprintf(out, sizeof out, "%s/fox", tmp);
    snprintf(ref, sizeof ref, "%s/ffmpeg_first.png", tmp);
    /* FFmpeg 5.1's "rotate" tag is counter-clockwise: 270 here is a clockwise turn of 90. */
    int rc = vf_test_system(
        "ffmpeg -loglevel error -y -framerate 10 -pattern_type glob -i '%s/*.jpg' "
        "-vf transpose=cclock -c:v libx264 -preset veryfast -crf 16 -pix_fmt yuv420p "
        "%s/sideways.mp4 && ffmpeg -loglevel error -y -i %s/sideways.mp4 -c copy "
        "-metadata:s:v:0 rotate=270 %s && ffmpeg -loglevel error -y -i %s -frames:v 1 %s",
        vf_test_shared(FOX), tmp, tmp, video, video, ref);
    CHECK(rc == 0, "ffmpeg made the test video");
    if (rc != 0)
        return;

    /* The test video is what it should be: ffmpeg itself shows the first photo upright. */
    vf_rgb8 first = {0, 0, NULL}, shown = {0, 0, NULL}, frame = {0, 0, NULL};
    CHECK(load_fox(0, &first) == 0 && vf_rgb8_load(ref, &shown) == VF_OK, "loaded references");
    double d = vf_rgb8_mean_abs_diff(&shown, &first);
    CHECK(d >= 0 && d < 4, "ffmpeg shows the video upright (difference %.2f)", d);

    vf_ingest_options options;
    vf_ingest_defaults(&options);
    options.select.max_frames = 20;
    json_t *report = NULL;
    double start = vf_now();
    vf_status status = vf_ingest_video(video, &options, out, &report);
    printf("fox video, 50 frames 540x960 (stored 960x540, rotated): ingest took %.2f s\n",
           vf_now() - start);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status != VF_OK)
        goto done;
    json_t *rotation = json_object_get(report, "rotation");
    CHECK(json_integer_value(json_object_get(rotation, "clockwise_degrees")) == 90,
          "rotation 90 read from the file");
    CHECK(report_int(report, "frame_count") == 50, "50 frames decoded");
    CHECK_NEAR(json_real_value(json_object_get(report, "fps")), 10, 1e-6);
    CHECK(report_int(report, "output_width") == 540 && report_int(report, "output_height") == 960,
          "portrait 540x960 frames, got %ldx%ld", report_int(report, "output_width"),
          report_int(report, "output_height"));

    /* At most 20 frames, one from each stretch of 2-3 frames, all over the video. */
    json_t *chosen = json_object_get(report, "chosen");
    int n = (int)json_array_size(chosen);
    CHECK(n >= 18 && n <= 20, "18..20 frames kept, got %d", n);
    int previous = -1, max_gap = 0;
    for (int k = 0; k < n; k++) {
        int i = (int)json_integer_value(json_array_get(chosen, k));
        int gap = i - previous;
        max_gap = gap > max_gap ? gap : max_gap;
        previous = i;
    }
    CHECK(max_gap <= 5 && previous >= 45, "spread over the video (largest gap %d, last %d)",
          max_gap, previous);

    /* Every kept frame is upright and is its photo, within compression error. */
    double worst = 0;
    for (int k = 0; k < n; k++) {
        int i = (int)json_integer_value(json_array_get(chosen, k));
        vf_rgb8 photo = {0, 0, NULL};
        if (load_output(out, report, k, &frame) != 0 || load_fox(i, &photo) != 0) {
            CHECK(0, "cannot load kept frame %d: %s", i, vf_error_message());
            continue;
        }
        double diff = vf_rgb8_mean_abs_diff(&frame, &photo);
        worst = diff < 0 || diff > worst ? (diff < 0 ? 999 : diff) : worst;
        vf_rgb8_free(&photo);
    }
    CHECK(worst < 4, "kept frames match their photos (worst mean difference %.2f)", worst);
    printf("kept %d frames; worst mean difference to the source photo %.2f grey levels\n", n,
           worst);
    json_decref(report);
done:
    vf_rgb8_free(&first);
    vf_rgb8_free(&shown);
    vf_rgb8_free(&frame);
}

/* (b) Photo 20 held for four more frames (the camera stopped), and frames 8, 33 and 34
 * blurred: those frames, and only those, are rejected, each for its reason. */
static void test_blurred_and_still_frames(void)
{
    char video[VF_PATH_MAX], out[VF_PATH_MAX], seq[VF_PATH_MAX];
    snprintf(video, sizeof video, "%s/shaky.mp4", tmp);
    snprintf(out, sizeof out, "%s/shaky", tmp);
    snprintf(seq, sizeof seq, "%s/sequence", tmp);
    /* The frame sequence as links: photos 0..20, photo 20 four more times, photos 21..49. */
    vf_mkdirs(seq);
    for (int i = 0; i < 54; i++) {
        char link[VF_PATH_MAX + 16], target[VF_PATH_MAX];
        int photo = i <= 20 ? i : i <= 24 ? 20 : i - 4;
        snprintf(link, sizeof link, "%s/%04d.jpg", seq, i);
        snprintf(target, sizeof target, "%s/%s", vf_test_shared(FOX), photos[photo]);
        CHECK(symlink(target, link) == 0, "link %s", link);
    }
    int rc = vf_test_system(
        "ffmpeg -loglevel error -y -framerate 10 -i %s/%%04d.jpg "
        "-vf \"boxblur=2:enable='eq(n,8)+eq(n,33)+eq(n,34)'\" "
        "-c:v libx264 -preset veryfast -crf 16 -pix_fmt yuv420p %s",
        seq, video);
    CHECK(rc == 0, "ffmpeg made the blurred video");
    if (rc != 0)
        return;
    vf_ingest_options options;
    vf_ingest_defaults(&options);
    json_t *report = NULL;
    vf_status status = vf_ingest_video(video, &options, out, &report);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status != VF_OK)
        return;
    CHECK(report_int(report, "frame_count") == 54, "54 frames, got %ld",
          report_int(report, "frame_count"));
    static const struct {
        int index;
        const char *reason;
    } expected[] = {{8, "blurry"},     {21, "duplicate"}, {22, "duplicate"},
                    {23, "duplicate"}, {24, "duplicate"}, {33, "blurry"}, {34, "blurry"}};
    const int count = sizeof expected / sizeof expected[0];
    json_t *rejected = json_object_get(report, "rejected");
    CHECK((int)json_array_size(rejected) == count, "%d rejected, got %zu", count,
          json_array_size(rejected));
    for (int k = 0; k < count && k < (int)json_array_size(rejected); k++) {
        json_t *r = json_array_get(rejected, k);
        int index = (int)json_integer_value(json_object_get(r, "index"));
        const char *reason = json_string_value(json_object_get(r, "reason"));
        CHECK(index == expected[k].index && reason && !strcmp(reason, expected[k].reason),
              "rejected #%d: frame %d (%s), wanted %d (%s)", k, index, reason ? reason : "?",
              expected[k].index, expected[k].reason);
    }
    CHECK(report_int(report, "kept") == 54 - count, "all the others kept (%ld)",
          report_int(report, "kept"));
    json_t *sharpness = json_object_get(report, "sharpness");
    printf("blur: sharpness of frame 33 %.0f, of frame 32 %.0f\n",
           json_real_value(json_array_get(sharpness, 33)),
           json_real_value(json_array_get(sharpness, 32)));
    json_decref(report);
}

/* (d) Background-removed RGBA photos: all kept, composited onto white, sizes unchanged. */
static void test_photo_folder(void)
{
    char out[VF_PATH_MAX];
    snprintf(out, sizeof out, "%s/spray", tmp);
    vf_ingest_options options;
    vf_ingest_defaults(&options);
    json_t *report = NULL;
    vf_status status = vf_ingest_photos(vf_test_shared(SPRAY), &options, out, &report);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status != VF_OK)
        return;
    CHECK(report_int(report, "frame_count") == 27, "27 photos");
    CHECK(report_int(report, "kept") + report_int(report, "blurry") +
                  report_int(report, "duplicates") ==
              27,
          "every photo kept or rejected with a reason");
    CHECK(report_int(report, "kept") >= 24, "nearly all kept (%ld)", report_int(report, "kept"));
    CHECK(report_int(report, "output_width") == 750 && report_int(report, "output_height") == 1000,
          "750x1000 (under --max-size)");
    json_t *orientation = json_object_get(report, "orientation");
    CHECK(json_integer_value(json_object_get(orientation, "portrait")) == 27 &&
              json_is_false(json_object_get(orientation, "mixed")),
          "27 portrait photos, not mixed");
    vf_rgb8 img = {0, 0, NULL};
    if (load_output(out, report, 0, &img) == 0) {
        const unsigned char *corner = img.data; /* transparent in the source */
        CHECK(corner[0] > 245 && corner[1] > 245 && corner[2] > 245, "white background (%d,%d,%d)",
              corner[0], corner[1], corner[2]);
    } else {
        CHECK(0, "cannot read the first output: %s", vf_error_message());
    }
    vf_rgb8_free(&img);
    json_decref(report);

    /* Shrinking: --max-size 400 gives 300x400. */
    snprintf(out, sizeof out, "%s/spray_small", tmp);
    options.max_size = 400;
    options.select.max_frames = 5;
    status = vf_ingest_photos(vf_test_shared(SPRAY), &options, out, &report);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status == VF_OK) {
        CHECK(report_int(report, "output_width") == 300 && report_int(report, "output_height") == 400,
              "shrunk to 300x400, got %ldx%ld", report_int(report, "output_width"),
              report_int(report, "output_height"));
        CHECK(report_int(report, "kept") <= 5, "at most 5 kept");
        json_decref(report);
    }
}

/* Portrait and landscape photos in one folder are reported as mixed. */
static void test_mixed_orientation(void)
{
    char folder[VF_PATH_MAX], out[VF_PATH_MAX];
    snprintf(folder, sizeof folder, "%s/mixed", tmp);
    snprintf(out, sizeof out, "%s/mixed_out", tmp);
    int rc = vf_test_system("mkdir -p %s && cp %s/0001.jpg %s/0018.jpg %s/0049.jpg %s/ && "
                            "ffmpeg -loglevel error -y -i %s/0090.jpg -vf transpose=clock %s/0090.jpg",
                            folder, vf_test_shared(FOX), vf_test_shared(FOX), vf_test_shared(FOX),
                            folder, vf_test_shared(FOX), folder);
    CHECK(rc == 0, "made the mixed folder");
    vf_ingest_options options;
    vf_ingest_defaults(&options);
    json_t *report = NULL;
    vf_log_set_quiet(0); /* the warning is part of the behaviour; it goes to stderr */
    vf_status status = vf_ingest_photos(folder, &options, out, &report);
    vf_log_set_quiet(1);
    CHECK(status == VF_OK, "%s", vf_error_message());
    if (status != VF_OK)
        return;
    json_t *orientation = json_object_get(report, "orientation");
    CHECK(json_integer_value(json_object_get(orientation, "landscape")) == 1 &&
              json_integer_value(json_object_get(orientation, "portrait")) == 3 &&
              json_is_true(json_object_get(orientation, "mixed")),
          "3 portrait + 1 landscape reported as mixed");
    CHECK(report_int(report, "kept") == 4, "all 4 kept");
    json_decref(report);
}

/* A real third-party RGBA frame (NeRF-synthetic, Lanczos-resized PNG) decodes as RGBA with
 * a transparent background, and composited onto white as RGB. */
static void test_real_frame(void)
{
    const char *path = vf_test_shared("data/nerf_synthetic/chair/train/r_0.png");
    vf_image img = {0}, rgb = {0};
    CHECK(vf_image_load(path, &img) == VF_OK, "load %s: %s", path, vf_error_message());
    CHECK(img.width == 200 && img.height == 200 && img.channels == 4, "chair frame %dx%dx%d",
          img.width, img.height, img.channels);
    CHECK(vf_image_load_rgb(path, (float[3]){1, 1, 1}, &rgb) == VF_OK, "load rgb");
    if (img.data && rgb.data) {
        CHECK(img.data[3] == 0.0f, "corner is transparent");
        CHECK(rgb.data[0] == 1.0f && rgb.data[2] == 1.0f, "corner is white");
        int opaque = 0;
        for (int i = 0; i < 200 * 200; i++)
            opaque += img.data[4 * i + 3] > 0.99f;
        CHECK(opaque > 2000 && opaque < 30000, "%d opaque chair pixels", opaque);
    }
    vf_image_free(&rgb);
    vf_image_free(&img);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    vf_log_set_quiet(1);
    snprintf(tmp, sizeof tmp, "%s", vf_test_tmpdir());
    list_fox_photos();
    CHECK(photo_count == 50, "50 fox photos, found %d", photo_count);
    if (photo_count != 50)
        return check_finish();
    CHECK_CASE(test_real_frame);
    CHECK_CASE(test_rotated_video);
    CHECK_CASE(test_blurred_and_still_frames);
    CHECK_CASE(test_photo_folder);
    CHECK_CASE(test_mixed_orientation);
    return check_finish();
}
