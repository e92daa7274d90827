/* tests/physical_helpers.h: what the tests of the physical loop share (header-only, static
 * inline). write_test_attack() makes an attack stage by hand: v*, its label set and samples,
 * committed as `vfcapture attack` leaves it, so that export, reshoot and score run on a known
 * v* without training a field (predictions are made up, "not fooled": export only copies
 * them). reshoot_video() runs `vfcapture reshoot --video` and returns the frames it saved. */
#ifndef VF_TEST_PHYSICAL_HELPERS_H
#define VF_TEST_PHYSICAL_HELPERS_H

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

/* WS/attack/test/attack.json with v*, the label set, the paper's search box and samples (count
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
    CHECK(vf_workspace_open(ws, 0, &w) == VF_OK && vf_stage_begin(&w, "attack/test", &stage) == VF_OK,
          "attack stage begun: %s", vf_error_message());
    snprintf(path, sizeof path, "%s/attack.json", stage.dir);
    CHECK(vf_json_save(path, doc) == VF_OK && vf_stage_commit(&stage, NULL, NULL) == VF_OK,
          "wrote %s", path);
    vf_workspace_close(&w);
    json_decref(doc);
}

/* `reshoot WS --target 0 --video VIDEO --smoothing 1` (no smoothing: the frames it saves are
 * those score keeps); returns the number saved, -1 when it failed. *advice (may be NULL) gets
 * the first frame's advice (static storage). */
static inline long long reshoot_video(const char *tool, const char *ws, const char *video,
                                      double tolerance, const char **advice)
{
    static char first[256];
    char out[VF_PATH_MAX];
    snprintf(out, sizeof out, "%s/reshoot.json", vf_test_tmpdir());
    int rc = vf_test_system("'%s' reshoot '%s' --target 0 --video '%s' --tolerance %g "
                            "--smoothing 1 --json >'%s' 2>/dev/null",
                            tool, ws, video, 100 * tolerance, out);
    CHECK(rc == 0, "reshoot exit %d", rc);
    json_error_t e;
    json_t *doc = json_load_file(out, 0, &e);
    long long saved = rc == 0 && doc ? json_integer_value(json_object_get(doc, "saved")) : -1;
    const char *text = json_string_value(
        json_object_get(json_array_get(json_object_get(doc, "advice"), 0), "advice"));
    snprintf(first, sizeof first, "%s", text ? text : "");
    if (advice)
        *advice = first;
    json_decref(doc);
    return saved;
}

#endif
