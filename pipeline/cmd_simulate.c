/* vfcapture simulate: the simulated studio (vf/studio.h). A person with a phone films a 3D
 * model in a room, or re-shoots it at an exported target; this parses and prints. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "vf/studio.h"

static const char usage[] =
    "usage: vfcapture simulate capture MODEL -o VIDEO.mp4 [options]\n"
    "       vfcapture simulate reshoot WS --target N -o VIDEO.mp4 [--object MODEL] [options]\n"
    "       vfcapture simulate check WS VIDEO.mp4\n"
    "\n"
    "A simulated studio for the physical loop. Blender films the 3D model standing on a\n"
    "textured floor in a room, the way a person films an object with a phone: handheld,\n"
    "walking around it, motion blur, sensor noise, drifting exposure, H.264 stored sideways\n"
    "with a rotation flag. VIDEO.truth.json beside the video holds the true camera of every\n"
    "frame; no other command reads it.\n"
    "\n"
    "  capture   one loop around the object a height, the heights joined by a smooth rise\n"
    "  reshoot   walk from the capture's first viewpoint to target N of the workspace's export\n"
    "            and film around it (the workspace was ingested from a simulated capture)\n"
    "  check     after 'vfcapture score WS VIDEO' on a re-shoot: score's localization and\n"
    "            kept frames against the truth, and the physical success rate\n"
    "\n"
    "options:\n"
    "  -o, --output VIDEO     the video to write (.mp4)\n"
    "      --size WxH         upright frame size (default 360x640; 1080x1920 costs 9x;\n"
    "                         reshoot: the capture's)\n"
    "      --fov DEG          vertical field of view (default 65; reshoot: the capture's)\n"
    "      --fps F            frames a second (default 30; reshoot: the capture's)\n"
    "      --render-samples N Cycles samples a pixel (default 8)\n"
    "      --shake S          scale of hand shake (default 1; 0: a tripod)\n"
    "      --noise S          scale of sensor noise and exposure drift (default 1; 0: none)\n"
    "      --denoise H        the phone's denoising of each frame before encoding: non-local\n"
    "                         means of strength H (default 6; 0: the raw grain)\n"
    "      --shutter S        open share of the frame interval (default 0.5; 0: no blur)\n"
    "      --seed N           every random choice (default 0)\n"
    "capture:\n"
    "      --loops N          loops, one a height (default 2)\n"
    "      --loop-seconds S   time a loop takes (default 8)\n"
    "      --elevation LO,HI  heights of the first and last loop, degrees (default 12,35)\n"
    "      --distance D       camera distance in object radii (default 3.2)\n"
    "reshoot:\n"
    "      --target N         exported target (0 is v*)\n"
    "      --object MODEL     the 3D model (default: the capture's)\n"
    "      --truth FILE       the capture's truth file (default: beside the ingested video)\n"
    "      --walk-seconds S   walking to the target (default 4)\n"
    "      --hold-seconds S   filming around it (default 6)\n"
    "      --jitter PERCENT   how far around the target the person wanders, per cent of each\n"
    "                         parameter's range (default 3)\n"
    "      --follow           closed loop: the person moves by the advice of 'vfcapture\n"
    "                         reshoot', which reads the phone as a camera frame by frame;\n"
    "                         reports per walk whether and when it reached the target and\n"
    "                         whether the advice ever pointed the wrong way (10 fps unless\n"
    "                         --fps; --hold-seconds: filming once on target, default 6)\n"
    "      --starts N         follow: walks, from the capture's viewpoints (default 3)\n"
    "      --give-up S        follow: a walk not on target by then ends (default 40)\n"
    "      --tolerance PCT    follow: reshoot's box, per cent of each range (default 10)\n"
    CLI_COMMON_HELP;

enum {
    OPT_SIZE = CLI_OPT_FIRST_CUSTOM, OPT_FOV, OPT_FPS, OPT_SAMPLES, OPT_SHAKE, OPT_NOISE, OPT_DENOISE,
    OPT_SHUTTER, OPT_SEED, OPT_LOOPS, OPT_LOOP_SECONDS, OPT_ELEVATION, OPT_DISTANCE, OPT_TARGET,
    OPT_MODEL, OPT_TRUTH, OPT_WALK, OPT_HOLD, OPT_JITTER, OPT_FOLLOW, OPT_STARTS, OPT_GIVE_UP,
    OPT_TOLERANCE, OPT_OLD_SAMPLES, OPT_OLD_MODEL
};

typedef struct simulate_options {
    const char *output, *model;
    vf_studio_capture_options capture;
    vf_studio_reshoot_options reshoot;
    int target_given;
    cli_flags flags;
} simulate_options;

static vf_status phone_option(int c, const char *arg, vf_studio_phone *p)
{
    vf_status s = VF_OK;
    if (c == OPT_SIZE)
        s = cli_size("--size", arg, &p->width, &p->height);
    else if (c == OPT_FOV)
        s = cli_number("--fov", arg, 5, 170, &p->fov_y);
    else if (c == OPT_FPS)
        s = cli_number("--fps", arg, 1, 240, &p->fps);
    else if (c == OPT_SAMPLES || c == OPT_OLD_SAMPLES) {
        if (c == OPT_OLD_SAMPLES) /* --samples is the attack's */
            cli_deprecated("simulate", "--samples", "--render-samples");
        s = cli_count_int("--render-samples", arg, 1, 4096, &p->samples);
    }
    else if (c == OPT_SHAKE)
        s = cli_number("--shake", arg, 0, 10, &p->shake);
    else if (c == OPT_NOISE)
        s = cli_number("--noise", arg, 0, 10, &p->noise);
    else if (c == OPT_DENOISE)
        s = cli_number("--denoise", arg, 0, 50, &p->denoise);
    else if (c == OPT_SHUTTER)
        s = cli_number("--shutter", arg, 0, 1, &p->shutter);
    else if (c == OPT_SEED)
        s = cli_seed("--seed", arg, &p->seed);
    return s;
}

