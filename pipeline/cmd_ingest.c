/* vfcapture ingest: bring frames into a workspace.
 *
 * From a capture (a video file, a folder of photos or a V4L2 webcam) the sharpest distinct
 * frames, spread over the capture, go to WS/ingest/images/ with WS/ingest/report.json
 * (vf/ingest.h does the work). A 3D model is rendered by Blender into a posed set, the
 * paper's capture (vf/object3d.h). A posed dataset (NeRF transforms.json) is imported as it is:
 * every image is decoded once to check it, copied into WS/ingest/images/, and listed with its
 * camera in WS/ingest/transforms.json, so later stages never depend on the original folder. */
#define _GNU_SOURCE
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <linux/videodev2.h>

#include "cli.h"
#include "vf/dataset.h"
#include "vf/image.h"
#include "vf/ingest.h"
#include "vf/log.h"
#include "vf/object3d.h"
#include "vf/workspace.h"

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
    "A posed image set (NeRF transforms.json) is imported whole, with its cameras.\n"
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
    "      --render-size PX   model: side of the square renders (default 200, as\n"
    "                         NeRF-synthetic)\n"
    "      --samples N        model: Cycles samples a pixel (default 32)\n"
    "      --seed S           model: where on the hemisphere the views are (default 0)\n"
    CLI_COMMON_HELP;

typedef struct ingest_options {
    const char *source;     /* video file or photo folder */
    const char *device;     /* --v4l2 */
    const char *transforms; /* --transforms */
    const char *workspace;
    vf_ingest_options capture;
    vf_object3d_capture model; /* a 3D model's capture */
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
    OPT_SEED,
};

/* Parse "WxH". */
static int parse_size(const char *text, int *width, int *height)
{
    char tail;
    return sscanf(text, "%dx%d%c", width, height, &tail) == 2 && *width > 0 && *height > 0 &&
                   *width <= 16384 && *height <= 16384
               ? 0
               : -1;
}

static vf_status parse_number(const char *text, const char *option, double lo, double hi,
                              double *out)
{
    double value;
    if (cli_parse_doubles(text, &value, 1) != 1 || !(value >= lo && value <= hi))
        return vf_fail(VF_EINPUT, "%s wants a number from %g to %g, not '%s'", option, lo, hi,
                       text);
    *out = value;
    return VF_OK;
}

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
                  {OPT_SAMPLES, "--samples", 1, 65536},
                  {OPT_SEED, "--seed", 0, LONG_MAX}};
    for (size_t i = 0; i < sizeof limits / sizeof limits[0]; i++) {
        long n;
        if (limits[i].option != c)
            continue;
        if (cli_parse_int(arg, limits[i].lo, limits[i].hi, &n))
            return vf_fail(VF_EINPUT, "%s wants a whole number from %ld to %ld, not '%s'",
                           limits[i].name, limits[i].lo, limits[i].hi, arg);
        int *field[] = {&m->views, &m->test_views, &m->size, &m->samples};
        if (c == OPT_SEED)
            m->seed = (uint64_t)n;
        else
            *field[i] = (int)n;
    }
    return VF_OK;
}

