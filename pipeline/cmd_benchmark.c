/* vfcapture benchmark: an ImageNet-V style viewpoint benchmark from attacked workspaces
 * (build), and any number of classifiers scored on it (eval). vf/vbench.h does the work. */
#define _GNU_SOURCE
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/vbench.h"


static const char usage[] =
    "usage: vfcapture benchmark build WS... -o DIR [--count N] [--seed S] [--attack NAME]\n"
    "       vfcapture benchmark eval DIR [--models A,B,...|all] [--json]\n"
    "\n"
    "build: for each attacked workspace, render N images at viewpoints sampled from its\n"
    "adversarial distribution p*(v) and N at its natural (training) viewpoints, as 256x256 PNG\n"
    "files in DIR/images with an index (DIR/index.json, DIR/index.csv: object, label set,\n"
    "split, viewpoint). DIR must not exist yet (or be empty).\n"
    "eval: top-1 accuracy of each model on natural and on adversarial viewpoints, per object\n"
    "and overall; a top-1 in the object's label set is correct. Writes DIR/results.csv,\n"
    "DIR/results.md and DIR/accuracy.png (bar chart) and prints the table.\n"
    "\n"
    "options:\n"
    "  -o, --output DIR       build: the folder to create\n"
    "      --count N          build: images per object and split (default 100)\n"
    "      --seed S           build: sampling seed (default 0)\n"
    "      --attack NAME      build: which attack of each workspace (needed only when one has\n"
    "                         several)\n"
    "      --models LIST      eval: model names or .onnx paths, comma-separated, or 'all' for\n"
    "                         every model found by name (see vfcapture models; default " VF_DEFAULT_MODEL
    ")\n"
    "      --models-dir DIR   eval: look for model names (and 'all') here first\n" CLI_ENGINE_HELP
        CLI_COMMON_HELP;

enum { OPT_SEED = CLI_OPT_FIRST_CUSTOM, OPT_MODELS, OPT_COUNT, OPT_MODELS_DIR };

typedef struct benchmark_options {
    const char *output, *models, *models_dir;
    vf_vbench_build_options build;
    cli_flags flags;
} benchmark_options;

static vf_status parse_options(int argc, char **argv, benchmark_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        CLI_ATTACK_OPTION,
        {"output", required_argument, NULL, 'o'},
        {"count", required_argument, NULL, OPT_COUNT},
        {"seed", required_argument, NULL, OPT_SEED},
        {"models", required_argument, NULL, OPT_MODELS},
        {"models-dir", required_argument, NULL, OPT_MODELS_DIR},
        {0, 0, 0, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:n:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "benchmark", usage))
            continue;
        if (c == 'o') {
            opt->output = optarg;
        } else if (c == 'n' || c == OPT_COUNT) {
            if (c == 'n')
                cli_deprecated("benchmark", "-n", "--count");
            if (cli_count_int("--count", optarg, 1, 100000, &opt->build.count) != VF_OK)
                return VF_EINPUT;
        } else if (c == OPT_SEED) {
            if (cli_seed("--seed", optarg, &opt->build.seed) != VF_OK)
                return VF_EINPUT;
        } else if (c == OPT_MODELS) {
            opt->models = optarg;
        } else if (c == OPT_MODELS_DIR) {
            opt->models_dir = optarg;
        } else if (c == CLI_OPT_ATTACK) {
            opt->build.attack = optarg;
        }
    }
    return VF_OK;
}