static vf_status parse_options(int argc, char **argv, simulate_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"output", required_argument, NULL, 'o'},
        {"size", required_argument, NULL, OPT_SIZE},
        {"fov", required_argument, NULL, OPT_FOV},
        {"fps", required_argument, NULL, OPT_FPS},
        {"render-samples", required_argument, NULL, OPT_SAMPLES},
        {"samples", required_argument, NULL, OPT_OLD_SAMPLES},
        {"shake", required_argument, NULL, OPT_SHAKE},
        {"noise", required_argument, NULL, OPT_NOISE},
        {"denoise", required_argument, NULL, OPT_DENOISE},
        {"shutter", required_argument, NULL, OPT_SHUTTER},
        {"seed", required_argument, NULL, OPT_SEED},
        {"loops", required_argument, NULL, OPT_LOOPS},
        {"loop-seconds", required_argument, NULL, OPT_LOOP_SECONDS},
        {"elevation", required_argument, NULL, OPT_ELEVATION},
        {"distance", required_argument, NULL, OPT_DISTANCE},
        {"target", required_argument, NULL, OPT_TARGET},
        {"object", required_argument, NULL, OPT_MODEL},
        {"model", required_argument, NULL, OPT_OLD_MODEL},
        {"truth", required_argument, NULL, OPT_TRUTH},
        {"walk-seconds", required_argument, NULL, OPT_WALK},
        {"hold-seconds", required_argument, NULL, OPT_HOLD},
        {"jitter", required_argument, NULL, OPT_JITTER},
        {"follow", no_argument, NULL, OPT_FOLLOW},
        {"starts", required_argument, NULL, OPT_STARTS},
        {"give-up", required_argument, NULL, OPT_GIVE_UP},
        {"tolerance", required_argument, NULL, OPT_TOLERANCE},
        {0, 0, 0, 0},
    };
    vf_studio_capture_defaults(&opt->capture);
    vf_studio_reshoot_defaults(&opt->reshoot);
    vf_studio_capture_options *cap = &opt->capture;
    vf_studio_reshoot_options *re = &opt->reshoot;
    int c;
    vf_status s = VF_OK;
    while (s == VF_OK &&
           (c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "simulate", usage))
            continue;
        if (c == 'o')
            opt->output = optarg;
        else if (c >= OPT_SIZE && c <= OPT_SEED) {
            /* one phone for both: the reshoot's size, field of view and rate default to the
             * capture's */
            vf_studio_phone kept = re->phone;
            if ((s = phone_option(c, optarg, &cap->phone)) == VF_OK)
                s = phone_option(c, optarg, &re->phone);
            if (c != OPT_SIZE)
                re->phone.width = kept.width, re->phone.height = kept.height;
            if (c != OPT_FOV)
                re->phone.fov_y = kept.fov_y;
            if (c != OPT_FPS)
                re->phone.fps = kept.fps;
        } else if (c == OPT_LOOPS)
            s = cli_count_int("--loops", optarg, 1, 10, &cap->loops);
        else if (c == OPT_LOOP_SECONDS)
            s = cli_number("--loop-seconds", optarg, 0.5, 600, &cap->loop_seconds);
        else if (c == OPT_ELEVATION) {
            double e[2];
            if (cli_parse_doubles(optarg, e, 2) != 2 || !(e[0] > -10 && e[1] < 80))
                s = vf_fail(VF_EINPUT,
                            "--elevation wants LO,HI in degrees from -10 to 80, not "
                            "'%s'",
                            optarg);
            cap->elevation_low = e[0], cap->elevation_high = e[1];
        } else if (c == OPT_DISTANCE)
            s = cli_number("--distance", optarg, 1.2, 50, &cap->distance);
        else if (c == OPT_TARGET) {
            s = cli_count_int("--target", optarg, 0, 10000, &re->target);
            opt->target_given = 1;
        } else if (c == OPT_MODEL || c == OPT_OLD_MODEL) {
            if (c == OPT_OLD_MODEL) /* --model is the classifier everywhere else */
                cli_deprecated("simulate", "--model", "--object");
            opt->model = optarg;
        }
        else if (c == OPT_TRUTH)
            re->truth = optarg;
        else if (c == OPT_WALK)
            s = cli_number("--walk-seconds", optarg, 0, 600, &re->walk_seconds);
        else if (c == OPT_HOLD)
            s = cli_number("--hold-seconds", optarg, 0.1, 600, &re->hold_seconds);
        else if (c == OPT_JITTER && (s = cli_number("--jitter", optarg, 0, 49, &re->jitter)) ==
                                        VF_OK)
            re->jitter /= 100;
        else if (c == OPT_FOLLOW)
            re->follow = 1;
        else if (c == OPT_STARTS)
            s = cli_count_int("--starts", optarg, 1, 100, &re->starts);
        else if (c == OPT_GIVE_UP)
            s = cli_number("--give-up", optarg, 1, 3600, &re->give_up_seconds);
        else if (c == OPT_TOLERANCE &&
                 (s = cli_number("--tolerance", optarg, 0.1, 100, &re->tolerance)) == VF_OK)
            re->tolerance /= 100;
    }
    return s;
}

