/* vfcapture reshoot: guided capture at an exported target.
 *
 * Frames come from a webcam or a video file. Each is localized; the pose is smoothed over
 * time (vf_pose_smoother) so the advice does not jitter, compared with the target, and turned
 * into advice ("orbit 12 deg right, raise 5 cm"). Frames whose (smoothed and raw) viewpoint
 * lies within the tolerance box of the target are saved with their poses to
 * WS/reshoot_tNN/frames/ (PNG) and poses.json, ready for `vfcapture score`. Advice is printed as
 * plain lines and, where a display exists, drawn over the frames in a live window
 * (vf/overlay.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "frames_in.h"
#include "physical.h"
#include "vf/attack_file.h"
#include "vf/calib.h"
#include "vf/log.h"
#include "vf/overlay.h"
#include "vf/targets.h"
#include "vf/workspace.h"

static const char usage[] =
    "usage: vfcapture reshoot WS --target N (--v4l2 /dev/videoN | --video FILE) [options]\n"
    "\n"
    "Guide a camera to exported target N (see 'vfcapture export'): every frame is localized\n"
    "against the capture's sparse model, the pose smoothed over time, and a line of advice\n"
    "printed (orbit, raise/lower, step back/closer, turn, tilt, roll; centimetres when the\n"
    "workspace has a metric scale), also over the frames in a live window where a display\n"
    "exists. Frames within the tolerance of the target are saved with their poses in\n"
    "WS/reshoot_tNN/ (frames/*.png, poses.json), ready for 'vfcapture score'.\n"
    "\n"
    "options:\n"
    "      --target N         exported target (0 is v*)\n"
    "      --v4l2 DEVICE      read a V4L2 webcam\n"
    "      --video FILE       read a video file\n"
    "      --tolerance R      box half-width, percent of each parameter's range (default 5)\n"
    "      --smoothing A      weight of the newest pose, 0..1 (default 0.4; 1: no smoothing)\n"
    "      --seconds S        webcam: stop after S seconds (default 60)\n"
    "      --every N          advise on every Nth frame (default 1)\n"
    "      --no-window        no live window, even where a display exists (q or Esc in the\n"
    "                         window stops the capture)\n" PHYSICAL_LOCALIZE_HELP
        CLI_COMMON_HELP;

enum {
    OPT_TARGET = CLI_OPT_FIRST_CUSTOM,
    OPT_V4L2,
    OPT_VIDEO,
    OPT_TOLERANCE,
    OPT_SMOOTHING,
    OPT_SECONDS,
    OPT_EVERY,
    OPT_NO_WINDOW
};

typedef struct reshoot_options {
    const char *workspace, *device, *video;
    int target, every, no_window;
    double tolerance, smoothing, seconds;
    vf_localize_options loc;
    cli_flags flags;
} reshoot_options;

typedef struct reshoot_run {
    const reshoot_options *opt;
    vf_attack_file attack;
    vf_viewpoint target_v;
    double target_c2w[16];
    double metres;
    vf_localizer *loc;
    vf_pose_smoother smoother;
    char frames_dir[VF_PATH_MAX];
    json_t *saved;           /* [{file, frame, viewpoint, c2w_object, ...}] */
    json_t *advice;          /* per frame, for --json */
    int seen, localized;
    vf_overlay *window;      /* the live window, or NULL */
    int quit;                /* the person closed it with q or Esc */
} reshoot_run;

