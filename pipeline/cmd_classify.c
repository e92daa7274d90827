/* vfcapture classify: an ImageNet model's top classes for some images.
 *
 * A quick check of what a classifier sees in photos or renders, and of the model and class
 * names themselves. Images are checked (header only) before the model loads, then decoded
 * and classified a batch at a time so memory stays flat for long lists. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "vf/classifier.h"
#include "vf/fsutil.h"
#include "vf/image.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/resources.h"

#define CLASSIFY_CHUNK 16

static const char usage[] =
    "usage: vfcapture classify IMAGE... [--model NAME|PATH] [--models-dir DIR] [--top K]\n"
    "                          [--label SET] [--json]\n"
    "\n"
    "Classify images with an ImageNet-1k model and print, for each, its most probable\n"
    "classes (index, probability, name). Transparent pixels are composited onto white.\n"
    "With --label, also say whether each top-1 is in the true label set, and the accuracy.\n"
    "\n"
    "options:\n"
    "  -m, --model NAME|PATH  model name (see vfcapture models) or an .onnx file\n"
    "                         (default " VF_DEFAULT_MODEL ")\n"
    "      --models-dir DIR   look for model names here first\n"
    "  -k, --top K            classes to show per image, 1..1000 (default 5)\n"
    "  -l, --label SET        true classes: indices and/or names, comma-separated\n"
    "                         (\"folding chair, rocking chair\" or \"559,765\"); a top-1 in\n"
    "                         the set counts as correct\n" CLI_ENGINE_HELP CLI_COMMON_HELP;

enum { OPT_MODELS_DIR = CLI_OPT_FIRST_CUSTOM };

typedef struct classify_options {
    const char *model;
    const char *models_dir;
    int top;
    int labels[VF_MAX_LABELS];
    int label_count; /* 0: no --label */
    char **images;
    int image_count;
    cli_flags flags;
} classify_options;

static vf_status parse_options(int argc, char **argv, classify_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        {"model", required_argument, NULL, 'm'},
        {"models-dir", required_argument, NULL, OPT_MODELS_DIR},
        {"top", required_argument, NULL, 'k'},
        {"label", required_argument, NULL, 'l'},
        {0, 0, 0, 0},
    };
    int c;
    long top;
    const char *label_text = NULL;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT "m:k:l:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "classify", usage))
            continue;
        if (c == 'm')
            opt->model = optarg;
        else if (c == OPT_MODELS_DIR)
            opt->models_dir = optarg;
        else if (c == 'k' && cli_count("--top", optarg, 1, VF_NUM_CLASSES, &top) != VF_OK)
            return VF_EINPUT;
        else if (c == 'k')
            opt->top = (int)top;
        else if (c == 'l')
            label_text = optarg;
    }
    if (label_text) {
        vf_status status = vf_parse_label_set(label_text, opt->labels, VF_MAX_LABELS, &opt->label_count);
        if (status != VF_OK)
            return status;
    }
    if (optind == argc)
        return vf_fail(VF_EINPUT, "give at least one image (see 'vfcapture classify --help')");
    opt->images = argv + optind;
    opt->image_count = argc - optind;
    return VF_OK;
}

/* Fail early, before the model loads, on a missing or unreadable image. */
static vf_status check_images(const classify_options *opt)
{
    for (int i = 0; i < opt->image_count; i++) {
        int w, h, channels;
        vf_status status = vf_image_info(opt->images[i], &w, &h, &channels);
        if (status != VF_OK)
            return status;
    }
    return VF_OK;
}

static json_t *top_json(const int *idx, const float *p, int k)
{
    json_t *list = json_array();
    for (int j = 0; j < k; j++)
        json_array_append_new(list, json_pack("{s:i, s:s, s:o}", "class", idx[j], "name",
                                              vf_class_name(idx[j]), "probability",
                                              vf_json_number((double)p[j])));
    return list;
}

static void print_top(const char *image, const int *idx, const float *p, int k,
                      const char *verdict)
{
    printf("%s%s\n", image, verdict);
    for (int j = 0; j < k; j++)
        printf("  %4d  %6.2f%%  %s\n", idx[j], 100.0 * p[j], vf_class_name(idx[j]));
}

