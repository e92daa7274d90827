/* vfcapture calib scale: metric scale of a posed workspace, from a printed ArUco marker of
 * known size or two picked points of known distance, kept in WS/calib/scale.json. */
#include <stdlib.h>
#include <string.h>

#include "calib_cmd.h"
#include "vf/log.h"

static const char usage[] =
    "usage: vfcapture calib scale WS (--marker ID --marker-size MM | --distance P1 P2 MM)\n"
    "\n"
    "Tie the workspace's scene units (the object frame of WS/poses/transforms.json) to metres,\n"
    "so that later commands can speak in metres. The result goes to WS/calib/scale.json as\n"
    "{\"metres_per_unit\": s, \"method\": ..., details}.\n"
    "\n"
    "  --marker ID --marker-size MM  an ArUco marker (original dictionary, OpenCV's\n"
    "                         DICT_ARUCO_ORIGINAL; 'vfcapture calib marker' prints one) lying\n"
    "                         in the scene during the capture; MM is the side of its black\n"
    "                         square. Its corners are found in the posed frames and\n"
    "                         triangulated; it must show in at least 2 frames.\n"
    "  --distance P1 P2 MM    two points MM millimetres apart, each picked in two or more\n"
    "                         frames as \"FRAME:U,V;FRAME:U,V\" (FRAME: the image's file name\n"
    "                         in the workspace, with or without extension; U,V: pixels from\n"
    "                         the image's top-left corner, in the image as stored), e.g.\n"
    "                         --distance 'frame_0003.jpg:812,433;frame_0017.jpg:640,210' \\\n"
    "                                    'frame_0003.jpg:1020,440;frame_0017.jpg:905,260' 300\n"
    "\n"
    "options:\n" CLI_COMMON_HELP;

enum { OPT_MARKER = CLI_OPT_FIRST_CUSTOM, OPT_SIZE, OPT_DISTANCE, OPT_OLD_SIZE };

typedef struct scale_args {
    const char *workspace;
    vf_scale_request req;
} scale_args;

static vf_status parse_args(int argc, char **argv, scale_args *a, cli_flags *flags)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"marker", required_argument, NULL, OPT_MARKER},
        {"marker-size", required_argument, NULL, OPT_SIZE},
        {"size", required_argument, NULL, OPT_OLD_SIZE}, /* --size is an image's elsewhere */
        {"distance", required_argument, NULL, OPT_DISTANCE},
        {0, 0, 0, 0},
    };
    *a = (scale_args){.req.marker = -1};
    long marker = -1;
    int c;
    vf_status status;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, flags, "calib scale", usage))
            continue;
        switch (c) {
        case OPT_MARKER:
            if (cli_count("--marker", optarg, 0, VF_ARUCO_IDS - 1, &marker) != VF_OK)
                return VF_EINPUT;
            a->req.marker = (int)marker;
            break;
        case OPT_OLD_SIZE: cli_deprecated("calib scale", "--size", "--marker-size"); /* fall through */
        case OPT_SIZE:
            if ((status = calib_parse_mm(optarg, "--marker-size", &a->req.size_m)) != VF_OK)
                return status;
            break;
        case OPT_DISTANCE: /* three values: P1 (optarg), then P2 and MM */
            if (optind + 1 >= argc)
                return vf_fail(VF_EINPUT, "--distance takes three values: P1 P2 MM");
            a->req.p1 = optarg;
            a->req.p2 = argv[optind];
            if ((status = calib_parse_mm(argv[optind + 1], "--distance", &a->req.distance_m)) !=
                VF_OK)
                return status;
            optind += 2;
            break;
        }
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture calib scale "
                                  "--help')");
    a->workspace = argv[optind];
    int by_marker = a->req.marker >= 0 || a->req.size_m > 0, by_distance = a->req.p1 != NULL;
    if (by_marker == by_distance)
        return vf_fail(VF_EINPUT, "give either --marker ID --marker-size MM or --distance P1 P2 MM");
    if (by_marker && (a->req.marker < 0 || !(a->req.size_m > 0)))
        return vf_fail(VF_EINPUT, "--marker needs --marker-size MM (the side of the black square) "
                                  "and --marker-size needs --marker ID");
    return VF_OK;
}

int calib_scale(int argc, char **argv)
{
    scale_args a;
    cli_flags flags = {0};
    json_t *result = NULL;
    vf_status status = parse_args(argc, argv, &a, &flags);
    vf_workspace ws = {0};
    if (status == VF_OK)
        status = vf_workspace_open(a.workspace, 0, &ws);
    if (status == VF_OK)
        status = vf_calib_scale_run(&ws, &a.req, &result);
    vf_workspace_close(&ws);
    if (status != VF_OK) {
        json_decref(result);
        return cli_fail("calib scale", status);
    }
    if (flags.json) {
        json_object_set_new(result, "workspace", json_string(a.workspace));
        cli_print_json(result);
        return 0;
    }
    double s = json_number_value(json_object_get(result, "metres_per_unit"));
    printf("1 scene unit = %.4f m (%.2f units per metre), by %s\n", s, 1.0 / s,
           a.req.p1 ? "two picked points" : "the marker");
    printf("scale in %s/calib/scale.json\n", a.workspace);
    json_decref(result);
    return 0;
}
