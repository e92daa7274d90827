/* vf/study.h: the tables of a study, read back from its finished workspaces.
 *
 *     json_t *doc;
 *     vf_status s = vf_study_tables("studies/tiny", &doc);   // writes studies/tiny/tables/
 *
 * A study folder (made by workflow/Snakefile, see samples/study_tiny.yaml) holds one
 * workspace per object (STUDY/OBJECT/, vf/workspace.h), STUDY/OBJECT/failed.json for an
 * object whose input the tool refused, and STUDY/imagenet_v/ATTACK/results.csv for the
 * ImageNet-V style sets (vf/vbench.h). Every current attack of every workspace is one row
 * (WS/attack/NAME/attack.json, with WS/real/NAME/real.json and WS/transfer/NAME/transfer.json
 * when those ran); a stale attack is listed, not counted. The tables, as the paper's:
 *
 *   table1  space x method x classifier: objects, R(p*(v)), R(v*), Real(v*), Real(p*(v)),
 *           natural accuracy of the field (and of the object), the random-search baseline
 *           each attack also measures; mean over objects with a 95% t-interval
 *   table2  per classifier, space and lambda (nes): R(p*(v)), R(v*) and the std of each
 *           parameter of the samples of p*(v)
 *   table3  transfer: per attack setting, the mean ASR of p*(v) and of v* on each model
 *   imagenet_v  per classifier: top-1 on natural and on adversarial viewpoints
 *   objects     one row per object and attack (the numbers the tables average)
 *   failed      objects that failed (stage and error line) and stale attacks
 *   costs       wall seconds and peak memory of every job (the workflow's benchmark files,
 *               STUDY/logs/OBJECT/STAGE.bench.tsv; else the manifests' seconds)
 *
 * Each as STUDY/tables/NAME.csv, all of them in STUDY/tables/tables.md with the paper's
 * numbers beside ours where the rows match (same space and method; the paper's classifiers
 * are ResNet-50 and ViT-B/16), and table1.png (R(p*(v)) per row). Every file is written
 * atomically. *result (may be NULL) gets {"objects", "attacks", "failed", "tables"}.
 * VF_EINPUT when the folder is not a study (no workspace and no failed object in it). */
#ifndef VF_STUDY_H
#define VF_STUDY_H

#include <jansson.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_STUDY_FAILED_FILE "failed.json" /* STUDY/OBJECT/failed.json, by the workflow */

vf_status vf_study_tables(const char *study_dir, json_t **result);

#ifdef __cplusplus
}
#endif
#endif