static vf_status parse_value(int c, const char *arg, reshoot_options *o)
{
    long n;
    double x;
    switch (c) {
    case OPT_TARGET:
        if (cli_parse_int(arg, 0, 100000, &n))
            return vf_fail(VF_EINPUT, "--target: give a target number (0 is v*)");
        o->target = (int)n;
        return VF_OK;
    case OPT_V4L2:
        o->device = arg;
        return VF_OK;
    case OPT_VIDEO:
        o->video = arg;
        return VF_OK;
    case OPT_TOLERANCE:
        if (cli_parse_doubles(arg, &x, 1) != 1 || !(x > 0 && x <= 100))
            return vf_fail(VF_EINPUT, "--tolerance: give a percentage in (0, 100], e.g. 5");
        o->tolerance = x / 100;
        return VF_OK;
    case OPT_SMOOTHING:
        if (cli_parse_doubles(arg, &x, 1) != 1 || !(x > 0 && x <= 1))
            return vf_fail(VF_EINPUT, "--smoothing: give a weight in (0, 1], e.g. 0.4");
        o->smoothing = x;
        return VF_OK;
    case OPT_SECONDS:
        if (cli_parse_doubles(arg, &x, 1) != 1 || !(x > 0))
            return vf_fail(VF_EINPUT, "--seconds: give a positive number of seconds");
        o->seconds = x;
        return VF_OK;
    case OPT_EVERY:
        if (cli_parse_int(arg, 1, 1000, &n))
            return vf_fail(VF_EINPUT, "--every: give a number from 1 to 1000");
        o->every = (int)n;
        return VF_OK;
    case OPT_NO_WINDOW:
        o->no_window = 1;
        return VF_OK;
    }
    return VF_OK;
}

static vf_status parse(int argc, char **argv, reshoot_options *o)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS, PHYSICAL_LOCALIZE_OPTIONS,
        {"target", required_argument, NULL, OPT_TARGET},
        {"v4l2", required_argument, NULL, OPT_V4L2},
        {"video", required_argument, NULL, OPT_VIDEO},
        {"tolerance", required_argument, NULL, OPT_TOLERANCE},
        {"smoothing", required_argument, NULL, OPT_SMOOTHING},
        {"seconds", required_argument, NULL, OPT_SECONDS},
        {"every", required_argument, NULL, OPT_EVERY},
        {"no-window", no_argument, NULL, OPT_NO_WINDOW},
        {0, 0, 0, 0}};
    *o = (reshoot_options){.target = -1, .every = 1, .tolerance = 0.05, .smoothing = 0.4,
                           .seconds = 60};
    vf_localize_defaults(&o->loc);
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, &o->flags, "reshoot", usage))
            continue;
        int handled;
        vf_status status = physical_localize_option(c, optarg, &o->loc, &handled);
        if (status == VF_OK && !handled)
            status = parse_value(c, optarg, o);
        if (status != VF_OK)
            return status;
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture reshoot --help')");
    o->workspace = argv[optind];
    if (o->target < 0)
        return vf_fail(VF_EINPUT, "say which target to shoot: --target N (0 is v*; see "
                                  "WS/export/targets.json)");
    if (!o->device == !o->video)
        return vf_fail(VF_EINPUT, "give one source: --v4l2 /dev/videoN or --video FILE");
    return VF_OK;
}

/* Save a frame on target with its pose. */
static vf_status save_frame(reshoot_run *run, const vf_rgb8 *frame, const frame_info *info,
                            const vf_localize_result *r, double box)
{
    char name[48], path[VF_PATH_MAX];
    /* PNG: lossless, so `score` on these files sees the pixels the camera gave. */
    snprintf(name, sizeof name, "frame_%05zu.png", json_array_size(run->saved));
    vf_status status = vf_path_join(path, sizeof path, run->frames_dir, name);
    if (status == VF_OK)
        status = vf_rgb8_save(path, frame);
    if (status == VF_OK)
        json_array_append_new(run->saved,
                              json_pack("{s:s, s:s, s:o, s:o, s:i, s:f, s:f}", "file", name,
                                        "source", info->name, "viewpoint",
                                        physical_viewpoint_json(&r->viewpoint), "c2w_object",
                                        physical_mat4_json(r->c2w_object), "inliers",
                                        r->inliers, "reprojection_px", r->reprojection_px,
                                        "box_distance", box));
    return status;
}

