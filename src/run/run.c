/* The whole pipeline on one capture (vf/run.h). */
#include "vf/run.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/json.h"
#include "vf/log.h"
#include "vf/real.h"

#define MEMORY_FILE "run.json"

void vf_run_defaults(vf_run_options *o)
{
    memset(o, 0, sizeof *o);
    vf_ingest_request_defaults(&o->ingest);
    vf_poses_defaults(&o->poses);
    vf_train_defaults(&o->train);
    vf_attack_defaults(&o->attack);
    vf_real_defaults(&o->real);
    vf_export_defaults(&o->export_);
}

/* One stage: its name, which it is, and the settings run.json remembers it by. */
typedef struct stage_call {
    const char *name;
    int which;
    json_t *settings;
    const char *(*skip)(const vf_workspace *ws); /* why it is not needed, asked when its turn
                                                    comes; NULL: always needed */
} stage_call;

enum { INGEST, POSES, TRAIN, ATTACK, REAL, EXPORT };

/* Stage `which` as run calls it; *out is the stage's result document. */
static vf_status call_stage(int which, vf_workspace *ws, const vf_run_options *o, json_t **out)
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

/* A posed set needs its points triangulated (the poses stage) only when its photos show the
 * surroundings: the depth loss places them (the fox, 3 minutes: 25.2 -> 27.4 dB held-out).
 * A set with the background removed (NeRF-synthetic) skips it: no gain was measured there,
 * and it would add COLMAP's time to every run. A poses stage already in the workspace (of an
 * earlier input) is redone instead, or training would read its stale frames. */
static const char *skip_poses_of_set(const vf_workspace *ws)
{
    const json_t *summary = json_object_get(vf_workspace_stage_record(ws, "ingest"), "summary");
    const char *background = json_string_value(json_object_get(summary, "background"));
    return background && !strcmp(background, "transparent") && !vf_workspace_has_stage(ws, "poses")
               ? "a posed set without a background needs no sparse points"
               : NULL;
}

static json_t *text_or_null(const char *text) { return text ? json_string(text) : json_null(); }

/* The input by content (a camera: its device path): the same path holding another video, or
 * the same video under another name, is told apart. */
static json_t *input_identity(const vf_ingest_request *in)
{
    json_t *identity = NULL;
    if (in->kind == VF_INGEST_CAMERA || vf_ingest_input_identity(in->input, &identity) != VF_OK)
        return json_string(in->input); /* an unreadable input fails in ingest itself */
    json_object_del(identity, "mtime"); /* a copy or a touch is the same input */
    return identity;
}

/* The stages this input needs, each with the settings that make its output what it is. */
static int plan_stages(const vf_run_options *o, const char *attack_stage, const char *real_stage,
                       stage_call *calls)
{
    const vf_ingest_kind kind = o->ingest.kind;
    const vf_ingest_options *cap = &o->ingest.capture;
    int n = 0;
    calls[n++] = (stage_call){
        .name = "ingest",
        .which = INGEST,
        .settings = json_pack("{s:o, s:s, s:i}", "input", input_identity(&o->ingest), "kind",
                              vf_ingest_kind_name(kind), "frames", cap->select.max_frames)};
    if (kind != VF_INGEST_MODEL) /* a posed set: its poses kept, points triangulated */
        calls[n++] = (stage_call){.name = "poses",
                                  .which = POSES,
                                  .settings = json_object(),
                                  .skip = kind == VF_INGEST_TRANSFORMS ? skip_poses_of_set : NULL};
    calls[n++] = (stage_call){
        .name = "train",
        .which = TRAIN,
        .settings = json_pack("{s:o, s:i}", "minutes",
                              vf_json_number(vf_train_minutes(&o->train, kind == VF_INGEST_MODEL)),
                              "steps", o->train.steps)};
    if (o->train.object_only) /* the key only when set: older workspaces stay current */
        json_object_set_new(calls[n - 1].settings, "object_only", json_true());
    if (o->train.appearance)
        json_object_set_new(calls[n - 1].settings, "appearance", json_true());
    calls[n++] = (stage_call){
        .name = attack_stage,
        .which = ATTACK,
        .settings = json_pack("{s:s, s:o, s:i, s:i}", "model", o->attack.model, "label",
                              text_or_null(o->attack.label), "samples", o->attack.samples,
                              "steps", o->attack.steps)};
    if (kind == VF_INGEST_MODEL) /* posed by Blender; the attack checked on the object */
        calls[n++] = (stage_call){.name = real_stage, .which = REAL, .settings = json_object()};
    calls[n++] = (stage_call){.name = "export", .which = EXPORT, .settings = json_object()};
    return n;
}

