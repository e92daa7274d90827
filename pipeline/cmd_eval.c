/* vfcapture eval: how well the trained radiance field reproduces a posed test set. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "vf/dataset.h"
#include "vf/log.h"
#include "vf/metrics.h"
#include "vf/poses.h"

#define ERROR_GAIN 4.0f /* error images: |render - photo| x 4, so 0.25 off shows white */

static const char usage[] =
    "usage: vfcapture eval WS --transforms PATH/transforms_test.json [--out DIR] [--json]\n"
    "\n"
    "Render every frame of a posed test set (NeRF transforms format, in the workspace's object\n"
    "frame; a posed set's own test set is moved there when the poses stage moved the set)\n"
    "with the trained field of WS at the frame's own resolution and camera, and report\n"
    "PSNR and SSIM per view and on average. Transparent test pixels are composited onto the\n"
    "field's background colour. With --out, the renders and error images are saved there.\n"
    "\n"
    "options:\n"
    "      --transforms PATH  the posed test set\n"
    "      --out DIR          save render_NNN.png and error_NNN.png (|render - photo| x 4)\n" CLI_COMMON_HELP;

enum { OPT_TRANSFORMS = CLI_OPT_FIRST_CUSTOM, OPT_OUT };

typedef struct eval_options {
    const char *workspace, *transforms, *out;
    cli_flags flags;
} eval_options;

static vf_status parse_options(int argc, char **argv, eval_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"transforms", required_argument, NULL, OPT_TRANSFORMS},
        {"out", required_argument, NULL, OPT_OUT},
        {0, 0, 0, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "eval", usage))
            continue;
        if (c == OPT_TRANSFORMS)
            opt->transforms = optarg;
        else if (c == OPT_OUT)
            opt->out = optarg;
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace (see 'vfcapture eval --help')");
    opt->workspace = argv[optind];
    if (!opt->transforms)
        return vf_fail(VF_EINPUT, "give the test set with --transforms PATH");
    return VF_OK;
}

/* Save the render and its error image as DIR/render_NNN.png and DIR/error_NNN.png. */
static vf_status save_view(const char *dir, int index, const vf_image *render,
                           const vf_image *photo)
{
    char path[VF_PATH_MAX];
    vf_image error = {0};
    snprintf(path, sizeof path, "%s/render_%03d.png", dir, index);
    vf_status status = vf_image_save(path, render);
    if (status == VF_OK)
        status = vf_image_error_map(render, photo, ERROR_GAIN, &error);
    snprintf(path, sizeof path, "%s/error_%03d.png", dir, index);
    if (status == VF_OK)
        status = vf_image_save(path, &error);
    vf_image_free(&error);
    return status;
}

static vf_status evaluate(const eval_options *opt, const vf_field *field, const vf_dataset *test,
                          json_t *views, double *mean_psnr, double *mean_ssim)
{
    float bg[3];
    vf_field_background(field, bg);
    double psnr_sum = 0, ssim_sum = 0;
    vf_status status = VF_OK;
    vf_progress progress;
    vf_progress_begin(&progress, "rendering", (size_t)test->count, "views");
    for (int i = 0; i < test->count && status == VF_OK; i++) {
        const vf_frame *frame = &test->frames[i];
        vf_image photo = {0}, render = {0};
        status = vf_image_load_rgb(frame->image_path, bg, &photo);
        if (status == VF_OK)
            status = vf_field_render(field, &frame->camera, frame->c2w, &render);
        if (status == VF_OK && opt->out)
            status = save_view(opt->out, i, &render, &photo);
        if (status == VF_OK) {
            double psnr = vf_image_psnr(&render, &photo), ssim = vf_image_ssim(&render, &photo);
            psnr_sum += psnr;
            ssim_sum += ssim;
            char name[VF_PATH_MAX];
            vf_path_basename(name, sizeof name, frame->image_path, 0);
            json_array_append_new(views, json_pack("{s:s, s:f, s:f}", "image", name, "psnr",
                                                   psnr, "ssim", ssim));
            if (!opt->flags.json)
                printf("  %-28s PSNR %6.2f dB  SSIM %.4f\n", name, psnr, ssim);
        }
        vf_image_free(&photo);
        vf_image_free(&render);
        vf_progress_update(&progress, (size_t)i + 1, NULL);
    }
    if (status == VF_OK)
        vf_progress_end(&progress);
    *mean_psnr = psnr_sum / test->count;
    *mean_ssim = ssim_sum / test->count;
    return status;
}

int cmd_eval(int argc, char **argv)
{
    eval_options opt = {0};
    vf_status status = parse_options(argc, argv, &opt);
    vf_dataset test = {0};
    if (status == VF_OK)
        status = vf_dataset_load(opt.transforms, &test);
    if (status == VF_OK && opt.out)
        status = vf_mkdirs(opt.out);
    vf_workspace ws;
    vf_field *field = NULL;
    if (status == VF_OK)
        status = cli_open_trained(opt.workspace, &ws, &field);
    int moved = 0;
    if (status == VF_OK && (status = vf_poses_move_set_frames(&ws, &test, &moved)) == VF_OK &&
        moved)
        vf_info("%s: moved from the posed set's frame into the object frame of the poses stage",
                opt.transforms);
    if (status != VF_OK) {
        vf_dataset_free(&test);
        return cli_fail("eval", status);
    }
    json_t *views = json_array();
    double psnr = NAN, ssim = NAN;
    status = evaluate(&opt, field, &test, views, &psnr, &ssim);
    if (status == VF_OK && opt.flags.json)
        cli_print_json(json_pack("{s:s, s:i, s:f, s:f, s:O}", "transforms", opt.transforms,
                                 "views", test.count, "psnr", psnr, "ssim", ssim, "per_view",
                                 views));
    else if (status == VF_OK)
        printf("%d views: mean PSNR %.2f dB, SSIM %.4f\n", test.count, psnr, ssim);
    json_decref(views);
    vf_field_free(field);
    vf_workspace_close(&ws);
    vf_dataset_free(&test);
    return status == VF_OK ? 0 : cli_fail("eval", status);
}