static void print_results(const vf_vbench_results *r, const char *dir)
{
    printf("%-34s %-16s %12s %12s\n", "model", "object", "natural", "adversarial");
    for (int m = 0; m < r->model_count; m++) {
        char model[256];
        vf_path_basename(model, sizeof model, r->models[m], 1);
        for (int o = 0; o <= r->object_count; o++) {
            const vf_vbench_row *rows = r->rows + (m * (r->object_count + 1) + o) * 2;
            printf("%-34s %-16s %6.1f%% %3d  %6.1f%% %3d\n", model,
                   o < r->object_count ? r->objects[o] : "all",
                   rows[0].total ? 100.0 * rows[0].correct / rows[0].total : 0.0, rows[0].total,
                   rows[1].total ? 100.0 * rows[1].correct / rows[1].total : 0.0, rows[1].total);
        }
    }
    for (int m = 0; m < r->model_count; m++) {
        char model[256];
        vf_path_basename(model, sizeof model, r->models[m], 1);
        printf("%s%s: %s", m ? ", " : "\nengines: ", model, r->engines[m] ? r->engines[m] : "?");
    }
    printf("\nreports: %s/results.md, %s/results.csv, %s/accuracy.png\n", dir, dir, dir);
}

static json_t *results_json(const vf_vbench_results *r)
{
    json_t *rows = json_array();
    for (int i = 0; i < r->row_count; i++) {
        const vf_vbench_row *row = &r->rows[i];
        json_array_append_new(
            rows, json_pack("{s:s, s:s, s:s, s:s, s:i, s:i}", "model", r->models[row->model],
                            "engine", r->engines[row->model] ? r->engines[row->model] : "", "object",
                            row->object < 0 ? "all" : r->objects[row->object], "split",
                            row->split == VF_VBENCH_NATURAL ? "natural" : "adversarial",
                            "correct", row->correct, "total", row->total));
    }
    return json_pack("{s:o}", "results", rows);
}

static int run_eval(const benchmark_options *opt, const char *dir)
{
    static char found[CLI_MAX_MODELS][VF_PATH_MAX];
    char *models[CLI_MAX_MODELS] = {0};
    int count = 0;
    vf_vbench_results results = {0};
    vf_status status = cli_models("--models", opt->models ? opt->models : VF_DEFAULT_MODEL,
                                  opt->models_dir, found, CLI_MAX_MODELS, &count);
    for (int i = 0; i < count; i++)
        models[i] = found[i];
    if (status == VF_OK)
        status = vf_vbench_eval(dir, (const char *const *)models, count, &results);
    if (status == VF_OK)
        status = vf_vbench_write_reports(&results, dir);
    if (status == VF_OK) {
        if (opt->flags.json)
            cli_print_json(results_json(&results));
        else
            print_results(&results, dir);
    }
    vf_vbench_results_free(&results);
    return status == VF_OK ? 0 : cli_fail("benchmark", status);
}

int cmd_benchmark(int argc, char **argv)
{
    benchmark_options opt = {.build = {.count = 100}};
    vf_status status = parse_options(argc, argv, &opt);
    if (status != VF_OK)
        return cli_fail("benchmark", status);
    const char *action = optind < argc ? argv[optind] : "";
    char **rest = argv + optind + 1;
    int rest_count = argc - optind - 1;
    if (!strcmp(action, "build")) {
        if (rest_count < 1 || !opt.output)
            status = vf_fail(VF_EINPUT, "give attacked workspaces and -o DIR "
                                        "(see 'vfcapture benchmark --help')");
        if (status == VF_OK)
            status = vf_vbench_build((const char *const *)rest, rest_count, opt.output,
                                     &opt.build);
        if (status == VF_OK && !opt.flags.json)
            printf("benchmark set written to %s (%d images per object and split)\n", opt.output,
                   opt.build.count);
        else if (status == VF_OK)
            cli_print_json(json_pack("{s:s, s:i}", "set", opt.output, "count", opt.build.count));
        return status == VF_OK ? 0 : cli_fail("benchmark", status);
    }
    if (!strcmp(action, "eval")) {
        if (rest_count != 1) {
            vf_fail(VF_EINPUT, "give one benchmark folder (see 'vfcapture benchmark --help')");
            return cli_fail("benchmark", VF_EINPUT);
        }
        return run_eval(&opt, rest[0]);
    }
    vf_fail(VF_EINPUT, "say 'build' or 'eval' (see 'vfcapture benchmark --help')");
    return cli_fail("benchmark", VF_EINPUT);
}
