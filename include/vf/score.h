/* vf/score.h: the score stage, the physical attack success rate from a re-capture.
 *
 * Every frame of the inputs (vf/frames.h: images, videos, folders) is checked for blur
 * (sharper than blur_ratio x the median of all of them), localized against the workspace's
 * sparse model (vf/localize.h), and kept when its viewpoint lies within the tolerance box
 * around v* (or exported target `target`); kept frames are classified, and the misclassified
 * share is the physical ASR with a 95% Wilson interval. Localized frames outside the box are
 * the natural-viewpoint control. Output in WS/score/: score.json {"workspace", "center",
 * "center_viewpoint", "tolerance_percent", "model", "engine", "label", "kept" {"frames",
 * "misclassified", "asr", "interval95", "predicted"}, "natural" {... "error_rate" ...},
 * "rejected" {"blurry", "not_localized", "out_of_tolerance", "total"}, "frames",
 * "localize_fps", "mode", "frames_detail" [per frame]}, frames.csv, and sheet.png: what the
 * classifier saw of up to 36 frames spread over the input (its centre square, in object mode
 * the cut-out), each with "on target" or "natural" and its class, red when fooled.
 *
 * When the field was trained in object mode (vf/train.h object_only), each localized frame is
 * cut out by the field's silhouette at the frame's pose (opacity over a half) and classified
 * on white, so the attack and the physical measurement see the same object ("mode":
 * "object", and each frame's "object_coverage"). */
#ifndef VF_SCORE_H
#define VF_SCORE_H

#include <jansson.h>

#include "vf/error.h"
#include "vf/localize.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_score_options {
    double tolerance;  /* box half-width, a share of each parameter's range (0.05) */
    int target;        /* exported target to centre on; -1: v* (-1) */
    const char *model; /* classifier; NULL: the attack's model, else the default */
    double blur_ratio; /* frames sharper than this x the median are used (0.3) */
    vf_localize_options loc;
} vf_score_options;

void vf_score_defaults(vf_score_options *o);

/* Score input_count inputs against an open workspace that has an attack and poses. *result
 * gets score.json's document without "frames_detail" (a new reference). */
vf_status vf_score_run(vf_workspace *ws, char *const *inputs, int input_count,
                       const vf_score_options *o, json_t **result);

/* WS/score/score.json of a completed score stage (the one reader of the file; a new reference
 * in *doc). VF_EINPUT "WS has no score yet: run ..." without one, or naming the file when it
 * lacks what score writes (center_viewpoint, tolerance_percent, kept, frames_detail). */
vf_status vf_score_load(const vf_workspace *ws, json_t **doc);

/* One row per workspace for a table across objects: {"object", "label", "natural_accuracy",
 * "asr_v_star", "asr_samples" (the attack's renders), "real_natural_accuracy",
 * "real_asr_v_star", "real_asr_samples" (the object itself, for a 3D model's `real`), and
 * when `score` ran "physical_asr", "interval95", "misclassified", "frames_used"}; rates are
 * -1 when unknown. VF_EINPUT naming a workspace with neither a score nor a real check. */
vf_status vf_score_summary(char *const *workspaces, int count, json_t **rows);

#ifdef __cplusplus
}
#endif
#endif
