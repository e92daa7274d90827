/* vfcapture eval: how well the trained radiance field reproduces a posed test set. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "vf/cutout.h"
#include "vf/dataset.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/poses.h"
#include "vf/train.h"


static const char usage[] =
    "usage: vfcapture eval WS --transforms PATH/transforms_test.json [-o DIR] [--json]\n"
    "\n"
    "Render every frame of a posed test set (NeRF transforms format, in the workspace's object\n"
    "frame; a posed set's own test set is moved there when the poses stage moved the set)\n"
    "with the trained field of WS at the frame's own resolution and camera, and report\n"
    "PSNR and SSIM per view and on average. Transparent test pixels are composited onto the\n"
    "field's background colour. Where WS has the sparse points of 'vfcapture poses', each\n"
    "render is also checked for the object where its photo shows it (the overlap of the\n"
    "photo's cut-out with the render's surfaces at the object; under 0.5: missing, as train\n"
    "checks its held-out views). With -o, the renders and error images are saved there.\n"
    "\n"
    "options:\n"
    "      --transforms PATH  the posed test set\n"
    "  -o, --output DIR       save render_NNN.png and error_NNN.png (|render - photo| x 4)\n" CLI_COMMON_HELP;

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
        {"output", required_argument, NULL, 'o'},
        {"out", required_argument, NULL, OPT_OUT}, /* before -o was the output everywhere */
        {0, 0, 0, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "eval", usage))
            continue;
        if (c == OPT_TRANSFORMS)
            opt->transforms = optarg;
        else if (c == 'o' || c == OPT_OUT)
            opt->out = optarg;
        if (c == OPT_OUT)
            cli_deprecated("eval", "--out", "-o/--output");
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace (see 'vfcapture eval --help')");
    opt->workspace = argv[optind];
    if (!opt->transforms)
        return vf_fail(VF_EINPUT, "give the test set with --transforms PATH");
    return VF_OK;
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
    vf_photo_scores scores;
    vf_object_points object = {0};
    vf_train_object_points(&ws, field, &test, &object);
    status = vf_field_score_photos(
        field, &test,
        &(vf_photo_scoring){.save_dir = opt.out, .object = object.count ? &object : NULL}, views,
        &scores);
    vf_object_points_free(&object);
    if (status == VF_OK && opt.flags.json) {
        cli_print_json(json_pack("{s:s, s:i, s:o, s:o, s:o, s:i, s:O}", "transforms",
                                 opt.transforms, "views", test.count, "psnr",
                                 vf_json_number(scores.psnr), "ssim", vf_json_number(scores.ssim),
                                 "object_iou_mean", vf_json_number(scores.object_iou_mean),
                                 "object_missing", scores.object_missing, "per_view", views));
    } else if (status == VF_OK) {
        size_t i;
        json_t *v;
        json_array_foreach(views, i, v)
        {
            const json_t *iou = json_object_get(v, "object_iou");
            printf("  %-28s PSNR %6.2f dB  SSIM %.4f",
                   json_string_value(json_object_get(v, "image")),
                   json_number_value(json_object_get(v, "psnr")),
                   json_number_value(json_object_get(v, "ssim")));
            if (json_is_number(iou))
                printf("  object %.2f%s", json_number_value(iou),
                       json_number_value(iou) < VF_OBJECT_PRESENT_IOU ? " (missing)" : "");
            printf("\n");
        }
        printf("%d views: mean PSNR %.2f dB, SSIM %.4f\n", test.count, scores.psnr, scores.ssim);
        if (scores.object_checked)
            printf("the object is in %d of %d renders (overlap with the photo's cut-out %.2f on "
                   "average)\n",
                   scores.object_checked - scores.object_missing, scores.object_checked,
                   scores.object_iou_mean);
    }
    json_decref(views);
    vf_field_free(field);
    vf_workspace_close(&ws);
    vf_dataset_free(&test);
    return status == VF_OK ? 0 : cli_fail("eval", status);
}
