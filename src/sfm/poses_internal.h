/* src/sfm/poses_internal.h: the poses stage's pieces, shared by poses.c (the flow, the
 * outputs) and poses_colmap.c (the COLMAP steps). Not installed. */
#ifndef VF_SFM_POSES_INTERNAL_H
#define VF_SFM_POSES_INTERNAL_H

#include <jansson.h>

#include "vf/camera.h"
#include "vf/colmap.h"
#include "vf/colmap_model.h"
#include "vf/dataset.h"
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
    int posed;                  /* WS/ingest is a posed set: its poses are kept */
    vf_dataset set;             /* that set (WS/ingest/transforms.json), when posed */
    double explained;           /* posed: the share of matched features its points take in */
} poses_run;

/* COLMAP steps (poses_colmap.c); each adds its wall time to run->seconds. */
/* Run one COLMAP command (args->items[0]), timed under its name; frees args. */
vf_status vf__poses_run_step(poses_run *run, const char *label, vf_args *args);
/* COLMAP's binary model in `input` as text files in `output` (created). */
vf_status vf__poses_convert_to_text(poses_run *run, const char *input, const char *output);
/* Move the kept model's text files to stage/sparse. */
vf_status vf__poses_keep_model_text(poses_run *run, const char *text);
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


/* A posed set (poses_known.c): its poses and camera kept, COLMAP only triangulates points. */
/* Load WS/ingest/transforms.json into run->set; its one camera becomes the known intrinsics
 * (VF_EINPUT when frames differ in camera, or the user gave intrinsics too). */
vf_status vf__poses_load_set(poses_run *run, const vf_workspace *ws);
/* Match each frame with the frames nearest in viewing direction, by the set's poses. */
vf_status vf__poses_match_posed(poses_run *run);
/* Triangulate at the set's poses into run->model (kept in stage/sparse); VF_EINPUT when no
 * point could be triangulated, or the points take in too few of the matched features (poses
 * that do not fit the photos). */
vf_status vf__poses_triangulate(poses_run *run);

#endif
