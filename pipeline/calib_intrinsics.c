/* vfcapture calib intrinsics: calibrate a camera from views of a checkerboard and save the
 * camera file that `poses --camera` reads. */
#include <stdlib.h>
#include <string.h>

#include "calib_cmd.h"
#include "vf/fsutil.h"
#include "vf/json.h"
#include "vf/log.h"

static const char usage[] =
    "usage: vfcapture calib intrinsics (VIDEO | DIR | --v4l2 /dev/videoN) --board COLSxROWS\n"
    "                                  --square MM [-o camera.json] [options]\n"
    "\n"
    "Find a printed checkerboard in the frames of a video, a folder of photos or a webcam,\n"
    "keep well-spread views, estimate the lens (OpenCV: fx, fy, cx, cy, k1, k2, p1, p2),\n"
    "drop views that reproject badly, refine with Ceres under a robust loss, and save the\n"
    "camera file (fl_x, fl_y, cx, cy, w, h, k1, k2, p1, p2, rms, views, per-view errors) that\n"
    "'vfcapture poses --camera FILE' uses. Film the whole board from many directions: tilted\n"
    "left, right, up and down, near the frame's corners and edges, with the same zoom and\n"
    "focus as the capture. 'vfcapture calib board' writes a board to print.\n"
    "A ChArUco board (--charuco) also counts views that show only part of it.\n"
    "\n"
    "options:\n"
    "      --board CxR        inner corners (where four squares meet), e.g. 9x6 for a board\n"
    "                         of 10 x 7 squares\n"
    "      --square MM        side of one square in millimetres (measure the print)\n"
    "      --charuco MM       the board is a ChArUco board whose markers have this side\n"
    "      --dict NAME        ChArUco: the markers' ArUco dictionary, OpenCV's DICT_* name\n"
    "                         without the prefix (default 6x6_250)\n"
    "  -o, --output FILE      the camera file (default camera.json)\n"
    "      --v4l2 DEV         calibrate a webcam live instead of VIDEO or DIR\n"
    "      --seconds S        webcam: how long to capture (default 30)\n"
    "      --frames N         video: frames to search, spread over it (default 200)\n"
    "      --max-views N      views to calibrate with, chosen for spread (default 40)\n"
    "      --min-views N      fewer boards found than this is an error (default 6)\n" CLI_COMMON_HELP;

enum {
    OPT_BOARD = CLI_OPT_FIRST_CUSTOM,
    OPT_SQUARE,
    OPT_CHARUCO,
    OPT_DICT,
    OPT_V4L2,
    OPT_SECONDS,
    OPT_FRAMES,
    OPT_MAX_VIEWS,
    OPT_MIN_VIEWS,
};

typedef struct intrinsics_args {
    const char *input, *device, *output;
    vf_calib_board board;
    vf_calib_options calib;
    double seconds;
    int frames;
} intrinsics_args;

static vf_status parse_option(int c, const char *arg, intrinsics_args *a)
{
    long n;
    double x;
    switch (c) {
    case OPT_BOARD:
        return calib_parse_board(arg, &a->board);
    case OPT_SQUARE:
        return calib_parse_mm(arg, "--square", &a->board.square);
    case OPT_CHARUCO:
        return calib_parse_mm(arg, "--charuco", &a->board.marker);
    case OPT_DICT:
        return vf_charuco_dictionary(arg, &a->board.dictionary);
    case 'o':
        a->output = arg;
        return VF_OK;
    case OPT_V4L2:
        a->device = arg;
        return VF_OK;
    case OPT_SECONDS:
        if (cli_number_above("--seconds", arg, 0, 3600, &x) != VF_OK)
            return VF_EINPUT;
        a->seconds = x;
        return VF_OK;
    case OPT_FRAMES:
    case OPT_MAX_VIEWS:
    case OPT_MIN_VIEWS:
        if (cli_count(c == OPT_FRAMES      ? "--frames"
                      : c == OPT_MAX_VIEWS ? "--max-views"
                                           : "--min-views",
                      arg, c == OPT_FRAMES ? 1 : 3, 100000, &n) != VF_OK)
            return VF_EINPUT;
        *(c == OPT_FRAMES ? &a->frames : c == OPT_MAX_VIEWS ? &a->calib.max_views
                                                            : &a->calib.min_views) = (int)n;
        return VF_OK;
    }
    return vf_fail(VF_EINPUT, "unknown option");
}

