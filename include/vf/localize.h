/* vf/localize.h: where was this frame taken? Registering new frames against a workspace's
 * sparse model.
 *
 * The map is what `vfcapture poses` left in WS/poses/: COLMAP's sparse model (sparse/), the
 * SIFT descriptors of its images (database.db) and the object frame (normalization.json). A
 * frame is localized by
 *   1. SIFT features (OpenCV) in COLMAP's descriptor convention (RootSIFT, uint8),
 *   2. matching them to the descriptors of the model's 3D point observations (FLANN, Lowe's
 *      ratio test between different 3D points),
 *   3. absolute pose by RANSAC on the undistorted matches (OpenCV solvePnPRansac),
 *   4. refinement of the pose through the full lens with a robust (Cauchy) reprojection loss
 *      (Ceres), and a final count of inliers under the refined pose.
 * A pose is only reported when the inliers are numerous (min_inliers) and a large enough
 * share of the matches (min_inlier_ratio); otherwise the result says "not localized: N
 * inliers" and why. A wrong pose is never handed out silently.
 *
 * Intrinsics: the camera COLMAP found for the capture, or a calibration (vf_camera); frames of
 * another size but the same aspect ratio use it scaled.
 *
 * Also here: smoothing a stream of poses (for live guidance).
 *
 * Threads: a vf_localizer is used by one thread at a time. Memory: vf_localizer_open
 * allocates the localizer, vf_localizer_close frees it; results are plain values. */
#ifndef VF_LOCALIZE_H
#define VF_LOCALIZE_H

#include <jansson.h>

#include "vf/camera.h"
#include "vf/error.h"
#include "vf/pose.h"
#include "vf/rgb8.h"
#include "vf/sfm_export.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_localize_options {
    int max_features;        /* SIFT features per frame (default 4096) */
    int max_side;            /* frames are shrunk to this longer side first (default 1024) */
    double ratio;            /* Lowe's ratio test (default 0.8) */
    double ransac_px;        /* RANSAC inlier threshold, pixels of the working frame (default 6) */
    int ransac_iterations;   /* default 2000 */
    double loss_px;          /* Cauchy loss scale of the refinement, pixels (default 2) */
    int min_inliers;         /* fewer inliers: not localized (default 20) */
    double min_inlier_ratio; /* fewer inliers per ratio-tested match: not localized (0.2) */
    int has_camera;          /* use `camera` instead of the model's camera */
    vf_camera camera;        /* a calibration, for frames of its size (or aspect) */
} vf_localize_options;

void vf_localize_defaults(vf_localize_options *opt);

typedef struct vf_localize_result {
    int localized;           /* 1: the pose fields are valid */
    char reason[160];        /* when not localized: "not localized: 12 inliers (need 30)" */
    int features;            /* SIFT features found */
    int matches;             /* of those, matched to a 3D point */
    int inliers;             /* matches within ransac_px under the refined pose */
    double inlier_ratio;     /* inliers / matches */
    double reprojection_px;  /* mean reprojection error of the inliers, pixels of the frame */
    double c2w_object[16];   /* camera-to-world, object frame, OpenGL axes */
    double c2w_colmap[16];   /* camera-to-world, COLMAP's frame, OpenGL axes */
    vf_viewpoint viewpoint;  /* the ViewFool viewpoint of c2w_object (vf/pose.h) */
    double seconds;          /* wall time of this frame */
} vf_localize_result;

typedef struct vf_localizer vf_localizer;

/* Load the map of a workspace (WS/poses/sparse, database.db, normalization.json). VF_EINPUT
 * when its poses stage is not complete and current (vf_workspace_need: run `vfcapture poses`
 * first) or its files are missing or inconsistent. */
vf_status vf_localizer_open(const vf_workspace *ws, const vf_localize_options *opt,
                            vf_localizer **out);
void vf_localizer_close(vf_localizer *loc);

/* Map size, for reports: 3D points and descriptors (observations) in the index. */
void vf_localizer_map_size(const vf_localizer *loc, int *points, int *descriptors);

/* The camera a frame of width x height is localized with: the calibration given, else the
 * capture's camera of the same aspect ratio, scaled (lens included). VF_EINPUT when the frame
 * fits neither (another aspect ratio or orientation). */
vf_status vf_localizer_camera(const vf_localizer *loc, int width, int height, vf_camera *cam);

/* Localize one frame. A frame that cannot be localized is VF_OK with result->localized = 0
 * and the reason; errors are for frames that cannot be used at all (a size whose aspect ratio
 * does not fit the camera) or internal failures. */
vf_status vf_localize_frame(vf_localizer *loc, const vf_rgb8 *frame, vf_localize_result *result);

/* {"localized", "features", "matches", "inliers", "inlier_ratio", "reprojection_px",
 * "seconds"} and either "reason" or "viewpoint", "c2w_object", "c2w_colmap" (a new
 * reference). */
json_t *vf_localize_result_json(const vf_localize_result *r);

/* ---- smoothing a stream of poses ---- */

/* Exponential smoothing of camera-to-world matrices: position by linear blending, rotation by
 * moving a share `alpha` of the way along the geodesic to the new rotation. A jump larger
 * than reset_deg or reset_distance restarts from the new pose (the person moved on). */
typedef struct vf_pose_smoother {
    double alpha;            /* weight of the newest pose, 0..1 (default 0.4) */
    double reset_deg;        /* default 30 */
    double reset_distance;   /* scene units, default 1 */
    int has_pose;
    double c2w[16];
} vf_pose_smoother;

void vf_pose_smoother_init(vf_pose_smoother *s, double alpha);
/* Add a pose; out (may alias c2w) receives the smoothed pose. */
void vf_pose_smoother_add(vf_pose_smoother *s, const double c2w[16], double out[16]);

#ifdef __cplusplus
}
#endif
#endif
