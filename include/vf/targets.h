/* vf/targets.h: adversarial viewpoints as places a person can stand, and how to get there.
 *
 * The attack (WS/attack/attack.json) leaves viewpoints v in the object frame (z up, object at
 * the origin). To reshoot them with a real camera they are turned into words: azimuth and
 * elevation of the camera around the object centre, its distance and height, the roll of the
 * image about the optical axis, and the point it looks at; and, for a camera seen live,
 * advice on how to move from where it is to a target ("orbit 12 deg right, raise 5 cm").
 *
 * Angles in degrees. Azimuth is measured about +z from the -y axis (the side the capture was
 * centred on, see vf/normalize.h), increasing counterclockwise seen from above, so a camera
 * facing the object moves to its right as the azimuth grows. Roll is 0 for an upright image
 * (world up points up in the picture) and positive when the camera is turned clockwise as
 * its user sees it; an upside-down view has roll +-180.
 *
 * Everything works on caller-owned plain values. attack.json itself is read through
 * vf/attack_file.h. */
#ifndef VF_TARGETS_H
#define VF_TARGETS_H

#include <jansson.h>

#include "vf/error.h"
#include "vf/fsutil.h"
#include "vf/pose.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- targets.json ---- */

/* The viewpoint of target n (from 0) of an export's targets.json. VF_EINPUT naming the file
 * when there is no such target or its six numbers are not finite and in range. */
vf_status vf_targets_file_target(const char *path, int n, vf_viewpoint *v);

/* Target n of WS/export/targets.json of the workspace at ws_root, and (c2w not NULL) its
 * object-frame camera-to-world. VF_EINPUT saying to run export first when there is none. */
vf_status vf_targets_workspace_target(const char *ws_root, int n, vf_viewpoint *v, double c2w[16]);


/* Whether viewpoint v lies within +-tolerance (a share, 0.05 for 5%) of each parameter's
 * measurement range (vf_attack_file.range) around `center`; psi differences wrap around 360
 * degrees. *worst (may be NULL) receives the largest |difference| / range. */
int vf_viewpoint_within(const vf_viewpoint *v, const vf_viewpoint *center, const double range[6],
                        double tolerance, double *worst);

/* ---- viewpoints in words ---- */

typedef struct vf_target_words {
    double azimuth_deg;      /* see the top comment */
    double elevation_deg;    /* of the camera above the horizontal plane through the centre */
    double distance;         /* camera to object centre */
    double height;           /* camera above the centre (z) */
    double roll_deg;
    double look_at[3];       /* the point of the optical axis nearest the object centre */
    double aim_offset;       /* its distance from the centre: how far off-centre it aims */
} vf_target_words;

/* Describe a camera-to-world matrix (object frame, OpenGL axes). Distances in scene units. */
void vf_target_describe(const double c2w_object[16], vf_target_words *out);

/* ---- choosing representative samples ---- */

/* Pick m of the n viewpoints (n x 6) spread over the set: first the medoid, then each time
 * the viewpoint farthest from all picked ones (distances per parameter as shares of range[i],
 * the measurement ranges, psi wrapping around). Writes min(m, n) indices to picked;
 * VF_EINTERNAL when out of memory. */
vf_status vf_targets_spread(const double *views, int n, const double range[6], int m,
                            int *picked);

/* ---- guidance ---- */

typedef struct vf_advice {
    double orbit_deg;        /* move around the object: + right, - left */
    double raise;            /* + up, - down (scene units) */
    double back;             /* + step back, - step closer (scene units) */
    double pan_deg;          /* then aim off the object: + right, - left */
    double tilt_deg;         /* + up, - down */
    double roll_deg;         /* + clockwise, - counterclockwise */
} vf_advice;

/* How to move from camera `current` to camera `target` (both c2w, object frame): orbit,
 * raise and step to the target's azimuth, height and distance, keeping the object in view;
 * pan and tilt are how much further the target aims off the object's centre (right, up) than
 * the current camera does (0 for two cameras that both aim at the centre, wherever they
 * stand); roll about the optical axis. */
void vf_advice_compute(const double current[16], const double target[16], vf_advice *out);

/* The advice as words, e.g. "orbit 12 deg right, raise 5 cm, step back 20 cm, roll 3 deg
 * clockwise"; steps under the thresholds (angles in degrees, distances in scene units) are
 * left out, and "hold still: on target" when all are. metres_per_unit > 0 gives distances in
 * cm, else in scene units. */
void vf_advice_text(const vf_advice *a, double metres_per_unit, double min_deg,
                    double min_distance, char *out, size_t size);

#ifdef __cplusplus
}
#endif
#endif
