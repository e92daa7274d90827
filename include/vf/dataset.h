/* vf/dataset.h: posed image sets in the NeRF "transforms.json" format.
 *
 * A dataset is a list of frames, each an image file with its camera intrinsics and a
 * camera-to-world matrix (row-major 4x4, OpenGL camera axes: x right, y up, looking along -z).
 * This is how posed data enters and leaves vfcapture: `ingest --transforms` imports it, `poses`
 * writes it, `train` and `eval` read it. Intrinsics come from camera_angle_x, or from
 * fl_x/fl_y/cx/cy/w/h (+ k1,k2,p1,p2), at the top level or per frame; image paths are relative
 * to the JSON file's folder, and a path without an extension gets ".png" (NeRF-synthetic).
 *
 * vf_dataset_load fills a vf_dataset the caller releases with vf_dataset_free. */
#ifndef VF_DATASET_H
#define VF_DATASET_H

#include "vf/camera.h"
#include "vf/error.h"
#include "vf/fsutil.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_frame {
    char image_path[VF_PATH_MAX]; /* resolved path of the image file */
    vf_camera camera;
    double c2w[16];               /* camera-to-world, row-major, OpenGL camera axes */
} vf_frame;

typedef struct vf_dataset {
    char source[VF_PATH_MAX];     /* the JSON file it came from */
    int count;
    vf_frame *frames;
} vf_dataset;

/* Read a transforms file and check every frame's image exists (and its size when the file
 * gives w/h). Errors name the file and the missing or malformed field. */
vf_status vf_dataset_load(const char *transforms_path, vf_dataset *out);

/* The posed frames the field of a workspace trains on (vf_workspace_training_views picks the
 * file; *real_capture, may be NULL, is 1 for frames the poses stage posed). */
struct vf_workspace;
vf_status vf_dataset_load_training(const struct vf_workspace *ws, vf_dataset *out,
                                   int *real_capture);

/* The frames' camera-to-world matrices, count x 16 in a new array (NULL when out of memory). */
double *vf_dataset_poses(const vf_dataset *ds);

/* Write a transforms file (atomically) with per-frame intrinsics; image paths are written
 * relative to the JSON file's folder when they lie under it. */
vf_status vf_dataset_save(const char *transforms_path, const vf_dataset *ds);

void vf_dataset_free(vf_dataset *ds);

#ifdef __cplusplus
}
#endif
#endif
