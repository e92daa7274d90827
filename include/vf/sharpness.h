/* vf/sharpness.h: how sharp a frame is, and a fingerprint to spot near-duplicates.
 *
 * A frame's score is measured on a grey copy shrunk (area averaging) so its longer side is at
 * most VF_SHARPNESS_SIDE pixels: the variance of its 4-neighbour Laplacian. Shrinking first
 * keeps sensor noise and compression blocks from passing for detail, makes the score
 * comparable between frames of different sizes, and keeps it cheap (about 1 ms a frame).
 * Scores are only meaningful relative to each other (frames of one capture).
 *
 * The thumbnail is a VF_THUMB_SIDE x VF_THUMB_SIDE grey version of the whole frame (aspect
 * ignored); two frames whose thumbnails differ by a grey level or two show the same view.
 * A vf_frame_score is a plain value: nothing to free. */
#ifndef VF_SHARPNESS_H
#define VF_SHARPNESS_H

#include "vf/error.h"
#include "vf/rgb8.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_SHARPNESS_SIDE 640
#define VF_THUMB_SIDE 32

typedef struct vf_frame_score {
    double sharpness; /* variance of the Laplacian, grey levels squared */
    unsigned char thumb[VF_THUMB_SIDE * VF_THUMB_SIDE];
} vf_frame_score;

/* Score one frame. Fails only when out of memory. */
vf_status vf_score_frame(const vf_rgb8 *frame, vf_frame_score *out);

/* Mean absolute difference of two thumbnails, in grey levels (0..255). */
double vf_thumb_difference(const vf_frame_score *a, const vf_frame_score *b);

#ifdef __cplusplus
}
#endif
#endif