/* Load n images as RGB on white and classify them into probs (n * VF_NUM_CLASSES). */
static vf_status classify_chunk(vf_classifier *cls, char **paths, int n, float *probs)
{
    static const float white[3] = {1, 1, 1};
    vf_image images[CLASSIFY_CHUNK] = {{0}};
    vf_status status = VF_OK;
    for (int i = 0; i < n && status == VF_OK; i++)
        status = vf_image_load_rgb(paths[i], white, &images[i]);
    if (status == VF_OK)
        status = vf_classifier_classify_images(cls, images, n, probs);
    for (int i = 0; i < n; i++)
        vf_image_free(&images[i]);
    return status;
}

/* Classify every image, printing text as it goes or adding to the JSON list. */
static vf_status classify_all(vf_classifier *cls, const classify_options *opt, json_t *list,
                              int *correct)
{
    float *probs = malloc(CLASSIFY_CHUNK * VF_NUM_CLASSES * sizeof(float));
    int *idx = malloc((size_t)opt->top * sizeof(int));
    float *p = malloc((size_t)opt->top * sizeof(float));
    vf_status status = probs && idx && p ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    int show_progress = opt->image_count > CLASSIFY_CHUNK;
    vf_progress progress;
    vf_progress_begin(&progress, "classifying", (size_t)opt->image_count, "images");
    for (int first = 0; first < opt->image_count && status == VF_OK; first += CLASSIFY_CHUNK) {
        int n = opt->image_count - first;
        n = n < CLASSIFY_CHUNK ? n : CLASSIFY_CHUNK;
        status = classify_chunk(cls, opt->images + first, n, probs);
        for (int i = 0; i < n && status == VF_OK; i++) {
            vf_topk(probs + (size_t)i * VF_NUM_CLASSES, opt->top, idx, p);
            const char *image = opt->images[first + i];
            int right = vf_label_set_contains(opt->labels, opt->label_count, idx[0]);
            *correct += right;
            const char *verdict = !opt->label_count ? "" : right ? "  (correct)" : "  (WRONG)";
            if (list) {
                json_t *entry = json_pack("{s:s, s:o}", "image", image, "top",
                                          top_json(idx, p, opt->top));
                if (opt->label_count)
                    json_object_set_new(entry, "correct", json_boolean(right));
                json_array_append_new(list, entry);
            } else {
                print_top(image, idx, p, opt->top, verdict);
            }
        }
        if (show_progress)
            vf_progress_update(&progress, (size_t)(first + n), NULL);
    }
    if (show_progress && status == VF_OK)
        vf_progress_end(&progress);
    free(probs);
    free(idx);
    free(p);
    return status;
}

static vf_status run(const classify_options *opt)
{
    char model_path[VF_PATH_MAX];
    vf_status status = check_images(opt);
    if (status == VF_OK)
        status = vf_find_model(opt->model, opt->models_dir, model_path, sizeof model_path);
    if (status == VF_OK)
        status = vf_class_names_load();
    vf_classifier *cls = NULL;
    if (status == VF_OK)
        status = vf_classifier_open(model_path, &cls);
    if (status != VF_OK)
        return status;
    int size = vf_classifier_input_size(cls);
    vf_info("model %s (input %dx%d, %s)", model_path, size, size, vf_classifier_engine(cls));
    json_t *list = opt->flags.json ? json_array() : NULL;
    int correct = 0;
    status = classify_all(cls, opt, list, &correct);
    char engine[64];
    snprintf(engine, sizeof engine, "%s", vf_classifier_engine(cls));
    vf_classifier_close(cls);
    double accuracy = (double)correct / opt->image_count;
    if (status == VF_OK && opt->label_count && !list)
        printf("top-1 accuracy: %d of %d (%.1f%%)\n", correct, opt->image_count, 100 * accuracy);
    if (status == VF_OK && list) {
        json_t *doc = json_pack("{s:s, s:s, s:i, s:o}", "model", model_path, "engine", engine,
                                "input_size", size, "images", list);
        if (opt->label_count)
            json_object_set_new(doc, "accuracy", vf_json_number(accuracy));
        cli_print_json(doc);
    } else {
        json_decref(list);
    }
    return status;
}

int cmd_classify(int argc, char **argv)
{
    classify_options opt = {.top = 5};
    vf_status status = parse_options(argc, argv, &opt);
    if (status == VF_OK)
        status = run(&opt);
    return status == VF_OK ? 0 : cli_fail("classify", status);
}
