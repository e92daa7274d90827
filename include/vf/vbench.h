/* vf/vbench.h: an ImageNet-V style viewpoint benchmark (the ViewFool paper's Section 5).
 *
 * Building: for each attacked workspace, N renders at viewpoints sampled from its adversarial
 * distribution p*(v) (WS/attack/attack.json) and N at natural viewpoints (its training
 * cameras), written as PNG files with an index (index.json and index.csv: file, object, label
 * set, split, viewpoint). Renders are 256x256 "photos" framed so that the standard
 * 224-pixel centre crop is exactly what the attack classified; every model then applies its
 * own preprocessing (vf_classifier_preprocess) to them.
 *
 * Evaluating: top-1 accuracy of any number of ONNX classifiers on a built set, per model,
 * object and split (natural / adversarial) and per model overall; a top-1 in the object's
 * label set counts as correct.
 *
 * Memory: results are plain arrays owned by a vf_vbench_results, freed with
 * vf_vbench_results_free. */
#ifndef VF_VBENCH_H
#define VF_VBENCH_H

#include <stdint.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_VBENCH_IMAGE_SIZE 256

typedef enum { VF_VBENCH_NATURAL = 0, VF_VBENCH_ADVERSARIAL = 1 } vf_vbench_split;

typedef struct vf_vbench_build_options {
    int count;     /* images per object and split (default 100) */
    uint64_t seed; /* sampling seed (default 0) */
    const char *attack; /* each workspace's attack of this name; NULL: its only one */
} vf_vbench_build_options;

/* Render the set for n workspaces into out_dir (created; must not hold a set already unless
 * it is empty). Object names are the workspaces' folder names, made unique. */
vf_status vf_vbench_build(const char *const *workspaces, int n, const char *out_dir,
                          const vf_vbench_build_options *opt);

/* One row of results: a model on one object's split (object -1: all objects together). */
typedef struct vf_vbench_row {
    int model, object;
    vf_vbench_split split;
    int correct, total;
} vf_vbench_row;

typedef struct vf_vbench_results {
    int model_count, object_count, row_count;
    char **models;  /* model file paths */
    char **engines; /* the engine that ran each (vf_classifier_engine) */
    char **objects; /* object names */
    vf_vbench_row *rows;
} vf_vbench_results;

/* Classify every image of the set in dir with each model (paths of ONNX files). */
vf_status vf_vbench_eval(const char *dir, const char *const *model_paths, int model_count,
                         vf_vbench_results *out);

/* Write results.csv, results.md and accuracy.png (a grouped bar chart: per model, natural and
 * adversarial top-1 over all objects, like the paper's Figure 6) into dir. */
vf_status vf_vbench_write_reports(const vf_vbench_results *r, const char *dir);

void vf_vbench_results_free(vf_vbench_results *r);

#ifdef __cplusplus
}
#endif
#endif
