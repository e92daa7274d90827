/* vfcapture run: parse the options, run the pipeline (vf/run.h), print its summary. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "vf/run.h"

static const char usage[] =
    "usage: vfcapture run VIDEO|PHOTO_FOLDER|TRANSFORMS_JSON|MODEL.glb -o WS [options]\n"
    "\n"
    "Run the whole pipeline on one capture: ingest, poses (COLMAP; skipped for a 3D model;\n"
    "a posed transforms.json keeps its poses and gets sparse points triangulated, unless its\n"
    "background is removed), train, attack, real (a 3D model only: the attack's\n"
    "viewpoints on the model itself) and export. Stages whose output is already in WS with the\n"
    "same settings are kept; the first missing or changed stage and every stage after it run.\n"
    "Ends with a summary and the paths of the shot card and the attack report. When a stage\n"
    "fails, fix what its message says and run the same command again to continue.\n"
    "\n"
    "options:\n"
    "  -o, --output WS      workspace folder (required; created when missing)\n"
    "  -m, --model NAME     classifier to attack (default: the attack stage's default)\n"
    "  -l, --label SET      true label set, names or indices (default: the classifier's\n"
    "                       majority vote over natural views)\n"
    "  -n, --frames N       frames to keep from a video or photo folder (default 100)\n"
    "      --minutes M      radiance-field training time (default 3; 5 for a 3D model)\n"
    "      --train-steps N  train for N steps instead (the same field on a busy machine)\n"
    "      --object-only    object mode: the object cut out of the field, on white (see\n"
    "                       'vfcapture train --help')\n"
    "      --appearance     learn each photo's exposure and white balance beside the field\n"
    "                       (see 'vfcapture train --help')\n"
    "      --samples K      attack samples per step (default 50)\n"
    "      --steps S        attack steps (default 100)\n"
    "      --attack NAME    the attack's name (default: model-method-lLAMBDA-space, see\n"
    "                       'vfcapture attack --help'); real and export use it\n"
    "      --restart        redo every stage, even those that are up to date\n" CLI_ENGINE_HELP CLI_COMMON_HELP;

enum {
    OPT_MINUTES = CLI_OPT_FIRST_CUSTOM,
    OPT_TRAIN_STEPS,
    OPT_SAMPLES,
    OPT_STEPS,
    OPT_RESTART,
    OPT_OBJECT_ONLY,
    OPT_APPEARANCE
};

typedef struct run_options {
    const char *workspace;
    vf_run_options run;
    cli_flags flags;
} run_options;

static vf_status parse_options(int argc, char **argv, run_options *o)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        CLI_ATTACK_OPTION,
        {"output", required_argument, NULL, 'o'},
        {"model", required_argument, NULL, 'm'},
        {"label", required_argument, NULL, 'l'},
        {"frames", required_argument, NULL, 'n'},
        {"minutes", required_argument, NULL, OPT_MINUTES},
        {"train-steps", required_argument, NULL, OPT_TRAIN_STEPS},
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"steps", required_argument, NULL, OPT_STEPS},
        {"restart", no_argument, NULL, OPT_RESTART},
        {"object-only", no_argument, NULL, OPT_OBJECT_ONLY},
        {"appearance", no_argument, NULL, OPT_APPEARANCE},
        {0, 0, 0, 0},
    };
    vf_run_defaults(&o->run);
    int c;
    vf_status s = VF_OK;
    while (s == VF_OK &&
           (c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:m:l:n:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &o->flags, "run", usage))
            continue;
        switch (c) {
        case 'o': o->workspace = optarg; break;
        case 'm': o->run.attack.model = optarg; break;
        case 'l': o->run.attack.label = optarg; break;
        case 'n':
            s = cli_count_int("--frames", optarg, 1, 100000, &o->run.ingest.capture.select.max_frames);
            break;
        case OPT_MINUTES:
            s = cli_number_above("--minutes", optarg, 0, 600, &o->run.train.minutes);
            break;
        case OPT_TRAIN_STEPS:
            s = cli_count_int("--train-steps", optarg, 1, 10000000, &o->run.train.steps);
            break;
        case OPT_SAMPLES:
            s = cli_count_int("--samples", optarg, 2, 100000, &o->run.attack.samples);
            break;
        case OPT_STEPS: s = cli_count_int("--steps", optarg, 0, 100000, &o->run.attack.steps); break;
        case OPT_RESTART: o->run.restart = 1; break;
        case CLI_OPT_ATTACK: o->run.attack.name = optarg; break;
        case OPT_OBJECT_ONLY: o->run.train.object_only = 1; break;
        case OPT_APPEARANCE: o->run.train.appearance = 1; break;
        }
    }
    if (s != VF_OK)
        return s;
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one video, photo folder, transforms.json or 3D model "
                                  "(see 'vfcapture run --help')");
    o->run.ingest.input = argv[optind];
    if (!o->workspace)
        return vf_fail(VF_EINPUT, "give the workspace folder with -o WS");
    return vf_ingest_input_kind(o->run.ingest.input, &o->run.ingest.kind);
}

static void print_summary(const run_options *opt, json_t *summary)
{
    if (opt->flags.json) {
        cli_print_json(summary);
        return;
    }
    double seconds = json_number_value(json_object_get(summary, "seconds"));
    const json_t *attack = json_object_get(summary, "attack");
    const char *card = json_string_value(json_object_get(summary, "shot_card"));
    const char *report = json_string_value(json_object_get(summary, "attack_report"));
    printf("\nvfcapture run finished in %.1f minutes\n", seconds / 60);
    if (json_is_object(attack)) {
        char *text = json_dumps(attack, JSON_COMPACT | JSON_REAL_PRECISION(4));
        printf("  attack:      %s\n", text ? text : "");
        free(text);
    }
    printf("  shot card:   %s\n  attack report: %s\n  details:     vfcapture info %s\n", card,
           report, opt->workspace);
    json_decref(summary);
}

int cmd_run(int argc, char **argv)
{
    run_options o = {0};
    json_t *summary = NULL;
    vf_status s = parse_options(argc, argv, &o);
    if (s == VF_OK)
        s = vf_run(o.workspace, &o.run, &summary);
    if (s != VF_OK)
        return cli_fail("run", s);
    print_summary(&o, summary);
    return 0;
}