/* Apply one of ingest's own options. */
static vf_status apply_option(int c, const char *arg, ingest_options *opt)
{
    vf_ingest_options *cap = &opt->capture;
    long n;
    switch (c) {
    case 't':
        opt->transforms = arg;
        return VF_OK;
    case 'o':
        opt->workspace = arg;
        return VF_OK;
    case 'n':
        if (cli_parse_int(arg, 1, 100000, &n))
            return vf_fail(VF_EINPUT, "--frames wants a whole number from 1 to 100000, not '%s'",
                           arg);
        cap->select.max_frames = (int)n;
        return VF_OK;
    case OPT_MAX_SIZE:
        if (cli_parse_int(arg, 16, 16384, &n))
            return vf_fail(VF_EINPUT, "--max-size wants pixels from 16 to 16384, not '%s'", arg);
        cap->max_size = (int)n;
        return VF_OK;
    case OPT_BLUR_RATIO:
        /* one knob for both rules (the local one of videos, the global one of photos) */
        if (parse_number(arg, "--blur-ratio", 0, 0.99, &cap->select.blur_ratio) != VF_OK)
            return VF_EINPUT;
        cap->photo_blur_ratio = cap->select.blur_ratio;
        return VF_OK;
    case OPT_DUPLICATE_THRESHOLD:
        return parse_number(arg, "--duplicate-threshold", 0, 255,
                            &cap->select.duplicate_threshold);
    case OPT_V4L2:
        opt->device = arg;
        return VF_OK;
    case OPT_SECONDS:
        return parse_number(arg, "--seconds", 0.1, 3600, &cap->seconds);
    case OPT_SIZE:
        if (parse_size(arg, &cap->width, &cap->height))
            return vf_fail(VF_EINPUT, "--size wants WIDTHxHEIGHT, e.g. 1280x720, not '%s'", arg);
        return VF_OK;
    case OPT_VIEWS:
    case OPT_TEST_VIEWS:
    case OPT_RENDER_SIZE:
    case OPT_SAMPLES:
    case OPT_SEED:
        return apply_model_option(c, arg, &opt->model);
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
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"seed", required_argument, NULL, OPT_SEED},
        {0, 0, 0, 0},
    };
    vf_ingest_defaults(&opt->capture);
    vf_object3d_capture_defaults(&opt->model);
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
    if (opt->source && !vf_is_file(opt->source) && !vf_is_dir(opt->source))
        return vf_fail(VF_EINPUT, "cannot read %s: no such file; give a video file, a folder "
                                  "of photos or a 3D model (.glb, .gltf, .obj, .blend)",
                       opt->source);
    if (!opt->workspace)
        return vf_fail(VF_EINPUT, "give the workspace folder with -o WS");
    return VF_OK;
}

/* Decode every image (in parallel) to catch corrupt files before anything is written, and
 * note whether any has an alpha channel (an object on a transparent background). Progress
 * shows only for sets big enough to take a while, so that a small import that fails says so
 * in one line. */
static vf_status check_images(const vf_dataset *ds, int *has_alpha)
{
    vf_status status = VF_OK;
    char message[1024] = ""; /* error messages are per thread: carry the first one out */
    int alpha = 0, done = 0;
    int show = ds->count >= 64;
    vf_progress progress;
    vf_progress_begin(&progress, "checking images", (size_t)ds->count, "images");
#pragma omp parallel for schedule(dynamic) reduction(| : alpha)
    for (int i = 0; i < ds->count; i++) {
        vf_image img;
        vf_status s = vf_image_load(ds->frames[i].image_path, &img);
        if (s == VF_OK) {
            if (img.width != ds->frames[i].camera.width || img.height != ds->frames[i].camera.height)
                s = vf_fail(VF_EINPUT, "%s changed size while reading", ds->frames[i].image_path);
            alpha |= img.channels == 4;
            vf_image_free(&img);
        }
#pragma omp critical
        {
            if (s != VF_OK && status == VF_OK) {
                status = s;
                snprintf(message, sizeof message, "%s", vf_error_message());
            }
            if (show)
                vf_progress_update(&progress, (size_t)++done, NULL);
        }
    }
    if (show)
        vf_progress_end(&progress);
    *has_alpha = alpha;
    return status == VF_OK ? VF_OK : vf_fail(status, "%s", message);
}

/* Copy the images into the staging folder; `copy` gets the new paths. */
static vf_status copy_images(const vf_dataset *ds, const char *stage_dir, vf_dataset *copy)
{
    char images_dir[VF_PATH_MAX];
    vf_status status = vf_path_join(images_dir, sizeof images_dir, stage_dir, "images");
    if (status == VF_OK)
        status = vf_mkdirs(images_dir);
    for (int i = 0; status == VF_OK && i < ds->count; i++) {
        char name[NAME_MAX + 1], file[NAME_MAX + 16];
        vf_path_basename(name, sizeof name, ds->frames[i].image_path, 0);
        snprintf(file, sizeof file, "%04d_%s", i, name); /* unique even if names repeat */
        copy->frames[i] = ds->frames[i];
        status = vf_path_join(copy->frames[i].image_path, VF_PATH_MAX, images_dir, file);
        if (status == VF_OK)
            status = vf_copy_file(ds->frames[i].image_path, copy->frames[i].image_path);
    }
    return status;
}

