/* vfcapture run: the whole pipeline on one capture, resuming where it left off.
 *
 * Calls each stage's library function (vf_ingest_run, vf_poses_run, vf_train_run,
 * vf_attack_run, vf_real_run, vf_export_run) in turn. WS/run.json remembers, per stage, the
 * settings it ran with and the completion stamp the manifest gave it; a stage is redone when
 * its output is missing, its settings changed, it was re-run by hand since, or a stage before
 * it was redone. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "vf/attack.h"
#include "vf/export.h"
#include "vf/ingest.h"
#include "vf/log.h"
#include "vf/object3d.h"
#include "vf/poses.h"
#include "vf/train.h"

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

typedef struct run_options {
    const char *workspace;
    vf_ingest_request ingest;
    vf_poses_options poses;
    vf_train_options train;
    vf_attack_options attack;
    vf_real_options real;
    vf_export_options export_;
    int restart;
    cli_flags flags;
} run_options;

/* One stage: its name, which it is, and the settings run.json remembers it by. */
typedef struct stage_call {
    const char *name;
    int which;
    json_t *settings;
} stage_call;

enum { INGEST, POSES, TRAIN, ATTACK, REAL, EXPORT };

/* Stage `which` as run calls it; *out is the stage's result document. */
static vf_status call_stage(int which, vf_workspace *ws, const run_options *o, json_t **out)
{
    switch (which) {
    case INGEST: return vf_ingest_run(ws->root, &o->ingest, out);
    case POSES: return vf_poses_run(ws, &o->poses, out);
    case TRAIN: return vf_train_run(ws, &o->train, out);
    case ATTACK: return vf_attack_run(ws, &o->attack, out);
    case REAL: return vf_real_run(ws, &o->real, out);
    default: return vf_export_run(ws, &o->export_, out);
    }
}

static json_t *text_or_null(const char *text) { return text ? json_string(text) : json_null(); }

/* The stages this input needs, each with the settings that make its output what it is. */
static int plan_stages(const run_options *o, stage_call *calls)
{
    const vf_ingest_kind kind = o->ingest.kind;
    const vf_ingest_options *cap = &o->ingest.capture;
    int n = 0;
    calls[n++] =
        (stage_call){"ingest", INGEST,
                     json_pack("{s:s, s:s, s:i}", "input", o->ingest.input, "kind",
                               vf_ingest_kind_name(kind), "frames", cap->select.max_frames)};
    if (kind != VF_INGEST_TRANSFORMS && kind != VF_INGEST_MODEL)
        calls[n++] = (stage_call){"poses", POSES, json_object()};
    calls[n++] = (stage_call){
        "train", TRAIN,
        json_pack("{s:f, s:i}", "minutes", o->train.minutes, "steps", o->train.steps)};
    calls[n++] = (stage_call){"attack", ATTACK,
                              json_pack("{s:s, s:o, s:i, s:i}", "model", o->attack.model, "label",
                                        text_or_null(o->attack.label), "samples",
                                        o->attack.samples, "steps", o->attack.steps)};
    if (kind == VF_INGEST_MODEL) /* posed by Blender; the attack checked on the object */
        calls[n++] = (stage_call){"real", REAL, json_object()};
    calls[n++] = (stage_call){"export", EXPORT, json_object()};
    return n;
}

static const char *completed_stamp(const vf_workspace *ws, const char *stage)
{
    return json_string_value(json_object_get(vf_workspace_stage_record(ws, stage), "completed"));
}

/* Whether a stage's output is there, made by run with these settings, and not redone since. */
static int stage_is_current(const vf_workspace *ws, const json_t *memory, const stage_call *call)
{
    const json_t *last = json_object_get(memory, call->name);
    const char *stamp = completed_stamp(ws, call->name);
    return stamp && last && json_equal(json_object_get(last, "settings"), call->settings) &&
           !strcmp(stamp, json_string_value(json_object_get(last, "completed")) ?: "");
}

