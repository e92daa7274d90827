/* vf/sfm_export.h: a COLMAP reconstruction as the poses stage hands it on.
 *
 * Three outputs, all in the object frame of vf/normalize.h:
 *   - a vf_dataset (NeRF transforms.json) of the registered frames: OpenGL camera-to-world
 *     matrices and each frame's COLMAP camera;
 *   - points3D.txt: the sparse points, in COLMAP's text layout (POINT3D_ID X Y Z R G B ERROR
 *     then (IMAGE_ID POINT2D_IDX) pairs, ids as in COLMAP's model and database), kept for
 *     relocalizing new photos later;
 *   - normalization.json: the similarity between the object frame and COLMAP's frame, both
 *     ways, with how it was found.
 * The dataset's frames are the caller's to free (vf_dataset_free). */
#ifndef VF_SFM_EXPORT_H
#define VF_SFM_EXPORT_H

#include "vf/colmap_model.h"
#include "vf/dataset.h"
#include "vf/normalize.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The registered images of `model` moved by `object_from_model`, sorted by name, each with
 * image path image_dir/NAME and its camera converted by vf_colmap_camera_to_vf. */
vf_status vf_sfm_dataset(const vf_colmap_model *model, const vf_similarity *object_from_model,
                         const char *image_dir, vf_dataset *out);

/* Write the model's points, moved by `object_from_model`, to `path` (atomically). */
vf_status vf_sfm_save_points(const char *path, const vf_colmap_model *model,
                             const vf_similarity *object_from_model);

/* Write normalization.json: object_from_colmap and colmap_from_object (scale, rotation,
 * translation, 4x4 matrix), the up direction and centre found in COLMAP's frame, the method,
 * and the mean camera distance before (COLMAP units) and after (4). */
vf_status vf_sfm_save_normalization(const char *path, const vf_normalization *norm);

/* The file's name in WS/poses. */
#define VF_NORMALIZATION_FILE "normalization.json"

/* Read normalization.json: the similarity from COLMAP's frame to the object frame and back
 * (either output may be NULL). VF_EINPUT naming the file when it is not valid JSON or its
 * similarity is not one (scale 1e-9..1e9, an orthonormal rotation with det +1). */
vf_status vf_normalization_load(const char *path, vf_similarity *object_from_colmap,
                                vf_similarity *colmap_from_object);
/* The same from a workspace's poses stage (WS/poses/normalization.json, the one place its path
 * is made). *found is 0, and VF_OK, when the stage has no such file (a posed set imported
 * without COLMAP's frame); found NULL makes that VF_EINPUT naming the file. */
vf_status vf_normalization_load_workspace(const vf_workspace *ws,
                                          vf_similarity *object_from_colmap,
                                          vf_similarity *colmap_from_object, int *found);

#ifdef __cplusplus
}
#endif
#endif
