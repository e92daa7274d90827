/* vf/attack.h: the attack stage, ViewFool against a real classifier on a workspace's field.
 *
 *     vf_attack_options o;
 *     vf_attack_defaults(&o);
 *     o.label = "folding chair";
 *     json_t *result;
 *     vf_status s = vf_attack_run(&ws, &o, &result);   // WS/attack/NAME/ committed
 *
 * The stage: check the model and the label set before anything heavy; load the field
 * (WS/train/model.vff) and the training cameras; classify renders at the training poses
 * (natural accuracy, and the label set by majority vote when none is given); choose the
 * search box (a real capture, one the poses stage posed: the range its photos cover,
 * vf/view_coverage.h; then --space, then the caller's bounds); keep the search to the
 * viewpoints the field can vouch for, those within o.trust_gap degrees of a photo
 * (vf_view_loss_set_trust: a penalty beyond, so p*(v) is pushed back; attack.json's "trust"
 * gives v*'s gap and the share of the samples inside, and a v* outside is a warning);
 * optimize p(v) (vf/viewfool.h)
 * with a checkpoint a step in the staging folder; measure v*, VF_EVAL_SAMPLES samples,
 * fluctuation and the random-search baseline (vf/attack_eval.h); write attack.json
 * (vf/attack_file.h), v_star.png, samples.png, loss.png and fluctuation.png; commit.
 *
 * A workspace keeps several attacks side by side, each the stage "attack/NAME" in its own
 * folder WS/attack/NAME/: the name is given (o.name) or made of the classifier, the method,
 * lambda and the space (vf_attack_default_name: "mobilenet_v2_1.0_224_quant-nes-l0.01-both").
 * An attack run again under its name replaces that one alone. Attacks of one workspace may run
 * at the same time in different processes (vf/workspace.h).
 *
 * Life cycle, as every stage with a checkpoint (train, a model's ingest, real): a failure
 * after the stage began leaves its staging folder and checkpoint, and the next run continues
 * from it when the model, labels and settings are the same; other settings are refused
 * (VF_EINPUT naming `--restart`), and `restart` discards the checkpoint, saying so. The
 * checkpoint is removed only once the new output is committed. */
#ifndef VF_ATTACK_H
#define VF_ATTACK_H

#include <jansson.h>
#include <stdint.h>

#include "vf/error.h"
#include "vf/viewfool.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    VF_SEARCH_NES = 0,   /* the paper's Eq. 7: natural-gradient NES with the entropy term */
    VF_SEARCH_PEPG = 1,  /* the reference code's optimizer */
    VF_SEARCH_RANDOM = 2 /* the baseline: VF_EVAL_SAMPLES uniform viewpoints, no optimizer */
} vf_attack_search;

/* "nes", "pepg", "random"; VF_EINPUT naming the choices otherwise. */
vf_status vf_attack_search_parse(const char *name, vf_attack_search *out);
const char *vf_attack_search_name(vf_attack_search m);

typedef struct vf_attack_options {
    const char *model;       /* classifier name or .onnx path (VF_DEFAULT_MODEL) */
    const char *models_dir;  /* looked in first for a name (NULL: the usual places) */
    const char *label;       /* label set, vf_parse_label_set's syntax; NULL: majority vote */
    vf_attack_search method; /* VF_SEARCH_NES */
    double lambda;           /* entropy weight; < 0: the method's default (0.01) */
    int samples;             /* viewpoints a step; 0: the method's default (50, pepg 51) */
    int steps;               /* optimization steps (100) */
    int components;          /* mixture size K, 1..VF_ATTACK_MAX_COMPONENTS, nes only (1) */
    vf_view_space space;     /* VF_SPACE_BOTH */
    const char *bounds;      /* "psi=-90:90,..." applied last (vf_view_bounds_parse), or NULL */
    uint64_t seed;           /* 0: the same seed gives the same result */
    int restart;             /* discard an interrupted attack's checkpoint (see the top) */
    const char *name;        /* the attack's name; NULL: vf_attack_default_name */
    double trust_gap;        /* degrees: viewpoints farther from the photos are not rendered,
                                never fooled, and pushed back (vf_view_loss_set_trust);
                                VF_TRUST_GAP_DEG, 0 switches it off */
} vf_attack_options;

void vf_attack_defaults(vf_attack_options *o);

/* The name an attack with these options gets when none is given: the classifier's file name
 * without .onnx, the method, "l" and lambda (not for random search), the space, and "k" and
 * the mixture size when above 1, joined by '-', in the characters a stage name takes. */
void vf_attack_default_name(const vf_attack_options *o, char *out, size_t size);

/* VF_EINPUT naming the option when the options cannot run (a method/components clash). */
vf_status vf_attack_options_check(const vf_attack_options *o);

/* Run the stage on an open workspace with a trained field. *result (may be NULL) gets
 * attack.json's document (a new reference). Progress and the choices made go to the log. */
vf_status vf_attack_run(vf_workspace *ws, const vf_attack_options *o, json_t **result);

#ifdef __cplusplus
}
#endif
#endif