static vf_status parse_options(int argc, char **argv, run_options *o)
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
    vf_ingest_request_defaults(&o->ingest);
    vf_poses_defaults(&o->poses);
    vf_train_defaults(&o->train);
    vf_attack_defaults(&o->attack);
    vf_real_defaults(&o->real);
    vf_export_defaults(&o->export_);
    int c;
    vf_status s = VF_OK;
    while (s == VF_OK &&
           (c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:m:l:n:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &o->flags, "run", usage))
            continue;
        switch (c) {
        case 'o': o->workspace = optarg; break;
        case 'm': o->attack.model = optarg; break;
        case 'l': o->attack.label = optarg; break;
        case 'n':
            s = cli_count_int("--frames", optarg, 1, 100000, &o->ingest.capture.select.max_frames);
            break;
        case OPT_MINUTES:
            if (cli_parse_doubles(optarg, &o->train.minutes, 1) != 1 ||
                !(o->train.minutes > 0 && o->train.minutes <= 600))
                s = vf_fail(VF_EINPUT, "--minutes must be a number above 0 (up to 600), not '%s'",
                            optarg);
            break;
        case OPT_TRAIN_STEPS:
            s = cli_count_int("--train-steps", optarg, 1, 10000000, &o->train.steps);
            break;
        case OPT_SAMPLES:
            s = cli_count_int("--samples", optarg, 2, 100000, &o->attack.samples);
            break;
        case OPT_STEPS: s = cli_count_int("--steps", optarg, 0, 100000, &o->attack.steps); break;
        case OPT_RESTART: o->restart = 1; break;
        }
    }
    if (s != VF_OK)
        return s;
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one video, photo folder, transforms.json or 3D model "
                                  "(see 'vfcapture run --help')");
    o->ingest.input = argv[optind];
    if (!o->workspace)
        return vf_fail(VF_EINPUT, "give the workspace folder with -o WS");
    return vf_ingest_input_kind(o->ingest.input, &o->ingest.kind);
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

/* Run the stages in order from the first one that is not current; each stage updates the
 * manifest itself, so the workspace is read again after it. */
static vf_status run_stages(vf_workspace *ws, const run_options *o, stage_call *calls, int count,
                            json_t *memory, const char *memory_path)
{
    int redo = o->restart;
    vf_status s = VF_OK;
    for (int i = 0; i < count && s == VF_OK; i++) {
        redo = redo || !stage_is_current(ws, memory, &calls[i]);
        if (!redo) {
            vf_info("== stage %d of %d: %s is up to date ==", i + 1, count, calls[i].name);
            continue;
        }
        vf_info("== stage %d of %d: %s ==", i + 1, count, calls[i].name);
        double start = vf_now();
        json_t *result = NULL;
        s = call_stage(calls[i].which, ws, o, &result);
        json_decref(result);
        vf_workspace_close(ws);
        vf_status reopened = vf_workspace_open(o->workspace, 0, ws);
        if (s == VF_OK && (s = reopened) == VF_OK) {
            vf_info("== %s done in %.0f s ==", calls[i].name, vf_now() - start);
            json_object_set_new(memory, calls[i].name,
                                json_pack("{s:O, s:s}", "settings", calls[i].settings, "completed",
                                          completed_stamp(ws, calls[i].name) ?: ""));
            s = vf_json_save(memory_path, memory);
        } else if (s != VF_OK) {
            vf_error_prefix("stage %s", calls[i].name);
        }
    }
    return s;
}

int cmd_run(int argc, char **argv)
{
    run_options o = {0};
    stage_call calls[6];
    int count = 0;
    char memory_path[VF_PATH_MAX];
    vf_workspace ws = {0};
    json_t *memory = NULL;
    vf_status s = parse_options(argc, argv, &o);
    if (s == VF_OK)
        count = plan_stages(&o, calls);
    if (s == VF_OK && (s = vf_workspace_open(o.workspace, 1, &ws)) == VF_OK &&
        (s = vf_path_join(memory_path, sizeof memory_path, ws.root, "run.json")) == VF_OK) {
        if (vf_is_file(memory_path) && vf_json_load(memory_path, &memory) != VF_OK)
            vf_warn("ignoring unreadable %s: every stage runs again", memory_path);
        if (!memory)
            memory = json_object();
        double start = vf_now();
        s = run_stages(&ws, &o, calls, count, memory, memory_path);
        if (s == VF_OK)
            print_summary(&ws, &o, vf_now() - start);
    }
    for (int i = 0; i < count; i++)
        json_decref(calls[i].settings);
    json_decref(memory);
    vf_workspace_close(&ws);
    return s == VF_OK ? 0 : cli_fail("run", s);
}
