/* vfcapture localize: where was each of these frames taken? Registers images and video frames
 * against the workspace's sparse model (vf/localize.h) and prints each pose, or why none. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "physical.h"
#include "vf/frames.h"
#include "vf/json.h"
#include "vf/log.h"

static const char usage[] =
    "usage: vfcapture localize WS IMAGE|VIDEO|FOLDER... [options]\n"
    "\n"
    "Find where each frame was taken, against the sparse model of WS (run 'vfcapture poses'\n"
    "first): SIFT features matched to the model's 3D points, pose by RANSAC, refined with a\n"
    "robust reprojection loss. For each frame: the camera-to-world matrix in the object frame,\n"
    "the viewpoint v = (psi, theta, phi, dx, dy, dz), inliers and reprojection error; or, when\n"
    "the evidence is too thin for a trustworthy pose, \"not localized\" and why.\n"
    "\n"
    "options:\n" PHYSICAL_LOCALIZE_HELP CLI_COMMON_HELP;

static vf_status parse(int argc, char **argv, vf_localize_options *lo, cli_flags *flags)
{
    static const struct option longopts[] = {CLI_COMMON_OPTIONS, PHYSICAL_LOCALIZE_OPTIONS,
                                             {0, 0, 0, 0}};
    vf_localize_defaults(lo);
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, flags, "localize", usage))
            continue;
        int handled;
        vf_status status = physical_localize_option(c, optarg, lo, &handled);
        if (status != VF_OK)
            return status;
    }
    if (argc - optind < 2)
        return vf_fail(VF_EINPUT, "give a workspace and at least one image, video or folder "
                                  "(see 'vfcapture localize --help')");
    return VF_OK;
}

static void print_frame(const vf_frame_info *info, const vf_localize_result *r)
{
    if (!r->localized) {
        printf("%s: %s\n", info->name, r->reason);
        return;
    }
    char v[160];
    physical_viewpoint_text(&r->viewpoint, v, sizeof v);
    const double *m = r->c2w_object;
    printf("%s: %s; position (%.3f %.3f %.3f); %d inliers of %d matches, %.2f px\n", info->name,
           v, m[3], m[7], m[11], r->inliers, r->matches, r->reprojection_px);
    for (int row = 0; row < 3; row++)
        printf("    [% .6f % .6f % .6f % .6f]\n", m[4 * row], m[4 * row + 1], m[4 * row + 2],
               m[4 * row + 3]);
}

static vf_status localize_all(vf_localizer *loc, vf_frames *in, const cli_flags *flags,
                              json_t *frames, int *total, int *localized, double *seconds)
{
    vf_rgb8 frame = {0};
    vf_frame_info info;
    int got;
    vf_status status;
    double busy = 0;
    while ((status = vf_frames_next(in, &frame, &info, &got)) == VF_OK && got) {
        vf_localize_result r;
        if ((status = vf_localize_frame(loc, &frame, &r)) != VF_OK) {
            vf_error_prefix("%s", info.name);
            break;
        }
        busy += r.seconds;
        (*total)++;
        *localized += r.localized;
        if (flags->json) {
            json_t *o = vf_localize_result_json(&r);
            json_object_set_new(o, "frame", json_string(info.name));
            json_array_append_new(frames, o);
        } else {
            print_frame(&info, &r);
            fflush(stdout);
        }
    }
    vf_rgb8_free(&frame);
    *seconds = busy;
    return status;
}

int cmd_localize(int argc, char **argv)
{
    vf_localize_options lo;
    cli_flags flags = {0};
    vf_status status = parse(argc, argv, &lo, &flags);
    if (status != VF_OK)
        return cli_fail("localize", status);
    const char *root = argv[optind];
    vf_workspace ws = {0};
    vf_localizer *loc = NULL;
    vf_frames in = {0};
    json_t *frames = json_array();
    int localized = 0, total = 0;
    double seconds = 0;
    status = vf_workspace_open(root, 0, &ws);
    if (status == VF_OK)
        status = vf_frames_open(argv + optind + 1, argc - optind - 1, &in);
    if (status == VF_OK)
        status = vf_localizer_open(&ws, &lo, &loc);
    if (status == VF_OK) {
        int points, descriptors;
        vf_localizer_map_size(loc, &points, &descriptors);
        vf_info("map: %d 3D points, %d descriptors", points, descriptors);
        status = localize_all(loc, &in, &flags, frames, &total, &localized, &seconds);
    }
    vf_localizer_close(loc);
    vf_frames_close(&in);
    vf_workspace_close(&ws);
    if (status != VF_OK) {
        json_decref(frames);
        return cli_fail("localize", status);
    }
    if (flags.json) {
        cli_print_json(json_pack("{s:s, s:i, s:i, s:o, s:o}", "workspace", root, "localized",
                                 localized, "total", total, "frames_per_second",
                                 vf_json_number(seconds > 0 ? total / seconds : 0.0), "frames",
                                 frames));
    } else {
        json_decref(frames);
        vf_info("localized %d of %d frames (%.1f frames/s)", localized, total,
                seconds > 0 ? total / seconds : 0.0);
    }
    return 0;
}
