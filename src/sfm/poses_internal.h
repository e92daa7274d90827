/* src/sfm/poses_internal.h: the poses stage's pieces, shared by poses.c (the flow, the
 * outputs) and poses_colmap.c (the COLMAP steps). Not installed. */
#ifndef VF_SFM_POSES_INTERNAL_H
#define VF_SFM_POSES_INTERNAL_H

#include <jansson.h>

#include "vf/camera.h"
#include "vf/colmap.h"
#include "vf/colmap_model.h"
#include "vf/poses.h"
#include "vf/sfm_images.h"
#include "vf/workspace.h"

#define RETRIEVAL_IMAGES 40 /* retrieval matching: each frame with this many most similar */

/* One run of the stage: everything the steps share. */
typedef struct poses_run {
    vf_poses_options *opt; /* the caller's, with the known camera fitted */
    vf_stage stage;
    vf_colmap colmap;
    char scratch[VF_PATH_MAX];  /* stage/.colmap: COLMAP's working files, dropped at the end */
    char images[VF_PATH_MAX];   /* stage/images: what COLMAP reads */
    char database[VF_PATH_MAX]; /* stage/database.db */
    vf_sfm_images frames;
    const char *matcher;        /* resolved */
    const char *camera_model;   /* resolved */
    vf_colmap_model model;      /* the largest model COLMAP made */
    char model_dir[VF_PATH_MAX]; /* its binary files */
    int model_count;
    json_t *seconds;            /* wall time per step */
} poses_run;

/* COLMAP steps (poses_colmap.c); each adds its wall time to run->seconds. */
vf_status vf__poses_extract_features(poses_run *run);
vf_status vf__poses_match(poses_run *run);
/* Map, convert every model COLMAP made to text, keep the largest in run->model and its text
 * files in stage/sparse. No model at all leaves run->model empty (0 images). */
vf_status vf__poses_map(poses_run *run);
/* Undistorted pinhole images in stage/undistorted/images and their cameras in `out`. */
vf_status vf__poses_undistort(poses_run *run, vf_colmap_model *out);

#endif