static const char *completed_stamp(const vf_workspace *ws, const char *stage)
{
    return json_string_value(json_object_get(vf_workspace_stage_record(ws, stage), "completed"));
}

/* Whether a stage's output is there, made by run with these settings, not redone since, and
 * not stale (nothing it was built on rerun by hand). */
static int stage_is_current(const vf_workspace *ws, const json_t *memory, const stage_call *call)
{
    const json_t *last = json_object_get(memory, call->name);
    const char *stamp = completed_stamp(ws, call->name);
    return stamp && last && !vf_workspace_is_stale(ws, call->name, NULL, 0) &&
           json_equal(json_object_get(last, "settings"), call->settings) &&
           !strcmp(stamp, json_string_value(json_object_get(last, "completed")) ?: "");
}

/* Run the stages in order from the first one that is not current; each stage updates the
 * manifest itself, so the workspace is read again after it. */
static vf_status run_stages(vf_workspace *ws, const vf_run_options *o,
                            stage_call *calls, int count, json_t *memory, const char *memory_path)
{
    int redo = o->restart;
    vf_status s = VF_OK;
    for (int i = 0; i < count && s == VF_OK; i++) {
        const char *skip = calls[i].skip ? calls[i].skip(ws) : NULL;
        if (skip) {
            vf_info("== stage %d of %d: %s is skipped: %s ==", i + 1, count, calls[i].name, skip);
            continue;
        }
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
        vf_status reloaded = vf_workspace_reload(ws); /* what the stage committed */
        if (s == VF_OK && (s = reloaded) == VF_OK) {
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

vf_status vf_run(const char *ws_root, const vf_run_options *options, json_t **summary)
{
    *summary = NULL;
    /* The attack is kept under its name (vf/attack.h); real and export read that one. */
    vf_run_options o = *options;
    char name[128], attack_stage[160], real_stage[160];
    if (o.attack.name)
        snprintf(name, sizeof name, "%s", o.attack.name);
    else
        vf_attack_default_name(&o.attack, name, sizeof name);
    o.attack.name = o.real.attack = o.export_.attack = name;
    snprintf(attack_stage, sizeof attack_stage, "attack/%s", name);
    snprintf(real_stage, sizeof real_stage, "real/%s", name);
    stage_call calls[6];
    int count = plan_stages(&o, attack_stage, real_stage, calls);
    char memory_path[VF_PATH_MAX];
    vf_workspace ws = {0};
    json_t *memory = NULL;
    vf_status s = vf_attack_options_check(&o.attack);
    if (s == VF_OK)
        s = vf_workspace_open(ws_root, 1, &ws);
    if (s == VF_OK && (s = vf_path_join(memory_path, sizeof memory_path, ws.root, MEMORY_FILE)) ==
                          VF_OK) {
        if (vf_is_file(memory_path) && vf_json_load(memory_path, &memory) != VF_OK)
            vf_warn("ignoring unreadable %s: every stage runs again", memory_path);
        if (!memory)
            memory = json_object();
        double start = vf_now();
        s = run_stages(&ws, &o, calls, count, memory, memory_path);
        if (s == VF_OK) {
            char card[VF_PATH_MAX], report[VF_PATH_MAX];
            vf_workspace_path(&ws, "export", "shot_card.png", card, sizeof card);
            vf_workspace_path(&ws, attack_stage, "attack.json", report, sizeof report);
            const json_t *attack =
                json_object_get(vf_workspace_stage_record(&ws, attack_stage), "summary");
            *summary = json_pack("{s:s, s:o, s:s, s:O, s:s, s:s}", "workspace", ws.root, "seconds",
                                 vf_json_number(vf_now() - start), "attack_name", name, "attack",
                                 attack ? attack : json_null(), "shot_card", card, "attack_report",
                                 report);
        }
    }
    for (int i = 0; i < count; i++)
        json_decref(calls[i].settings);
    json_decref(memory);
    vf_workspace_close(&ws);
    return s;
}
