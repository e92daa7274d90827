/* pipeline/attack_ws.h: what the commands that use a trained field (render, eval, attack,
 * transfer) read from a workspace: the field and the cameras it was trained from. Private to
 * the pipeline. */
#ifndef VF_PIPELINE_ATTACK_WS_H
#define VF_PIPELINE_ATTACK_WS_H

#include "vf/field.h"
#include "vf/workspace.h"

/* Open the workspace at root (never created) and load WS/train/model.vff. VF_EINPUT with
 * what to run first when the folder is not a workspace or has no trained field. */
vf_status attack_ws_open(const char *root, vf_workspace *ws, vf_field **field);

/* The training cameras (count x 16 camera-to-world, object frame; the caller frees *c2w):
 * WS/poses/transforms.json after the poses stage (a real capture: *real_capture = 1), else
 * the posed import WS/ingest/transforms.json. */
vf_status attack_ws_training_poses(const vf_workspace *ws, double **c2w, int *count,
                                   int *real_capture);

#endif
