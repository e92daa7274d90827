/* vfcapture transfer: do an attack's viewpoints fool other classifiers too?
 *
 * Re-renders the attack's v* and its 100 samples of p*(v) (from WS/attack/attack.json) for
 * each model's input size (same field of view) and measures, per model, the natural accuracy
 * over the training views, the ASR of R(v*) and the ASR over the samples, with the attack's
 * label set. Writes WS/transfer/transfer.json. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "vf/attack_file.h"
#include "vf/classifier.h"
#include "vf/dataset.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/view_loss.h"

#define MAX_MODELS 16

static const char usage[] =
    "usage: vfcapture transfer WS --models A,B,... [--models-dir DIR] [--json]\n"
    "\n"
    "Measure how the viewpoints found by 'vfcapture attack' transfer to other ImageNet models:\n"
    "for each model, the natural accuracy over the training views, the attack success rate of\n"
    "v* and over the attack's 100 samples of p*(v), with the attack's label set. Models of any\n"
    "input size work (renders keep the field of view). Writes WS/transfer/transfer.json.\n"
    "\n"
    "options:\n"
    "      --models A,B,...   model names (see vfcapture models) or .onnx paths; CNNs and\n"
    "                         transformers may be mixed\n"
    "      --models-dir DIR   look for model names here first\n" CLI_ENGINE_HELP CLI_COMMON_HELP;

enum { OPT_MODELS = CLI_OPT_FIRST_CUSTOM, OPT_MODELS_DIR };

typedef struct transfer_options {
    const char *workspace, *models, *models_dir;
    cli_flags flags;
} transfer_options;

static vf_status parse_options(int argc, char **argv, transfer_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
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
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture transfer --help')");
    opt->workspace = argv[optind];
    if (!opt->models || !opt->models[0])
        return vf_fail(VF_EINPUT, "give the models to test with --models A,B,...");
    return VF_OK;
}

/* Resolve every model name first, so a typo fails before any work. */
static vf_status find_models(const transfer_options *opt, char paths[][VF_PATH_MAX], int *count)
{
    char buf[4096];
    if (snprintf(buf, sizeof buf, "%s", opt->models) >= (int)sizeof buf)
        return vf_fail(VF_EINPUT, "--models is too long");
    *count = 0;
    char *save = NULL;
    for (char *name = strtok_r(buf, ",", &save); name; name = strtok_r(NULL, ",", &save)) {
        if (*count == MAX_MODELS)
            return vf_fail(VF_EINPUT, "at most %d models at a time", MAX_MODELS);
        vf_status s = vf_find_model(name, opt->models_dir, paths[*count], VF_PATH_MAX);
        if (s != VF_OK)
            return s;
        (*count)++;
    }
    return *count ? VF_OK : vf_fail(VF_EINPUT, "--models names no model");
}

static double fooled_rate(const vf_view_prediction *p, int n)
{
    int fooled = 0;
    for (int i = 0; i < n; i++)
        fooled += !p[i].correct;
    return (double)fooled / n;
}

/* One model: natural accuracy, ASR of v*, ASR over the samples, as a JSON row. */
static vf_status measure_model(const char *model, const vf_field *field, const double *c2w,
                               int views, const vf_attack_file *r, json_t **row)
{
    vf_classifier *cls = NULL;
    vf_view_loss *vl = NULL;
    vf_view_prediction *pred = malloc((size_t)(views > r->sample_count ? views : r->sample_count) *
                                      sizeof *pred);
    vf_view_prediction star;
    vf_status s = pred ? vf_classifier_open(model, &cls) : vf_fail(VF_EINTERNAL, "out of memory");
    if (s == VF_OK)
        s = vf_view_loss_create(field, cls, &vl);
    if (s == VF_OK)
        s = vf_view_loss_set_labels(vl, r->labels, r->label_count);
    double natural = 0, asr = 0;
    if (s == VF_OK && (s = vf_view_loss_classify_poses(vl, c2w, views, pred)) == VF_OK)
        natural = 1 - fooled_rate(pred, views);
    if (s == VF_OK)
        s = vf_view_loss_classify(vl, r->samples, r->sample_count, pred, NULL);
    if (s == VF_OK)
        asr = fooled_rate(pred, r->sample_count);
    if (s == VF_OK) {
        double v_star[VF_VIEW_DIM];
        vf_viewpoint_to_array(&r->v_star, v_star);
        s = vf_view_loss_classify(vl, v_star, 1, &star, NULL);
    }
    if (s == VF_OK)
        *row = json_pack("{s:s, s:s, s:i, s:f, s:f, s:f, s:o}", "model", model, "engine",
                         vf_classifier_engine(cls), "input_size",
                         vf_classifier_input_size(cls), "natural_accuracy", natural, "asr_samples",
                         asr, "asr_v_star", star.correct ? 0.0 : 1.0, "v_star_prediction",
                         vf_view_prediction_to_json(&star));
    vf_view_loss_free(vl);
    vf_classifier_close(cls);
    free(pred);
    return s;
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
    static char models[MAX_MODELS][VF_PATH_MAX];
    int model_count = 0;
    vf_workspace ws = {0};
    vf_field *field = NULL;
    vf_dataset natural = {0};
    double *c2w = NULL;
    vf_attack_file r = {0};
    json_t *rows = json_array();
    vf_stage stage;
    vf_status s = find_models(opt, models, &model_count);
    if (s == VF_OK)
        s = vf_class_names_load();
    if (s == VF_OK)
        s = cli_open_trained(opt->workspace, &ws, &field);
    if (s == VF_OK)
        s = vf_attack_file_load_workspace(&ws, &r);
    if (s == VF_OK && r.sample_count < 1)
        s = vf_fail(VF_EINPUT, "%s/attack/attack.json has no samples: run the attack again",
                    ws.root);
    if (s == VF_OK && (s = vf_dataset_load_training(&ws, &natural, NULL)) == VF_OK &&
        !(c2w = vf_dataset_poses(&natural)))
        s = vf_fail(VF_EINTERNAL, "out of memory");
    vf_progress progress;
    vf_progress_begin(&progress, "transfer", (size_t)model_count, "models");
    for (int m = 0; m < model_count && s == VF_OK; m++) {
        json_t *row = NULL;
        s = measure_model(models[m], field, c2w, natural.count, &r, &row);
        if (s == VF_OK)
            json_array_append_new(rows, row);
        vf_progress_update(&progress, (size_t)m + 1, NULL);
    }
    if (s == VF_OK)
        vf_progress_end(&progress);
    char path[VF_PATH_MAX];
    json_t *doc = NULL;
    if (s == VF_OK && (s = vf_stage_begin(&ws, "transfer", &stage)) == VF_OK) {
        doc = json_pack("{s:s, s:O, s:i, s:O}", "attack_model", r.model, "label", r.label,
                        "samples", r.sample_count, "models", rows);
        s = vf_path_join(path, sizeof path, stage.dir, "transfer.json");
        if (s == VF_OK)
            s = vf_json_save(path, doc);
        if (s == VF_OK)
            s = vf_stage_commit(&stage, json_pack("{s:s}", "models", opt->models), NULL);
        else
            vf_stage_abort(&stage);
    }
    if (s == VF_OK) {
        if (opt->flags.json)
            cli_print_json(json_incref(doc));
        else
            print_table(rows);
    }
    json_decref(doc);
    json_decref(rows);
    vf_attack_file_free(&r);
    vf_dataset_free(&natural);
    free(c2w);
    vf_field_free(field);
    vf_workspace_close(&ws);
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
