/* calib/calib_ceres.h: Ceres refinement of a calibration (internal to the library).
 *
 * Same layout as calib/calib_cv.h: board corners at object_xy on z = 0, uv[v] the
 * pixels of view v, poses 6 doubles per view (rotation vector, translation; board -> camera,
 * OpenCV axes). */
#ifndef VF_CALIB_CERES_H
#define VF_CALIB_CERES_H

#include "vf/camera.h"
#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Refine cam (fx, fy, cx, cy, k1, k2, p1, p2) and every pose together, minimizing the
 * reprojection error under a Huber loss of scale huber_px (a corner off by more than that
 * counts linearly, not squared). cam and poses are starting values and results. */
vf_status vf_ceres_refine_calibration(vf_camera *cam, double *poses, int views,
                                      const double *object_xy, int corners,
                                      const double *const *uv, double huber_px);

#ifdef __cplusplus
}
#endif
#endif
