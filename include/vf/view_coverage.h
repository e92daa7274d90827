/* vf/view_coverage.h: the ViewFool viewpoints a set of real photos covers.
 *
 * A radiance field renders garbage where no camera looked, so an attack on a real capture
 * should search only the viewpoints the capture covers. This converts each training camera
 * (camera-to-world, object frame, OpenGL axes) to its viewpoint (vf/pose.h) and takes the
 * range per parameter, with yaw handled on the circle (the covered arc is the complement of
 * the largest gap between cameras). Plain values; nothing is allocated. */
#ifndef VF_VIEW_COVERAGE_H
#define VF_VIEW_COVERAGE_H

#include "vf/error.h"
#include "vf/viewfool.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Margin added on each side of the covered range: this fraction of its width, but at least
 * VF_COVERAGE_MIN_DEG degrees (angles) or VF_COVERAGE_MIN_UNITS scene units (offsets). */
#define VF_COVERAGE_MARGIN 0.05
#define VF_COVERAGE_MIN_DEG 5.0
#define VF_COVERAGE_MIN_UNITS 0.1

/* The box of viewpoints `count` cameras cover (count x 16 doubles), margins included: psi as
 * an arc that may run past 180 (for example [150, 230]; the full [-180, 180] when cameras
 * surround the object with no gap over 60 degrees), theta clipped to [-89, 89].
 * VF_EINPUT when count < 2. */
vf_status vf_view_coverage(const double *c2w, int count, vf_view_bounds *out);

#ifdef __cplusplus
}
#endif
#endif
