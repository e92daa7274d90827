/* vf/normalize.h: the object frame of a reconstructed scene (../shared/DESIGN.md, coordinate frames).
 *
 * Structure from motion returns cameras in an arbitrary frame and scale. The object frame puts
 * the object at the origin with z up and the cameras at a mean distance of 4
 * (VF_CAMERA_DISTANCE), the frame the ViewFool viewpoint is defined in:
 *   - up (+z): perpendicular to the cameras' x axes (photos are taken level, so image right is
 *     horizontal however the camera tilts); for cameras facing nearly one way (spread under
 *     about 15 degrees), the mean of their up vectors (people hold the camera upright);
 *   - origin: the point nearest to all optical axes (least squares), which is what the cameras
 *     look at; when the axes are (nearly) parallel or that point lies behind the cameras, the
 *     per-axis median of the sparse points in front of the cameras instead;
 *   - -y (where the viewpoint has psi = 0 for upright views, phi > 90): the mean horizontal
 *     direction from the origin to the cameras when they cluster on one side, else the first
 *     camera's; x = y cross z;
 *   - scale: mean distance from the cameras to the origin becomes 4.
 * Plain values, caller-owned arrays, nothing allocated that outlives a call. */
#ifndef VF_NORMALIZE_H
#define VF_NORMALIZE_H

#include "vf/error.h"
#include "vf/pose.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_normalization {
    vf_similarity object_from_world; /* x_object = scale * R x_world + t */
    double up_world[3];              /* the up direction found, in the input frame (unit) */
    double center_world[3];          /* the origin found, in the input frame */
    double world_distance;           /* mean camera distance to it, in input units */
    const char *up_method;           /* "level camera x axes" or "mean camera up" (static) */
    const char *center_method;       /* "optical axes" or "sparse points" (static string) */
} vf_normalization;

/* Find the object frame for `count` cameras (camera-to-world 4x4, OpenGL axes, count x 16
 * doubles) and optional sparse points (point_count x 3, may be NULL / 0). VF_EINPUT when there
 * are fewer than 2 cameras, their up vectors cancel out, or no centre can be found. */
vf_status vf_normalize_scene(const double *c2w_gl, int count, const double *points,
                             int point_count, vf_normalization *out);

#ifdef __cplusplus
}
#endif
#endif
