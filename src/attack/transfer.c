/* Cross-model transfer (vf/transfer.h): the attack's viewpoints re-rendered for other
 * classifiers. */
#include "vf/transfer.h"

#include <stdlib.h>

#include "vf/attack_file.h"
#include "vf/classifier.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/view_loss.h"
#include "vf/workspace.h"

static double fooled_rate(const vf_view_prediction *p, int n)
{
    int fooled = 0;
    for (int i = 0; i < n; i++)
        fooled += !p[i].correct;
    return (double)fooled / n;
}

/* One model: natural accuracy, ASR of v*, ASR over the samples, as a JSON row. */
static vf_status measure_model(const char *model, const vf_field *field, const double *c2w,
                               int views, const vf_attack_file *r, json_t **row)
{
    vf_classifier *cls = NULL;
    vf_view_loss *vl = NULL;
    vf_view_prediction *pred = malloc((size_t)(views > r->sample_count ? views : r->sample_count) *
                                      sizeof *pred);
    vf_view_prediction star;
    vf_status s = pred ? vf_classifier_open(model, &cls) : vf_fail(VF_EINTERNAL, "out of memory");
    if (s == VF_OK)
        s = vf_view_loss_create(field, cls, &vl);
    if (s == VF_OK)
        s = vf_view_loss_set_labels(vl, r->labels, r->label_count);
    double natural = 0, asr = 0;
    if (s == VF_OK && (s = vf_view_loss_classify_poses(vl, c2w, views, pred)) == VF_OK)
        natural = 1 - fooled_rate(pred, views);
    if (s == VF_OK)
        s = vf_view_loss_classify(vl, r->samples, r->sample_count, pred, NULL);
    if (s == VF_OK)
        asr = fooled_rate(pred, r->sample_count);
    if (s == VF_OK) {
        double v_star[VF_VIEW_DIM];
        vf_viewpoint_to_array(&r->v_star, v_star);
        s = vf_view_loss_classify(vl, v_star, 1, &star, NULL);
    }
    if (s == VF_OK)
        *row =
            json_pack("{s:s, s:s, s:i, s:o, s:o, s:o, s:o}", "model", model, "engine",
                      vf_classifier_engine(cls), "input_size", vf_classifier_input_size(cls),
                      "natural_accuracy", vf_json_number(natural), "asr_samples",
                      vf_json_number(asr), "asr_v_star", vf_json_number(star.correct ? 0.0 : 1.0),
                      "v_star_prediction", vf_view_prediction_to_json(&star));
    vf_view_loss_free(vl);
    vf_classifier_close(cls);
    free(pred);
    return s;
}

vf_status vf_transfer_run(vf_workspace *ws, const char *attack, char *const *models,
                          int model_count, json_t **result)
{
    char stage_name[160];
    *result = NULL;
    vf_field *field = NULL;
    vf_dataset natural = {0};
    double *c2w = NULL;
    vf_attack_file r = {0};
    json_t *rows = json_array();
    vf_stage stage;
    vf_status s = model_count > 0 ? vf_class_names_load()
                                  : vf_fail(VF_EINPUT, "transfer: give at least one model");
    if (s == VF_OK)
        s = vf_field_load_workspace(ws, &field);
    if (s == VF_OK)
        s = vf_attack_file_load_workspace(ws, attack, &r);
    if (s == VF_OK && r.sample_count < 1)
        s = vf_fail(VF_EINPUT, "%s/%s/attack.json has no samples: run the attack again",
                    ws->root, r.stage);
    if (s == VF_OK && snprintf(stage_name, sizeof stage_name, "transfer/%s", r.stage + 7) >=
                          (int)sizeof stage_name)
        s = vf_fail(VF_EINPUT, "attack name too long: %s", r.stage);
    if (s == VF_OK && (s = vf_dataset_load_training(ws, &natural, NULL)) == VF_OK &&
        !(c2w = vf_dataset_poses(&natural)))
        s = vf_fail(VF_EINTERNAL, "out of memory");
    vf_progress progress;
    vf_progress_begin(&progress, "transfer", (size_t)model_count, "models");
    for (int m = 0; m < model_count && s == VF_OK; m++) {
        json_t *row = NULL;
        s = measure_model(models[m], field, c2w, natural.count, &r, &row);
        if (s == VF_OK)
            json_array_append_new(rows, row);
        vf_progress_update(&progress, (size_t)m + 1, NULL);
    }
    if (s == VF_OK)
        vf_progress_end(&progress);
    char path[VF_PATH_MAX];
    json_t *doc = NULL;
    if (s == VF_OK && (s = vf_stage_begin(ws, stage_name, &stage)) == VF_OK) {
        doc = json_pack("{s:s, s:O, s:i, s:O}", "attack_model", r.model, "label", r.label,
                        "samples", r.sample_count, "models", rows);
        s = vf_path_join(path, sizeof path, stage.dir, "transfer.json");
        if (s == VF_OK)
            s = vf_json_save(path, doc);
        json_t *names = json_array();
        for (int m = 0; m < model_count; m++)
            json_array_append_new(names, json_string(models[m]));
        if (s == VF_OK) {
            s = vf_stage_commit(&stage, json_pack("{s:s, s:o}", "attack", r.stage + 7, "models", names),
                                NULL);
        } else {
            json_decref(names);
            vf_stage_abort(&stage);
        }
    }
    if (s == VF_OK)
        *result = doc;
    else
        json_decref(doc);
    json_decref(rows);
    vf_attack_file_free(&r);
    vf_dataset_free(&natural);
    free(c2w);
    vf_field_free(field);
    return s;
}

