/* vf/camera.h: camera intrinsics and lens distortion.
 *
 * One model for every camera in the tool: a pinhole (fx, fy, cx, cy in pixels, origin at the
 * top-left corner of the top-left pixel, pixel centres at +0.5) plus COLMAP's OPENCV distortion
 * (radial k1, k2; tangential p1, p2). A pinhole camera is the same struct with zero distortion.
 * Projection works in OpenCV camera axes (x right, y down, z forward); vf/pose.h converts to
 * and from the OpenGL axes used for camera-to-world matrices. Plain values, no ownership. */
#ifndef VF_CAMERA_H
#define VF_CAMERA_H

#include <jansson.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_camera {
    int width, height;
    double fx, fy, cx, cy;
    double k1, k2, p1, p2;
} vf_camera;

/* A pinhole camera from a horizontal field of view (radians), principal point at the centre. */
vf_camera vf_camera_from_fov(int width, int height, double fov_x);

/* The same camera for images scaled to new_width x new_height (fx, cx scale with the width,
 * fy, cy with the height; distortion acts on normalized coordinates and is unchanged). */
vf_camera vf_camera_scaled(const vf_camera *cam, int new_width, int new_height);

int vf_camera_has_distortion(const vf_camera *cam);

/* Apply / remove the lens distortion on normalized image coordinates (x/z, y/z):
 *   x_d = x (1 + k1 r^2 + k2 r^4) + 2 p1 x y + p2 (r^2 + 2 x^2)
 *   y_d = y (1 + k1 r^2 + k2 r^4) + p1 (r^2 + 2 y^2) + 2 p2 x y,   r^2 = x^2 + y^2.
 * Undistort inverts this by Newton's method (to about 1e-15 on ordinary lenses). */
void vf_camera_distort(const vf_camera *cam, double x, double y, double *xd, double *yd);
void vf_camera_undistort(const vf_camera *cam, double xd, double yd, double *x, double *y);

/* A point in OpenCV camera axes to pixel coordinates (with distortion): u = fx x_d + cx,
 * v = fy y_d + cy. Returns 0 (u, v untouched) when the point is not in front (z <= 0). */
int vf_camera_project(const vf_camera *cam, const double p_cam[3], double *u, double *v);

/* The unit ray through pixel (u, v), in OpenCV camera axes (distortion removed). */
void vf_camera_pixel_ray(const vf_camera *cam, double u, double v, double dir[3]);

/* ---- the camera as JSON: one format and one set of bounds for every file that holds one
 * (camera files from `calib`, attack.json, the intrinsics of transforms files) ---- */

/* The bounds every camera read from a file must meet: whole sizes from 1 to
 * VF_CAMERA_MAX_SIDE, focal lengths above 0 and below VF_CAMERA_MAX_PIXELS, principal point
 * within +-VF_CAMERA_MAX_PIXELS, distortion terms within +-VF_CAMERA_MAX_DISTORTION (all
 * bounds exclusive). */
#define VF_CAMERA_MAX_SIDE 100000
#define VF_CAMERA_MAX_PIXELS 1e7
#define VF_CAMERA_MAX_DISTORTION 100
/* VF_OK, or VF_EINPUT naming the first value out of those bounds. */
vf_status vf_camera_check(const vf_camera *cam);

/* {"fl_x", "fl_y", "cx", "cy", "w", "h", "k1", "k2", "p1", "p2"} (a new reference). */
json_t *vf_camera_json(const vf_camera *cam);
/* Read those keys from a JSON object (fx, fy, width and height are accepted for the first
 * ones; the distortion terms are optional, 0 when absent) and check the bounds. VF_EINPUT
 * "WHERE: ..." naming the key. */
vf_status vf_camera_from_json(const json_t *obj, const char *where, vf_camera *cam);

#ifdef __cplusplus
}
#endif
#endif
