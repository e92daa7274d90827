/* src/studio/studio_internal.h: the studio's walks (walk.c) and its film (film.c). Private to
 * src/studio. */
#ifndef VF_STUDIO_INTERNAL_H
#define VF_STUDIO_INTERNAL_H

#include "vf/camera.h"
#include "vf/object3d.h"
#include "vf/rgb8.h"
#include "vf/pose.h"
#include "vf/rng.h"
#include "vf/studio.h"

/* A smooth random signal: a sum of sines of random frequency in [f_lo, f_hi] Hz and random
 * phase, scaled so its standard deviation is `amplitude`. */
#define STUDIO_WAVES 6
typedef struct studio_wave {
    double freq[STUDIO_WAVES], phase[STUDIO_WAVES], amplitude;
} studio_wave;

void vf__wave_init(studio_wave *w, vf_rng *rng, double f_lo, double f_hi, double amplitude);
double vf__wave_at(const studio_wave *w, double t);

/* The hand holding the phone: shake of the position (object units) and tremor of the
 * rotation, both from the phone's shake scale. */
typedef struct studio_hand {
    studio_wave pos[3], tremor[3], roll;
} studio_hand;

void vf__hand_init(studio_hand *h, vf_rng *rng, double shake, double distance);
/* A camera at `eye` aiming at `aim` (z up, OpenGL axes), moved by the hand at time t. */
void vf__hand_camera(const studio_hand *h, double t, const double eye[3], const double aim[3],
                     double c2w[16]);
/* A camera held still at `steady`, moved by the hand at time t. */
void vf__hand_move(const studio_hand *h, double t, const double steady[16], double c2w[16]);

/* The phone's pinhole camera (upright frame). */
vf_camera vf__phone_camera(const vf_studio_phone *p);

/* The capture's walk: n = loops * loop_seconds * fps frames into c2w (n x 16, object frame).
 * Returns n, or -1 out of memory (*c2w NULL). */
int vf__capture_walk(const vf_studio_capture_options *o, double **c2w);

/* Render c2w[0..n) through the phone into video and write the truth document `truth` (stolen;
 * its "frames" are filled in here, each with the fields of extra[i] when extra is not NULL)
 * beside it. obj->transform.scale 0: fitted (and put in the truth). */
vf_status vf__film(const struct vf_object3d *obj, const vf_studio_phone *phone,
                   const double *c2w, int n, const json_t *extra, const char *video,
                   json_t *truth, json_t **report);

/* A capture's truth file (vf/studio.h), loaded. */
typedef struct capture_truth {
    json_t *doc;
    struct vf_object3d obj; /* model, transform, room */
    vf_camera camera;       /* the upright frames */
    double fps;
    int count;
    double *c2w;            /* count x 16, model frame */
} capture_truth;

vf_status vf__truth_load(const char *path, capture_truth *t);
void vf__truth_free(capture_truth *t);

/* The capture's truth file of a workspace: `given`, or the one beside the ingested video. */
vf_status vf__truth_of_workspace(const vf_workspace *ws, const char *given, char *out,
                                 size_t size);

/* The similarity from the model's frame to the workspace's: the capture's true camera centres
 * against the poses stage's, matched by the video frame each ingested image came from.
 * *report gets {"frames", "scale", "rotation_median_deg", "position_median"}. */
vf_status vf__align_workspace(const vf_workspace *ws, const capture_truth *t, vf_similarity *s,
                              json_t **report);

/* The phone's sensor on one rendered frame: exposure gain on linear light, shot and read
 * noise scaled by phone->noise, then the image processor's denoising (phone->denoise). */
vf_status vf__develop(vf_rgb8 *img, double gain, const vf_studio_phone *phone, vf_rng *rng);

/* The upright frames dir/f00001.png... as the phone stores them (H.264, sideways, rotation
 * flag) into video; FFmpeg's log in work/. */
vf_status vf__encode(const char *dir, double fps, const char *video, const char *work);

/* What reshoot's advice asked (vf_advice_text's words read back, as the person reads the
 * screen): degrees, distances in workspace units. given = 0: no advice (NULL text). */
typedef struct read_advice {
    int given;
    double orbit, raise, back, pan, tilt, roll;
} read_advice;

/* Read "orbit 12 deg right, raise 5 cm, step back 0.20 units, turn 3 deg left, tilt 2 deg up,
 * roll 3 deg counterclockwise" (cm through metres_per_unit; "hold still: on target" is all
 * zeros). */
read_advice vf__read_advice(const char *text, double metres_per_unit);

/* A closed-loop re-shoot (follow.c): the person moves by reshoot's advice. */
vf_status vf__follow(vf_workspace *ws, capture_truth *t, const vf_similarity *to_ws,
                     const vf_studio_phone *phone, const vf_studio_reshoot_options *o,
                     const char *video, const char *truth_path, json_t *alignment,
                     json_t **report);

#endif
