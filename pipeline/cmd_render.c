/* vfcapture render: one view of the trained radiance field, at a ViewFool viewpoint or at any
 * camera pose, framed as the classifier sees it. */
#include <string.h>

#include "cli.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/pose.h"

static const char usage[] =
    "usage: vfcapture render WS (--viewpoint PSI,THETA,PHI,DX,DY,DZ | --pose M00,...,M33)\n"
    "                       [--size PX] -o OUT.png\n"
    "\n"
    "Render the trained field of WS (WS/train/model.vff) from a ViewFool viewpoint (psi,\n"
    "theta, phi: rotations about the object in degrees; dx, dy, dz: offsets in scene units;\n"
    "the camera looks at the object from distance 4 + dy) or from a camera-to-world matrix\n"
    "(16 numbers, row-major, object frame, OpenGL camera axes). The image is the\n"
    "classifier's square view: the training camera's centre crop at PX x PX.\n"
    "\n"
    "options:\n"
    "      --viewpoint V      psi,theta,phi,dx,dy,dz\n"
    "      --pose M           16 comma-separated numbers\n"
    "      --size PX          image side, 16..4096 (default 224)\n"
    "  -o, --output FILE    where to write the image (.png, .jpg or .exr)\n" CLI_COMMON_HELP;

enum { OPT_VIEWPOINT = CLI_OPT_FIRST_CUSTOM, OPT_POSE, OPT_SIZE };

typedef struct render_options {
    const char *workspace, *output;
    double c2w[16];
    int have_pose, size;
    cli_flags flags;
} render_options;

static vf_status parse_options(int argc, char **argv, render_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"viewpoint", required_argument, NULL, OPT_VIEWPOINT},
        {"pose", required_argument, NULL, OPT_POSE},
        {"size", required_argument, NULL, OPT_SIZE},
        {"output", required_argument, NULL, 'o'},
        {0, 0, 0, 0},
    };
    int c;
    long size;
    double v[VF_VIEW_DIM];
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "render", usage))
            continue;
        if (c == OPT_VIEWPOINT) {
            if (cli_numbers("--viewpoint", optarg, VF_VIEW_DIM, "psi,theta,phi,dx,dy,dz", v) !=
                VF_OK)
                return VF_EINPUT;
            vf_viewpoint p = vf_viewpoint_from_array(v);
            vf_viewpoint_to_c2w(&p, opt->c2w);
            opt->have_pose = 1;
        } else if (c == OPT_POSE) {
            if (cli_numbers("--pose", optarg, 16, "a 4x4 camera-to-world matrix by rows",
                            opt->c2w) != VF_OK)
                return VF_EINPUT;
            opt->have_pose = 1;
        } else if (c == OPT_SIZE) {
            if (cli_count("--size", optarg, 16, 4096, &size) != VF_OK)
                return VF_EINPUT;
            opt->size = (int)size;
        } else if (c == 'o') {
            opt->output = optarg;
        }
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace (see 'vfcapture render --help')");
    opt->workspace = argv[optind];
    if (!opt->have_pose)
        return vf_fail(VF_EINPUT, "give --viewpoint or --pose");
    if (!opt->output)
        return vf_fail(VF_EINPUT, "give the output image with -o OUT.png");
    return VF_OK;
}

int cmd_render(int argc, char **argv)
{
    render_options opt = {.size = 224};
    vf_status status = parse_options(argc, argv, &opt);
    vf_workspace ws;
    vf_field *field = NULL;
    if (status == VF_OK)
        status = cli_open_trained(opt.workspace, &ws, &field);
    if (status != VF_OK)
        return cli_fail("render", status);
    vf_camera cam = vf_field_classifier_camera(field, opt.size);
    vf_image image = {0};
    double start = vf_now();
    status = vf_field_render(field, &cam, opt.c2w, &image);
    double ms = 1000 * (vf_now() - start);
    if (status == VF_OK)
        status = vf_image_save(opt.output, &image);
    if (status == VF_OK && opt.flags.json)
        cli_print_json(json_pack("{s:s, s:i, s:o}", "image", opt.output, "size", opt.size,
                                 "render_ms", vf_json_number(ms)));
    else if (status == VF_OK)
        vf_info("rendered %dx%d in %.1f ms: %s", opt.size, opt.size, ms, opt.output);
    vf_image_free(&image);
    vf_field_free(field);
    vf_workspace_close(&ws);
    return status == VF_OK ? 0 : cli_fail("render", status);
}