static void print_report(const simulate_options *opt, const json_t *r)
{
    if (opt->flags.json) {
        cli_print_json(json_incref((json_t *)r));
        return;
    }
    printf("wrote %s: %lld frames %lldx%lld, %.1f s of video (rendered in %.0f s)\n",
           json_string_value(json_object_get(r, "video")),
           json_integer_value(json_object_get(r, "frames")),
           json_integer_value(json_object_get(r, "width")),
           json_integer_value(json_object_get(r, "height")),
           json_number_value(json_object_get(r, "seconds")),
           json_number_value(json_object_get(r, "render_seconds")));
    printf("true camera poses: %s\n", json_string_value(json_object_get(r, "truth")));
    const json_t *walks = json_object_get(r, "walks");
    for (size_t i = 0; i < json_array_size(walks); i++) {
        const json_t *w = json_array_get(walks, i);
        const json_t *on = json_object_get(w, "seconds_to_on_target");
        const json_t *in = json_object_get(w, "seconds_to_truly_in_box");
        char when[96] = "reshoot never said on target";
        if (json_is_number(on))
            snprintf(when, sizeof when, "on target after %.1f s (truly in the box after %.1f s)",
                     json_number_value(on), json_is_number(in) ? json_number_value(in) : NAN);
        printf("walk %zu: %s, %s; %lld of the %lld frames called on target truly were; true "
               "distance %.3f at the end (%.3f at the start, shares of the range); advice the "
               "wrong way on %lld of %lld localized frames, at most %.1f s in a row\n",
               i + 1, json_is_true(json_object_get(w, "reached")) ? "reached" : "NOT reached",
               when, json_integer_value(json_object_get(w, "on_target_truly_in_box")),
               json_integer_value(json_object_get(w, "on_target_frames")),
               json_number_value(json_object_get(w, "final_box_distance")),
               json_number_value(json_object_get(w, "from_box_distance")),
               json_integer_value(json_object_get(w, "wrong_way_frames")),
               json_integer_value(json_object_get(w, "localized")),
               json_number_value(json_object_get(w, "wrong_way_longest_seconds")));
    }
    const json_t *a = json_object_get(r, "alignment");
    if (a)
        printf("the workspace's poses against the truth (%lld frames): rotation median %.2f deg, "
               "position median %.2f%% of the distance\n",
               json_integer_value(json_object_get(a, "frames")),
               json_number_value(json_object_get(a, "rotation_median_deg")),
               100 * json_number_value(json_object_get(a, "position_median")));
}

