/* vf/export.h: the export stage, the attack's viewpoints as shots a person can take.
 *
 * From WS/attack/attack.json (vf/attack_file.h): target 0 is v*, targets 1..count are samples
 * of p*(v) spread over the distribution (vf_targets_spread). Each gets its camera-to-world in
 * the object frame and in COLMAP's frame (normalization undone, when the poses stage ran), its
 * description in words (vf/targets.h; metres when WS/calib has a scale), the predicted class
 * (from attack.json, or the classifier on the preview), and a preview rendered with the
 * attack's camera from the trained field when there is one. Output in WS/export/:
 * targets.json {"convention", "units", "metres_per_unit", "targets": [{"index", "kind" ("v*"
 * or "sample"), "viewpoint", "c2w_object", "c2w_colmap", "words" {...}, "sample",
 * "prediction", "preview"}]}, targets.csv (one row a target), previews/target_NN.png and
 * shot_card.png (a tile a target, to take to the object). */
#ifndef VF_EXPORT_H
#define VF_EXPORT_H

#include <jansson.h>

#include "vf/error.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_EXPORT_MAX_COUNT 1000

typedef struct vf_export_options {
    const char *attack; /* the attack exported (vf_attack_choose); NULL: the only one */
    int count;          /* samples of p*(v) besides v*, 0..VF_EXPORT_MAX_COUNT (8) */
} vf_export_options;

void vf_export_defaults(vf_export_options *o);

/* Run the stage on an open workspace that has an attack. *result (may be NULL) gets
 * targets.json's document (a new reference). */
vf_status vf_export_run(vf_workspace *ws, const vf_export_options *o, json_t **result);

/* The name of the attack the workspace's export used (a borrowed string), or NULL when there
 * is no export: the physical loop (reshoot, score, the studio) follows that attack. */
const char *vf_export_attack(const vf_workspace *ws);

#ifdef __cplusplus
}
#endif
#endif
