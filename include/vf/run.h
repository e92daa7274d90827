/* vf/run.h: the whole pipeline on one capture, resuming where it left off.
 *
 *     vf_run_options o;
 *     vf_run_defaults(&o);
 *     o.ingest.input = "fox.mp4";   o.ingest.kind = VF_INGEST_VIDEO;
 *     json_t *summary;
 *     vf_status s = vf_run("WS", &o, &summary);
 *
 * Calls each stage's library function in turn: ingest, poses (not for a 3D model; for a posed
 * set only when its photos have a background, and then it keeps the set's poses and only
 * triangulates points), train, attack, real (a 3D model only: the attack's viewpoints on the
 * object itself) and export. WS/run.json remembers, per stage, the settings it ran with and the completion
 * stamp the manifest gave it; a stage is redone when its output is missing, its settings
 * changed, it was re-run by hand since, or a stage before it was redone (or `restart`). Each
 * stage resumes an interrupted run of its own as it does when called alone. */
#ifndef VF_RUN_H
#define VF_RUN_H

#include <jansson.h>

#include "vf/attack.h"
#include "vf/error.h"
#include "vf/export.h"
#include "vf/ingest.h"
#include "vf/object3d.h"
#include "vf/real.h"
#include "vf/poses.h"
#include "vf/train.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_run_options {
    vf_ingest_request ingest; /* the input, its kind and the ingest settings */
    vf_poses_options poses;
    vf_train_options train;
    vf_attack_options attack;
    vf_real_options real;
    vf_export_options export_;
    int restart; /* redo every stage, even those that are up to date */
} vf_run_options;

/* Every stage's defaults; no input. */
void vf_run_defaults(vf_run_options *o);

/* Run the stages into the workspace at ws_root (created when missing). *summary (a new
 * reference) gets {workspace, seconds, attack_name, attack (the attack stage's summary),
 * shot_card, attack_report}. The attack is the stage "attack/NAME" (o->attack.name, or
 * vf_attack_default_name); real and export use that one. A failing stage's message says which ("stage poses: ..."); the stages before
 * it stay done for the next run. */
vf_status vf_run(const char *ws_root, const vf_run_options *o, json_t **summary);

#ifdef __cplusplus
}
#endif
#endif
