/* vfcapture transfer: parse the options, resolve the model names, run the transfer stage
 * (vf/transfer.h), print its table. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "vf/classifier.h"
#include "vf/resources.h"
#include "vf/transfer.h"


static const char usage[] =
    "usage: vfcapture transfer WS --models A,B,... [--models-dir DIR] [--attack NAME] [--json]\n"
    "\n"
    "Measure how the viewpoints found by 'vfcapture attack' transfer to other ImageNet models:\n"
    "for each model, the natural accuracy over the training views, the attack success rate of\n"
    "v* and over the attack's 100 samples of p*(v), with the attack's label set. Models of any\n"
    "input size work (renders keep the field of view). Writes WS/transfer/NAME/transfer.json\n"
    "for the attack NAME.\n"
    "\n"
    "options:\n"
    "      --models A,B,...   model names (see vfcapture models) or .onnx paths, or 'all' for\n"
    "                         every model found; CNNs and transformers may be mixed\n"
    "      --models-dir DIR   look for model names here first\n" CLI_ATTACK_HELP CLI_ENGINE_HELP
        CLI_COMMON_HELP;

enum { OPT_MODELS = CLI_OPT_FIRST_CUSTOM, OPT_MODELS_DIR };

typedef struct transfer_options {
    const char *workspace, *models, *models_dir, *attack;
    cli_flags flags;
} transfer_options;

static vf_status parse_options(int argc, char **argv, transfer_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        CLI_ATTACK_OPTION,
        {"models", required_argument, NULL, OPT_MODELS},
        {"models-dir", required_argument, NULL, OPT_MODELS_DIR},
        {0, 0, 0, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "transfer", usage))
            continue;
        if (c == OPT_MODELS)
            opt->models = optarg;
        else if (c == OPT_MODELS_DIR)
            opt->models_dir = optarg;
        else if (c == CLI_OPT_ATTACK)
            opt->attack = optarg;
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture transfer --help')");
    opt->workspace = argv[optind];
    if (!opt->models || !opt->models[0])
        return vf_fail(VF_EINPUT, "give the models to test with --models A,B,...");
    return VF_OK;
}

static void print_table(const json_t *rows)
{
    printf("%-36s %5s %9s %10s %10s  %s\n", "model", "input", "natural", "ASR R(v*)",
           "ASR p*(v)", "v* seen as");
    size_t i;
    json_t *row;
    json_array_foreach(rows, i, row) {
        char name[VF_PATH_MAX];
        vf_path_basename(name, sizeof name, json_string_value(json_object_get(row, "model")), 1);
        json_t *star = json_object_get(row, "v_star_prediction");
        printf("%-36s %5d %8.0f%% %9.0f%% %9.0f%%  %s %.0f%%\n", name,
               (int)json_integer_value(json_object_get(row, "input_size")),
               100 * json_number_value(json_object_get(row, "natural_accuracy")),
               100 * json_number_value(json_object_get(row, "asr_v_star")),
               100 * json_number_value(json_object_get(row, "asr_samples")),
               json_string_value(json_object_get(star, "name")),
               100 * json_number_value(json_object_get(star, "confidence")));
    }
}

static vf_status run(const transfer_options *opt)
{
    static char models[CLI_MAX_MODELS][VF_PATH_MAX];
    char *paths[CLI_MAX_MODELS];
    int model_count = 0;
    json_t *doc = NULL;
    vf_status s = cli_models("--models", opt->models, opt->models_dir, models, CLI_MAX_MODELS,
                             &model_count);
    for (int m = 0; m < model_count; m++)
        paths[m] = models[m];
    vf_workspace ws = {0};
    if (s == VF_OK)
        s = vf_workspace_open(opt->workspace, 0, &ws);
    if (s == VF_OK)
        s = vf_transfer_run(&ws, opt->attack, paths, model_count, &doc);
    vf_workspace_close(&ws);
    if (s == VF_OK && opt->flags.json)
        cli_print_json(json_incref(doc));
    else if (s == VF_OK)
        print_table(json_object_get(doc, "models"));
    json_decref(doc);
    return s;
}

int cmd_transfer(int argc, char **argv)
{
    transfer_options opt = {0};
    vf_status status = parse_options(argc, argv, &opt);
    if (status == VF_OK)
        status = run(&opt);
    return status == VF_OK ? 0 : cli_fail("transfer", status);
}
