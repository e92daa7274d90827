/* vfcapture ingest: parse the options, run the ingest stage (vf/ingest.h), print the summary. */
#define _GNU_SOURCE
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include <linux/videodev2.h>

#include "cli.h"
#include "vf/ingest.h"

static const char usage[] =
    "usage: vfcapture ingest VIDEO|PHOTO_FOLDER -o WS [options]\n"
    "       vfcapture ingest --v4l2 /dev/videoN -o WS [--seconds S] [--size WxH] [options]\n"
    "       vfcapture ingest [--transforms] FILE.json -o WS [options]\n"
    "       vfcapture ingest MODEL.glb|.gltf|.obj|.blend -o WS [--views N] [--render-size PX]\n"
    "\n"
    "Bring a capture of an object into the workspace WS (created when missing).\n"
    "From a video (anything FFmpeg plays; phone rotation is applied), a folder of JPEG/PNG\n"
    "photos or a webcam, every frame is scored for sharpness and the sharpest distinct frames,\n"
    "spread evenly over the capture, are written to WS/ingest/images/; blurry frames and\n"
    "near-duplicates are left out. WS/ingest/report.json says what was kept and why.\n"
    "A posed image set (NeRF transforms.json) is imported whole, with its cameras; train on\n"
    "it directly, or run 'vfcapture poses' first to triangulate the sparse points its depth\n"
    "loss and object mode read (worth it when the photos show their surroundings).\n"
    "A 3D model is rendered by Blender (Cycles, every core) as the ViewFool paper's capture:\n"
    "views on the upper hemisphere at distance 4 with the NeRF-synthetic camera, transparent\n"
    "background, plus held-out test views (WS/ingest/transforms_test.json); the model is\n"
    "centred and scaled into the unit sphere, and WS/ingest/object.json records how. An\n"
    "interrupted model ingest continues where it stopped when run again.\n"
    "\n"
    "options:\n"
    "  -o, --output WS        workspace folder (required)\n"
    "  -n, --frames N         keep at most N frames (default 100)\n"
    "      --max-size PX      shrink frames to at most PX on the longer side (default 1024)\n"
    "      --blur-ratio R     reject frames below R x the local median sharpness (default 0.4);\n"
    "                         photos: below R x the median of all photos (default 0.2, so\n"
    "                         only the truly unusable: a folder has no order to compare in)\n"
    "      --duplicate-threshold D\n"
    "                         frames whose thumbnails differ by less than D grey levels are\n"
    "                         repeats (default 1.5)\n"
    "      --v4l2 DEVICE      capture from a V4L2 webcam (YUYV or MJPEG)\n"
    "      --seconds S        webcam: capture for S seconds (default 10)\n"
    "      --size WxH         webcam: frame size to ask for (default 1280x720)\n"
    "      --pixel-format F   webcam: mjpeg or yuyv, used when offered (default mjpeg)\n"
    "  -t, --transforms FILE  import a posed dataset instead\n"
    "      --views N          model: training views (default 100)\n"
    "      --test-views N     model: held-out views (default 25)\n"
    "      --render-size PX   model: side of the square renders (default 256: the\n"
    "                         classifier's 224 crop then sees the field at the\n"
    "                         resolution it was trained at; NeRF-synthetic is 200)\n"
    "      --render-samples N model: Cycles samples a pixel (default 32)\n"
    "      --seed S           model: where on the hemisphere the views are (default 0)\n"
    "      --scene S          model: studio (white, transparent background; the paper's) or\n"
    "                         room (on a textured floor inside a textured wall, as a photo in\n"
    "                         a room; default studio)\n" CLI_COMMON_HELP;

typedef struct ingest_options {
    const char *source;     /* video file, photo folder or 3D model */
    const char *device;     /* --v4l2 */
    const char *transforms; /* --transforms */
    const char *workspace;
    vf_ingest_request req; /* what the stage is asked, filled from the above at the end */
    cli_flags flags;
} ingest_options;

enum {
    OPT_MAX_SIZE = CLI_OPT_FIRST_CUSTOM,
    OPT_BLUR_RATIO,
    OPT_DUPLICATE_THRESHOLD,
    OPT_V4L2,
    OPT_SECONDS,
    OPT_SIZE,
    OPT_PIXEL_FORMAT,
    OPT_VIEWS,
    OPT_TEST_VIEWS,
    OPT_RENDER_SIZE,
    OPT_SAMPLES,
    OPT_OLD_SAMPLES,
    OPT_SEED,
    OPT_SCENE,
};