static json_t *summarize(const vf_dataset *ds, int has_alpha)
{
    double distance = 0;
    for (int i = 0; i < ds->count; i++) {
        const double *m = ds->frames[i].c2w;
        distance += sqrt(m[3] * m[3] + m[7] * m[7] + m[11] * m[11]) / ds->count;
    }
    const vf_camera *cam = &ds->frames[0].camera;
    return json_pack("{s:i, s:i, s:i, s:f, s:f, s:b, s:s, s:f}", "frames", ds->count, "width",
                     cam->width, "height", cam->height, "focal_x", cam->fx, "focal_y", cam->fy,
                     "distortion", vf_camera_has_distortion(cam), "background",
                     has_alpha ? "transparent" : "opaque", "mean_camera_distance", distance);
}

/* Import a posed dataset into the staging folder. */
static vf_status import_transforms(const ingest_options *opt, const char *stage_dir,
                                   json_t **params, json_t **summary)
{
    vf_dataset ds, copy = {0};
    char source[PATH_MAX], transforms_out[VF_PATH_MAX];
    int has_alpha = 0;

    vf_status status = vf_dataset_load(opt->transforms, &ds);
    if (status != VF_OK)
        return status;
    if ((status = check_images(&ds, &has_alpha)) == VF_OK)
        vf_info("%s: %d posed frames", opt->transforms, ds.count);
    copy.count = ds.count;
    copy.frames = calloc((size_t)ds.count, sizeof *copy.frames);
    if (status == VF_OK && !copy.frames)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    if (status == VF_OK)
        status = copy_images(&ds, stage_dir, &copy);
    if (status == VF_OK)
        status = vf_path_join(transforms_out, sizeof transforms_out, stage_dir, "transforms.json");
    if (status == VF_OK)
        status = vf_dataset_save(transforms_out, &copy);
    if (status == VF_OK) {
        if (!realpath(opt->transforms, source))
            snprintf(source, sizeof source, "%s", opt->transforms);
        *summary = summarize(&ds, has_alpha);
        *params = json_pack("{s:s, s:s}", "source", "transforms", "transforms", source);
    }
    free(copy.frames);
    vf_dataset_free(&ds);
    return status;
}

/* The manifest's summary of a capture ingest, from its report. */
static json_t *summarize_capture(const json_t *report)
{
    json_t *source = json_object_get(report, "source");
    json_t *summary = json_pack(
        "{s:O, s:O, s:O, s:O, s:O, s:O, s:O, s:O, s:s}", "source", json_object_get(source, "kind"),
        "input", json_object_get(source, "path"), "frames", json_object_get(report, "kept"),
        "frames_read", json_object_get(report, "frame_count"), "blurry",
        json_object_get(report, "blurry"), "duplicates", json_object_get(report, "duplicates"),
        "width", json_object_get(report, "output_width"), "height",
        json_object_get(report, "output_height"), "report", "ingest/report.json");
    json_t *rotation = json_object_get(json_object_get(report, "rotation"), "clockwise_degrees");
    if (rotation)
        json_object_set(summary, "rotation", rotation);
    json_t *orientation = json_object_get(report, "orientation");
    if (orientation)
        json_object_set(summary, "mixed_orientation", json_object_get(orientation, "mixed"));
    return summary;
}

/* The options as the manifest records them. */
static json_t *capture_params(const ingest_options *opt, const char *kind, const json_t *report)
{
    const vf_ingest_options *cap = &opt->capture;
    json_t *params = json_pack(
        "{s:s, s:O, s:i, s:i, s:f, s:f}", "source", kind, "input",
        json_object_get(json_object_get(report, "source"), "path"), "frames",
        cap->select.max_frames, "max_size", cap->max_size, "blur_ratio", cap->select.blur_ratio,
        "duplicate_threshold", cap->select.duplicate_threshold);
    if (opt->device) {
        json_object_set_new(params, "seconds", json_real(cap->seconds));
        json_object_set_new(params, "size", json_pack("[i, i]", cap->width, cap->height));
    }
    return params;
}

