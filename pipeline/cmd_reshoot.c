/* vfcapture reshoot: parse the options, run the reshoot stage (vf/reshoot.h), print its advice
 * a line a frame. */
#include <stdio.h>

#include "cli.h"
#include "physical.h"
#include "vf/reshoot.h"

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
    const char *workspace;
    int every; /* print every Nth frame's advice */
    vf_reshoot_options reshoot;
    cli_flags flags;
} reshoot_options;

static vf_status parse_value(int c, const char *arg, reshoot_options *o)
{
    long n;
    double x;
    switch (c) {
    case OPT_TARGET:
        if (cli_count("--target", arg, 0, 100000, &n) != VF_OK) /* 0 is v* */
            return VF_EINPUT;
        o->reshoot.target = (int)n;
        return VF_OK;
    case OPT_V4L2: o->reshoot.device = arg; return VF_OK;
    case OPT_VIDEO: o->reshoot.video = arg; return VF_OK;
    case OPT_TOLERANCE:
        if (cli_number_above("--tolerance", arg, 0, 100, &x) != VF_OK) /* percent */
            return VF_EINPUT;
        o->reshoot.tolerance = x / 100;
        return VF_OK;
    case OPT_SMOOTHING:
        if (cli_number_above("--smoothing", arg, 0, 1, &x) != VF_OK)
            return VF_EINPUT;
        o->reshoot.smoothing = x;
        return VF_OK;
    case OPT_SECONDS:
        if (cli_number_above("--seconds", arg, 0, 86400, &x) != VF_OK)
            return VF_EINPUT;
        o->reshoot.seconds = x;
        return VF_OK;
    case OPT_EVERY:
        if (cli_count("--every", arg, 1, 1000, &n) != VF_OK)
            return VF_EINPUT;
        o->every = (int)n;
        return VF_OK;
    case OPT_NO_WINDOW: o->reshoot.window = 0; return VF_OK;
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
    *o = (reshoot_options){.every = 1};
    vf_reshoot_defaults(&o->reshoot);
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, &o->flags, "reshoot", usage))
            continue;
        int handled;
        vf_status status = physical_localize_option(c, optarg, &o->reshoot.loc, &handled);
        if (status == VF_OK && !handled)
            status = parse_value(c, optarg, o);
        if (status != VF_OK)
            return status;
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture reshoot --help')");
    o->workspace = argv[optind];
    if (o->reshoot.target < 0)
        return vf_fail(VF_EINPUT, "say which target to shoot: --target N (0 is v*; see "
                                  "WS/export/targets.json)");
    if (!o->reshoot.device == !o->reshoot.video)
        return vf_fail(VF_EINPUT, "give one source: --v4l2 /dev/videoN or --video FILE");
    return VF_OK;
}

typedef struct printer {
    int every, json, seen;
    json_t *advice; /* per frame, for --json */
} printer;

static void print_frame(const json_t *entry, const char *line, void *ctx)
{
    printer *p = ctx;
    if (p->json)
        json_array_append(p->advice, (json_t *)entry);
    else if (p->seen % p->every == 0) {
        printf("%s: %s\n", json_string_value(json_object_get(entry, "frame")), line);
        fflush(stdout);
    }
    p->seen++;
}

int cmd_reshoot(int argc, char **argv)
{
    reshoot_options o;
    vf_workspace ws;
    json_t *result = NULL;
    printer p = {.advice = json_array()};
    vf_status s = parse(argc, argv, &o);
    p.every = o.every;
    p.json = o.flags.json;
    if (s == VF_OK && (s = vf_workspace_open(o.workspace, 0, &ws)) == VF_OK) {
        s = vf_reshoot_run(&ws, &o.reshoot, print_frame, &p, &result);
        vf_workspace_close(&ws);
    }
    if (s == VF_OK) {
        long long seen = json_integer_value(json_object_get(result, "seen"));
        long long localized = json_integer_value(json_object_get(result, "localized"));
        long long saved = json_integer_value(json_object_get(result, "saved"));
        if (o.flags.json)
            cli_print_json(json_pack("{s:i, s:I, s:I, s:I, s:O, s:O}", "target", o.reshoot.target,
                                     "frames", seen, "localized", localized, "saved", saved,
                                     "advice", p.advice, "saved_frames",
                                     json_object_get(result, "frames")));
        else
            printf("%lld frames, %lld localized, %lld on target saved to %s/reshoot_t%02d/\n",
                   seen, localized, saved, o.workspace, o.reshoot.target);
    }
    json_decref(result);
    json_decref(p.advice);
    return s == VF_OK ? 0 : cli_fail("reshoot", s);
}
