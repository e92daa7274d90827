/* vfcapture real: the attack's viewpoints checked against the object itself (a workspace made
 * from a 3D model, or filmed by the studio). The work is vf_real_run (vf/object3d.h); this
 * parses and prints. */
#include <math.h>
#include <stdio.h>

#include "cli.h"
#include "vf/object3d.h"
#include "vf/real.h"
#include "vf/resources.h"
#include "vf/studio.h"

static const char usage[] =
    "usage: vfcapture real WS [--model NAME|PATH] [--fluctuation-samples N] [--natural-views N]\n"
    "                         [--seed S] [--attack NAME] [--json]\n"
    "\n"
    "For a workspace made from a 3D model (vfcapture ingest MODEL.glb) or filmed by the studio\n"
    "(vfcapture simulate capture: its truth file places the model), after attack: render\n"
    "the model itself with Blender, with the classifier's camera, at v*, at the attack's samples\n"
    "of p*(v), at fluctuation points around v* and at natural training views, and classify\n"
    "them beside the field's renders at the same cameras. Reports the paper's Real(v*) and\n"
    "Real(p*(v)) beside the rendered ASR, both fluctuation curves and both natural accuracies.\n"
    "Writes WS/real/NAME/ for the attack NAME: real.json, sheet.png (field | object for v* and\n"
    "samples), fluctuation.png and the object's renders. An interrupted run continues where it\n"
    "stopped.\n"
    "\n"
    "options:\n"
    "  -m, --model NAME|PATH  classifier (default: the one the attack used)\n"
    "      --models-dir DIR   look for model names here first\n"
    "      --fluctuation-samples N\n"
    "                         viewpoints a fluctuation level r = 1..10% (default 20)\n"
    "      --natural-views N  training views checked, spread over them (default 100)\n"
    "      --seed S           draws of the fluctuation boxes (default 0)\n" CLI_ATTACK_HELP
        CLI_ENGINE_HELP CLI_COMMON_HELP;

enum { OPT_MODELS_DIR = CLI_OPT_FIRST_CUSTOM, OPT_FLUCT, OPT_NATURAL, OPT_SEED };

typedef struct real_options {
    const char *workspace;
    vf_real_options real;
    cli_flags flags;
} real_options;

static vf_status parse_options(int argc, char **argv, real_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        CLI_ATTACK_OPTION,
        {"model", required_argument, NULL, 'm'},
        {"models-dir", required_argument, NULL, OPT_MODELS_DIR},
        {"fluctuation-samples", required_argument, NULL, OPT_FLUCT},
        {"natural-views", required_argument, NULL, OPT_NATURAL},
        {"seed", required_argument, NULL, OPT_SEED},
        {0, 0, 0, 0},
    };
    vf_real_defaults(&opt->real);
    int c;
    long n;
    vf_status s = VF_OK;
    while (s == VF_OK &&
           (c = getopt_long(argc, argv, CLI_COMMON_SHORT "m:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "real", usage))
            continue;
        if (c == 'm')
            opt->real.classifier = optarg;
        else if (c == OPT_MODELS_DIR)
            opt->real.models_dir = optarg;
        else if (c == CLI_OPT_ATTACK)
            opt->real.attack = optarg;
        else if (c == OPT_FLUCT && (s = cli_count("--fluctuation-samples", optarg, 1, 1000, &n)) == VF_OK)
            opt->real.fluctuation_samples = (int)n;
        else if (c == OPT_NATURAL && (s = cli_count("--natural-views", optarg, 1, 100000, &n)) == VF_OK)
            opt->real.natural_views = (int)n;
        else if (c == OPT_SEED)
            s = cli_seed("--seed", optarg, &opt->real.seed);
    }
    if (s != VF_OK)
        return s;
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace (see vfcapture real --help)");
    opt->workspace = argv[optind];
    return VF_OK;
}

static double side(const json_t *doc, const char *key, const char *which)
{
    return json_number_value(json_object_get(json_object_get(doc, key), which));
}

static void print_result(const real_options *opt, const json_t *doc)
{
    printf("object %s, classifier %s, label set {%s}\n",
           json_string_value(json_object_get(doc, "object")),
           json_string_value(json_object_get(doc, "classifier")),
           json_string_value(json_object_get(doc, "label")));
    printf("                      rendered (field)   real (object)\n");
    printf("natural accuracy      %6.0f%%            %6.0f%%   (%lld training views)\n",
           100 * side(doc, "natural_accuracy", "field"), 100 * side(doc, "natural_accuracy", "real"),
           json_integer_value(json_object_get(doc, "natural_views")));
    printf("ASR of R(v*)          %6.0f%%            %6.0f%%\n", 100 * side(doc, "asr_v_star", "field"),
           100 * side(doc, "asr_v_star", "real"));
    printf("ASR of R(p*(v))       %6.0f%%            %6.0f%%   (%lld samples)\n",
           100 * side(doc, "asr_samples", "field"), 100 * side(doc, "asr_samples", "real"),
           json_integer_value(json_object_get(doc, "samples")));
    const json_t *fl = json_object_get(doc, "fluctuation");
    const char *rows[2] = {"field", "real"};
    for (int k = 0; k < 2; k++) {
        printf("fluctuation %-6s    ", rows[k]);
        const json_t *curve = json_object_get(fl, rows[k]);
        for (size_t i = 0; i < json_array_size(curve); i++)
            printf(" %3.0f", 100 * json_number_value(json_array_get(curve, i)));
        printf("   (%% at r = 1..10%%)\n");
    }
    printf("top-1 agreement field/object: %.0f%% of all cameras, %.0f%% of natural views\n",
           100 * json_number_value(json_object_get(doc, "agreement")),
           100 * json_number_value(json_object_get(doc, "agreement_natural")));
    const json_t *psnr = json_object_get(doc, "psnr");
    printf("field against object (PSNR): v* %.1f dB, samples %.1f dB, natural views %.1f dB\n",
           json_number_value(json_object_get(psnr, "v_star")),
           json_number_value(json_object_get(psnr, "samples")),
           json_number_value(json_object_get(psnr, "natural")));
    printf("written: %s/real/{real.json, sheet.png, fluctuation.png, renders/}\n", opt->workspace);
}

int cmd_real(int argc, char **argv)
{
    real_options opt = {0};
    vf_workspace ws;
    json_t *doc = NULL;
    vf_status s = parse_options(argc, argv, &opt);
    if (s == VF_OK && !vf_is_dir(opt.workspace))
        s = vf_fail(VF_EINPUT, "workspace %s does not exist", opt.workspace);
    if (s == VF_OK && (s = vf_workspace_open(opt.workspace, 0, &ws)) == VF_OK) {
        vf_object3d filmed_object;
        vf_similarity to_object;
        int filmed = 0;
        s = vf_studio_object(&ws, &filmed_object, &to_object, &filmed);
        if (filmed) {
            opt.real.object = &filmed_object;
            opt.real.to_object = &to_object;
        }
        if (s == VF_OK)
            s = vf_real_run(&ws, &opt.real, &doc);
        vf_workspace_close(&ws);
    }
    if (s != VF_OK)
        return cli_fail("real", s);
    if (opt.flags.json) {
        json_object_del(doc, "views");
        cli_print_json(doc);
    } else {
        print_result(&opt, doc);
        json_decref(doc);
    }
    return 0;
}
