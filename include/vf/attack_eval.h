/* vf/attack_eval.h: measuring an attack's result the way the ViewFool paper reports it.
 *
 * Given the answer v* = a tanh(mu*) + b, the last step's best sample v_best and 100 viewpoints
 * sampled from the learned distribution p*(v) (or, for the random-search baseline, the best of
 * 100 uniform viewpoints as both answers and those 100), this renders and classifies them
 * through a vf_view_loss and measures: the ASR of R(v*) and of R(v_best) (0 or 1 each), the
 * ASR over the samples, the per-parameter standard deviation of the samples (Table 2), the ASR
 * under camera fluctuation (20 uniform viewpoints within +-r% of the paper's full range of
 * each parameter around v*, r = 1..10, vf_view_fluctuation) and the most frequent wrong
 * classes. The result is a plain struct (no heap) and
 * serializes to the attack.json keys of the workspace contract. */
#ifndef VF_ATTACK_EVAL_H
#define VF_ATTACK_EVAL_H

#include <jansson.h>
#include <stdint.h>

#include "vf/error.h"
#include "vf/view_loss.h"
#include "vf/viewfool.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_EVAL_SAMPLES 100    /* samples of p*(v) the ASR is measured on */
#define VF_FLUCT_LEVELS 10     /* r = 1..10 percent */
#define VF_FLUCT_SAMPLES 20    /* viewpoints per fluctuation level */
#define VF_TOP_WRONG 5         /* wrong classes listed */

typedef struct vf_attack_eval {
    double v_star[VF_VIEW_DIM];
    vf_view_prediction v_star_pred;
    double asr_v_star; /* 1 when R(v*) fools the classifier */
    double v_best[VF_VIEW_DIM]; /* the best sample of the last step */
    vf_view_prediction v_best_pred;
    double asr_v_best;
    int sample_count;
    double samples[VF_EVAL_SAMPLES * VF_VIEW_DIM];
    vf_view_prediction sample_pred[VF_EVAL_SAMPLES];
    double asr_samples;
    double sample_std[VF_VIEW_DIM];
    double fluct_asr[VF_FLUCT_LEVELS]; /* index r - 1 */
    int wrong_count;                   /* entries in wrong_class / wrong_votes */
    int wrong_class[VF_TOP_WRONG], wrong_votes[VF_TOP_WRONG];
} vf_attack_eval;

/* Measure v* and VF_EVAL_SAMPLES samples of the learned distribution (drawn with a generator
 * seeded by `seed`; the fluctuation boxes use it too). vl must have its labels set. */
vf_status vf_attack_eval_distribution(vf_view_loss *vl, const vf_attack_state *st,
                                      const vf_attack_config *cfg, uint64_t seed,
                                      vf_attack_eval *out);

/* The random-search baseline measured the same way: VF_EVAL_SAMPLES uniform viewpoints in
 * the box, v* the one with the highest loss. */
vf_status vf_attack_eval_random(vf_view_loss *vl, const vf_view_bounds *bounds, uint64_t seed,
                                vf_attack_eval *out);

/* One prediction as {"class", "name", "confidence", "label_probability", "fooled"}. */
json_t *vf_view_prediction_to_json(const vf_view_prediction *p);

#ifdef __cplusplus
}
#endif
#endif
