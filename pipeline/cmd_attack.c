/* vfcapture attack: parse the options, run the attack stage (vf/attack.h), print what it
 * found. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "vf/attack.h"
#include "vf/attack_eval.h"
#include "vf/classifier.h"
#include "vf/resources.h"

static const char usage[] =
    "usage: vfcapture attack WS [--model NAME|PATH] [--label L1,L2,...]\n"
    "                       [--method nes|pepg|random] [--lambda X] [--samples K] [--steps N] "
    "[--components K]\n"
    "                       [--space rotation|translation|both] [--bounds name=lo:hi,...]\n"
    "                       [--trust-gap DEG] [--seed S] [--attack NAME] [--restart] [--json]\n"
    "\n"
    "Find the viewpoints from which the classifier misreads the object (ViewFool, Dong et al.,\n"
    "NeurIPS 2022): learn a distribution p(v) over viewpoints v = (psi, theta, phi in degrees,\n"
    "dx, dy, dz in scene units) that maximizes the cross-entropy of the true label set on\n"
    "renders of the trained field, plus lambda times its entropy. Writes WS/attack/NAME/:\n"
    "attack.json, v_star.png, samples.png, loss.png and fluctuation.png. A workspace keeps\n"
    "several attacks side by side; NAME is made of the model, the method, lambda and the\n"
    "space (mobilenet_v2_1.0_224_quant-nes-l0.01-both) unless --attack gives it.\n"
    "\n"
    "options:\n"
    "  -m, --model NAME|PATH  ImageNet classifier (default " VF_DEFAULT_MODEL ")\n"
    "      --models-dir DIR   look for model names here first\n"
    "  -l, --label L1,L2,...  true label set: class indices or names; a view counts as correct\n"
    "                         when the top-1 is any of them (default: the majority top-1 of\n"
    "                         renders at the training poses)\n"
    "      --method M         nes (the paper's Eq. 7: natural-gradient NES with the entropy\n"
    "                         term, default), pepg (the reference code's optimizer) or\n"
    "                         random (the baseline: 100 uniform viewpoints)\n"
    "      --lambda X         entropy weight (default 0.01): larger keeps p*(v) wider, 0 lets\n"
    "                         it shrink to a point\n"
    "      --samples K        viewpoints a step (default 50; pepg 51, the mean and 25 pairs)\n"
    "      --steps N          optimization steps (default 100)\n"
    "      --components K     mixture of K Gaussians, 1..8 (nes only; default 1)\n"
    "      --space S          rotation (only the angles move), translation (only the\n"
    "                         offsets) or both (default); the fixed ones stay at the training\n"
    "                         view the classifier recognises best\n"
    "      --bounds B         per-parameter box, e.g. psi=-90:90,phi=100:160 (parameters psi,\n"
    "                         theta, phi, dx, dy, dz). Default: psi -180:180, theta -30:30,\n"
    "                         phi 20:160, dx -0.5:0.5, dy -1:1, dz -0.5:0.5; for a real capture\n"
    "                         (poses stage) the range its photos cover\n"
    "      --trust-gap DEG    search only where the field can be trusted: a viewpoint more\n"
    "                         than DEG from every photo (angle seen from the object, distance\n"
    "                         ratio counted as an angle) is not rendered, never counts as\n"
    "                         fooled and pushes the search back (default 20; 0 switches it\n"
    "                         off). attack.json's \"trust\" gives v*'s gap\n"
    "      --seed S           random seed (default 0): the same seed gives the same result\n"
    "      --attack NAME      the attack's name (default: model-method-lLAMBDA-space); the\n"
    "                         same name again replaces that attack\n"
    "      --restart          discard an interrupted attack (by default a run with the same\n"
    "                         settings continues it from its last step)\n" CLI_ENGINE_HELP
        CLI_COMMON_HELP;

enum {
    OPT_MODELS_DIR = CLI_OPT_FIRST_CUSTOM,
    OPT_METHOD,
    OPT_LAMBDA,
    OPT_COMPONENTS,
    OPT_SPACE,
    OPT_BOUNDS,
    OPT_SEED,
    OPT_RESTART,
    OPT_SAMPLES,
    OPT_STEPS,
    OPT_TRUST_GAP,
};

typedef struct attack_cli {
    const char *workspace;
    vf_attack_options attack;
    cli_flags flags;
} attack_cli;

static vf_status parse_options(int argc, char **argv, attack_cli *cli)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        CLI_ATTACK_OPTION,
        {"model", required_argument, NULL, 'm'},
        {"models-dir", required_argument, NULL, OPT_MODELS_DIR},
        {"label", required_argument, NULL, 'l'},
        {"method", required_argument, NULL, OPT_METHOD},
        {"lambda", required_argument, NULL, OPT_LAMBDA},
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"steps", required_argument, NULL, OPT_STEPS},
        {"components", required_argument, NULL, OPT_COMPONENTS},
        {"space", required_argument, NULL, OPT_SPACE},
        {"bounds", required_argument, NULL, OPT_BOUNDS},
        {"seed", required_argument, NULL, OPT_SEED},
        {"restart", no_argument, NULL, OPT_RESTART},
        {"trust-gap", required_argument, NULL, OPT_TRUST_GAP},
        {0, 0, 0, 0},
    };
    vf_attack_options *o = &cli->attack;
    int c;
    vf_status s = VF_OK;
    while (s == VF_OK &&
           (c = getopt_long(argc, argv, CLI_COMMON_SHORT "m:l:k:n:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &cli->flags, "attack", usage))
            continue;
        switch (c) {
        case 'm': o->model = optarg; break;
        case OPT_MODELS_DIR: o->models_dir = optarg; break;
        case 'l': o->label = optarg; break;
        case OPT_METHOD:
            if (vf_attack_search_parse(optarg, &o->method) != VF_OK)
                s = vf_fail(VF_EINPUT, "--method must be nes, pepg or random, not '%s'", optarg);
            break;
        case OPT_LAMBDA: s = cli_number("--lambda", optarg, 0, 1e6, &o->lambda); break;
        case 'k': cli_deprecated("attack", "-k", "--samples"); /* fall through */
        case OPT_SAMPLES: s = cli_count_int("--samples", optarg, 2, 100000, &o->samples); break;
        case 'n': cli_deprecated("attack", "-n", "--steps"); /* fall through */
        case OPT_STEPS: s = cli_count_int("--steps", optarg, 0, 100000, &o->steps); break;
        case OPT_COMPONENTS:
            s = cli_count_int("--components", optarg, 1, VF_ATTACK_MAX_COMPONENTS,
                              &o->components);
            break;
        case OPT_SPACE:
            if (vf_view_space_parse(optarg, &o->space) != VF_OK)
                s = vf_fail(VF_EINPUT, "--space must be rotation, translation or both, not '%s'",
                            optarg);
            break;
        case OPT_BOUNDS: o->bounds = optarg; break;
        case OPT_SEED: s = cli_seed("--seed", optarg, &o->seed); break;
        case OPT_RESTART: o->restart = 1; break;
        case OPT_TRUST_GAP: s = cli_number("--trust-gap", optarg, 0, 180, &o->trust_gap); break;
        case CLI_OPT_ATTACK: o->name = optarg; break;
        default: break;
        }
    }
    if (s != VF_OK)
        return s;
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture attack --help')");
    cli->workspace = argv[optind];
    if (o->components > 1 && o->method != VF_SEARCH_NES)
        return vf_fail(VF_EINPUT, "--components needs --method nes");
    return VF_OK;
}

