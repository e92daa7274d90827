/* vf/poses.h: the poses stage, camera poses for the ingested frames by structure from motion.
 *
 * WS/ingest/images -> WS/poses/ with COLMAP (vf/colmap.h; CPU, headless): the frames as COLMAP
 * read them (images/, alpha composited on white), its database and log, its sparse model
 * (sparse/, COLMAP's frame), and in the object frame (z up, object at the origin, cameras at
 * a mean distance of 4; vf/normalize.h): transforms.json (OpenGL camera-to-world, COLMAP's
 * lens), points3D.txt, normalization.json, and undistorted pinhole images (undistorted/) with
 * transforms_undistorted.json. Fewer than min_registered of the frames registering is
 * VF_EINPUT saying what usually causes it; a failed run keeps a copy of COLMAP's log in
 * $TMPDIR and names it.
 *
 * The "auto" matcher chooses by what the frames are (the ingest report says): up to 40
 * frames, all pairs; frames of a video or webcam, in capture order, sequential; a photo
 * folder, whose file names say nothing about where the photos were taken, all pairs up to 80
 * photos and beyond that retrieval (each photo with its 40 most similar by a vocabulary tree
 * built from the capture's own features). A model from sequential or retrieval matching is
 * then checked: 16 of its frames, matched all pairs with each other and registered on their
 * own, must agree with it (medians under 2 deg and 2% of the cameras' spread, no more than a
 * fifth over 5 deg).
 * When they disagree, or too few frames register, "auto" falls back to all pairs; with a
 * matcher the user chose either is VF_EINPUT. The
 * "auto" camera model is OPENCV, or SIMPLE_RADIAL
 * when more than 40% of the frames' pixels are removed background (few features).
 *
 * A posed set (`ingest --transforms`) keeps its poses and its camera: COLMAP extracts features
 * with the set's intrinsics, matches each frame with the 20 frames nearest in viewing direction
 * by those poses (or by --matcher), and only triangulates points at the poses
 * (point_triangulator, poses and intrinsics fixed); the outputs are those above, with the
 * set's poses moved into the object frame ("mapping": "known poses", "matches_explained": the
 * share of the features matched between frames that the points take in). Poses that do not
 * fit the photos (another axis convention, another photo's pose) leave most matches
 * unexplained: under 10% is VF_EINPUT (measured: right poses 19-29%, shuffled 3%). Those
 * points are what the field's depth loss and object mode read. Measured on the instant-ngp
 * fox (50 photos):
 * 110 s (features 26 s, 560 pairs 76 s), 9,670 points at 0.70 px. No point at all is
 * VF_EINPUT; --intrinsics, --camera and --camera-model are refused (the set brings its own). */
#ifndef VF_POSES_H
#define VF_POSES_H

#include <jansson.h>

#include "vf/camera.h"
#include "vf/error.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_poses_options {
    const char *matcher;      /* "auto", "sequential", "exhaustive", "retrieval" (auto) */
    const char *camera_model; /* "auto" or a COLMAP model name (auto) */
    const char *vocab_tree;   /* a tree for loop detection and retrieval, or NULL: build one */
    int overlap;              /* sequential matching: neighbours per frame (10) */
    int max_features;         /* SIFT features per frame (2048) */
    double min_registered;    /* share of frames that must register (0.5) */
    int undistort;            /* write the undistorted images (1) */
    int check;                /* check a sequential or retrieval model against all-pairs
                               * matching of a sample of its frames (1) */
    int has_intrinsics;       /* known camera, not refined: `known` holds it; width 0 means
                               * "stated for the frames as they are", else it is scaled */
    vf_camera known;
    const char *camera_file; /* where `known` came from, or NULL (for the log) */
} vf_poses_options;

void vf_poses_defaults(vf_poses_options *o);

/* The matcher "auto" chooses for `frames` frames, in capture order (a video, a webcam) or not
 * (photos): "exhaustive" or "retrieval" ("sequential", neighbours only, never closes the loop
 * of a walk around the object: only when asked). */
const char *vf_poses_auto_matcher(int frames, int ordered);

/* VF_EINPUT naming the option that cannot run. */
vf_status vf_poses_options_check(const vf_poses_options *o);

/* Run the stage on an open workspace with an ingest. *summary gets {"registered", "total",
 * "models", "unregistered", "reprojection_error_px", "points", "matcher" ("poses" for a
 * posed set's pairs by viewing direction), "camera_model",
 * "cameras", "up_method", "center_method", "scale_to_object", "seconds" {per COLMAP step},
 * "check" {"verdict", "sampled", "registered", "rotation_median_deg", ...} or null,
 * "mapping" ("default", or "relaxed": a model that left out more than a tenth of the frames was
 * mapped again admitting frames on 15 inliers, not 30, and registered more; "known poses": a
 * posed set's), and
 * "fallback_from" (the matcher first chosen) when "auto" fell back to all pairs}
 * (a new reference). */
vf_status vf_poses_run(vf_workspace *ws, const vf_poses_options *o, json_t **summary);

/* A posed set's poses stage moved its frames into the object frame: a test set that comes
 * with it (its transforms_test.json, in the set's frame) is moved the same way here, by
 * WS/poses/normalization.json. *moved is 1 when it was, 0 when the workspace's frames are the
 * set's own (no poses stage, or one that posed a capture: nothing to do). */
struct vf_dataset;
vf_status vf_poses_move_set_frames(const vf_workspace *ws, struct vf_dataset *ds, int *moved);

#ifdef __cplusplus
}
#endif
#endif
