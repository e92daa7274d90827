/* vf/real.h: the real stage, the adversarial viewpoints seen on the object itself.
 *
 * A stage above the domains it joins (src/stages/real_stage.c): the attack's viewpoints
 * (vf/attack_file.h), the field's renders (vf/field.h) and the 3D model's (vf/object3d.h),
 * each classified (vf/classifier.h). The paper's Real(v*) and Real(p*(v)) columns. */
#ifndef VF_REAL_H
#define VF_REAL_H

#include <jansson.h>
#include <stdint.h>

#include "vf/error.h"
#include "vf/object3d.h"
#include "vf/pose.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_real_options {
    const char *attack;      /* the attack checked (vf_attack_choose); NULL: the only one */
    const char *classifier;  /* name or path (vf_find_model); NULL: the attack's model */
    const char *models_dir;  /* searched first for a classifier name (may be NULL) */
    int fluctuation_samples; /* viewpoints a level r = 1..10 % (default 20, the paper's) */
    int natural_views;       /* training views checked, spread over them (default 100) */
    uint64_t seed;           /* the fluctuation boxes' draws (default 0) */
    /* The object of a workspace not made from a model (a studio capture, vf_studio_object):
     * the model and the similarity from the workspace's frame to the object's. NULL (the
     * default): WS/ingest/object.json, whose frame is the workspace's. */
    const vf_object3d *object;
    const vf_similarity *to_object;
} vf_real_options;

void vf_real_defaults(vf_real_options *o);

/* The stage "real/NAME" of a workspace made from a 3D model (or filmed by the studio, with
 * o->object), after the attack NAME: render the model
 * itself with the classifier camera at v*, at the attack's samples of p*(v), at fluctuation
 * points around v* and at natural training views; classify them, and the field's renders at the
 * same cameras; write WS/real/NAME/real.json (both columns: Real(v*), Real(p*(v)), the fluctuation
 * curves, natural accuracy, their agreement), sheet.png (field | model, v* and samples),
 * fluctuation.png and the model's renders. Resumable: renders already made in the staging
 * folder are kept. *result (may be NULL) gets real.json's document (a new reference). */
vf_status vf_real_run(vf_workspace *ws, const vf_real_options *o, json_t **result);

#define VF_REAL_FILE "real.json" /* in WS/real/NAME/ */

/* The object's side of real.json: natural accuracy, Real(v*), Real(p*(v)). */
typedef struct vf_real_rates {
    double natural_accuracy, asr_v_star, asr_samples;
} vf_real_rates;

/* Read those rates of the attack stage `attack` ("attack/NAME") from WS/real/NAME/real.json;
 * *found = 0 (and VF_OK) when that check has not run. */
vf_status vf_real_load_rates(const vf_workspace *ws, const char *attack, vf_real_rates *out,
                             int *found);

#ifdef __cplusplus
}
#endif
#endif
