/* src/localize/localize_internal.h (internal): the pieces behind vf/localize.h.
 *
 *   localize_db.c     descriptors of the model's 3D points from COLMAP's database.db
 *   localize_cv.cpp   SIFT on a frame, nearest-neighbour index, PnP with RANSAC (OpenCV)
 *   pose_ceres.cpp    robust reprojection refinement of one pose (Ceres)
 *   localize.c        the flow, thresholds and frames
 *
 * Descriptors everywhere are 128 uint8 in COLMAP's convention (RootSIFT: L1-normalised,
 * square-rooted, times 512, clipped to 255), so a frame's features compare directly with
 * the ones COLMAP stored. */
#ifndef VF_LOCALIZE_INTERNAL_H
#define VF_LOCALIZE_INTERNAL_H

#include "vf/camera.h"
#include "vf/colmap_model.h"
#include "vf/error.h"
#include "vf/rgb8.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_DESC_DIM 128

/* The map: one row per observation of a 3D point in a registered image. */
typedef struct vf_loc_map {
    int count;
    unsigned char *descriptors; /* count x 128 */
    int *point;                 /* index into the model's points, per row */
} vf_loc_map;

/* Read the descriptors of every track observation of `model`'s points from database.db.
 * VF_EINPUT when the file is not a COLMAP database or lacks an image of the model. */
vf_status vf_loc_map_load(const char *database, const vf_colmap_model *model, vf_loc_map *out);
void vf_loc_map_free(vf_loc_map *map);

/* SIFT features of a frame, at most max_features (strongest first): pixel positions
 * (count x 2) and descriptors (count x 128), malloc'd into *xy and *desc (caller frees). */
vf_status vf_loc_sift(const vf_rgb8 *frame, int max_features, double **xy, unsigned char **desc,
                      int *count);

/* Approximate nearest neighbours over the map's descriptors (a FLANN k-d forest). */
typedef struct vf_loc_index vf_loc_index;
vf_status vf_loc_index_build(const vf_loc_map *map, vf_loc_index **out);
void vf_loc_index_free(vf_loc_index *index);

/* For each query descriptor, the nearest map row and the nearest row of another 3D point; a
 * match (query i -> that point) is kept when best < ratio * second (Lowe's test across
 * points, so several views of one point do not veto each other). Writes query indices and
 * point indices of the kept matches (each array sized n) and their number to *matches. */
vf_status vf_loc_index_match(const vf_loc_index *index, const vf_loc_map *map,
                             const unsigned char *desc, int n, double ratio, int *query,
                             int *point, int *matches);

/* Absolute pose by RANSAC (AP3P minimal sets, then EPnP on the inliers) from n 3D points
 * (n x 3) and their undistorted pixel positions (n x 2) for the pinhole fx, fy, cx, cy.
 * Writes world-to-camera rvec / t (OpenCV axes) and the inlier mask (n bytes); *found is 0
 * when no pose was found. */
vf_status vf_loc_pnp_ransac(const double *xyz, const double *uv, int n, const vf_camera *pinhole,
                            double threshold_px, int iterations, double rvec[3], double t[3],
                            unsigned char *inlier, int *found);

/* Refine a world-to-camera pose (rvec, t updated in place) by minimising the reprojection
 * error through the full lens (camera, with distortion) over n correspondences (xyz: n x 3,
 * uv: n x 2 observed pixels), each under a Cauchy loss of scale loss_px, so outliers fade out
 * instead of pulling. */
vf_status vf_loc_refine_pose(const vf_camera *cam, const double *xyz, const double *uv, int n,
                             double loss_px, double rvec[3], double t[3]);

#ifdef __cplusplus
}
#endif
#endif
