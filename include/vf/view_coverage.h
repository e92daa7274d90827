/* vf/view_coverage.h: the ViewFool viewpoints a set of real photos covers, and how far any
 * viewpoint is from them (the field's trust there).
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

/* ---- how far a viewpoint is from the photos: the field's trust there ----
 *
 * A field is right where photos saw the object and fog where none did; what it renders
 * between photos degrades with the distance to the nearest one. The gap of a camera c to a
 * photo's camera c_i (both camera-to-world, object at the origin) is
 *
 *     gap_i = sqrt( angle(c, c_i)^2 + ln(|c| / |c_i|)^2 )   (radians, reported in degrees)
 *
 * the angle between their directions from the object plus the log ratio of their distances
 * counted as an angle (10% closer weighs like 5.5 degrees of turn: a close-up sees detail no
 * wider photo resolved, a wider view sees surroundings no close-up saw). A viewpoint's gap is
 * the smallest over the photos the field was trained on. The threshold below which a view is
 * trusted, and how the gap predicts render error, were measured on real captures and the
 * shared 3D models (docs/field.md, "Where the field can be trusted"). */
#define VF_TRUST_GAP_DEG 20.0

typedef struct vf_view_trust {
    double gap_deg;        /* the smallest gap over the photos */
    int nearest;           /* the photo it is measured to */
    double angle_deg;      /* that photo's angle part */
    double distance_ratio; /* |c| / |c_nearest| */
} vf_view_trust;

/* The gap of camera c2w (4x4, camera-to-world) to the nearest of `count` photo cameras
 * (count x 16 doubles). count >= 1. */
vf_view_trust vf_view_trust_of_pose(const double *photos, int count, const double c2w[16]);
/* The same for a ViewFool viewpoint (psi, theta, phi, dx, dy, dz). */
vf_view_trust vf_view_trust_of(const double *photos, int count, const double view[VF_VIEW_DIM]);
/* 1 when the gap is at most VF_TRUST_GAP_DEG. */
int vf_view_trusted(const vf_view_trust *t);

#ifdef __cplusplus
}
#endif
#endif