static vf_status parse_args(int argc, char **argv, intrinsics_args *a, cli_flags *flags)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"board", required_argument, NULL, OPT_BOARD},
        {"square", required_argument, NULL, OPT_SQUARE},
        {"charuco", required_argument, NULL, OPT_CHARUCO},
        {"dict", required_argument, NULL, OPT_DICT},
        {"output", required_argument, NULL, 'o'},
        {"v4l2", required_argument, NULL, OPT_V4L2},
        {"seconds", required_argument, NULL, OPT_SECONDS},
        {"frames", required_argument, NULL, OPT_FRAMES},
        {"max-views", required_argument, NULL, OPT_MAX_VIEWS},
        {"min-views", required_argument, NULL, OPT_MIN_VIEWS},
        {0, 0, 0, 0},
    };
    *a = (intrinsics_args){.output = "camera.json", .seconds = 30, .frames = 200};
    vf_calib_defaults(&a->calib);
    vf_status status = vf_charuco_dictionary(CALIB_DEFAULT_DICTIONARY, &a->board.dictionary);
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:", longopts, NULL)) != -1) {
        if (cli_common_option(c, flags, "calib intrinsics", usage))
            continue;
        status = parse_option(c, optarg, a);
        if (status != VF_OK)
            return status;
    }
    int inputs = argc - optind + (a->device != NULL);
    if (inputs != 1)
        return vf_fail(VF_EINPUT, "give one video, folder of photos or --v4l2 device (see "
                                  "'vfcapture calib intrinsics --help')");
    if (!a->device)
        a->input = argv[optind];
    if (a->board.cols == 0)
        return vf_fail(VF_EINPUT, "give the board's inner corners with --board COLSxROWS, e.g. "
                                  "--board 9x6");
    if (!(a->board.square > 0))
        return vf_fail(VF_EINPUT, "give the side of one square with --square MM");
    if (a->board.marker >= a->board.square)
        return vf_fail(VF_EINPUT, "--charuco: the marker side must be below the square side");
    if (a->calib.min_views > a->calib.max_views)
        return vf_fail(VF_EINPUT, "--min-views is above --max-views");
    return VF_OK;
}

static vf_status collect(const intrinsics_args *a, vf_calib_views *views)
{
    if (a->device)
        return vf_calib_collect_camera(a->device, NULL, &a->board, a->seconds, views);
    if (vf_is_dir(a->input))
        return vf_calib_collect_folder(a->input, &a->board, views);
    if (!vf_is_file(a->input))
        return vf_fail(VF_EINPUT, "%s does not exist", a->input);
    return vf_calib_collect_video(a->input, &a->board, a->frames, views);
}

static json_t *summary_json(const intrinsics_args *a, const vf_calib_result *r,
                            const vf_calib_views *v, double detect_s)
{
    const vf_camera *c = &r->camera;
    json_t *per_view = json_array();
    for (int i = 0; i < v->count; i++)
        if (v->views[i].state != VF_VIEW_SPARE)
            json_array_append_new(per_view,
                                  json_pack("{s:s, s:s, s:o}", "frame", v->views[i].name, "state",
                                            v->views[i].state == VF_VIEW_USED ? "used" : "outlier",
                                            "rms", vf_json_number(v->views[i].rms)));
    return json_pack(
        "{s:s, s:o, s:o, s:o, s:i, s:i, s:i, s:i, s:o, s:{s:o, s:o, s:o, s:o}}",
        "camera_file", a->output, "camera", vf_camera_json(c), "rms", vf_json_number(r->rms),
        "rms_opencv", vf_json_number(r->rms_opencv), "frames_searched", v->frames_seen,
        "boards_found", v->count, "views", r->used, "outlier_views", r->outliers, "per_view",
        per_view, "seconds", "detect", vf_json_number(detect_s), "detect_per_frame",
        vf_json_number(v->frames_seen ? detect_s / v->frames_seen : 0.0), "opencv",
        vf_json_number(r->seconds_opencv), "ceres", vf_json_number(r->seconds_ceres));
}