/* One frame: localize, smooth, advise, save when on target. */
static vf_status handle_frame(reshoot_run *run, const vf_rgb8 *frame, const frame_info *info)
{
    vf_localize_result r;
    vf_status status = vf_localize_frame(run->loc, frame, &r);
    if (status != VF_OK)
        return status;
    run->seen++;
    char line[512];
    json_t *entry = json_pack("{s:s, s:b}", "frame", info->name, "localized", r.localized);
    if (!r.localized) {
        snprintf(line, sizeof line, "%s (keep the object in view, move slowly)", r.reason);
    } else {
        run->localized++;
        double smooth[16], box_raw, box_smooth;
        vf_pose_smoother_add(&run->smoother, r.c2w_object, smooth);
        vf_viewpoint sv;
        vf_c2w_to_viewpoint(smooth, &sv);
        int raw_in = physical_within_box(&r.viewpoint, &run->target_v, run->attack.range,
                                         run->opt->tolerance, &box_raw);
        int smooth_in = physical_within_box(&sv, &run->target_v, run->attack.range,
                                            run->opt->tolerance, &box_smooth);
        vf_advice a;
        vf_advice_compute(smooth, run->target_c2w, &a);
        /* Below these a person cannot act on the advice anyway. */
        char text[384];
        vf_advice_text(&a, run->metres, 2.0, 0.02 * VF_CAMERA_DISTANCE, text, sizeof text);
        int keep = raw_in && smooth_in;
        if (keep && (status = save_frame(run, frame, info, &r, box_raw)) != VF_OK) {
            json_decref(entry);
            return status;
        }
        snprintf(line, sizeof line, "%s%s", keep ? "ON TARGET, saved; " : "", text);
        json_object_set_new(entry, "advice", json_string(text));
        json_object_set_new(entry, "on_target", json_boolean(keep));
        json_object_set_new(entry, "box_distance", json_real(box_smooth));
        json_object_set_new(entry, "viewpoint", physical_viewpoint_json(&r.viewpoint));
    }
    if (run->opt->flags.json)
        json_array_append_new(run->advice, entry);
    else
        json_decref(entry);
    if (!run->opt->flags.json && (run->seen - 1) % run->opt->every == 0) {
        printf("%s: %s\n", info->name, line);
        fflush(stdout);
    }
    if (run->window) {
        char head[96], counts[96];
        snprintf(head, sizeof head, "target %d - %.60s", run->opt->target, info->name);
        snprintf(counts, sizeof counts, "%d of %d frames localized, %d saved", run->localized,
                 run->seen, (int)json_array_size(run->saved));
        const char *lines[3] = {head, line, counts};
        status = vf_overlay_show(run->window, frame, lines, 3,
                                 strncmp(line, "ON TARGET", 9) == 0, &run->quit);
    }
    return status;
}

static vf_status capture(reshoot_run *run)
{
    frames_in in;
    char *video = (char *)run->opt->video;
    vf_status status = run->opt->device ? frames_in_open_v4l2(run->opt->device, &in)
                                        : frames_in_open(&video, 1, &in);
    if (status != VF_OK)
        return status;
    if (run->opt->device)
        vf_info("reading %s for %.0f s", run->opt->device, run->opt->seconds);
    if (!run->opt->no_window && vf_overlay_available() &&
        vf_overlay_open("vfcapture reshoot", &run->window) == VF_OK)
        vf_info("showing the advice in a window (q or Esc stops)");
    vf_rgb8 frame = {0};
    frame_info info;
    int got;
    double start = vf_now();
    while ((status = frames_in_next(&in, &frame, &info, &got)) == VF_OK && got) {
        if ((status = handle_frame(run, &frame, &info)) != VF_OK) {
            vf_error_prefix("%s", info.name);
            break;
        }
        if (run->quit || (run->opt->device && vf_now() - start > run->opt->seconds))
            break;
    }
    vf_overlay_close(run->window);
    run->window = NULL;
    vf_rgb8_free(&frame);
    frames_in_close(&in);
    return status;
}

