/* src/sfm/poses_internal.h: the poses stage's pieces, shared by poses.c (the flow, the
 * outputs) and poses_colmap.c (the COLMAP steps). Not installed. */
#ifndef VF_SFM_POSES_INTERNAL_H
#define VF_SFM_POSES_INTERNAL_H

#include <jansson.h>

#include "vf/camera.h"
#include "vf/colmap.h"
#include "vf/colmap_model.h"
#include "vf/pose.h"
#include "vf/poses.h"
#include "vf/sfm_images.h"
#include "vf/workspace.h"

#define RETRIEVAL_IMAGES 40 /* retrieval matching: each frame with this many most similar */

/* The registration check (vf__poses_check): CHECK_FRAMES registered frames are matched all
 * pairs with each other and registered on their own; after a similarity alignment of the
 * camera centres the model disagrees with that when the rotations differ by more than
 * CHECK_MAX_ROTATION_DEG (median), a fifth of the frames are more than 5 degrees off, or the
 * centres by more than CHECK_MAX_POSITION (median, a share of the cameras' spread around their
 * centroid). Measured on the 50 fox photos under shuffled names: a right sequential model
 * 0.21 deg and 0.47%; a wrong one (overlap 4: its positions 6.6% of the spread off the
 * dataset's, rotations 3.5 deg) 9.8 deg, every frame over 5 deg. */
#define CHECK_FRAMES 16
#define CHECK_MAX_ROTATION_DEG 2.0
#define CHECK_MAX_POSITION 0.02

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
    int relaxed;                /* the model is a second mapping's, on fewer matches */
    json_t *seconds;            /* wall time per step */
    int checking;               /* the registration check's steps are timed as "check" */
    json_t *check;              /* its result for the summary, or NULL (not run) */
    const char *fallback;       /* the automatic matcher given up for all pairs, or NULL */
} poses_run;

/* COLMAP steps (poses_colmap.c); each adds its wall time to run->seconds. */
vf_status vf__poses_extract_features(poses_run *run);
vf_status vf__poses_match(poses_run *run);
/* Map, convert every model COLMAP made to text, keep the largest in run->model and its text
 * files in stage/sparse. No model at all leaves run->model empty (0 images). */
vf_status vf__poses_map(poses_run *run);
/* The registration check of run->model; verdict "agrees", "disagrees" or "inconclusive"
 * (fewer than 3/4 of the sample registered on its own: its frames are too far apart for
 * their own model to be a reference; measured on 100 rendered views spread over a
 * hemisphere, 11 of 16 registered into a wrong model, 158 deg off a right one). Adds the sample's pairs to the
 * database, which a later exhaustive matching then reuses. */
typedef struct poses_check {
    int sampled, registered; /* frames in the sample; of them, registered on their own */
    vf_pose_agreement agreement;
    const char *verdict;
    double seconds;
} poses_check;
vf_status vf__poses_check(poses_run *run, poses_check *out);
/* Undistorted pinhole images in stage/undistorted/images and their cameras in `out`. */
vf_status vf__poses_undistort(poses_run *run, vf_colmap_model *out);

#endif
