/* tests/attack_helpers.h: an attack stage made by hand (header-only, static inline), for the
 * tests of the physical loop: v*, its label set and samples, committed as `vfcapture attack`
 * leaves it, so that export, reshoot and score run on a known v* without training a field.
 * Predictions are made up ("not fooled"): export only copies them. */
#ifndef VF_TEST_ATTACK_HELPERS_H
#define VF_TEST_ATTACK_HELPERS_H

#include <jansson.h>
#include <stdio.h>

#include "check.h"
#include "vf/resources.h"
#include "vf/json.h"
#include "vf/pose.h"
#include "vf/workspace.h"

typedef struct test_label_set {
    int count;
    int indices[4];
    const char *names[4];
} test_label_set;

/* WS/attack/attack.json with v*, the label set, the paper's search box and samples (count
 * viewpoints), the default classifier. */
static inline void write_test_attack(const char *ws, const test_label_set *labels,
                                     const vf_viewpoint *v_star, const vf_viewpoint *samples,
                                     int count)
{
    json_t *sample_list = json_array(), *preds = json_array();
    json_t *indices = json_array(), *names = json_array();
    for (int i = 0; i < count; i++) {
        double a[VF_VIEW_DIM];
        vf_viewpoint_to_array(&samples[i], a);
        json_array_append_new(sample_list, vf_json_doubles(a, VF_VIEW_DIM));
        json_array_append_new(preds, json_pack("{s:i, s:s, s:f, s:b}", "class", labels->indices[0],
                                               "name", labels->names[0], "confidence", 0.5,
                                               "fooled", 0));
    }
    for (int k = 0; k < labels->count; k++) {
        json_array_append_new(indices, json_integer(labels->indices[k]));
        json_array_append_new(names, json_string(labels->names[k]));
    }
    double v[VF_VIEW_DIM];
    vf_viewpoint_to_array(v_star, v);
    json_t *doc = json_pack(
        "{s:s, s:{s:o, s:o}, s:{s:[f,f,f,f,f,f], s:[f,f,f,f,f,f]}, s:o, s:o, s:o, s:f, s:f, "
        "s:f}",
        "model", VF_DEFAULT_MODEL, "label", "indices", indices, "names", names, "bounds", "lo",
        -180.0, -30.0, 110.0, -0.5, -1.0, -0.5, "hi", 180.0, 30.0, 250.0, 0.5, 1.0, 0.5,
        "v_star", vf_json_doubles(v, VF_VIEW_DIM), "samples", sample_list,
        "sample_predictions", preds, "natural_accuracy", 0.9, "asr_v_star", 1.0, "asr_samples",
        0.5);
    char path[2 * VF_PATH_MAX];
    vf_workspace w;
    vf_stage stage;
    CHECK(vf_workspace_open(ws, 0, &w) == VF_OK && vf_stage_begin(&w, "attack", &stage) == VF_OK,
          "attack stage begun: %s", vf_error_message());
    snprintf(path, sizeof path, "%s/attack.json", stage.dir);
    CHECK(vf_json_save(path, doc) == VF_OK && vf_stage_commit(&stage, NULL, NULL) == VF_OK,
          "wrote %s", path);
    vf_workspace_close(&w);
    json_decref(doc);
}

#endif
