/* vfcapture run: the whole pipeline on one capture, resuming where it left off.
 *
 * Runs ingest, poses, train, attack and export by calling each stage's command in-process with
 * the arguments a user would type. WS/run.json remembers, per stage, the arguments it ran with
 * and the completion stamp the manifest gave it; a stage is redone when its output is missing,
 * its arguments changed, it was re-run by hand since, or a stage before it was redone. */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "vf/object3d.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/workspace.h"

static const char usage[] =
    "usage: vfcapture run VIDEO|PHOTO_FOLDER|TRANSFORMS_JSON|MODEL.glb -o WS [options]\n"
    "\n"
    "Run the whole pipeline on one capture: ingest, poses (COLMAP; skipped for a posed\n"
    "transforms.json or a 3D model), train, attack, real (a 3D model only: the attack's\n"
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
    "      --minutes M      radiance-field training time (default 3)\n"
    "      --train-steps N  train for N steps instead (the same field on a busy machine)\n"
    "      --samples K      attack samples per step (default 50)\n"
    "      --steps S        attack steps (default 100)\n"
    "      --restart        redo every stage, even those that are up to date\n" CLI_ENGINE_HELP CLI_COMMON_HELP;

enum { OPT_MINUTES = CLI_OPT_FIRST_CUSTOM, OPT_TRAIN_STEPS, OPT_SAMPLES, OPT_STEPS, OPT_RESTART };

#define MAX_STAGE_ARGS 24

typedef struct run_options {
    const char *input;
    const char *workspace;
    const char *model, *label, *frames, *minutes, *train_steps, *samples, *steps;
    int restart;
    cli_flags flags;
} run_options;

typedef struct stage_call {
    const char *name;
    int (*run)(int argc, char **argv);
    char *argv[MAX_STAGE_ARGS];
    int argc;
} stage_call;

static void push(stage_call *call, const char *arg)
{
    if (call->argc < MAX_STAGE_ARGS - 1)
        call->argv[call->argc++] = (char *)arg;
    call->argv[call->argc] = NULL;
}

static void push_option(stage_call *call, const char *option, const char *value)
{
    if (value) {
        push(call, option);
        push(call, value);
    }
}

static int is_transforms_file(const char *path)
{
    size_t n = strlen(path);
    return vf_is_file(path) && n > 5 && !strcmp(path + n - 5, ".json");
}

/* The stages this input needs, with the arguments each is called with. */
static int plan_stages(const run_options *opt, stage_call *calls)
{
    int n = 0;
    stage_call *c = &calls[n++];
    *c = (stage_call){.name = "ingest", .run = cmd_ingest};
    push(c, "ingest");
    int model = vf_object3d_is_model(opt->input); /* posed by Blender; checked by `real` */
    if (is_transforms_file(opt->input)) {
        push_option(c, "--transforms", opt->input);
    } else if (model) {
        push(c, opt->input);
    } else {
        push(c, opt->input);
        push_option(c, "--frames", opt->frames);
    }
    push_option(c, "--output", opt->workspace);

    if (!is_transforms_file(opt->input) && !model) {
        c = &calls[n++];
        *c = (stage_call){.name = "poses", .run = cmd_poses};
        push(c, "poses");
        push(c, opt->workspace);
    }

    c = &calls[n++];
    *c = (stage_call){.name = "train", .run = cmd_train};
    push(c, "train");
    push(c, opt->workspace);
    push_option(c, "--minutes", opt->minutes);
    push_option(c, "--steps", opt->train_steps);

    c = &calls[n++];
    *c = (stage_call){.name = "attack", .run = cmd_attack};
    push(c, "attack");
    push(c, opt->workspace);
    push_option(c, "--model", opt->model);
    push_option(c, "--label", opt->label);
    push_option(c, "--samples", opt->samples);
    push_option(c, "--steps", opt->steps);

    if (model) {
        c = &calls[n++];
        *c = (stage_call){.name = "real", .run = cmd_real};
        push(c, "real");
        push(c, opt->workspace);
    }

    c = &calls[n++];
    *c = (stage_call){.name = "export", .run = cmd_export};
    push(c, "export");
    push(c, opt->workspace);

    if (opt->flags.quiet)
        for (int i = 0; i < n; i++)
            push(&calls[i], "--quiet");
    return n;
}

static json_t *args_json(const stage_call *call)
{
    json_t *list = json_array();
    for (int i = 1; i < call->argc; i++)
        json_array_append_new(list, json_string(call->argv[i]));
    return list;
}

static const char *completed_stamp(const vf_workspace *ws, const char *stage)
{
    return json_string_value(json_object_get(vf_workspace_stage_record(ws, stage), "completed"));
}

/* Whether a stage's output is there, made by run with these arguments, and not redone since. */
static int stage_is_current(const vf_workspace *ws, const json_t *memory, const stage_call *call)
{
    const json_t *last = json_object_get(memory, call->name);
    const char *stamp = completed_stamp(ws, call->name);
    json_t *args = args_json(call);
    int current = stamp && last && json_equal(json_object_get(last, "args"), args) &&
                  !strcmp(stamp, json_string_value(json_object_get(last, "completed")) ?: "");
    json_decref(args);
    return current;
}

