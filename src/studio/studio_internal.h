/* src/studio/studio_internal.h: the studio's walks (walk.c) and its film (film.c). Private to
 * src/studio. */
#ifndef VF_STUDIO_INTERNAL_H
#define VF_STUDIO_INTERNAL_H

#include "vf/camera.h"
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
struct vf_object3d;
vf_status vf__film(const struct vf_object3d *obj, const vf_studio_phone *phone,
                   const double *c2w, int n, const json_t *extra, const char *video,
                   json_t *truth, json_t **report);

#endif