/* Apply one of the options of a model's capture. */
static vf_status apply_model_option(int c, const char *arg, vf_object3d_capture *m)
{
    static const struct {
        int option;
        const char *name;
        long lo, hi;
    } limits[] = {{OPT_VIEWS, "--views", 3, 10000},
                  {OPT_TEST_VIEWS, "--test-views", 0, 10000},
                  {OPT_RENDER_SIZE, "--render-size", 16, 4096},
                  {OPT_SAMPLES, "--render-samples", 1, 65536}};
    if (c == OPT_SEED)
        return cli_seed("--seed", arg, &m->seed);
    for (size_t i = 0; i < sizeof limits / sizeof limits[0]; i++) {
        long n;
        if (limits[i].option != c)
            continue;
        vf_status s = cli_count(limits[i].name, arg, limits[i].lo, limits[i].hi, &n);
        if (s != VF_OK)
            return s;
        int *field[] = {&m->views, &m->test_views, &m->size, &m->samples};
        *field[i] = (int)n;
    }
    return VF_OK;
}

/* Apply one of ingest's own options. */
static vf_status apply_option(int c, const char *arg, ingest_options *opt)
{
    vf_ingest_options *cap = &opt->req.capture;
    switch (c) {
    case 't':
        opt->transforms = arg;
        return VF_OK;
    case 'o':
        opt->workspace = arg;
        return VF_OK;
    case 'n': return cli_count_int("--frames", arg, 1, 100000, &cap->select.max_frames);
    case OPT_MAX_SIZE: return cli_count_int("--max-size", arg, 16, 16384, &cap->max_size);
    case OPT_BLUR_RATIO:
        /* one knob for both rules (the local one of videos, the global one of photos) */
        if (cli_number("--blur-ratio", arg, 0, 0.99, &cap->select.blur_ratio) != VF_OK)
            return VF_EINPUT;
        cap->photo_blur_ratio = cap->select.blur_ratio;
        return VF_OK;
    case OPT_DUPLICATE_THRESHOLD:
        return cli_number("--duplicate-threshold", arg, 0, 255, &cap->select.duplicate_threshold);
    case OPT_V4L2:
        opt->device = arg;
        return VF_OK;
    case OPT_SECONDS:
        return cli_number("--seconds", arg, 0.1, 3600, &cap->seconds);
    case OPT_SIZE: return cli_size("--size", arg, &cap->width, &cap->height);
    case OPT_VIEWS:
    case OPT_TEST_VIEWS:
    case OPT_RENDER_SIZE:
    case OPT_OLD_SAMPLES:
        if (c == OPT_OLD_SAMPLES) { /* --samples is the attack's */
            cli_deprecated("ingest", "--samples", "--render-samples");
            c = OPT_SAMPLES;
        }
        /* fall through */
    case OPT_SAMPLES:
    case OPT_SEED: return apply_model_option(c, arg, &opt->req.model);
    case OPT_SCENE:
        if (strcmp(arg, "studio") && strcmp(arg, "room"))
            return vf_fail(VF_EINPUT, "--scene: use studio or room, not '%s'", arg);
        opt->req.model.scene = arg;
        return VF_OK;
    case OPT_PIXEL_FORMAT:
        if (!strcasecmp(arg, "mjpeg") || !strcasecmp(arg, "mjpg"))
            cap->pixel_format = V4L2_PIX_FMT_MJPEG;
        else if (!strcasecmp(arg, "yuyv"))
            cap->pixel_format = V4L2_PIX_FMT_YUYV;
        else
            return vf_fail(VF_EINPUT, "--pixel-format wants mjpeg or yuyv, not '%s'", arg);
        return VF_OK;
    default:
        return VF_OK;
    }
}