static vf_status reshoot(const reshoot_options *o, vf_workspace *ws, reshoot_run *run)
{
    char path[VF_PATH_MAX], stage_name[32];
    vf_status status = vf_workspace_path(ws, "attack", "attack.json", path, sizeof path);
    if (status == VF_OK && !vf_is_file(path))
        return vf_fail(VF_EINPUT, "%s does not exist: run 'vfcapture attack' first", path);
    if (status == VF_OK)
        status = vf_attack_file_load(path, &run->attack);
    if (status == VF_OK)
        status = physical_load_target(o->workspace, o->target, &run->target_v, run->target_c2w);
    if (status == VF_OK)
        status = vf_localizer_open(o->workspace, &o->loc, &run->loc);
    if (status != VF_OK)
        return status;
    if (!vf_workspace_metres_per_unit(ws, &run->metres))
        run->metres = 0;
    vf_pose_smoother_init(&run->smoother, o->smoothing);
    vf_stage stage;
    snprintf(stage_name, sizeof stage_name, "reshoot_t%02d", o->target);
    if ((status = vf_stage_begin(ws, stage_name, &stage)) != VF_OK)
        return status;
    status = vf_path_join(run->frames_dir, sizeof run->frames_dir, stage.dir, "frames");
    if (status == VF_OK)
        status = vf_mkdirs(run->frames_dir);
    /* A capture that stops early (a webcam unplugged, a frame of another size) keeps the
     * frames already on target: they are committed, and the error is returned after. */
    vf_status stopped = VF_OK;
    char stop_message[1024] = "";
    if (status == VF_OK && (stopped = capture(run)) != VF_OK && json_array_size(run->saved) == 0)
        status = stopped;
    else if (stopped != VF_OK)
        snprintf(stop_message, sizeof stop_message, "%s", vf_error_message());
    json_t *doc = json_pack("{s:i, s:o, s:f, s:O}", "target", o->target, "target_viewpoint",
                            physical_viewpoint_json(&run->target_v), "tolerance_percent",
                            100 * o->tolerance, "frames", run->saved);
    if (stop_message[0])
        json_object_set_new(doc, "stopped_early", json_string(stop_message));
    if (status == VF_OK && (status = vf_path_join(path, sizeof path, stage.dir, "poses.json")) ==
                               VF_OK)
        status = vf_json_save(path, doc);
    json_decref(doc);
    if (status == VF_OK)
        status = vf_stage_commit(&stage, json_pack("{s:i, s:f}", "target", o->target,
                                                   "tolerance_percent", 100 * o->tolerance),
                                 json_pack("{s:i, s:i, s:i}", "frames", run->seen, "localized",
                                           run->localized, "saved",
                                           (int)json_array_size(run->saved)));
    else
        vf_stage_abort(&stage);
    if (status == VF_OK && stop_message[0])
        status = vf_fail(stopped, "%s (the %zu frames on target before it are kept in %s/%s)",
                         stop_message, json_array_size(run->saved), o->workspace, stage_name);
    return status;
}

int cmd_reshoot(int argc, char **argv)
{
    reshoot_options o;
    vf_workspace ws;
    vf_status status = parse(argc, argv, &o);
    if (status == VF_OK)
        status = vf_workspace_open(o.workspace, 0, &ws);
    if (status != VF_OK)
        return cli_fail("reshoot", status);
    reshoot_run run = {.opt = &o, .saved = json_array(), .advice = json_array()};
    status = reshoot(&o, &ws, &run);
    if (status == VF_OK) {
        int saved = (int)json_array_size(run.saved);
        if (o.flags.json)
            cli_print_json(json_pack("{s:i, s:i, s:i, s:i, s:O, s:O}", "target", o.target,
                                     "frames", run.seen, "localized", run.localized, "saved",
                                     saved, "advice", run.advice, "saved_frames", run.saved));
        else
            printf("%d frames, %d localized, %d on target saved to %s/reshoot_t%02d/\n",
                   run.seen, run.localized, saved, o.workspace, o.target);
    }
    vf_localizer_close(run.loc);
    vf_attack_file_free(&run.attack);
    json_decref(run.saved);
    json_decref(run.advice);
    vf_workspace_close(&ws);
    return status == VF_OK ? 0 : cli_fail("reshoot", status);
}
