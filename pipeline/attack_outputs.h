/* pipeline/attack_outputs.h: what `vfcapture attack` leaves in WS/attack/: attack.json and the
 * pictures (v_star.png, samples.png, loss.png, fluctuation.png). Private to the pipeline. */
#ifndef VF_PIPELINE_ATTACK_OUTPUTS_H
#define VF_PIPELINE_ATTACK_OUTPUTS_H

#include <jansson.h>

#include "vf/attack_eval.h"
#include "vf/view_loss.h"
#include "vf/viewfool.h"

#define ATTACK_SHEET_SAMPLES 24 /* samples of p*(v) on the contact sheet */

/* The four pictures, written into dir. st is NULL for the random-search baseline (no loss
 * curve is drawn then). */
vf_status attack_write_pictures(const char *dir, vf_view_loss *vl, const vf_attack_state *st,
                                const vf_attack_eval *ev);

/* The distribution and the optimizer's history as attack.json keys, added to doc: "mu",
 * "sigma", "weights", "v_components", "loss_per_step", "max_loss_per_step", "entropy_per_step",
 * "batch_asr_per_step". st NULL (random search): the distribution keys are null and the
 * histories empty. */
void attack_json_add_distribution(json_t *doc, const vf_attack_state *st,
                                  const vf_attack_config *cfg);

/* {"fl_x", "fl_y", "cx", "cy", "w", "h"} of a pinhole camera. */
json_t *attack_camera_json(const vf_camera *cam);

#endif
