/* vf/attack_file.h: WS/attack/NAME/attack.json, an attack's result, written and read here only.
 *
 * The attack stage (vf/attack.h) writes it with vf_attack_file_json; export, reshoot, score,
 * transfer, real and the ImageNet-V style set read it with vf_attack_file_load. Keys (all
 * viewpoints are 6 numbers psi, theta, phi in degrees, dx, dy, dz in scene units, ../shared/DESIGN.md):
 *
 *   "v_star", "v_star_prediction", "asr_v_star"     v* and the classifier's answer there
 *   "v_best", "v_best_prediction", "asr_v_best"     the best sample of the last step
 *   "samples", "sample_predictions", "asr_samples", "sample_std"
 *                                                   VF_EVAL_SAMPLES draws of p*(v)
 *   "measure_ranges"                                vf_view_ranges_paper: tolerances are shares
 *   "fluctuation" {"r_percent", "asr", "samples_per_level"}, "top_wrong_classes"
 *   "mu", "sigma", "weights", "v_components"        the distribution: one 6-vector each for a
 *                                                   single Gaussian, one row a component for a
 *                                                   mixture; null for random search
 *   "loss_per_step", "max_loss_per_step", "entropy_per_step", "batch_asr_per_step"
 *   "model", "engine", "method", "space", "config"  what ran (config: vf_attack_config JSON)
 *   "label" {"indices", "names", "proposed"}        the true label set
 *   "bounds" {"lo", "hi", "limited_to_capture"}     the search box
 *   "camera" {"fl_x", "fl_y", "cx", "cy", "w", "h"} the classifier camera the renders used
 *   "natural_accuracy", "natural_views"             renders at the training poses
 *   "random_search" {"asr_samples", "best_view", "best_loss", "samples"}  the baseline
 *   "timings" {...}                                 seconds per part, ms per view
 *
 * Files written before a key existed still load: "measure_ranges" falls back to the paper's
 * ranges, a missing camera, distribution or prediction is reported as absent. */
#ifndef VF_ATTACK_FILE_H
#define VF_ATTACK_FILE_H

#include <jansson.h>

#include "vf/attack_eval.h"
#include "vf/camera.h"
#include "vf/classifier.h"
#include "vf/error.h"
#include "vf/fsutil.h"
#include "vf/pose.h"
#include "vf/rng.h"
#include "vf/view_loss.h"
#include "vf/viewfool.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_ATTACK_FILE "attack.json" /* in the stage folder WS/attack/NAME/ */

/* ---- writing ---- */

/* Everything the attack stage measured, as it hands it over to be written. */
typedef struct vf_attack_outcome {
    const char *model, *engine, *method, *space;
    const int *labels;
    int label_count, label_proposed; /* proposed: the majority vote chose the set */
    const vf_attack_config *cfg;     /* its bounds are the search box */
    const int *limited;              /* VF_VIEW_DIM flags: narrowed to the capture */
    vf_camera camera;
    double natural_accuracy;
    int natural_views;
    const vf_attack_state *st; /* NULL for random search */
    const vf_attack_eval *ev;
    const vf_random_search_result *baseline; /* NULL for random search */
    double seconds_natural, seconds_attack, seconds_eval, seconds_baseline;
    vf_view_loss_stats stats;
    double trust_gap; /* the trust limit in degrees (0: off; vf_view_loss_set_trust) */
} vf_attack_outcome;

/* attack.json's document (a new reference). */
json_t *vf_attack_file_json(const vf_attack_outcome *o);

/* ---- reading ---- */

typedef struct vf_sample_prediction {
    int cls; /* predicted class index, -1 when unknown */
    char name[96];
    double confidence;
    int fooled;
} vf_sample_prediction;

typedef struct vf_attack_file {
    char stage[128];         /* "attack/NAME" (vf_attack_file_load_workspace; "" otherwise) */
    char model[VF_PATH_MAX]; /* classifier the attack used ("" when not given) */
    char method[16];         /* nes, pepg, random ("" when not given) */
    int label_count;
    int labels[VF_MAX_LABELS]; /* the true label set */
    char label_text[256];      /* its names, comma-separated */
    json_t *label;             /* the "label" object as written (a reference) */
    double lo[6], hi[6];       /* the attack's search box */
    double range[6];           /* measurement ranges ("measure_ranges"; the paper's full
                                * ranges when absent): tolerances are shares of these */
    vf_viewpoint v_star;
    int sample_count;
    double *samples;                        /* sample_count x 6: the samples of p*(v) */
    vf_sample_prediction *predictions;      /* sample_count entries, or NULL when absent */
    vf_sample_prediction v_star_prediction; /* cls -1 when attack.json does not say */
    double natural_accuracy, asr_v_star, asr_samples; /* NAN when absent */
    double trust_gap; /* the attack's trust limit in degrees ("trust"); 0 when off or absent */
    int has_camera;
    vf_camera camera; /* the render camera */
    /* p*(v): components 0 for random search (or a file without "mu"/"sigma") */
    int components;
    double mu[VF_ATTACK_MAX_COMPONENTS][VF_VIEW_DIM], sigma[VF_ATTACK_MAX_COMPONENTS][VF_VIEW_DIM];
    double weight[VF_ATTACK_MAX_COMPONENTS];
} vf_attack_file;

/* Read attack.json. VF_EINPUT naming the file and the missing key ("v_star", "bounds",
 * "label") when it cannot be used; samples, predictions, rates, camera and distribution are
 * optional. Free with vf_attack_file_free (also after a failure). */
vf_status vf_attack_file_load(const char *path, vf_attack_file *out);
void vf_attack_file_free(vf_attack_file *a);

/* Which attack a command uses: "attack/NAME" when name is given, else the workspace's only
 * attack, into stage. VF_EINPUT, one line, when there is none, when the named one is not
 * there (naming those that are), when several are and none is named, or when it is stale. */
vf_status vf_attack_choose(const vf_workspace *ws, const char *name, char *stage, size_t size);
/* The chosen attack's attack.json (vf_attack_choose); out->stage names it. */
vf_status vf_attack_file_load_workspace(const vf_workspace *ws, const char *name,
                                        vf_attack_file *out);

/* Whether class `cls` belongs to the attack's label set. */
int vf_attack_is_label(const vf_attack_file *a, int cls);

/* Six viewpoint numbers (or ranges of them) from a JSON array: 1 when they are finite, the
 * angles within two turns and the offsets within 100 camera distances (nothing later renders
 * from infinity), else 0. */
int vf_json_read_view(const json_t *array, double view[6]);

/* n fresh draws of p*(v) with the caller's generator (views: n x 6), through the optimizer's
 * own sampler (vf_attack_sample_views). VF_EINPUT when the file has no distribution. */
vf_status vf_attack_file_sample(const vf_attack_file *a, vf_rng *rng, int n, double *views);

#ifdef __cplusplus
}
#endif
#endif