static vf_status parse_options(int argc, char **argv, run_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        {"output", required_argument, NULL, 'o'},
        {"model", required_argument, NULL, 'm'},
        {"label", required_argument, NULL, 'l'},
        {"frames", required_argument, NULL, 'n'},
        {"minutes", required_argument, NULL, OPT_MINUTES},
        {"train-steps", required_argument, NULL, OPT_TRAIN_STEPS},
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"steps", required_argument, NULL, OPT_STEPS},
        {"restart", no_argument, NULL, OPT_RESTART},
        {0, 0, 0, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:m:l:n:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "run", usage))
            continue;
        switch (c) {
        case 'o': opt->workspace = optarg; break;
        case 'm': opt->model = optarg; break;
        case 'l': opt->label = optarg; break;
        case 'n': opt->frames = optarg; break;
        case OPT_MINUTES: opt->minutes = optarg; break;
        case OPT_TRAIN_STEPS: opt->train_steps = optarg; break;
        case OPT_SAMPLES: opt->samples = optarg; break;
        case OPT_STEPS: opt->steps = optarg; break;
        case OPT_RESTART: opt->restart = 1; break;
        }
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one video, photo folder, transforms.json or 3D model "
                                  "(see 'vfcapture run --help')");
    opt->input = argv[optind];
    if (!opt->workspace)
        return vf_fail(VF_EINPUT, "give the workspace folder with -o WS");
    if (!vf_is_file(opt->input) && !vf_is_dir(opt->input))
        return vf_fail(VF_EINPUT, "cannot read %s: no such file or folder", opt->input);
    return VF_OK;
}

/* Run one stage's command; a failure keeps its exit code (the stage printed why). With
 * --json the stages' own reports go to stderr, so stdout carries run's JSON alone. */
static int run_stage(stage_call *call, int index, int count, int json)
{
    int saved_stdout = -1;
    fflush(stdout);
    if (json && (saved_stdout = dup(STDOUT_FILENO)) >= 0)
        dup2(STDERR_FILENO, STDOUT_FILENO);
    vf_info("== stage %d of %d: %s ==", index + 1, count, call->name);
    /* getopt_long reorders the argv it is given: hand over a copy, keep ours for run.json */
    char *argv[MAX_STAGE_ARGS];
    memcpy(argv, call->argv, sizeof argv);
    optind = 0; /* each command parses its own argv from the start */
    double start = vf_now();
    int code = call->run(call->argc, argv);
    if (code == 0)
        vf_info("== %s done in %.0f s ==", call->name, vf_now() - start);
    fflush(stdout);
    if (saved_stdout >= 0) {
        dup2(saved_stdout, STDOUT_FILENO);
        close(saved_stdout);
    }
    return code;
}

static void print_summary(const vf_workspace *ws, const run_options *opt, double seconds)
{
    char card[VF_PATH_MAX], report[VF_PATH_MAX];
    vf_workspace_path(ws, "export", "shot_card.png", card, sizeof card);
    vf_workspace_path(ws, "attack", "attack.json", report, sizeof report);
    const json_t *attack = json_object_get(vf_workspace_stage_record(ws, "attack"), "summary");
    if (opt->flags.json) {
        cli_print_json(json_pack("{s:s, s:f, s:O, s:s, s:s}", "workspace", ws->root, "seconds",
                                 seconds, "attack", attack ? attack : json_null(), "shot_card",
                                 card, "attack_report", report));
        return;
    }
    printf("\nvfcapture run finished in %.1f minutes\n", seconds / 60);
    if (attack) {
        char *text = json_dumps(attack, JSON_COMPACT | JSON_REAL_PRECISION(4));
        printf("  attack:      %s\n", text ? text : "");
        free(text);
    }
    printf("  shot card:   %s\n  attack report: %s\n  details:     vfcapture info %s\n", card,
           report, ws->root);
}

int cmd_run(int argc, char **argv)
{
    run_options opt = {0};
    vf_status status = parse_options(argc, argv, &opt);
    if (status != VF_OK)
        return cli_fail("run", status);

    stage_call calls[6];
    int count = plan_stages(&opt, calls);
    char memory_path[VF_PATH_MAX];
    vf_workspace ws;
    if ((status = vf_workspace_open(opt.workspace, 1, &ws)) != VF_OK ||
        (status = vf_path_join(memory_path, sizeof memory_path, ws.root, "run.json")) != VF_OK)
        return cli_fail("run", status);
    json_t *memory = NULL;
    if (vf_is_file(memory_path) && vf_json_load(memory_path, &memory) != VF_OK)
        vf_warn("ignoring unreadable %s: every stage runs again", memory_path);
    if (!memory)
        memory = json_object();

    double start = vf_now();
    int redo = opt.restart, code = 0;
    for (int i = 0; i < count && code == 0; i++) {
        redo = redo || !stage_is_current(&ws, memory, &calls[i]);
        if (!redo) {
            vf_info("== stage %d of %d: %s is up to date ==", i + 1, count, calls[i].name);
            continue;
        }
        vf_workspace_close(&ws); /* the stage updates the manifest itself */
        code = run_stage(&calls[i], i, count, opt.flags.json);
        if ((status = vf_workspace_open(opt.workspace, 0, &ws)) != VF_OK) {
            json_decref(memory);
            return cli_fail("run", status);
        }
        if (code != 0)
            break;
        json_object_set_new(memory, calls[i].name,
                            json_pack("{s:o, s:s}", "args", args_json(&calls[i]), "completed",
                                      completed_stamp(&ws, calls[i].name) ?: ""));
        if ((status = vf_json_save(memory_path, memory)) != VF_OK)
            code = cli_fail("run", status);
    }
    if (code == 0)
        print_summary(&ws, &opt, vf_now() - start);
    json_decref(memory);
    vf_workspace_close(&ws);
    return code;
}
