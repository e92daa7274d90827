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
 * Memory: vf_attack_file_load fills a struct that owns its arrays (vf_attack_file_free);
 * everything else works on caller-owned plain values. */
#ifndef VF_TARGETS_H
#define VF_TARGETS_H

#include "vf/camera.h"
#include "vf/classifier.h"
#include "vf/error.h"
#include "vf/fsutil.h"
#include "vf/pose.h"
#include "vf/viewfool.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- attack.json, as far as the physical loop reads it ---- */

typedef struct vf_sample_prediction {
    int cls;                 /* predicted class index, -1 when unknown */
    char name[96];
    double confidence;
    int fooled;
} vf_sample_prediction;

typedef struct vf_attack_file {
    char model[VF_PATH_MAX];        /* classifier the attack used ("" when not given) */
    int label_count;
    int labels[VF_MAX_LABELS];      /* the true label set */
    char label_text[256];           /* its names, comma-separated */
    double lo[6], hi[6];            /* the attack's search box */
    double range[6];                /* measurement ranges ("measure_ranges"; the paper's full
                                     * ranges when absent): tolerances are shares of these */
    vf_viewpoint v_star;
    int sample_count;
    double *samples;                /* sample_count x 6: the samples of p*(v) */
    vf_sample_prediction *predictions; /* sample_count entries, or NULL when absent */
    vf_sample_prediction v_star_prediction; /* cls -1 when attack.json does not say */
    double natural_accuracy, asr_v_star, asr_samples; /* NAN when absent */
    int has_camera;
    vf_camera camera;               /* the render camera */
} vf_attack_file;

/* Read attack.json. VF_EINPUT naming the file and the missing key ("v_star", "bounds",
 * "label") when it cannot be used; samples, predictions, rates and camera are optional. */
vf_status vf_attack_file_load(const char *path, vf_attack_file *out);
void vf_attack_file_free(vf_attack_file *a);

/* The viewpoint of target n (from 0) of an export's targets.json. VF_EINPUT naming the file
 * when there is no such target or its six numbers are not finite and in range. */
vf_status vf_targets_file_target(const char *path, int n, vf_viewpoint *v);

/* Whether class `cls` belongs to the attack's label set. */
int vf_attack_is_label(const vf_attack_file *a, int cls);

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
    double pan_deg;          /* then turn the camera: + right, - left */
    double tilt_deg;         /* + up, - down */
    double roll_deg;         /* + clockwise, - counterclockwise */
} vf_advice;

/* How to move from camera `current` to camera `target` (both c2w, object frame): orbit,
 * raise and step to the target's azimuth, height and distance; pan and tilt are measured
 * after the orbit (which turns the camera with it); roll about the optical axis. */
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
