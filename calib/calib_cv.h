/* calib/calib_cv.h: OpenCV's camera calibration, for calib/ (internal to the library).
 *
 * Board corners lie on z = 0 at object_xy (2 per corner); uv[v] holds view v's 2 * corners
 * pixel positions (vf/camera.h convention), NaN for corners the view did not see. Poses are
 * 6 doubles per view: rotation vector and translation, board -> camera in OpenCV axes
 * (x_cam = R x_board + t). */
#ifndef VF_CALIB_CV_H
#define VF_CALIB_CV_H

#include "vf/camera.h"
#include "vf/calib.h"
#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ChArUco (charuco_cv.cpp): the board's printable image, and its corners in a frame (as
 * vf_calib_find_board, which calls it for boards with markers). */
vf_status vf_cv_charuco_image(const vf_calib_board *board, int square_px, vf_rgb8 *out);
vf_status vf_cv_find_charuco(const vf_rgb8 *frame, const vf_calib_board *board, double *uv,
                             double quad[8], int *found);

/* calibrateCamera with the OPENCV lens (k3 and higher fixed at 0): cam gets width, height,
 * fx, fy, cx, cy, k1, k2, p1, p2; poses (6 * views) the board poses. */
vf_status vf_cv_calibrate(const double *object_xy, int corners, const double *const *uv,
                          int views, int width, int height, vf_camera *cam, double *poses);

#ifdef __cplusplus
}
#endif
#endif
