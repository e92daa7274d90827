/* vfcapture train: parse the options, run the train stage (vf/train.h), print the scores. */
#include <stdio.h>

#include "cli.h"
#include "vf/train.h"

static const char usage[] =
    "usage: vfcapture train WS [--minutes M | --train-steps N] [--holdout N]\n"
    "                      [--surroundings MODE]\n"
    "                      [--color MODEL] [--view-smoothing W] [--depth W] [--appearance]\n"
    "                      [--object-only] [--restart]\n"
    "\n"
    "Fit a radiance field (an explicit density + spherical-harmonics grid, coarse to fine) to\n"
    "the posed images of WS: the undistorted frames of the poses stage, or an imported posed\n"
    "set. Every Nth view is held out and its PSNR reported, beside as many training views\n"
    "(a held-out PSNR far below theirs: fog between the photos); with the sparse points of\n"
    "'vfcapture poses', each held-out render is also checked for the object where its photo\n"
    "shows it. An interrupted run continues from its last checkpoint. Writes\n"
    "WS/train/model.vff, report.json and held_out.jpg (held-out photos beside their renders).\n"
    "\n"
    "options:\n"
    "      --minutes M        training wall time (default 3; 5 for a 3D model's workspace)\n"
    "      --train-steps N    train for N optimizer steps instead of a time (the same field\n"
    "                         however busy the machine is)\n"
    "      --holdout N        hold out every Nth view for scoring, 0 for none (default 10)\n"
    "      --surroundings MODE  what lies beyond the box the cameras look at: auto (a coarser\n"
    "                         outer grid for opaque photos, none for background-removed ones;\n"
    "                         the default), grid, or none (the box must explain everything)\n"
    "      --color MODEL      how colour may change with the viewing direction: view\n"
    "                         (degree-1 harmonics, smoothed: highlights and glass; the\n"
    "                         default) or diffuse (one colour a point: matte objects)\n"
    "      --view-smoothing W smooth the colour's direction terms in space (total variation,\n"
    "                         0 off): stops noisy photos becoming a speckle; default 1e-4\n"
    "                         for a workspace made from a 3D model (Blender's renders are\n"
    "                         noisy), 0 for photos\n"
    "      --depth W          how strongly the sparse points of 'vfcapture poses' place the\n"
    "                         surfaces: each training photo's points pull the rays through\n"
    "                         them to their distance, over the first half of the training\n"
    "                         (default 10; 0 off; report.json's depth_points counts them)\n"
    "      --appearance       learn each photo's exposure and white balance (a colour gain\n"
    "                         and offset a photo) beside the field, so they do not become\n"
    "                         haze; renders show the photos' mean. For photos whose\n"
    "                         exposure wanders (the wall clock: 11 points more of its\n"
    "                         renders named like the photos; held-out PSNR 0.4-0.9 dB lower,\n"
    "                         those photos keeping their own exposure)\n"
    "      --object-only      object mode: the object alone, on white, as the paper's\n"
    "                         objects: each photo's cut (the poses stage's sparse points\n"
    "                         near the centre, minus the surface it stands on, seed\n"
    "                         GrabCut; WS/train/object/masks.jpg) votes it out of the\n"
    "                         field trained on the whole photos, and the surface goes;\n"
    "                         held_out.jpg shows photos cut by the field's silhouette\n"
    "      --restart          ignore a checkpoint of an interrupted run\n" CLI_COMMON_HELP;

enum {
    OPT_MINUTES = CLI_OPT_FIRST_CUSTOM,
    OPT_STEPS,
    OPT_TRAIN_STEPS,
    OPT_HOLDOUT,
    OPT_SURROUNDINGS,
    OPT_COLOR,
    OPT_VIEW_SMOOTHING,
    OPT_DEPTH,
    OPT_APPEARANCE,
    OPT_RESTART,
    OPT_OBJECT_ONLY
};

typedef struct cli_train {
    const char *workspace;
    vf_train_options train;
    cli_flags flags;
} cli_train;