static int parse_options(int argc, char **argv, ingest_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"transforms", required_argument, NULL, 't'},
        {"output", required_argument, NULL, 'o'},
        {"frames", required_argument, NULL, 'n'},
        {"max-size", required_argument, NULL, OPT_MAX_SIZE},
        {"blur-ratio", required_argument, NULL, OPT_BLUR_RATIO},
        {"duplicate-threshold", required_argument, NULL, OPT_DUPLICATE_THRESHOLD},
        {"v4l2", required_argument, NULL, OPT_V4L2},
        {"seconds", required_argument, NULL, OPT_SECONDS},
        {"size", required_argument, NULL, OPT_SIZE},
        {"pixel-format", required_argument, NULL, OPT_PIXEL_FORMAT},
        {"views", required_argument, NULL, OPT_VIEWS},
        {"test-views", required_argument, NULL, OPT_TEST_VIEWS},
        {"render-size", required_argument, NULL, OPT_RENDER_SIZE},
        {"render-samples", required_argument, NULL, OPT_SAMPLES},
        {"samples", required_argument, NULL, OPT_OLD_SAMPLES},
        {"seed", required_argument, NULL, OPT_SEED},
        {"scene", required_argument, NULL, OPT_SCENE},
        {0, 0, 0, 0},
    };
    vf_ingest_request_defaults(&opt->req);
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT "t:o:n:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "ingest", usage))
            continue;
        vf_status status = apply_option(c, optarg, opt);
        if (status != VF_OK)
            return status;
    }
    if (optind < argc)
        opt->source = argv[optind++];
    if (optind < argc)
        return vf_fail(VF_EINPUT, "unexpected argument '%s': give one video or photo folder",
                       argv[optind]);
    size_t n = opt->source ? strlen(opt->source) : 0;
    if (n > 5 && !strcmp(opt->source + n - 5, ".json") && !opt->transforms) {
        opt->transforms = opt->source; /* a posed set given like a video: as `run` takes it */
        opt->source = NULL;
    }
    if (!!opt->source + !!opt->device + !!opt->transforms != 1)
        return vf_fail(VF_EINPUT, "give one source: a video file, a photo folder, --v4l2 DEVICE "
                                  "or --transforms FILE");
    vf_status s = VF_OK;
    if (opt->source && (s = vf_ingest_input_kind(opt->source, &opt->req.kind)) != VF_OK)
        return s;
    opt->req.kind = opt->device       ? VF_INGEST_CAMERA
                    : opt->transforms ? VF_INGEST_TRANSFORMS
                                      : opt->req.kind;
    opt->req.input = opt->device ? opt->device : opt->transforms ? opt->transforms : opt->source;
    if (!opt->workspace)
        return vf_fail(VF_EINPUT, "give the workspace folder with -o WS");
    return VF_OK;
}

static void print_result(const ingest_options *opt, json_t *summary)
{
    if (opt->flags.json) {
        json_object_set_new(summary, "workspace", json_string(opt->workspace));
        cli_print_json(summary);
        return;
    }
    long long frames = json_integer_value(json_object_get(summary, "frames"));
    long long width = json_integer_value(json_object_get(summary, "width"));
    long long height = json_integer_value(json_object_get(summary, "height"));
    if (opt->req.kind == VF_INGEST_MODEL)
        printf("rendered %lld + %lld views (%lldx%lld) of %s in %.0f s into %s/ingest\n", frames,
               json_integer_value(json_object_get(summary, "test_frames")), width, height,
               opt->source, json_number_value(json_object_get(summary, "seconds")),
               opt->workspace);
    else if (opt->transforms)
        printf("imported %lld frames (%lldx%lld, %s background) into %s/ingest\n", frames, width,
               height, json_string_value(json_object_get(summary, "background")), opt->workspace);
    else
        printf("kept %lld of %lld frames (%lld blurry, %lld repeated; %lldx%lld) in "
               "%s/ingest/images\n",
               frames, json_integer_value(json_object_get(summary, "frames_read")),
               json_integer_value(json_object_get(summary, "blurry")),
               json_integer_value(json_object_get(summary, "duplicates")), width, height,
               opt->workspace);
    json_decref(summary);
}

int cmd_ingest(int argc, char **argv)
{
    ingest_options opt = {0};
    vf_status status = parse_options(argc, argv, &opt);
    json_t *summary = NULL;
    if (status == VF_OK)
        status = vf_ingest_run(opt.workspace, &opt.req, &summary);
    if (status != VF_OK)
        return cli_fail("ingest", status);
    print_result(&opt, summary);
    return 0;
}
