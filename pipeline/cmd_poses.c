/* vfcapture poses: parse the options, run the poses stage (vf/poses.h), print the summary. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "vf/calib.h"
#include "vf/poses.h"

static const char usage[] =
    "usage: vfcapture poses WS [options]\n"
    "\n"
    "Find the camera pose of every frame in WS/ingest/images with COLMAP (CPU, headless) and\n"
    "write them to WS/poses/ in the object frame: z up, the object at the origin, cameras at a\n"
    "mean distance of 4. Outputs: transforms.json (OpenGL camera-to-world, COLMAP's lens),\n"
    "transforms_undistorted.json with undistorted/ (pinhole images), points3D.txt,\n"
    "normalization.json (object frame <-> COLMAP frame), sparse/ (COLMAP's model), database.db\n"
    "and colmap.log. Fewer than half the frames registering is an error.\n"
    "\n"
    "A posed set (ingest --transforms) keeps its own poses and camera: COLMAP matches each\n"
    "frame with the 20 nearest in viewing direction and only triangulates the sparse points\n"
    "that training's depth loss and object mode read (the fox: 110 s, 9,670 points; its field\n"
    "25.2 -> 27.4 dB held-out after 3 minutes).\n"
    "\n"
    "options:\n"
    "      --matcher M       auto, sequential, exhaustive or retrieval. auto chooses by what the\n"
    "                        frames are: up to 40 frames, all pairs (exhaustive); photos (no\n"
    "                        order) all pairs up to 80; beyond that each frame with its 40 most\n"
    "                        similar by a vocabulary tree built from the capture's own features\n"
    "                        (retrieval). Frames of a video too: sequential (each frame with its\n"
    "                        neighbours) is faster but never closes the loop of a walk around\n"
    "                        the object (measured 2.56 deg off against 0.51 deg)\n"
    "      --no-check        keep a sequential or retrieval model unchecked. By default 16 of\n"
    "                        its frames are matched all pairs and registered on their own, and\n"
    "                        must agree with it (medians under 2 deg and 2% of the cameras'\n"
    "                        spread, at most a fifth over 5 deg off): a wrong model that\n"
    "                        registers every frame looks fine by every count. When they\n"
    "                        disagree, or too few frames register, auto matches all pairs\n"
    "                        instead; a chosen matcher is an error\n"
    "      --overlap N       sequential: match each frame with its next N (default 10, plus\n"
    "                        frames 2^k ahead)\n"
    "      --vocab-tree FILE a COLMAP vocabulary tree: sequential matching then also detects\n"
    "                        loops; retrieval uses it instead of building one from the capture\n"
    "      --camera-model M  auto, OPENCV, SIMPLE_RADIAL, RADIAL, PINHOLE or SIMPLE_PINHOLE\n"
    "                        (default auto: OPENCV, or SIMPLE_RADIAL when the frames' background\n"
    "                        was removed: few features, so a simpler lens)\n"
    "      --intrinsics FX,FY,CX,CY  known pinhole intrinsics in pixels (not refined)\n"
    "      --camera FILE     known intrinsics from JSON: fl_x, fl_y, cx, cy, w, h and optional\n"
    "                        k1, k2, p1, p2 (a calibration result; not refined)\n"
    "      --max-features N  SIFT features per frame (default 2048)\n"
    "      --min-registered F  share of frames that must register (default 0.5)\n"
    "      --no-undistort    skip the undistorted images\n" CLI_COMMON_HELP "\n"
    "COLMAP is `colmap` on PATH, or $VF_COLMAP.\n";

enum {
    OPT_MATCHER = CLI_OPT_FIRST_CUSTOM,
    OPT_OVERLAP,
    OPT_VOCAB_TREE,
    OPT_CAMERA_MODEL,
    OPT_INTRINSICS,
    OPT_CAMERA,
    OPT_MAX_FEATURES,
    OPT_MIN_REGISTERED,
    OPT_NO_UNDISTORT,
    OPT_NO_CHECK,
};

static vf_status parse_option(int c, const char *arg, vf_poses_options *opt)
{
    long n;
    double x[4];
    switch (c) {
    case OPT_MATCHER: opt->matcher = arg; return VF_OK;
    case OPT_OVERLAP:
        if (cli_count("--overlap", arg, 1, 1000, &n) != VF_OK)
            return VF_EINPUT;
        opt->overlap = (int)n;
        return VF_OK;
    case OPT_VOCAB_TREE: opt->vocab_tree = arg; return VF_OK;
    case OPT_CAMERA_MODEL: opt->camera_model = arg; return VF_OK;
    case OPT_INTRINSICS:
        if (cli_numbers("--intrinsics", arg, 4, "fx,fy,cx,cy in pixels", x) != VF_OK)
            return VF_EINPUT;
        if (!(x[0] > 0 && x[1] > 0 && x[2] > 0 && x[3] > 0))
            return vf_fail(VF_EINPUT,
                           "--intrinsics wants fx,fy,cx,cy above 0, e.g. "
                           "1000,1000,640,360, not '%s'",
                           arg);
        opt->known = (vf_camera){.fx = x[0], .fy = x[1], .cx = x[2], .cy = x[3]};
        opt->has_intrinsics = 1;
        opt->camera_file = NULL;
        return VF_OK;
    case OPT_CAMERA:
        opt->has_intrinsics = 1;
        opt->camera_file = arg;
        return vf_calib_load_camera(arg, &opt->known);
    case OPT_MAX_FEATURES:
        if (cli_count("--max-features", arg, 100, 100000, &n) != VF_OK)
            return VF_EINPUT;
        opt->max_features = (int)n;
        return VF_OK;
    case OPT_MIN_REGISTERED:
        if (cli_number_above("--min-registered", arg, 0, 1, x) != VF_OK)
            return VF_EINPUT;
        opt->min_registered = x[0];
        return VF_OK;
    case OPT_NO_UNDISTORT:
        opt->undistort = 0;
        return VF_OK;
    case OPT_NO_CHECK: opt->check = 0; return VF_OK;
    }
    return vf_fail(VF_EINPUT, "unknown option");
}

static vf_status parse_options(int argc, char **argv, const char **workspace,
                               vf_poses_options *opt, cli_flags *flags)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"matcher", required_argument, NULL, OPT_MATCHER},
        {"overlap", required_argument, NULL, OPT_OVERLAP},
        {"vocab-tree", required_argument, NULL, OPT_VOCAB_TREE},
        {"camera-model", required_argument, NULL, OPT_CAMERA_MODEL},
        {"intrinsics", required_argument, NULL, OPT_INTRINSICS},
        {"camera", required_argument, NULL, OPT_CAMERA},
        {"max-features", required_argument, NULL, OPT_MAX_FEATURES},
        {"min-registered", required_argument, NULL, OPT_MIN_REGISTERED},
        {"no-undistort", no_argument, NULL, OPT_NO_UNDISTORT},
        {"no-check", no_argument, NULL, OPT_NO_CHECK},
        {0, 0, 0, 0},
    };
    vf_poses_defaults(opt);
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, flags, "poses", usage))
            continue;
        vf_status status = parse_option(c, optarg, opt);
        if (status != VF_OK)
            return status;
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture poses --help')");
    *workspace = argv[optind];
    return vf_poses_options_check(opt);
}

static void print_summary(const json_t *s, const char *workspace)
{
    const char *mapping = json_string_value(json_object_get(s, "mapping"));
    int known = mapping && !strcmp(mapping, "known poses");
    printf("%s %lld of %lld frames, mean reprojection error %.2f px, %lld points\n",
           known ? "kept the set's poses of" : "registered",
           json_integer_value(json_object_get(s, "registered")),
           json_integer_value(json_object_get(s, "total")),
           json_number_value(json_object_get(s, "reprojection_error_px")),
           json_integer_value(json_object_get(s, "points")));
    const char *step;
    json_t *seconds;
    printf("time:");
    json_object_foreach(json_object_get(s, "seconds"), step, seconds)
        printf(" %s %.1f s,", step, json_number_value(seconds));
    printf("\nposes in %s/poses/transforms.json (object frame: z up, cameras at distance 4)\n",
           workspace);
}

int cmd_poses(int argc, char **argv)
{
    const char *root = NULL;
    vf_poses_options opt;
    cli_flags flags = {0};
    vf_workspace ws;
    json_t *summary = NULL;
    vf_status s = parse_options(argc, argv, &root, &opt, &flags);
    if (s == VF_OK && (s = vf_workspace_open(root, 0, &ws)) == VF_OK) {
        s = vf_poses_run(&ws, &opt, &summary);
        vf_workspace_close(&ws);
    }
    if (s != VF_OK)
        return cli_fail("poses", s);
    if (flags.json) {
        json_object_set_new(summary, "workspace", json_string(root));
        cli_print_json(summary);
    } else {
        print_summary(summary, root);
        json_decref(summary);
    }
    return 0;
}
