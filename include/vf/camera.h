/* vf/camera.h: camera intrinsics and lens distortion.
 *
 * One model for every camera in the tool: a pinhole (fx, fy, cx, cy in pixels, origin at the
 * top-left corner of the top-left pixel, pixel centres at +0.5) plus COLMAP's OPENCV distortion
 * (radial k1, k2; tangential p1, p2). A pinhole camera is the same struct with zero distortion.
 * Projection works in OpenCV camera axes (x right, y down, z forward); vf/pose.h converts to
 * and from the OpenGL axes used for camera-to-world matrices. Plain values, no ownership. */
#ifndef VF_CAMERA_H
#define VF_CAMERA_H

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

#ifdef __cplusplus
}
#endif
#endif
