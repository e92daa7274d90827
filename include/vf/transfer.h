/* vf/transfer.h: do an attack's viewpoints fool other classifiers too?
 *
 * The transfer stage re-renders an attack's v* and its samples of p*(v) (WS/attack/NAME/attack.json)
 * at each model's input size (same field of view) and measures, per model, the natural accuracy
 * over the training views, the ASR of R(v*) and the ASR over the samples, with the attack's
 * label set: the paper's cross-model transfer. It writes WS/transfer/NAME/transfer.json:
 *   {"attack_model", "label", "samples", "models": [{"model", "engine", "input_size",
 *    "natural_accuracy", "asr_samples", "asr_v_star", "v_star_prediction"}, ...]} */
#ifndef VF_TRANSFER_H
#define VF_TRANSFER_H

#include <jansson.h>

#include "vf/error.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Run the stage "transfer/NAME" on an open workspace (a trained field and the attack NAME,
 * with samples; attack NULL: the only one, vf_attack_choose) for the model files
 * models[0..model_count-1]; *result gets transfer.json's document (a new reference). */
vf_status vf_transfer_run(vf_workspace *ws, const char *attack, char *const *models,
                          int model_count, json_t **result);

#ifdef __cplusplus
}
#endif
#endif