static void print_summary(const json_t *s, const vf_calib_views *v)
{
    const json_t *cam = json_object_get(s, "camera"), *sec = json_object_get(s, "seconds");
#define NUM(obj, key) json_number_value(json_object_get(obj, key))
    printf("board found in %d of %d frames; calibrated with %lld views (%lld outliers dropped)\n",
           v->count, v->frames_seen, json_integer_value(json_object_get(s, "views")),
           json_integer_value(json_object_get(s, "outlier_views")));
    printf("fx %.2f  fy %.2f  cx %.2f  cy %.2f  (%lldx%lld)\n", NUM(cam, "fl_x"), NUM(cam, "fl_y"),
           NUM(cam, "cx"), NUM(cam, "cy"), json_integer_value(json_object_get(cam, "w")),
           json_integer_value(json_object_get(cam, "h")));
    printf("k1 %.5f  k2 %.5f  p1 %.5f  p2 %.5f\n", NUM(cam, "k1"), NUM(cam, "k2"), NUM(cam, "p1"),
           NUM(cam, "p2"));
    printf("RMS reprojection error %.3f px (OpenCV alone %.3f px)\n", NUM(s, "rms"),
           NUM(s, "rms_opencv"));
    printf("per view:");
    for (int i = 0; i < v->count; i++)
        if (v->views[i].state != VF_VIEW_SPARE)
            printf(" %s %.2f%s;", v->views[i].name, v->views[i].rms,
                   v->views[i].state == VF_VIEW_OUTLIER ? " (outlier)" : "");
    printf("\ntime: search %.2f s (%.1f ms per frame), OpenCV %.2f s, Ceres %.2f s\n",
           NUM(sec, "detect"), 1000 * NUM(sec, "detect_per_frame"), NUM(sec, "opencv"),
           NUM(sec, "ceres"));
    printf("camera file: %s (for 'vfcapture poses WS --camera %s')\n",
           json_string_value(json_object_get(s, "camera_file")),
           json_string_value(json_object_get(s, "camera_file")));
#undef NUM
}

int calib_intrinsics(int argc, char **argv)
{
    intrinsics_args a;
    cli_flags flags = {0};
    vf_calib_views views = {0};
    vf_calib_result result;
    vf_status status = parse_args(argc, argv, &a, &flags);
    double start = vf_now(), detect_s = 0;
    if (status == VF_OK)
        status = collect(&a, &views);
    detect_s = vf_now() - start;
    if (status == VF_OK)
        status = vf_calib_solve(&views, &a.board, &a.calib, &result);
    if (status == VF_OK && result.rms > 1.0)
        vf_warn("the RMS reprojection error is %.2f px (a good calibration has well under 1 px): "
                "check that the board is flat, --board is right, and the frames are sharp",
                result.rms);
    if (status == VF_OK)
        status = vf_calib_save_camera(a.output, &result, &views, &a.board);
    if (status != VF_OK) {
        vf_calib_views_free(&views);
        return cli_fail("calib intrinsics", status);
    }
    json_t *summary = summary_json(&a, &result, &views, detect_s);
    if (flags.json) {
        cli_print_json(summary);
    } else {
        print_summary(summary, &views);
        json_decref(summary);
    }
    vf_calib_views_free(&views);
    return 0;
}