static void print_check(const simulate_options *opt, const json_t *r)
{
    if (opt->flags.json) {
        cli_print_json(json_incref((json_t *)r));
        return;
    }
    const json_t *p = json_object_get(r, "physical");
    printf("%s against its truth:\n", json_string_value(json_object_get(r, "video")));
    printf("  localized %lld of %lld frames: rotation median %.2f deg, position median %.2f%% "
           "of the distance\n",
           json_integer_value(json_object_get(r, "localized")),
           json_integer_value(json_object_get(r, "frames")),
           json_number_value(json_object_get(r, "rotation_median_deg")),
           100 * json_number_value(json_object_get(r, "position_median")));
    printf("  tolerance box +-%.0f%%: %lld frames truly in it, score kept %lld; %lld agree with "
           "the truth, %lld within localization noise (%.3f) of the box's edge (%.0f%% "
           "agreement off the edge)\n",
           100 * json_number_value(json_object_get(r, "tolerance")),
           json_integer_value(json_object_get(r, "truly_in_box")),
           json_integer_value(json_object_get(r, "kept")),
           json_integer_value(json_object_get(r, "agree")),
           json_integer_value(json_object_get(r, "at_box_edge")),
           json_number_value(json_object_get(r, "edge_band")),
           100 * json_number_value(json_object_get(r, "agreement")));
    const json_t *ci = json_object_get(p, "interval95");
    printf("  physical success rate %.0f%% (%lld of %lld kept frames misclassified; 95%% "
           "interval %.0f%% to %.0f%%)\n",
           100 * json_number_value(json_object_get(p, "asr")),
           json_integer_value(json_object_get(p, "misclassified")),
           json_integer_value(json_object_get(p, "frames")),
           100 * json_number_value(json_array_get(ci, 0)),
           100 * json_number_value(json_array_get(ci, 1)));
    const json_t *real = json_object_get(r, "real");
    if (json_is_object(real))
        printf("  the object itself (vfcapture real): Real(v*) %.0f%%, Real(p*(v)) %.0f%%, "
               "natural accuracy %.0f%%; physical minus Real(v*): %+.0f points\n",
               100 * json_number_value(json_object_get(real, "asr_v_star")),
               100 * json_number_value(json_object_get(real, "asr_samples")),
               100 * json_number_value(json_object_get(real, "natural_accuracy")),
               100 * (json_number_value(json_object_get(p, "asr")) -
                      json_number_value(json_object_get(real, "asr_v_star"))));
    else
        printf("  (run 'vfcapture real WS' to put the object's own Real(v*) beside it)\n");
}

int cmd_simulate(int argc, char **argv)
{
    simulate_options opt = {0};
    vf_status s = parse_options(argc, argv, &opt);
    const char *what = s == VF_OK && optind < argc ? argv[optind] : "";
    json_t *report = NULL;
    if (s == VF_OK && strcmp(what, "check") && !opt.output)
        s = vf_fail(VF_EINPUT, "say where the video goes (-o VIDEO.mp4)");
    if (s == VF_OK && !strcmp(what, "capture")) {
        if (optind + 2 != argc)
            s = vf_fail(VF_EINPUT, "give one 3D model (see vfcapture simulate --help)");
        else
            s = vf_studio_capture(argv[optind + 1], &opt.capture, opt.output, &report);
    } else if (s == VF_OK && !strcmp(what, "reshoot")) {
        vf_workspace ws;
        if (optind + 2 != argc)
            s = vf_fail(VF_EINPUT, "give one workspace (see vfcapture simulate --help)");
        else if (!opt.target_given)
            s = vf_fail(VF_EINPUT, "say which target to re-shoot (--target N; 0 is v*)");
        else if (!vf_is_dir(argv[optind + 1]))
            s = vf_fail(VF_EINPUT, "workspace %s does not exist", argv[optind + 1]);
        else if ((s = vf_workspace_open(argv[optind + 1], 0, &ws)) == VF_OK) {
            s = vf_studio_reshoot(&ws, opt.model, &opt.reshoot, opt.output, &report);
            vf_workspace_close(&ws);
        }
    } else if (s == VF_OK && !strcmp(what, "check")) {
        vf_workspace ws;
        if (optind + 3 != argc)
            s = vf_fail(VF_EINPUT, "give a workspace and a re-shoot video (see vfcapture "
                                   "simulate --help)");
        else if (!vf_is_dir(argv[optind + 1]))
            s = vf_fail(VF_EINPUT, "workspace %s does not exist", argv[optind + 1]);
        else if ((s = vf_workspace_open(argv[optind + 1], 0, &ws)) == VF_OK) {
            s = vf_studio_check(&ws, argv[optind + 2], &report);
            vf_workspace_close(&ws);
        }
        if (s == VF_OK) {
            print_check(&opt, report);
            json_decref(report);
            return 0;
        }
    } else if (s == VF_OK) {
        s = vf_fail(VF_EINPUT, "say 'capture', 'reshoot' or 'check' (see vfcapture simulate "
                               "--help)");
    }
    if (s != VF_OK)
        return cli_fail("simulate", s);
    print_report(&opt, report);
    json_decref(report);
    return 0;
}