/* Ingest a video, photo folder or webcam into the staging folder. */
static vf_status import_capture(const ingest_options *opt, const char *stage_dir,
                                json_t **params, json_t **summary)
{
    json_t *report = NULL;
    const char *kind = opt->device ? "camera" : vf_is_dir(opt->source) ? "photos" : "video";
    vf_status status;
    if (opt->device)
        status = vf_ingest_camera(opt->device, &opt->capture, stage_dir, &report);
    else if (!strcmp(kind, "photos"))
        status = vf_ingest_photos(opt->source, &opt->capture, stage_dir, &report);
    else
        status = vf_ingest_video(opt->source, &opt->capture, stage_dir, &report);
    if (status == VF_OK) {
        *summary = summarize_capture(report);
        *params = capture_params(opt, kind, report);
    }
    json_decref(report);
    return status;
}

/* Render a 3D model's capture into the staging folder. */
static vf_status import_model(const ingest_options *opt, const char *stage_dir, json_t **params,
                              json_t **summary)
{
    const vf_object3d_capture *m = &opt->model;
    vf_info("%s: rendering %d + %d views of %dx%d with Blender (%d samples)", opt->source,
            m->views, m->test_views, m->size, m->size, m->samples);
    vf_status status = vf_object3d_ingest(opt->source, m, stage_dir, summary);
    if (status == VF_OK)
        *params = json_pack("{s:s, s:O, s:i, s:i, s:i, s:i, s:I}", "source", "model", "input",
                            json_object_get(*summary, "input"), "views", m->views, "test_views",
                            m->test_views, "size", m->size, "samples", m->samples, "seed",
                            (json_int_t)m->seed);
    return status;
}

typedef vf_status (*import_fn)(const ingest_options *opt, const char *stage_dir,
                               json_t **params, json_t **summary);

/* Run an import in the workspace's staging folder and swap it in when it succeeds. A
 * workspace this run created is removed again when it fails, so bad input leaves nothing
 * behind, and an existing one keeps its earlier outputs. A model's renders are slow: when
 * they stop half-way (interrupted, not refused) the staging folder is kept for the next run. */
static vf_status run_in_stage(const ingest_options *opt, import_fn import, json_t **summary_out)
{
    vf_workspace ws;
    vf_stage stage;
    json_t *params = NULL, *summary = NULL;
    int fresh = !vf_is_dir(opt->workspace);
    vf_status status = vf_workspace_open(opt->workspace, 1, &ws);
    if (status != VF_OK)
        return status;
    int resumable = import == import_model;
    status = resumable ? vf_stage_resume(&ws, "ingest", &stage)
                       : vf_stage_begin(&ws, "ingest", &stage);
    if (status == VF_OK)
        status = import(opt, stage.dir, &params, &summary);
    char first[VF_PATH_MAX]; /* renders made so far stay for a retry */
    int keep = resumable && status == VF_EINTERNAL &&
               vf_path_join(first, sizeof first, stage.dir, "images/r_000.png") == VF_OK &&
               vf_is_file(first);
    if (status == VF_OK) {
        *summary_out = json_deep_copy(summary);
        status = vf_stage_commit(&stage, params, summary);
    } else {
        json_decref(params);
        json_decref(summary);
        if (!keep)
            vf_stage_abort(&stage);
    }
    vf_workspace_close(&ws);
    if (status != VF_OK && fresh && !keep)
        vf_remove_tree(opt->workspace);
    return status;
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
    if (!strcmp(json_string_value(json_object_get(summary, "source")) ?: "", "model"))
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
        status = run_in_stage(&opt,
                              opt.transforms                                 ? import_transforms
                              : opt.source && vf_object3d_is_model(opt.source) ? import_model
                                                                               : import_capture,
                              &summary);
    if (status != VF_OK)
        return cli_fail("ingest", status);
    print_result(&opt, summary);
    return 0;
}