static double number(const json_t *doc, const char *key)
{
    return json_number_value(json_object_get(doc, key));
}

static const char *class_of(const json_t *prediction)
{
    return json_string_value(json_object_get(prediction, "name")) ?: "?";
}

/* The six numbers of a viewpoint-sized array, formatted with the given precisions. */
static void print_six(const char *fmt, const json_t *a)
{
    double x[VF_VIEW_DIM] = {0};
    for (int i = 0; i < VF_VIEW_DIM; i++)
        x[i] = json_number_value(json_array_get(a, (size_t)i));
    printf(fmt, x[0], x[1], x[2], x[3], x[4], x[5]);
}

static void print_summary(const attack_cli *cli, const json_t *doc)
{
    const json_t *label = json_object_get(doc, "label");
    const json_t *names = json_object_get(label, "names");
    int random = cli->attack.method == VF_SEARCH_RANDOM;
    printf("label set {");
    for (size_t i = 0; i < json_array_size(names); i++)
        printf("%s%s", i ? ", " : "", json_string_value(json_array_get(names, i)));
    printf("}%s; natural accuracy %.0f%% over %lld training views\n",
           json_is_true(json_object_get(label, "proposed")) ? " (proposed)" : "",
           100 * number(doc, "natural_accuracy"),
           json_integer_value(json_object_get(doc, "natural_views")));
    const json_t *star = json_object_get(doc, "v_star_prediction");
    print_six("v* = psi %.1f, theta %.1f, phi %.1f deg, dx %.3f, dy %.3f, dz %.3f",
              json_object_get(doc, "v_star"));
    printf(": '%s' %.0f%% (%s)\n", class_of(star), 100 * number(star, "confidence"),
           number(doc, "asr_v_star") > 0 ? "fooled" : "not fooled");
    if (!random) {
        const json_t *best = json_object_get(doc, "v_best_prediction");
        printf("best sample of the last step: '%s' %.0f%% (%s)\n", class_of(best),
               100 * number(best, "confidence"),
               number(doc, "asr_v_best") > 0 ? "fooled" : "not fooled");
    }
    printf("ASR of R(v*): %.0f%%   ASR over %zu samples of %s: %.0f%%",
           100 * number(doc, "asr_v_star"), json_array_size(json_object_get(doc, "samples")),
           random ? "uniform viewpoints" : "p*(v)", 100 * number(doc, "asr_samples"));
    const json_t *baseline = json_object_get(doc, "random_search");
    if (baseline)
        printf("   (random search: %.0f%%)", 100 * number(baseline, "asr_samples"));
    const json_t *trust = json_object_get(doc, "trust");
    if (json_is_number(json_object_get(trust, "gap_limit_deg")))
        printf("\ntrust: v* %.1f deg from the nearest photo (%s the %.0f deg limit); %.0f%% of "
               "the samples within it",
               number(trust, "v_star_gap_deg"),
               json_is_true(json_object_get(trust, "v_star_trusted")) ? "within" : "BEYOND",
               number(trust, "gap_limit_deg"), 100 * number(trust, "samples_trusted"));
    print_six("\nstd of the samples: psi %.2f, theta %.2f, phi %.2f, dx %.3f, dy %.3f, dz %.3f\n",
              json_object_get(doc, "sample_std"));
    printf("ASR under fluctuation r = 1..10%%:");
    const json_t *fluct = json_object_get(json_object_get(doc, "fluctuation"), "asr");
    for (size_t i = 0; i < json_array_size(fluct); i++)
        printf(" %.0f", 100 * json_number_value(json_array_get(fluct, i)));
    printf("\ntop wrong classes:");
    const json_t *wrong = json_object_get(doc, "top_wrong_classes");
    for (size_t i = 0; i < json_array_size(wrong); i++) {
        const json_t *w = json_array_get(wrong, i);
        printf("%s %s (%lld)", i ? "," : "", class_of(w),
               json_integer_value(json_object_get(w, "count")));
    }
    char name[128];
    if (cli->attack.name)
        snprintf(name, sizeof name, "%s", cli->attack.name);
    else
        vf_attack_default_name(&cli->attack, name, sizeof name);
    printf("%s\nwritten: %s/attack/%s/{attack.json, v_star.png, samples.png, %sfluctuation.png}\n",
           json_array_size(wrong) ? "" : " none", cli->workspace, name, random ? "" : "loss.png, ");
}

int cmd_attack(int argc, char **argv)
{
    attack_cli cli = {0};
    vf_attack_defaults(&cli.attack);
    vf_workspace ws;
    json_t *doc = NULL;
    vf_status s = parse_options(argc, argv, &cli);
    if (s == VF_OK && (s = vf_workspace_open(cli.workspace, 0, &ws)) == VF_OK) {
        s = vf_attack_run(&ws, &cli.attack, &doc);
        vf_workspace_close(&ws);
    }
    if (s != VF_OK)
        return cli_fail("attack", s);
    if (cli.flags.json)
        cli_print_json(doc);
    else {
        print_summary(&cli, doc);
        json_decref(doc);
    }
    return 0;
}