static vf_status parse_options(int argc, char **argv, cli_train *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"minutes", required_argument, NULL, OPT_MINUTES},
        {"train-steps", required_argument, NULL, OPT_TRAIN_STEPS},
        {"steps", required_argument, NULL, OPT_STEPS},
        {"holdout", required_argument, NULL, OPT_HOLDOUT},
        {"surroundings", required_argument, NULL, OPT_SURROUNDINGS},
        {"color", required_argument, NULL, OPT_COLOR},
        {"view-smoothing", required_argument, NULL, OPT_VIEW_SMOOTHING},
        {"depth", required_argument, NULL, OPT_DEPTH},
        {"appearance", no_argument, NULL, OPT_APPEARANCE},
        {"restart", no_argument, NULL, OPT_RESTART},
        {"object-only", no_argument, NULL, OPT_OBJECT_ONLY},
        {0, 0, 0, 0},
    };
    int c;
    long value;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "train", usage))
            continue;
        if (c == OPT_MINUTES) {
            if (cli_number_above("--minutes", optarg, 0, 600, &opt->train.minutes) != VF_OK)
                return VF_EINPUT;
        } else if (c == OPT_STEPS || c == OPT_TRAIN_STEPS) {
            if (c == OPT_STEPS)
                cli_deprecated("train", "--steps", "--train-steps (--steps is the attack's)");
            if (cli_count_int("--train-steps", optarg, 1, 10000000, &opt->train.steps) != VF_OK)
                return VF_EINPUT;
        } else if (c == OPT_HOLDOUT) {
            if (cli_parse_int(optarg, 0, 1000000, &value) != 0 || value == 1)
                return vf_fail(VF_EINPUT,
                               "--holdout wants 0 or a whole number from 2 to "
                               "1000000, not '%s'",
                               optarg);
            opt->train.holdout = (int)value;
        } else if (c == OPT_SURROUNDINGS) {
            int mode = vf_field_surroundings_parse(optarg);
            if (mode < 0)
                return vf_fail(VF_EINPUT, "--surroundings must be auto, grid or none, not '%s'",
                               optarg);
            opt->train.surroundings = (vf_field_surroundings)mode;
        } else if (c == OPT_COLOR) {
            int model = vf_field_color_parse(optarg);
            if (model < 0)
                return vf_fail(VF_EINPUT, "--color must be view or diffuse, not '%s'",
                               optarg);
            opt->train.color = (vf_field_color)model;
        } else if (c == OPT_VIEW_SMOOTHING) {
            if (cli_number("--view-smoothing", optarg, 0, 1, &opt->train.view_smoothing) != VF_OK)
                return VF_EINPUT;
        } else if (c == OPT_DEPTH) {
            if (cli_number("--depth", optarg, 0, 1000, &opt->train.depth) != VF_OK)
                return VF_EINPUT;
        } else if (c == OPT_APPEARANCE) {
            opt->train.appearance = 1;
        } else if (c == OPT_RESTART) {
            opt->train.restart = 1;
        } else if (c == OPT_OBJECT_ONLY) {
            opt->train.object_only = 1;
        }
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace (see 'vfcapture train --help')");
    opt->workspace = argv[optind];
    return VF_OK;
}

int cmd_train(int argc, char **argv)
{
    cli_train opt = {0};
    vf_train_defaults(&opt.train);
    vf_workspace ws;
    json_t *report = NULL;
    char model[VF_PATH_MAX];
    vf_status s = parse_options(argc, argv, &opt);
    if (s == VF_OK && (s = vf_workspace_open(opt.workspace, 0, &ws)) == VF_OK) {
        s = vf_train_run(&ws, &opt.train, &report);
        if (s == VF_OK)
            s = vf_workspace_path(&ws, "train", VF_FIELD_FILE, model, sizeof model);
        vf_workspace_close(&ws);
    }
    if (s != VF_OK) {
        json_decref(report);
        return cli_fail("train", s);
    }
    double psnr = json_number_value(json_object_get(report, "held_out_psnr"));
    double ssim = json_number_value(json_object_get(report, "held_out_ssim"));
    double steps = json_number_value(json_object_get(report, "steps"));
    double seconds = json_number_value(json_object_get(report, "seconds"));
    char fit[96] = "";
    if (json_object_get(report, "psnr_gap"))
        snprintf(fit, sizeof fit, "; training views %.2f dB (%.1f dB above)",
                 json_number_value(json_object_get(report, "training_psnr")),
                 json_number_value(json_object_get(report, "psnr_gap")));
    if (opt.flags.json)
        cli_print_json(json_pack("{s:s, s:O}", "model", model, "report", report));
    else if (json_object_get(report, "held_out_psnr_object"))
        printf("trained %.0f steps in %.0f s; held-out views: PSNR %.2f dB inside the "
               "object's masks (%.2f dB with the white around), SSIM %.3f%s\n",
               steps, seconds, json_number_value(json_object_get(report, "held_out_psnr_object")),
               psnr, ssim, fit);
    else if (json_object_get(report, "held_out_psnr"))
        printf("trained %.0f steps in %.0f s; held-out views: PSNR %.2f dB, SSIM %.3f%s\n", steps,
               seconds, psnr, ssim, fit);
    else
        printf("trained %.0f steps in %.0f s\n", steps, seconds);
    const json_t *check = json_object_get(report, "object_check");
    if (check && !opt.flags.json)
        printf("the object is in %lld of %lld held-out renders (overlap with the photo's cut-out "
               "%.2f on average, %.2f at worst; training views %.2f%s)\n",
               json_integer_value(json_object_get(check, "views")) -
                   json_integer_value(json_object_get(check, "missing")),
               json_integer_value(json_object_get(check, "views")),
               json_number_value(json_object_get(check, "iou_mean")),
               json_number_value(json_object_get(check, "iou_min")),
               json_number_value(json_object_get(check, "training_iou_mean")),
               json_is_true(json_object_get(check, "conclusive")) ? "" : ": inconclusive");
    json_decref(report);
    return 0;
}
